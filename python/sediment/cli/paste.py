# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment paste: steel balls and paste backfill (validation cases D-F)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..constants import BINGHAM_LAWS
from .types import count, quantity, setting


EXAMPLES = [
    'sediment paste drop-test --out out/paste',
    'sediment paste funnel --runs 15 --jobs 2 --out out/paste',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command, its studies and their options."""
    parser = commands.add_parser("paste", help="steel balls and paste backfill (cases D-F): drop test, single "
                                 "balls, the funnel")
    studies = parser.add_subparsers(dest="study", required=True)
    target = studies.add_parser("restitution", help="the 'damping tsuji' input giving a restitution (drop deck)")
    target.add_argument("--target", type=quantity("restitution"), default=0.612)
    for name, text in (("drop-test", "rebounds of the five drops of case F with steel.lmp"),
                       ("balls", "8, 12.6 and 16 mm balls from six fall heights, with and without partial "
                                 "submergence: settling distances")):
        study = studies.add_parser(name, help=text)
        study.add_argument("--out", type=Path, default=Path("out/paste"), help="output folder")
        if name == "balls":
            study.add_argument("--law", default="bingham", choices=BINGHAM_LAWS, help="the paste's drag law")
            study.add_argument("--viscosity", type=quantity("viscosity"),
                               help="the paste's plastic viscosity [Pa s] (default: "
                               "the law's calibration, 0.279 for bingham and Zhang & Li's 0.7 for theirs; see the "
                               "viscosity study)")
    calibration = studies.add_parser("viscosity", help="the paste's plastic viscosity with which a law puts "
                                     "Zhang & Li's calibration drop (12.6 mm from 255 mm) where their law puts it")
    calibration.add_argument("--law", default="bingham", choices=BINGHAM_LAWS, help="the paste's drag law")
    calibration.add_argument("--out", type=Path, help="also write viscosity_calibration.csv into this folder")
    energy = studies.add_parser("energy", help="energy balance of one ball entering the paste")
    energy.add_argument("--diameter", type=quantity("ball_diameter"), default=0.0126, help="[m]")
    energy.add_argument("--fall", type=quantity("fall_height"), default=0.255, help="fall height above the paste [m]")
    energy.add_argument("--dt", type=quantity("time_step"), default=1e-5, help="[s]")
    energy.add_argument("--law", default="bingham", choices=BINGHAM_LAWS, help="the paste's drag law")
    energy.add_argument("--out", type=Path, help="also write energy_balance.csv into this folder")
    pour = studies.add_parser("funnel", help="68 balls poured from a funnel, several random packings")
    pour.add_argument("--runs", type=count, default=15)
    pour.add_argument("--jobs", type=count, default=2, help="runs at a time")
    pour.add_argument("--dt", type=quantity("time_step"), default=1e-6, help="[s]")
    pour.add_argument("--set", type=setting, action="append", default=[], metavar="NAME=VALUE",
                      help="a variable of examples/paste/in.funnel (or of the steel.lmp and mould.lmp it includes), "
                      "for a variant: stem=0.05, fall=0.15, effect_submergence=no, tsuji=0.2, ...; repeatable")
    pour.add_argument("--out", type=Path, default=Path("out/paste"), help="output folder")
    variants = studies.add_parser("funnel-compare", help="funnel studies saved by 'funnel --out DIR' side by side: "
                                  "spills, balls at the surface, depths; funnel_variants.csv and .png")
    variants.add_argument("folders", type=Path, nargs="+", help="folders of saved studies (labelled by their names)")
    variants.add_argument("--out", type=Path, default=Path("out/paste"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Runs the study, prints its table and writes its files."""
    from ..studies import funnel, paste

    if args.study == "restitution":
        c = paste.tsuji_for_restitution(args.target)
        print(f"damping tsuji {c:.4f} gives a simulated restitution of {paste.simulated_restitution(c):.4f} "
              f"(the input {args.target} itself gives {paste.simulated_restitution(args.target):.4f})")
        return 0
    if args.study == "drop-test":
        result = paste.drop_study()
    elif args.study == "balls":
        result = paste.ball_study(law=args.law, plastic_viscosity=args.viscosity)
    elif args.study == "viscosity":
        result = paste.calibrate_viscosity(args.law)
    elif args.study == "energy":
        result = paste.energy_balance(args.diameter, args.fall, args.dt, law=args.law)
    elif args.study == "funnel-compare":
        result = funnel.compare(args.folders)
    else:
        result = funnel.funnel_study(runs=args.runs, jobs=args.jobs, dt=args.dt, settings=dict(args.set))
    print(result.table().text(), end="")
    if args.out is not None:
        result.save(args.out)
    return 0
