# SPDX-License-Identifier: GPL-2.0-or-later
"""The papers' one-way assumption, measured: docs/effects.md's table and figure of the test's column under
two-way coupling against its one-way twin, for draws that have run.

    /usr/bin/python3 benchmarks/two_way_column.py --sample 2 DRAW [DRAW ...] [--out FIGURE]

A draw is a folder holding `two/` (the column of `sediment sample --two-way --seed K`, run) and `one/`
(the same files run with `--var flow no`), as `sediment plan --measure-flow` leaves them in
OUT/flow/seed_K. Per instrument and reading, the change two-way minus one-way is paired per draw, and
its standard error is the draws' spread over sqrt(draws) (sediment.planner.flow). Prints each reading's
mean change and the screen's estimate beside the largest; draws each instrument's changes against
time with two standard errors.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.figures import pyplot, save  # noqa: E402
from sediment.lab.psd import read_psd  # noqa: E402
from sediment.planner.flow import gather, read_draw  # noqa: E402
from sediment.planner.screening import SedimentationTest, screen  # noqa: E402

PSDS = HERE.parent / "examples" / "granulometry" / "psd"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sample", type=int, required=True, help="Bravo et al.'s sample (1-5)")
    parser.add_argument("draws", type=Path, nargs="+", help="folders holding two/ and one/ (see above)")
    parser.add_argument("--out", type=Path, help="the figure (default docs/effects/two_way_column_sampleN.png)")
    args = parser.parse_args()
    test = SedimentationTest(read_psd(PSDS / f"sample{args.sample}.csv"))
    results = []
    for draw in args.draws:
        two, one = read_draw(test, draw)
        results.append((two, one, (np.nan, np.nan)))
    measured = gather(None, list(range(1, len(results) + 1)), results)
    print(measured.table().text(), end="")
    name, at, change, error = measured.largest()
    estimate = next(s.change for s in screen(test) if s.effect == "two-way")
    print(f"sample {args.sample}, {len(results)} draws: the largest mean change {change:+.3g} +- {error:.2g} pp "
          f"({name} at {at / 60:.3g} min); the screen's estimate {estimate:.3g} pp; at 0.5 pp the one-way "
          f"assumption {measured.verdict(0.5)}")
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for k, (instrument, (times, mean, err)) in enumerate(measured.changes().items()):
        band = 2 * np.nan_to_num(err)
        ax.errorbar(times / 60, mean, yerr=band, fmt="o-", ms=3, capsize=2, color=f"C{k}", label=instrument)
    ax.axhline(0.0, color="k", lw=0.6)
    for bound in (-estimate, estimate):
        ax.axhline(bound, color="grey", ls=":", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("time [min]")
    ax.set_ylabel("two-way minus one-way [points]")
    ax.set_title(f"sample {args.sample} at 60 g/L: {len(results)} draws, two standard errors "
                 f"(dotted: the screen's estimate)", fontsize=9)
    ax.legend(fontsize=8)
    out = args.out or HERE.parent / "docs" / "effects" / f"two_way_column_sample{args.sample}.png"
    save(fig, out)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
