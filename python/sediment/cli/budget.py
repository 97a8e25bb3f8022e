# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment budget: how far each modelling choice moves a test's readings (the error budget)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..constants import LAB_TEMPERATURE, SPECIMEN_MASS
from .types import count, positive, quantity, temperature


EXAMPLES = [
    'sediment budget examples/granulometry/psd/sample5.csv --out out/budget',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser(
        "budget", help="error budget of simulated tests: the change of every instrument's readings from each "
        "uncertain modelling choice (drag curve, hindrance, buoyancy, temperature, dispersant, wall, Brownian "
        "motion, parcels, time step)",
        description="For each PSD: runs the sedimentation test with the best physics (standard drag curve, "
        "Richardson & Zaki's hindrance) and again with one choice changed at a time (same placement), reduces "
        "every run as a laboratory would, and writes OUT/budget.csv, budget.json and budget.png. "
        "`sediment readout --band OUT/budget.json` puts the physical total around a run's readings. "
        "See docs/error-budget.md. Example: sediment budget examples/granulometry/psd/sample5.csv --out out/budget")
    parser.add_argument("psd", type=Path, nargs="+", help="PSD tables (CSV: diameter_um,percent_finer)")
    parser.add_argument("--particles", type=count, default=20000, help="parcels of every run (default 20000)")
    parser.add_argument("--courant", type=positive, default=2.0, help="the reference's Courant number (default 2)")
    parser.add_argument("--replicas", type=count, default=3, help="reference runs with independent seeds, for the "
                        "sampling row (default 3, at least 2)")
    parser.add_argument("--temperature", type=temperature, default=LAB_TEMPERATURE,
                        help="recorded water temperature [C] (default 20)")
    parser.add_argument("--mass", type=quantity("specimen_mass"),
                        default=SPECIMEN_MASS, help="dry sample mass [kg] (default 0.06)")
    parser.add_argument("--seed", type=int, default=1, help="placement seed of the reference")
    parser.add_argument("--jobs", type=count, default=2, help="runs at once, one core each (default 2)")
    parser.add_argument("--out", type=Path, default=Path("out/budget"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Runs every test's budget, prints the tables and writes the report."""
    from ..lab.psd import read_psd
    from ..studies.budget import error_budget, save

    psds = [read_psd(p) for p in args.psd]
    names = [p.stem for p in args.psd]
    if len(set(names)) != len(names):
        raise ValueError("two PSD tables have the same name: the budget names each sample by its file")
    budgets = []
    for path, psd in zip(args.psd, psds):
        budget = error_budget(psd, args.out / "runs" / path.stem, particles=args.particles, courant=args.courant,
                              replicas=args.replicas, temperature=args.temperature, mass=args.mass, seed=args.seed,
                              jobs=args.jobs, name=path.stem)
        print(budget.table().text(), end="")
        budgets.append(budget)
    save(budgets, args.out)
    return 0
