#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The fit of law `bingham`'s two constants on Valentik & Whitmore's (1965) suspensions 1, 3 and 5
(tests/data/vw1965_fit.csv, 64 spheres), and every Bingham law's terminal speeds against the measured
ones (docs/physics.md 4.1).

The law's other constants come from the literature and are not fitted: the standard curve of a
sphere for the plastic viscosity's part, Beris et al.'s critical yield number 0.048 for the static
yield force, and Re_w = 1 for the middle of the yield part's rise. The fit is least squares on the
logarithm of the force balance at the measured speed with a soft-L1 loss (sediment.studies.valentik).
Besides the fit, each suspension is left out in turn (fitted on the other two, scored on it): how the law
does on a suspension it has not seen. --score adds a CSV of spheres it never fits on (the development
rows of suspensions 2, 4 and 6: tests/data/vw1965_dev.csv).

    /usr/bin/python3 benchmarks/fit_bingham.py [--score tests/data/vw1965_dev.csv] [--figure docs/paste/bingham_law.png]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment import _core, figures  # noqa: E402
from sediment.studies.valentik import Sphere, fit_bingham, law_speeds, read_spheres, score_law  # noqa: E402

FIT_CSV = HERE.parent / "tests" / "data" / "vw1965_fit.csv"
LAWS = ("zhang-li", "zhang-li/smooth", "bingham")


def row(label: str, spheres: list[Sphere], law: str, **constants: float) -> str:
    score = score_law(spheres, law, **constants)
    return (f"| {label} | {law} | {len(spheres)} | {score.median:.1%} | {score.mean:.1%} | {score.worst:.0%} | "
            f"{len(spheres) - score.held} / {score.held} |")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fit", type=Path, default=FIT_CSV, help="spheres to fit on (default: %(default)s)")
    parser.add_argument("--score", type=Path, action="append", default=[],
                        help="spheres to score on only (suspensions not in --fit)")
    parser.add_argument("--figure", type=Path, help="predicted against measured speeds, every law (PNG)")
    args = parser.parse_args()

    spheres = read_spheres(args.fit)
    constants = fit_bingham(spheres)
    print(f"fitted on {args.fit} ({len(spheres)} spheres): yield_weight {constants['yield_weight']:.5g}, "
          f"yield_rise {constants['yield_rise']:.5g}")
    built = _core.DragModel("bingham", 1.0, 1.0, 1.0)
    check = _core.DragModel("bingham", 1.0, 1.0, 1.0, **{k: float(f"{v:.3g}") for k, v in constants.items()})
    same = abs(built.force(1.0, 0.5) / check.force(1.0, 0.5) - 1) < 1e-12
    print("the core's constants (core/include/sediment/drag.hpp, bingham_law::fitted) "
          + ("are these, to 3 digits" if same else "DIFFER from these: update them"))

    print("\n| spheres | law | n | median | mean | worst | moving / held |\n|---|---|---|---|---|---|---|")
    for law in LAWS:
        print(row("fit (1, 3, 5)", spheres, law))
    suspensions = sorted({s.suspension for s in spheres})
    for left_out in suspensions:
        rest = [s for s in spheres if s.suspension != left_out]
        held_out = [s for s in spheres if s.suspension == left_out]
        refit = fit_bingham(rest)
        print(row(f"suspension {left_out} left out (refit: w {refit['yield_weight']:.4g}, rise "
                  f"{refit['yield_rise']:.3g})", held_out, "bingham", **refit))
        print(row(f"suspension {left_out} left out", held_out, "zhang-li"))
    scored: list[Sphere] = []
    for path in args.score:
        fitted_suspensions = set(suspensions)
        others = [s for s in read_spheres(path) if s.suspension not in fitted_suspensions]
        scored += others
        for law in LAWS:
            print(row(f"{path.name}, suspensions {', '.join(sorted({s.suspension for s in others}))}", others, law))
    if args.figure:
        print(f"wrote {plot(spheres, scored, args.figure)}")
    return 0


def plot(fitted: list[Sphere], scored: list[Sphere], path: Path) -> Path:
    """Predicted against measured terminal speeds, one panel per law."""
    plt = figures.pyplot()
    fig, axes = plt.subplots(1, len(LAWS), figsize=(4.6 * len(LAWS), 4.4), sharey=True)
    top = 1.1 * max(s.measured for s in fitted + scored)
    for ax, law in zip(axes, LAWS):
        for spheres, marker, label in ((fitted, "o", "fitted on (suspensions 1, 3, 5)"),
                                       (scored, "s", "never fitted on (2, 4, 6)")):
            if spheres:
                ax.plot([s.measured for s in spheres], law_speeds(spheres, law), marker, mfc="none", ms=6,
                        label=label)
        ax.plot([0, top], [0, top], "k-", lw=0.8)
        for factor in (0.9, 1.1):
            ax.plot([0, top], [0, top * factor], "k:", lw=0.6, label="+-10 %" if factor > 1 else None)
        ax.set(xlabel="measured terminal speed [m/s]", title=f"law {law}", xlim=(0, top), ylim=(0, top))
        ax.legend(fontsize=7)
    axes[0].set_ylabel("the law's terminal speed [m/s]")
    fig.suptitle("Valentik & Whitmore (1965): spheres in clay suspensions", fontsize=10)
    return figures.save(fig, path)


if __name__ == "__main__":
    sys.exit(main())
