# SPDX-License-Identifier: GPL-2.0-or-later
"""What fix fluid/flow's solve schedule costs in accuracy: the flow solved every step against `drift D`
(the fix solves once the spheres may have moved D cells, or their largest speed changed by the fraction
D) and `every N`, in four scenes unlike one another, each answer's change set beside the change of the
same answer from one random draw of the scene to another (its own scatter).

    /usr/bin/python3 benchmarks/flow_drift.py [--schedules "drift 0.02,drift 0.1,drift 0.2,drift 0.5,every 10"]
        [--ranks 1] [--scenes cloud,dense,suspension,column] [--fraction 1]

Scenes (one rank, a few seconds each):
- cloud: 1000 spheres of 15 um in a cloud of 1.5 mm (N a / R = 10, 32^3 cells), 650 steps of 16 tau;
  its speed (examples/falling_cloud);
- dense: a cloud of 5000 spheres of the same size in the same cloud (N a / R = 50);
- suspension: 4000 quartz grains of 20 um at 2 % solids in a periodic box (16^3 cells), 600 steps
  of 5 ms; their mean fall (benchmarks/in.flow_drift);
- column: 50 and 100 um quartz grains in a closed 4 x 4 x 8 mm column (16 x 16 x 32 cells) settling
  onto its floor, 300 steps of 5 ms; each class's mean fall.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.sim.run import run_batch  # noqa: E402

CLOUD = HERE.parent / "examples" / "falling_cloud" / "in.falling_cloud"
SCENES = HERE / "in.flow_drift"

# name, deck, variables, the RESULT values compared, the variable that draws another scene
REGIMES = [
    ("cloud", CLOUD, {"R": 1.5e-3, "n": 1000, "cells": 32, "steps": 650}, ("speed",), "seed"),
    ("dense", CLOUD, {"R": 1.5e-3, "n": 5000, "na_r": 50, "cells": 32, "steps": 650}, ("speed",), "seed"),
    ("suspension", SCENES, {"scene": "suspension", "steps": 600}, ("fine",), "seed"),
    ("column", SCENES, {"scene": "column", "steps": 300}, ("fine", "coarse"), "seed"),
]


def run(deck: Path, variables: dict, ranks: int, cwd: Path) -> tuple[dict[str, float], float]:
    out = run_batch(deck, variables, ranks=ranks, cwd=cwd)
    return out.results, sum(seconds for seconds, _ in out.loops)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--schedules", default="drift 0.02,drift 0.1,drift 0.2,drift 0.5,every 10")
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--scenes", default=",".join(name for name, *_ in REGIMES))
    parser.add_argument("--fraction", type=float, default=1.0, help="of each scene's steps (a quick look)")
    args = parser.parse_args(argv)
    schedules = [s.strip() for s in args.schedules.split(",") if s.strip()]
    scenes = args.scenes.split(",")
    unknown = set(scenes) - {name for name, *_ in REGIMES}
    if unknown or not 0 < args.fraction <= 1:
        parser.error(f"unknown scenes {sorted(unknown)}" if unknown else "--fraction must be in (0, 1]")
    print("scene        solved       solves  loop (s)  largest relative change   (another draw, solved every step)")
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        for name, deck, variables, keys, draw in (regime for regime in REGIMES if regime[0] in scenes):
            variables = {**variables, "steps": max(1, round(args.fraction * variables["steps"]))}
            reference, loop = run(deck, {**variables, "solve": "every 1"}, args.ranks, cwd)
            other, _ = run(deck, {**variables, "solve": "every 1", draw: 97}, args.ranks, cwd)
            scatter = max(abs(other[k] - reference[k]) / abs(reference[k]) for k in keys)
            print(f"{name:<12} {'every 1':<12} {reference['solves']:6.0f}  {loop:8.2f}  {'-':>23}   ({scatter:.1e})")
            for schedule in schedules:
                result, loop = run(deck, {**variables, "solve": schedule}, args.ranks, cwd)
                change = max(abs(result[k] - reference[k]) / abs(reference[k]) for k in keys)
                print(f"{'':<12} {schedule:<12} {result['solves']:6.0f}  {loop:8.2f}  {change:23.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
