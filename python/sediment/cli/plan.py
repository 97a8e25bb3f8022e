# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment plan: which effects a scene calls for, from screening numbers and measured changes."""
from __future__ import annotations

import argparse
import math
from pathlib import Path

from ..constants import INSTRUMENTS
from ..progress import bar as progress_bar
from .sample import add_test_options, cylinder_of, suspension_of
from .types import count, positive, positive_list, quantity, setting


def _counts(text: str) -> list[int]:
    return [count(word) for word in text.split(",")]


def _ladder(text: str) -> tuple[str, list[str]]:
    name, values = setting(text, "a ladder is NAME=RICHEST,...,CHEAPEST")
    return name, [v.strip() for v in values.split(",")]


MAX_FLOW_SEEDS = 100
EXAMPLES = [
    'sediment plan examples/granulometry/psd/sample5.csv --out out/plan',
    'sediment plan --deck examples/planner/in.suspension --observe speed --out out/plan-deck',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser(
        "plan", help="the effects a scene calls for: screening numbers, measured changes and costs, the cheapest "
        "setting within a tolerance, its deck and a report",
        description="For a sedimentation test (PSD and the options of `sediment sample`) or a deck with "
        "'variable effect_NAME index yes' lines (--deck): screens every effect, runs the scene with each effect "
        "and resolution in question changed against the richest run, chooses the cheapest setting within "
        "--tolerance, verifies it with a run, and writes OUT/decision (the deck), effects.csv, trials.csv, "
        "report.json and plan.png. See docs/effects.md.")
    parser.add_argument("psd", type=Path, nargs="?", help="PSD table of the sample (CSV: diameter_um,percent_finer)")
    parser.add_argument("--deck", type=Path, help="plan a deck instead: it reads effect_NAME variables (yes/no), "
                        "prints RESULT/SERIES observables and may print 'SCREEN number value' lines")
    parser.add_argument("--tolerance", type=positive, help="largest error allowed: points of percent finer for a test "
                        "(default 0.5), relative for a deck (default 0.01)")
    parser.add_argument("--jobs", type=count, default=2, help="runs at once, one core each (default 2)")
    parser.add_argument("--out", type=Path, default=Path("out/plan"), help="output folder")
    parser.add_argument("--measure-all", action="store_true",
                        help="measure every effect, also those the screening settled")
    parser.add_argument("--screen-only", action="store_true", help="print the screening and stop (no runs)")
    parser.add_argument("--set", type=setting, action="append", metavar="NAME=VALUE",
                        help="fix an effect or resolution instead of planning it (e.g. hindrance=none, "
                        "particles=20000, contacts=no)")
    test = parser.add_argument_group("sedimentation test")
    add_test_options(test)
    test.add_argument("--instruments", nargs="+", default=list(INSTRUMENTS), choices=INSTRUMENTS,
                      help="the readings that make the answer")
    test.add_argument("--particles", type=_counts, default=[40000, 20000, 10000, 5000],
                      help="parcel ladder, comma-separated (default 40000,20000,10000,5000; the largest is the reference)")
    test.add_argument("--courant", type=positive_list, default=[1.0, 2.0, 4.0, 8.0],
                      help="Courant ladder, comma-separated (default 1,2,4,8; the smallest is the reference)")
    test.add_argument("--replicas", type=count, default=3,
                      help="runs of the reference with independent seeds (default 3): their mean stands for the "
                      "converged answer and their spread for its sampling error, which every error includes")
    test.add_argument("--no-models", action="store_true",
                      help="skip the runs of the other drag models (Bravo et al.'s difelice, Dallavalle's and Schiller "
                      "& Naumann's curves, Garside's and Di Felice's hindrance) against the reference")
    test.add_argument("--measure-contacts", action="store_true",
                      help="also measure what contacts, and contacts with lubrication, change: a reduced real-grain "
                      "scene (the grains above --contact-cut in a periodic box) run both ways, written to "
                      "OUT/contacts.csv and contacts.json (minutes; docs/effects.md section 5)")
    test.add_argument("--contact-cut", type=quantity("contact_cut"), metavar="UM",
                      help="smallest grain of the reduced scene [um] (default a third of the largest: smaller "
                      "grains meet larger ones with an interception efficiency below 9 %%)")
    test.add_argument("--measure-flow", action="store_true",
                      help="also measure what two-way coupling changes: the test's column of parcels three swirls "
                      "wide (20 000 parcels, or the largest of --particles) under fix fluid/flow and its one-way twin, "
                      "--flow-seeds draws, written to OUT/flow.csv "
                      "and flow.json (15-50 min per draw on one core for Bravo et al.'s samples; docs/effects.md "
                      "section 3)")
    test.add_argument("--flow-seeds", type=count, default=3, help="draws of --measure-flow (default 3)")
    test.add_argument("--flow-cells", type=count, default=None, metavar="N",
                      help="fix fluid/flow's cells across the column of --measure-flow (default 16; docs/effects.md "
                      "section 3 shows what the grid changes)")
    deck = parser.add_argument_group("deck")
    deck.add_argument("--observe", nargs="+", metavar="NAME", help="RESULT or SERIES names the deck prints")
    deck.add_argument("--ladder", type=_ladder, action="append", metavar="NAME=V1,V2",
                      help="a resolution variable of the deck, richest value first (e.g. dt=1e-5,2e-5,4e-5)")
    deck.add_argument("--var", nargs=2, action="append", metavar=("NAME", "VALUE"), help="LAMMPS -var for every run")
    deck.add_argument("--np", type=count, default=1, help="MPI ranks per deck run")
    # which options belong to which kind of scene, to refuse those that would be ignored
    parser.set_defaults(kinds={"test": {a.dest: a.default for a in test._group_actions},
                               "deck": {a.dest: a.default for a in deck._group_actions}})
    return parser


def run(args: argparse.Namespace) -> int:
    """Screens (and unless --screen-only measures and decides), prints the tables, writes the report."""
    from ..planner.plan import pin, plan_effects
    from ..planner.scenes import DeckScene, SampleScene
    from ..plausible import check

    if (args.psd is None) == (args.deck is None):
        raise ValueError("give either a PSD table (a sedimentation test) or --deck DECK")
    other = "test" if args.deck is not None else "deck"
    ignored = [name for name, default in args.kinds[other].items() if getattr(args, name) != default]
    if ignored:
        raise ValueError(f"--{ignored[0].replace('_', '-')} is an option of a {'sedimentation test' if other == 'test' else 'deck'}"
                         f", not of {'a deck' if other == 'test' else 'a sedimentation test'}")
    if args.tolerance is not None:    # its unit depends on the scene
        check(args.tolerance, "relative_tolerance" if args.deck is not None else "test_tolerance", "--tolerance")
    if args.deck is not None:
        from ..sim.deck import refuse_unread

        refuse_unread(args.deck, [name for name, _ in args.var or []])
        tolerance = args.tolerance or 0.01
        scene = DeckScene(args.deck, args.observe or [], dict(args.ladder or []), tolerance, dict(args.var or []),
                          args.np)
        name = args.deck.name
        if args.screen_only:
            raise ValueError("a deck is screened from the numbers its reference run prints: --screen-only needs a PSD")
    else:
        from ..lab.psd import read_psd
        from ..planner.screening import SedimentationTest

        tolerance = args.tolerance or 0.5
        psd = read_psd(args.psd)
        test = SedimentationTest(psd, suspension_of(args), cylinder_of(args), args.mass,
                                 tuple(dict.fromkeys(args.instruments)))
        options = dict(geometry=args.geometry, width=args.width, classes=args.classes, layers=args.layers,
                       t_end=args.t_end)
        scene = SampleScene(test, options, args.particles, args.courant, tolerance, args.replicas, not args.no_models)
        if args.temperature_record is not None:    # its trial runs follow it, and its report names it
            from ..lab.sheet import read_temperature_record

            scene.water_record = read_temperature_record(args.temperature_record, args.t_end)
        name = args.psd.stem
        if args.contact_cut is not None and not args.measure_contacts:
            raise ValueError("--contact-cut sets the reduced scene of --measure-contacts: give both")
        if args.flow_seeds > MAX_FLOW_SEEDS:
            raise ValueError(f"--flow-seeds {args.flow_seeds}: at most {MAX_FLOW_SEEDS} draws (each takes minutes to an "
                             "hour)")
        for name in ("flow_seeds", "flow_cells"):
            if getattr(args, name) != args.kinds["test"][name] and not args.measure_flow:
                raise ValueError(f"--{name.replace('_', '-')} sets the draws of --measure-flow: give both")
        if args.screen_only:
            if args.set:
                pin(scene, dict(args.set))    # a wrong setting named first
                raise ValueError("--set pins what the planner would decide: --screen-only decides nothing")
            _print_screens(scene.screens)
            if args.measure_contacts:
                _measure_contacts(test, args, tolerance)
            if args.measure_flow:
                _measure_flow(test, args, tolerance, options)
            return 0
    pin(scene, dict(args.set or []))
    plan = plan_effects(scene, args.out, tolerance, args.jobs, args.seed if args.deck is None else 1,
                        args.measure_all, name=name)
    print(plan.text(), end="")
    print(f"the chosen scene: {args.final_out / 'decision'}")
    if args.deck is None and args.measure_contacts:
        _measure_contacts(test, args, tolerance)
    if args.deck is None and args.measure_flow:
        measured = _measure_flow(test, args, tolerance, options)
        if measured.verdict(tolerance).startswith("fails"):
            from ..planner.flow import switch_on

            switch_on(args.out, scene, measured, tolerance)
            print(f"two-way coupling is on in the decision: {scene.describe(dict(plan.decision.settings, two_way=True))}")
    return 0


def _measure_flow(test, args: argparse.Namespace, tolerance: float, options: dict):
    """Runs --flow-seeds draws of the two-way column and its twin, --jobs at once, one bar each."""
    import json
    import sys

    from ..planner.flow import coarser_cells, draw_name, flow_scene, measure_draw, measure_flow
    from ..planner.scenes import prepare
    from ..results import write_text
    from ..sim.process import Runs

    seeds = [args.seed + k for k in range(args.flow_seeds)]
    options = {k: v for k, v in options.items() if k != "width"}    # the column's width is the swirls'
    if args.flow_cells is not None:
        options["flow_cells"] = args.flow_cells
    if args.particles != args.kinds["test"]["particles"]:    # else `sediment sample --two-way`'s 20 000
        options["particles"] = max(args.particles)
    first = flow_scene(test, seeds[0], **options)
    across, tall = first.flow_grid()
    check = coarser_cells(first)
    print(f"measuring two-way coupling: a column {first.width * 1e3:.3g} mm wide ({across} x {across} x {tall} cells), "
          f"{len(first.diameter)} parcels, {sum(n for _, n in first.stages())} steps, and its one-way twin, "
          f"{len(seeds)} draws" + (f", and seed {seeds[0]}'s on {check} cells across (the grid check)" if check else "")
          + f" ({min(args.jobs, len(seeds) + bool(check))} at once) ...", flush=True)
    running = Runs()
    folder = prepare(args.out / "flow")
    labels = {draw_name(seed): f"seed {seed}" for seed in seeds}
    if check:
        labels[draw_name(seeds[0], check)] = f"seed {seeds[0]}, {check} across"
    bars = {name: progress_bar(total=1, desc=f"two-way {label}", unit="step", position=k, file=sys.stderr,
                               dynamic_ncols=True, mininterval=0.5) for k, (name, label) in enumerate(labels.items())}

    def draw(test, scene, where):
        bar = bars[where.name]

        def update(done: int, total: int) -> None:
            bar.total = total
            bar.update(done - bar.n)
        return measure_draw(test, scene, where, running=running, on_progress=update)

    try:
        measured = measure_flow(test, seeds, folder, jobs=args.jobs, running=running, draw=draw, check_cells=check,
                                **options)
    finally:
        for bar in bars.values():
            bar.close()
    table = measured.table()
    print(table.text(), end="")
    name, at, change, error = measured.largest()
    verdict = measured.verdict(tolerance)
    print(f"two-way coupling moves the {name} reading at {at / 60:.3g} min by {change:+.3g} +- {error:.2g} pp "
          f"(tolerance {tolerance:g}): the one-way assumption {verdict}")
    grid = measured.grid_check()
    if grid is not None:
        print(f"grid check: seed {seeds[0]}'s change there is {grid[2]:+.3g} pp on {grid[0]} cells across, "
              f"{grid[3]:+.3g} on {grid[1]} (the grid's effect on this measurement)")
    write_text(args.out / "flow.csv", table.csv())
    write_text(args.out / "flow.json", json.dumps({
        "seeds": seeds, "width_m": first.width, "grid": [across, across, tall], "parcels": len(first.diameter),
        "loop_seconds": measured.loop_seconds, "largest": {"instrument": name, "time_s": at, "change_pp": change,
                                                            "standard_error_pp": error if math.isfinite(error) else None},
        "tolerance_pp": tolerance, "verdict": verdict,
        "grid_check": None if grid is None else {"cells": grid[0], "change_pp": grid[2], "check_cells": grid[1],
                                                 "check_change_pp": grid[3]}}, indent=2) + "\n")
    return measured


def _measure_contacts(test, args: argparse.Namespace, tolerance: float) -> None:
    """Runs the reduced real-grain scene with contacts, and with contacts and lubrication, at once."""
    import json
    import sys
    from concurrent.futures import ThreadPoolExecutor

    from ..planner.contacts import ReducedScene, measure_contacts
    from ..planner.scenes import prepare
    from ..results import write_text
    from ..sim.process import Runs

    largest = test.psd.span()[1]
    cut = largest / 3 if args.contact_cut is None else args.contact_cut * 1e-6
    setups = [ReducedScene(cut, 7.5 * largest, 75 * largest, lubrication=lub, seed=args.seed) for lub in (False, True)]
    print(f"measuring contacts: grains above {cut * 1e6:.3g} um in a periodic box of {setups[0].width * 1e3:.3g} x "
          f"{setups[0].width * 1e3:.3g} x {setups[0].height * 1e3:.3g} mm, without and with lubrication "
          f"({min(args.jobs, 2)} at once) ...", flush=True)
    # One name per measurement: its run folder and its rows in contacts.csv/json.
    kinds = ["contacts_lubrication" if setup.lubrication else "contacts" for setup in setups]
    running = Runs()
    # One bar per run in steps (the relaxation and the measured window), with tqdm's ETA.
    bars = [progress_bar(total=1, desc=kind, unit="step", position=k, file=sys.stderr, dynamic_ncols=True,
                     mininterval=0.5) for k, kind in enumerate(kinds)]

    def follow(bar):
        def update(done: int, total: int) -> None:
            bar.total = total
            bar.update(done - bar.n)
        return update

    try:
        with ThreadPoolExecutor(max_workers=min(args.jobs, 2)) as pool:
            folders = [prepare(args.out / kind) for kind in kinds]
            runs = [pool.submit(measure_contacts, test, setup, folder, running=running, on_progress=follow(bar))
                    for setup, folder, bar in zip(setups, folders, bars)]
            try:
                measured = [run.result() for run in runs]
            except BaseException:    # Ctrl-C or a failed run: stop the other one too
                running.stop()
                raise
    finally:
        for bar in bars:
            bar.close()
    header, rows, summary = "", [], {}
    for kind, m in zip(kinds, measured):
        table = m.table()
        print(table.text(), end="")
        verdict = ("within the tolerance: omit" if m.change <= tolerance else
                   "beyond the tolerance, as an upper bound (DEM contacts are ballistic, and Di Felice's "
                   "correlation holds the real encounters): not simulable at real grain counts, left out")
        summary[kind] = {"cut_um": cut * 1e6, "grains": int(m.grains.sum()), "steps": m.steps, "time_step": m.time_step,
                         "loop_seconds": m.loop_seconds, "largest_overlap": m.largest_overlap,
                         "reading_change_pp": m.change, "verdict": verdict}
        print(f"{kind}: readings move by up to {m.change:.3g} pp (tolerance {tolerance:g}): {verdict}")
        lines = table.csv().splitlines(keepends=True)
        header, rows = lines[0], rows + [f"{kind},{line}" for line in lines[1:]]
    write_text(args.out / "contacts.csv", "scene," + header + "".join(rows))
    write_text(args.out / "contacts.json", json.dumps(summary, indent=2) + "\n")


def _print_screens(screens) -> None:
    from ..results import Table

    table = Table(["effect", "screening_number", "value", "estimated_change", "verdict"],
                  notes=[f"{s.effect}: {s.reason}" for s in screens])
    for s in screens:
        table.add(s.effect, s.number, f"{s.value:.4g}", "" if s.change is None else f"{s.change:.3g}", s.verdict)
    print(table.text(), end="")
