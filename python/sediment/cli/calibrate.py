# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment calibrate: paste and contact parameters from slump, drop and tilt tests."""
from __future__ import annotations

import argparse
from pathlib import Path

from .types import positive, quantity


EXAMPLES = [
    'sediment calibrate slump --slump 0.102 0.103 0.100 --height 0.152 --density 1843',
    'sediment calibrate tilt --lift 205 205 202 202 208 --length 600',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command, its three tests and their options."""
    parser = commands.add_parser("calibrate", help="paste and contact parameters from a slump, drop or tilt test")
    tests = parser.add_subparsers(dest="test", required=True)
    slump = tests.add_parser("slump", help="yield stress from a cylindrical slump test (Pashias & Boger 1996)")
    slump.add_argument("--slump", type=quantity("slump_length"), nargs="+", required=True, help="measured slumps [m]")
    slump.add_argument("--height", type=quantity("slump_length"), required=True, help="cylinder height [m]")
    slump.add_argument("--density", type=quantity("paste_density"), required=True, help="paste density [kg/m3]")
    drop = tests.add_parser("restitution", help="coefficient of restitution from drop and rebound heights")
    drop.add_argument("--drop", type=positive, nargs="+", required=True, help="fall heights (any length unit)")
    drop.add_argument("--rebound", type=positive, nargs="+", required=True, help="rebound heights (same unit)")
    tilt = tests.add_parser("tilt", help="static friction from a tilt test, mu_s = H_l / L")
    tilt.add_argument("--lift", type=positive, nargs="+", required=True, help="lift heights at sliding")
    tilt.add_argument("--length", type=positive, required=True, help="plate length (same unit)")
    for test in (slump, drop, tilt):
        test.add_argument("--out", type=Path, help="also write calibration.csv into this folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Prints the calibrated value of each test and their mean."""
    from ..lab import calibrate

    if args.test == "slump":
        result = calibrate.yield_stress_from_slump(args.slump, args.height, args.density)
    elif args.test == "restitution":
        result = calibrate.restitution_from_drops(args.drop, args.rebound)
    else:
        result = calibrate.friction_from_tilt(args.lift, args.length)
    print(result.table().text(), end="")
    if args.out is not None:
        result.save(args.out)
    return 0
