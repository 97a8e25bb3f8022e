# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment spheres: terminal velocities of spheres in Bingham suspensions (Valentik & Whitmore)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..constants import BINGHAM_LAWS


EXAMPLES = [
    'sediment spheres tests/data/vw1965_dev.csv --out out/spheres',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("spheres", help="terminal velocities of spheres in Bingham suspensions, simulated "
                                 "vs the law and the measurement (Valentik & Whitmore 1965 columns)")
    parser.add_argument("csv", type=Path, help="CSV with suspension,rho_f,eta_B,tau_y,d,rho_p,v_ter_measured (SI)")
    parser.add_argument("--law", nargs="+", default=["bingham", "zhang-li"], choices=BINGHAM_LAWS,
                        help="drag laws to settle each sphere under (default: %(default)s)")
    parser.add_argument("--out", type=Path, default=Path("out/spheres"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Settles every sphere, prints the table and writes the CSV and the figure."""
    from ..studies.valentik import study

    result = study(args.csv, laws=args.law)
    print(result.table().text(), end="")
    result.save(args.out)
    return 0
