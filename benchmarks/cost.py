# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost per particle-step of the SEDIMENT effects, as ratios measured in one run on this machine.

    /usr/bin/python3 benchmarks/cost.py [--particles 20000] [--steps 2000] [--repeats 3] [--baseline LMP]
                                        [--scenes plain,drag,...]

Each scene runs `repeats` times, the scenes taking turns (so that a drift of the machine's speed
during the run touches every scene alike); the best loop time is kept. LAMMPS reports the loop
time, which excludes start-up. With --baseline (another lmp_sediment, e.g. a build of an earlier
commit) every scene also runs with it, the two taking turns scene by scene, and the table gains
the ratio this build / baseline, as the ratio of the best times and as the median of the ratios of
back-to-back pairs (robust to the machine's drift during the run): on a machine whose speed drifts
by 10 % between runs, the way to measure one change.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.cli.types import count  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402

SCENES = {"plain": "nve/sphere + gravity (reference)",
          "peer": "nve/sphere + fix viscous + reduced gravity (LAMMPS's own fixes, same Stokes physics)",
          "explicit": "nve/sphere + buoyancy + stokes drag (explicit)",
          "bare": "nve/sphere/fluid + gravity, no fluid fixes (every effect off)",
          "drag": "nve/sphere/fluid + buoyancy + stokes drag",
          "nonlinear": "as drag with dallavalle (general Newton step)",
          "hindered": "as nonlinear + concentration/grid (400 layers) + difelice",
          "cells": "as hindered on 20 x 20 x 100 3d cells",
          "lubricated": "as drag + pair lubricate/fluid"}


def loop_time(scene: str, particles: int, steps: int, lmp: Path | None = None) -> float:
    """Loop time of the scene, with `lmp` instead of the lmp_sediment in use when given."""
    previous = os.environ.get("SEDIMENT_LMP")
    if lmp is not None:
        os.environ["SEDIMENT_LMP"] = str(lmp)
    try:
        return run_batch(HERE / "in.cost", {"scene": scene, "n": particles, "steps": steps}).loops[0][0]
    finally:
        if previous is None:
            os.environ.pop("SEDIMENT_LMP", None)
        else:
            os.environ["SEDIMENT_LMP"] = previous


def existing_file(text: str) -> Path:
    path = Path(text)
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"no such file: {text}")
    return path.resolve()


def scene_list(text: str) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in SCENES]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"unknown scene(s) {', '.join(unknown) or text!r}; expected some of "
                                         f"{', '.join(SCENES)}")
    return names


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=count, default=20000)
    parser.add_argument("--steps", type=count, default=2000)
    parser.add_argument("--repeats", type=count, default=3)
    parser.add_argument("--baseline", type=existing_file, help="another lmp_sediment to take turns with")
    parser.add_argument("--scenes", type=scene_list, default=list(SCENES),
                        help="comma-separated scenes to run (default: all; plain and peer always run, the ratios need them)")
    args = parser.parse_args()
    scenes = {s: SCENES[s] for s in SCENES if s in args.scenes or s in ("plain", "peer")}
    times = {s: float("inf") for s in scenes}
    baseline = {s: float("inf") for s in scenes}
    pair_ratios: dict[str, list[float]] = {s: [] for s in scenes}
    for _ in range(args.repeats):
        for s in scenes:
            mine = loop_time(s, args.particles, args.steps)
            times[s] = min(times[s], mine)
            if args.baseline:
                theirs = loop_time(s, args.particles, args.steps, args.baseline)
                baseline[s] = min(baseline[s], theirs)
                pair_ratios[s].append(mine / theirs)
    per = {s: t / (args.particles * args.steps) * 1e9 for s, t in times.items()}
    print(f"{args.particles} particles x {args.steps} steps, best of {args.repeats}, 1 rank")
    against = f" {'baseline ns':>12s} {'this/baseline':>14s} {'median of pairs':>16s}" if args.baseline else ""
    print(f"{'scene':10s} {'ns/particle-step':>17s} {'ratio to plain':>15s}{against}  what")
    for s, what in scenes.items():
        other = baseline[s] / (args.particles * args.steps) * 1e9
        against = (f" {other:12.2f} {times[s] / baseline[s]:14.3f} {statistics.median(pair_ratios[s]):16.3f}"
                   if args.baseline else "")
        print(f"{s:10s} {per[s]:17.2f} {per[s] / per['plain']:15.2f}{against}  {what}")
    if args.baseline:
        print(f"baseline: {args.baseline}; the peer and plain scenes run the same code in both builds, so "
              "their ratios show this machine's noise")
    if "bare" in per:
        print(f"every effect off: {100 * (per['bare'] / per['plain'] - 1):+.1f} % against fix nve/sphere")
    against_peer = [f"{label} {per[s] / per['peer']:.2f}x" for s, label in
                    (("explicit", "explicit stokes + buoyancy"), ("drag", "implicit"), ("nonlinear", "nonlinear implicit"))
                    if s in per]
    if against_peer:
        print("against the peer (LAMMPS's own fixes): " + ", ".join(against_peer))
    if "nonlinear" in per and "hindered" in per:
        grid = per["hindered"] - per["nonlinear"]
        cells = f"; with 3d cells {per['cells'] - per['nonlinear']:.1f} ns ({(per['cells'] - per['nonlinear']) / per['plain']:.2f}x)" \
            if "cells" in per else ""
        print(f"grid + Di Felice hindrance on top of the nonlinear step: {grid:.1f} ns/particle-step "
              f"({grid / per['plain']:.2f}x the plain step){cells}")
    if "drag" in per and "lubricated" in per:
        film = per["lubricated"] - per["drag"]
        print(f"lubrication on top of the Stokes step: {film:.1f} ns/particle-step ({film / per['plain']:.2f}x the plain step)")


if __name__ == "__main__":
    main()
