# SPDX-License-Identifier: GPL-2.0-or-later
"""A settling bed with contacts (benchmarks/in.bed), as ratios measured in one run on this machine:
two ranks against one for each way of splitting the box, or with --laws the whole loop under each
drag law against the same bed with LAMMPS's own fix viscous (the peer), on one rank.

    /usr/bin/python3 benchmarks/bed.py [--steps 1000] [--repeats 2] [--laws standard,dallavalle,stokes]

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


LAWS = ("standard", "dallavalle", "stokes")    # one word each: the deck compares law with LAMMPS's if


def law_list(text: str) -> list[str]:
    laws = [law for law in text.split(",") if law]
    unknown = [law for law in laws if law not in LAWS]
    if unknown or not laws:
        raise argparse.ArgumentTypeError(f"unknown law {', '.join(unknown) or '(none)'}; laws: {', '.join(LAWS)}")
    return laws


def compare_laws(laws: list[str], steps: int, repeats: int) -> None:
    """The loop of the bed under each law against the peer's, one rank, the runs taking turns."""
    runs = ["viscous"] + laws
    best = {law: float("inf") for law in runs}
    for _ in range(repeats):
        for law in runs:
            out = run_batch(HERE / "in.bed", {"split": "z", "steps": steps, "law": law}, 1)
            best[law] = min(best[law], out.loops[0][0])
    peer = best["viscous"]
    print(f"settling bed with contacts, {steps} steps, best of {repeats}, 1 rank: the whole loop against the peer "
          f"(fix nve/sphere + fix viscous + reduced gravity) {peer:.2f} s")
    for law in laws:
        print(f"law {law:17s} {best[law]:6.2f} s  {best[law] / peer:.2f}x the peer")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=count, default=1000)
    parser.add_argument("--repeats", type=count, default=2)
    parser.add_argument("--laws", type=law_list, default=None,
                        help="compare the loop under these laws with the fix viscous peer instead of the splits")
    args = parser.parse_args()
    if args.laws:
        compare_laws(args.laws, args.steps, args.repeats)
        return
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
