# SPDX-License-Identifier: GPL-2.0-or-later
"""What two-way coupling costs (fix fluid/flow), beside the one-way scene and beside LAMMPS's PPPM.

    /usr/bin/python3 benchmarks/flow_cost.py [--particles 20000] [--steps 100] [--repeat 3]
        [--grid 16] [--every 1,5,20,0] [--drift 0.1,0.5] [--grids 16,32,64] [--ranks 1,2]

The scene (benchmarks/in.flow_cost): real 20 um grains at random in a periodic box at 2 % solids under
Stokes' drag with Richardson & Zaki's hindrance. First the step with the flow solved every N steps,
and with the fix choosing the steps (drift D), against the one-way step, at --grid cells and the
largest of --ranks. Then the flow's own time per
step (the Modify time above the one-way scene's, which holds the per-atom path's too) against PPPM's (Kspace time) for the same number
of particles on the same mesh, over --grids and --ranks. Times are the least of --repeat runs, taken
in turn (a machine's load slows a run, never speeds it); each ratio is of runs of one invocation.
"""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.cli.types import count  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402

DECK = HERE / "in.flow_cost"


def section(text: str, name: str) -> float:
    """The average time of a section of LAMMPS's timing breakdown (the last run's)."""
    rows = re.findall(rf"^{name}\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+)", text, re.M)
    return float(rows[-1]) if rows else 0.0


def run(variables: dict[str, object], ranks: int, cwd: Path) -> dict[str, float]:
    out = run_batch(DECK, variables, ranks=ranks, cwd=cwd)
    loop, steps = out.loops[-1]
    solves = re.findall(r"^SOLVES (\S+)", out.text, re.M)
    return {"step": loop / steps, "modify": section(out.text, "Modify") / steps,
            "kspace": section(out.text, "Kspace") / steps, "solves": float(solves[-1]) if solves else 0.0}


def least(configs: list[tuple[dict, int]], repeat: int, cwd: Path) -> list[dict[str, float]]:
    """Each configuration's least times over `repeat` rounds, the configurations taken in turn."""
    best: list[dict[str, float]] = [{} for _ in configs]
    for _ in range(repeat):
        for slot, (variables, ranks) in zip(best, configs):
            times = run(variables, ranks, cwd)
            for key, value in times.items():
                slot[key] = min(slot.get(key, value), value)
    return best


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=count, default=20000)
    parser.add_argument("--steps", type=count, default=100)
    parser.add_argument("--repeat", type=count, default=3)
    parser.add_argument("--grid", type=count, default=16, help="cells per side of the step comparison")
    parser.add_argument("--every", default="1,5,20,0",
                        help="solve intervals of the step comparison (0: once, at the run's start: what the "
                             "integrator's per-atom path costs alone)")
    parser.add_argument("--drift", default="0.1,0.5", help="drift values of the step comparison (fix fluid/flow drift D)")
    parser.add_argument("--grids", default="16,32,64")
    parser.add_argument("--ranks", default="1,2")
    args = parser.parse_args(argv)
    everies = [int(v) for v in args.every.split(",")]
    drifts = [float(v) for v in args.drift.split(",")] if args.drift else []
    grids = [int(v) for v in args.grids.split(",")]
    rank_counts = [int(v) for v in args.ranks.split(",")]
    common = {"n": args.particles, "steps": args.steps}
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        ranks = max(rank_counts)
        solves = [f"every {every or 1000000}" for every in everies] + [f"drift {drift:g}" for drift in drifts]
        labels = [str(every or "once") for every in everies] + [f"drift {drift:g}" for drift in drifts]
        configs = [({**common, "mode": "oneway"}, ranks)] + \
            [({**common, "mode": "flow", "cells": args.grid, "solve": solve}, ranks) for solve in solves]
        oneway, *flows = least(configs, args.repeat, cwd)
        print(f"{args.particles} grains, {args.grid}^3 cells, {ranks} ranks: one-way step {oneway['step'] * 1e3:.3f} ms")
        print("solved       step (ms)  / one-way  solves")
        for label, flow in zip(labels, flows):
            print(f"{label:>11}  {flow['step'] * 1e3:9.3f}  {flow['step'] / oneway['step']:8.2f}  {flow['solves']:6.0f}")
        print("\nthe flow's time per step (fix fluid/flow, every 1) and PPPM's (order 5), same particles and mesh")
        print("cells  ranks  flow (ms)  PPPM (ms)  flow / PPPM")
        for ranks in rank_counts:
            configs = [({**common, "mode": "oneway"}, ranks)]
            for cells in grids:
                configs += [({**common, "mode": "flow", "cells": cells}, ranks), ({**common, "mode": "pppm", "cells": cells}, ranks)]
            oneway, *rest = least(configs, args.repeat, cwd)
            for cells, flow, pppm in zip(grids, rest[0::2], rest[1::2]):
                solve = flow["modify"] - oneway["modify"]
                print(f"{cells:5d}  {ranks:5d}  {solve * 1e3:9.3f}  {pppm['kspace'] * 1e3:9.3f}  {solve / pppm['kspace']:11.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
