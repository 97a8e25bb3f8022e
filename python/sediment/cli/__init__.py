# SPDX-License-Identifier: GPL-2.0-or-later
"""The `sediment` command line: one module per command, each with ``add_parser(commands)`` and
``run(args)``; results are printed with their ``table()`` and written with their ``save(folder)``."""
from __future__ import annotations

import argparse
import sys

from ..sim.run import RunInterrupted
from . import budget, calibrate, case_a, invert, paste, plan, readout, run, sample, spheres, sweep, terminal

COMMANDS = (terminal, case_a, sample, plan, run, readout, budget, invert, calibrate, paste, spheres, sweep)


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command."""
    parser = argparse.ArgumentParser(prog="sediment", description="SEDIMENT: settling of DEM spheres in "
                                     "fluids with LAMMPS, and sedimentation-test readouts.")
    commands = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add_parser(commands).set_defaults(func=command.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs one command. Errors end with one line on stderr: exit status 2 for a problem with the
    input or the files, 130 when interrupted (Ctrl-C or SIGTERM; a run stops every rank first)."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except RunInterrupted as exc:    # says what the run left
        print(f"sediment {args.command}: {exc}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print(f"sediment {args.command}: interrupted; files being written were left as *.partial or not written",
              file=sys.stderr)
        return 130
    except (ValueError, OSError, RuntimeError) as exc:    # SheetError is a ValueError    # OSError: missing, read-only or full files and folders
        print(f"sediment {args.command}: error: {exc}", file=sys.stderr)
        return 2
