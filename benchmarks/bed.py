# SPDX-License-Identifier: GPL-2.0-or-later
"""Two ranks against one on a settling bed with contacts (benchmarks/in.bed), for each way of
splitting the box, as ratios measured in one run on this machine.

    /usr/bin/python3 benchmarks/bed.py [--steps 1000] [--repeats 2]

The runs take turns and the best loop time of each is kept.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.cli.types import count  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402

SPLITS = {"z": "LAMMPS's default split (along z, the tall axis)",
          "columns": "processors * * 1 (every rank a column of bed and suspension)",
          "balance": "default split moved by fix balance (shift z) every 200 steps"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=count, default=1000)
    parser.add_argument("--repeats", type=count, default=2)
    args = parser.parse_args()
    runs = [("z", 1)] + [(split, 2) for split in SPLITS]
    best = {run: float("inf") for run in runs}
    for _ in range(args.repeats):
        for split, ranks in runs:
            out = run_batch(HERE / "in.bed", {"split": split, "steps": args.steps}, ranks)
            best[split, ranks] = min(best[split, ranks], out.loops[0][0])
    serial = best["z", 1]
    print(f"settling bed, {args.steps} steps, best of {args.repeats}: 1 rank {serial:.2f} s")
    for split, what in SPLITS.items():
        print(f"2 ranks, {split:8s} {best[split, 2]:6.2f} s  speed-up {serial / best[split, 2]:.2f}x  {what}")


if __name__ == "__main__":
    main()
