# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment run: a deck through lmp_sediment, serial or with mpirun, with a progress bar."""
from __future__ import annotations

import argparse
from pathlib import Path

from .types import count


EXAMPLES = [
    'sediment run out/sample5/in.sedimentation --np 2',
    'sediment run out/sample5/in.sedimentation --resume    # after a kill: continues from its restart file',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("run", help="run a deck with lmp_sediment (serial or mpirun) with a progress bar")
    parser.add_argument("deck", type=Path, help="LAMMPS input deck (e.g. from `sediment sample`)")
    parser.add_argument("--np", type=count, default=1, help="MPI ranks")
    parser.add_argument("--var", nargs=2, action="append", metavar=("NAME", "VALUE"), help="LAMMPS -var")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--oversubscribe", action="store_true", help="allow more ranks than cores")
    parser.add_argument("--resume", action="store_true",
                        help="continue a killed or failed run from its last restart file (decks of `sediment sample`)")
    parser.add_argument("--force", action="store_true",
                        help="let the layer file replace one written by another run (-var overwrite yes)")
    return parser


def run(args: argparse.Namespace) -> int:
    """Runs the deck and says what it did."""
    from ..sim.deck import refuse_unread
    from ..sim.run import run_deck

    refuse_unread(args.deck, [name for name, _ in args.var or []])
    try:
        result = run_deck(args.deck, ranks=args.np, variables=dict(args.var or []), progress=not args.quiet,
                          oversubscribe=args.oversubscribe, force=args.force, resume=args.resume)
    except RuntimeError as exc:
        if "'overwrite yes'" not in str(exc):
            raise
        # LAMMPS names its own variable; here the same choice is an option (a killed run shorter than
        # the restart spacing has no restart file, so its frames can only be started anew).
        raise RuntimeError(f"{exc}\n  sediment run --resume continues a killed run from its last restart file; "
                           "--force starts it anew (-var overwrite yes)") from None
    print(f"{result.deck.name}: {result.steps} steps, {result.simulated_time:.6g} s simulated in "
          f"{result.wall_seconds:.1f} s on {args.np} rank(s); log {result.log}")
    return 0
