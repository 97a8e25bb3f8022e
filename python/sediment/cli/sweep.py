# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment sweep: accuracy against cost for one lever of a deck."""
from __future__ import annotations

import argparse
from pathlib import Path

from .types import count, positive_list, quantity


EXAMPLES = [
    'sediment sweep out/sample5/in.sedimentation --parameter dt_scale --dt 0.5,1,2 --observe hydrometer pipette --out out/sweep',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser(
        "sweep", help="accuracy vs cost: a deck at several time steps (and integrators), errors against a "
        "reference, loop times, table and figure",
        description="Runs DECK with -var dt VALUE for each value (and -var integrator nve/sphere/fluid|nve/sphere), "
        "reads the observables it prints (RESULT name value; SERIES name x y) or the readout curves of the layer "
        "file it writes, and scores each run against --reference or the finest run. See docs/sweep.md.")
    parser.add_argument("deck", type=Path, help="LAMMPS deck with 'variable dt index ...'")
    parser.add_argument("--dt", type=positive_list, required=True, help="comma-separated values of the swept variable")
    parser.add_argument("--parameter", default="dt", help="the deck variable swept (default dt; e.g. courant for a "
                        "deck written by `sediment sample`)")
    parser.add_argument("--integrator", help="comma-separated: implicit (nve/sphere/fluid), explicit (nve/sphere)")
    parser.add_argument("--observe", nargs="+", required=True, metavar="NAME",
                        help="RESULT or SERIES names the deck prints, or hydrometer, buoyancy, pipette")
    parser.add_argument("--reference", action="append", metavar="NAME=EXPR",
                        help="analytic reference: a number, or an expression of x for a series "
                        "(numpy exp, log, sqrt, ...); default: the finest run")
    parser.add_argument("--tolerance", type=quantity("relative_tolerance"),
                        default=0.01, help="relative error to meet (default 1 %%)")
    parser.add_argument("--tau", type=quantity("time_scale"),
                        help="drag relaxation time [s]: marks the explicit limit 2 tau")
    parser.add_argument("--rayleigh", type=quantity("time_scale"), help="Rayleigh time [s]: marks the 20 %% rule")
    parser.add_argument("--var", nargs=2, action="append", metavar=("NAME", "VALUE"), help="LAMMPS -var for every run")
    parser.add_argument("--np", type=count, default=1, help="MPI ranks per run")
    parser.add_argument("--title", default="", help="figure title")
    parser.add_argument("--out", type=Path, default=Path("out/sweep"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Runs the sweep, prints its table and the cheapest runs, writes sweep.csv and sweep.png."""
    from ..sim.deck import refuse_unread
    from ..studies import sweep

    references = dict(sweep.parse_reference(r) for r in args.reference or [])
    integrators = args.integrator.split(",") if args.integrator else None
    # a variable the deck never reads would make every run the same, or run as if not given
    refuse_unread(args.deck, [args.parameter], "--parameter")
    if integrators:
        refuse_unread(args.deck, ["integrator"], "--integrator")
    refuse_unread(args.deck, [name for name, _ in args.var or []])
    result = sweep.run_sweep(args.deck, args.dt, args.observe, integrators, args.parameter, references,
                             dict(args.var or []), args.np, args.out / "runs", args.tau, args.rayleigh)
    result.save(args.out, args.tolerance, args.title)
    print(result.table(args.tolerance).text(), end="")
    return 0
