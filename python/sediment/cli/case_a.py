# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment case-a: the single-sphere validation (case A)."""
from __future__ import annotations

import argparse
from pathlib import Path


EXAMPLES = [
    'sediment case-a --out out/case_a',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("case-a", help="single-sphere validation (case A): velocity curves and error vs "
                                 "time step for the implicit and explicit integrators")
    parser.add_argument("--out", type=Path, default=Path("out/case_a"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Runs the study, prints its table and writes its files."""
    from ..studies.single_sphere import case_a_study

    result = case_a_study(args.out / "runs")
    print(result.table().text(), end="")
    result.save(args.out)
    return 0
