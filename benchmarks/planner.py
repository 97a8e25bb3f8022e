# SPDX-License-Identifier: GPL-2.0-or-later
"""Time to answer of the main job (sample 5, 24 h in the D422 column) at the planner's decision
against the all-effects configuration, as a ratio measured in one run on this machine.

    /usr/bin/python3 benchmarks/planner.py [--plan out/sample5/plan/report.json] [--ranks 2] [--repeats 2]
                                           [--scaling]

The all-effects run is what a user would run without the planner: the best physics (the standard drag
curve under Richardson & Zaki's hindrance), the parcels of the old default main job (50 000) and the
Courant number 1. The planner's
run is its decision (from --plan, or a plan made here). Both take turns; the best loop time of each
is kept, and the largest difference between their readings is printed next to the ratio.

With --scaling, the planner's decision instead runs on 1 rank and on --ranks ranks, taking turns,
with LAMMPS's timing breakdown (the deck's `timing` variable): the best loop time of each, the
speed-up, and where the time of those runs goes (each section summed over the deck's stages; the
average over ranks, and the slowest rank's for the sections a rank can wait in).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.cli.types import count  # noqa: E402

PSD = HERE.parent / "examples" / "granulometry" / "psd" / "sample5.csv"
ALL_EFFECTS = {"drag": "standard", "hindrance": "richardson-zaki", "particles": 50000, "courant": 1.0}
SECTIONS = ("Pair", "Bond", "Kspace", "Neigh", "Comm", "Output", "Modify", "Other")


def main() -> None:
    from sediment.lab.granulometry import read_all
    from sediment.lab.psd import read_psd
    from sediment.lab.readout import Column
    from sediment.planner.scenes import decided_options
    from sediment.sim.layers import read_layers
    from sediment.sim.run import run_batch
    from sediment.sim.scene import Effects, plan
    from sediment.sim.scenefiles import write

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plan", type=Path, help="a plan's report.json (default: plan sample 5 here first)")
    parser.add_argument("--ranks", type=count, default=2)
    parser.add_argument("--repeats", type=count, default=2)
    parser.add_argument("--scaling", action="store_true", help="the decision on 1 rank against --ranks ranks")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        report = args.plan
        if report is None:
            from sediment import cli
            if cli.main(["plan", str(PSD), "--out", str(tmp / "plan")]) != 0:
                raise SystemExit("the plan failed")
            report = tmp / "plan" / "report.json"
        decided, _ = decided_options(report)
        if args.scaling:
            scaling(decided, tmp, args.ranks, args.repeats)
            return
        configs = {"all effects": ALL_EFFECTS, "planner's decision": decided}
        best, readings = {}, {}
        for _ in range(args.repeats):
            for name, c in configs.items():
                folder = tmp / name.replace(" ", "_").replace("'", "")
                scene = plan(read_psd(PSD), particles=c["particles"], courant=c["courant"],
                             effects=Effects(c["drag"], hindrance=c["hindrance"]))
                write(scene, folder)
                out = run_batch(folder / "in.sedimentation", {"overwrite": "yes"}, args.ranks)
                best[name] = min(best.get(name, float("inf")), sum(t for t, _ in out.loops))
                found, _ = read_all(Column.from_layers(read_layers(folder / "layers.h5")),
                                    ["hydrometer", "buoyancy", "pipette"])
                readings[name] = {r.instrument: r.percent_finer for r in found}
    full, chosen = best["all effects"], best["planner's decision"]
    gap = max(float(abs(readings["all effects"][k] - readings["planner's decision"][k]).max()) for k in readings["all effects"])
    print(f"main job (sample 5, 24 h, {args.ranks} ranks), best loop time of {args.repeats}:")
    for name, c in configs.items():
        print(f"  {name:19s} {best[name]:7.2f} s  (drag {c['drag']}, hindrance {c['hindrance']}, {c['particles']} "
              f"parcels, Courant {c['courant']:g})")
    print(f"  time to answer: {full / chosen:.1f}x faster at the planner's decision; readings differ by at most "
          f"{gap:.2f} points of percent finer")


def breakdown(text: str) -> dict[str, tuple[float, float]]:
    """LAMMPS's timing sections summed over every run of a log: (average over ranks, slowest rank;
    "Other" has an average only)."""
    sums: dict[str, list[float]] = {}
    for line in text.splitlines():
        fields = [f.strip() for f in line.split("|")]
        if len(fields) < 6 or fields[0] not in SECTIONS:
            continue
        total = sums.setdefault(fields[0], [0.0, 0.0])
        total[0] += float(fields[2])
        total[1] += float(fields[3] or fields[2])
    return {k: (v[0], v[1]) for k, v in sums.items()}


def scaling(decided: dict, tmp: Path, ranks: int, repeats: int) -> None:
    from sediment.lab.psd import read_psd
    from sediment.sim.run import run_batch
    from sediment.sim.scene import Effects, plan
    from sediment.sim.scenefiles import write

    folder = tmp / "decision"
    write(plan(read_psd(PSD), particles=decided["particles"], courant=decided["courant"],
               effects=Effects(decided["drag"], hindrance=decided["hindrance"])), folder)
    best: dict[int, tuple[float, str]] = {}
    for _ in range(repeats):
        for n in (1, ranks):
            out = run_batch(folder / "in.sedimentation", {"overwrite": "yes", "timing": "yes"}, n)
            loop = sum(t for t, _ in out.loops)
            if loop < best.get(n, (float("inf"), ""))[0]:
                best[n] = (loop, out.text)
    print(f"main job at the planner's decision (sample 5, 24 h; drag {decided['drag']}, hindrance "
          f"{decided['hindrance']}, {decided['particles']} "
          f"parcels, Courant {decided['courant']:g}), best loop time of {repeats}:")
    for n, (loop, text) in best.items():
        sections = breakdown(text)
        parts = ", ".join(f"{name} {average:.3f} s" + (f" (slowest rank {slowest:.3f})" if n > 1 and name in
                                                       ("Modify", "Comm") else "")
                          for name, (average, slowest) in sections.items() if average >= 0.0005)
        print(f"  {n} rank{'s' if n > 1 else ' '} {loop:6.3f} s: {parts}")
    print(f"  speed-up on {ranks} ranks: {best[1][0] / best[ranks][0]:.2f}x")


if __name__ == "__main__":
    main()
