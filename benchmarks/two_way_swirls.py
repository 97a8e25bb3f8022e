# SPDX-License-Identifier: GPL-2.0-or-later
"""The papers' one-way assumption, seen in the readings: docs/effects.md's figure of the planner's
two-way screen.

    /usr/bin/python3 benchmarks/two_way_swirls.py [--samples 1,2,3,4,5] [--out docs/effects/two_way_swirls.png]

For Bravo et al.'s samples at 60 g/L in the 1000 mL D422 cylinder, every instrument's percent
finer against time as the screen computes it: the classes at their terminal speeds, and with each
class's arrival spread by the swirls the grains drive (Segre et al.'s measured fluctuation; the mean of
the readings at speeds (1 +- spread), planner/screening.py). Below, the difference in points. Each
panel's largest difference is the one `sediment plan --screen-only` reports (checked here).
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
from sediment.lab.settling import terminal_speeds  # noqa: E402
from sediment.planner.screening import ReadingModel, SedimentationTest, screen, swirl_spread_of  # noqa: E402

PSDS = HERE.parent / "examples" / "granulometry" / "psd"


def readings(sample: int) -> tuple[dict, dict, dict, float]:
    """Each instrument's reading times [s], its readings without and with the swirls' spread, and the
    screen's change."""
    test = SedimentationTest(read_psd(PSDS / f"sample{sample}.csv"))
    single = lambda d: terminal_speeds(test.suspension, d)    # noqa: E731 - the screen's reference speeds
    model = ReadingModel(test, single)
    swirled = model.spread_readings(single, swirl_spread_of(test)[0])
    reported = next(s.change for s in screen(test) if s.effect == "two-way")
    largest = model.largest_change(swirled)
    if not np.isclose(largest, reported, rtol=1e-9):
        raise SystemExit(f"sample {sample}: the figure's largest change {largest:.4g} pp is not the screen's "
                         f"{reported:.4g} pp")
    return model.reading_times, model.reference, swirled, reported


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--samples", default="1,2,3,4,5", help="Bravo et al.'s samples (1-5), comma-separated")
    parser.add_argument("--out", type=Path, default=HERE.parent / "docs" / "effects" / "two_way_swirls.png")
    args = parser.parse_args()
    samples = [int(s) for s in args.samples.split(",")]
    plt = pyplot()
    fig, axes = plt.subplots(2, len(samples), figsize=(4.4 * len(samples), 6.0), sharex=True,
                             gridspec_kw={"height_ratios": [2, 1]}, squeeze=False)
    for column, sample in enumerate(samples):
        times, reference, swirled, change = readings(sample)
        top, bottom = axes[0, column], axes[1, column]
        for k, name in enumerate(reference):
            minutes, colour = times[name] / 60.0, f"C{k}"
            top.plot(minutes, reference[name], "o-", ms=3, color=colour, label=f"{name}, one way")
            top.plot(minutes, swirled[name], "x--", ms=4, color=colour, label=f"{name}, with the swirls")
            bottom.plot(minutes, swirled[name] - reference[name], "o-", ms=3, color=colour, label=name)
            print(f"sample {sample} {name}: largest change {np.max(np.abs(swirled[name] - reference[name])):.3g} pp")
        print(f"sample {sample}: the screen's largest change of a reading {change:.3g} pp")
        top.set(xscale="log", ylabel="percent finer", title=f"sample {sample}, 60 g/L: up to {change:.2g} pp")
        bottom.axhline(0.0, color="0.6", lw=0.8)
        bottom.set(xlabel="time [min]", ylabel="with the swirls - one way [pp]")
        top.legend(fontsize=7)
    save(fig, args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
