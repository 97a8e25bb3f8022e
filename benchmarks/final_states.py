# SPDX-License-Identifier: GPL-2.0-or-later
"""Whether a change of the step keeps the final states: the cost scenes (benchmarks/in.cost) of every
law, at dt/tau from 1e-4 to 1e4, with and without fix nve/sphere/fluid's floor, and the settling bed
with contacts (benchmarks/in.bed) under three laws, each run with this build and with a baseline
(another lmp_sediment, e.g. a build of an earlier commit), their final positions, velocities and
spins written with 17 digits and compared.
    /usr/bin/python3 benchmarks/final_states.py --baseline LMP [--particles 2000] [--steps 300] [--bed-steps 300]
                                                [--no-bed] [--ranks 1]
Prints each pair that differs, with its largest difference of velocity (relative to the largest
speed) and of position (in metres), and how many of the pairs are the same byte for byte. Exits 1
when a run fails or the two runs of a scene hold different atoms.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
sys.path.insert(0, str(HERE))

from cost import TAU  # noqa: E402  (of in.cost's grains)
from sediment.cli.types import count  # noqa: E402
from sediment.sim.paths import lmp_executable  # noqa: E402

LAWS = ("drag", "nonlinear", "standard", "hindered", "richardson", "bingham", "binghamlaw", "cells", "zhangli",
        "schiller")
RATIOS = (1e-4, 1e-2, 1.0, 1e2, 1e4)
FLOOR = "floor z 0.006"    # a floor a third of the way up the box: spheres come to rest on it
BED_LAWS = ("standard", "dallavalle", "stokes")


def final_state(lmp: str, deck: Path, variables: dict[str, str], out: Path, ranks: int) -> np.ndarray:
    """Runs the deck with these variables on this many MPI ranks and reads the final state it dumps
    (rows by atom id)."""
    cmd = ["mpirun", "-np", str(ranks)] if ranks > 1 else []
    cmd += [lmp, "-in", str(deck), "-log", "none", "-screen", "none"]
    for name, value in {**variables, "dump_final": "1", "final_dump": str(out)}.items():
        cmd += ["-var", name, value]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0 or not out.exists():
        sys.exit(f"final_states.py: {' '.join(cmd)} failed (exit {done.returncode}):\n{done.stdout[-1500:]}"
                 f"{done.stderr[-1500:]}")
    return np.loadtxt(out, skiprows=9, ndmin=2)


def compare(label: str, ours: Path, theirs: Path, a: np.ndarray, b: np.ndarray) -> bool:
    """True when the two dumps are the same byte for byte; otherwise prints the largest differences."""
    if ours.read_bytes() == theirs.read_bytes():
        return True
    if a.shape != b.shape or not np.array_equal(a[:, 0], b[:, 0]):
        sys.exit(f"final_states.py: {label}: the two runs end with different atoms")
    speed = np.abs(b[:, 4:7]).max()
    dv = np.abs(a[:, 4:7] - b[:, 4:7]).max()
    dx = np.abs(a[:, 1:4] - b[:, 1:4]).max()
    relative = f"{dv / speed:.2e}" if speed > 0 else f"{dv:.2e} m/s (all at rest in the baseline)"
    print(f"  {label:40s} velocity {relative} of the largest speed, position {dx:.2e} m")
    return False


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--baseline", required=True, help="the lmp_sediment to compare with")
    parser.add_argument("--particles", type=count, default=2000)
    parser.add_argument("--steps", type=count, default=300)
    parser.add_argument("--bed-steps", type=count, default=300, help="steps of the bed")
    parser.add_argument("--no-bed", action="store_true", help="the cost scenes only")
    parser.add_argument("--ranks", type=count, default=1, help="MPI ranks of every run (mpirun -np)")
    args = parser.parse_args()
    if shutil.which(args.baseline) is None:
        sys.exit(f"final_states.py: --baseline {args.baseline}: no such executable")
    if args.ranks > 1 and shutil.which("mpirun") is None:
        sys.exit("final_states.py: --ranks needs mpirun (Debian package openmpi-bin)")
    ours_lmp = str(lmp_executable())
    runs = [(f"{law} dt/tau {ratio:g}{' floor' if floor else ''}", HERE / "in.cost",
             {"scene": law, "n": str(args.particles), "steps": str(args.steps), "dt": repr(ratio * TAU),
              "step_options": floor})
            for floor in ("", FLOOR) for law in LAWS for ratio in RATIOS]
    if not args.no_bed:
        runs += [(f"bed {law}", HERE / "in.bed", {"split": "z", "steps": str(args.bed_steps), "law": law})
                 for law in BED_LAWS]
    same = 0
    print(f"final states of this build ({ours_lmp}) against {args.baseline}: the pairs that differ")
    with tempfile.TemporaryDirectory() as tmp:
        for k, (label, deck, variables) in enumerate(runs):
            ours, theirs = Path(tmp) / f"{k}.ours", Path(tmp) / f"{k}.theirs"
            a = final_state(ours_lmp, deck, variables, ours, args.ranks)
            b = final_state(args.baseline, deck, variables, theirs, args.ranks)
            same += compare(label, ours, theirs, a, b)
    print(f"{same} of {len(runs)} byte for byte")


if __name__ == "__main__":
    main()
