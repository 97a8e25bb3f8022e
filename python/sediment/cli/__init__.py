# SPDX-License-Identifier: GPL-2.0-or-later
"""The `sediment` command line: one module per command, each with ``add_parser(commands)``,
``run(args)`` and ``EXAMPLES`` (shown under its --help); results are printed with their ``table()``
and written with their ``save(folder)``. A command with ``--out`` writes into a stage that is
published as one set when it returns (`sediment.folders`). Every --help works before the C++ core is
built."""
from __future__ import annotations

import argparse
import io
import os
import re
import signal
import sys
import threading
from pathlib import Path

from . import budget, calibrate, case_a, invert, paste, plan, readout, run, sample, spheres, sweep, terminal

# In the order of the work: plan a test, sample it, run it, read it; the physics' uncertainty; a
# laboratory's sheets in; then the single-sphere, accuracy and paste studies.
COMMANDS = (plan, sample, run, readout, budget, invert, terminal, sweep, case_a, spheres, paste, calibrate)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Examples kept as written; each option's default shown where it has one that says something
    (not None, False or one its help already names)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if (action.default in (None, False, argparse.SUPPRESS) or "default" in text or not action.option_strings
                or isinstance(action.default, (list, dict)) and not action.default):
            return text
        return text + " (default: %(default)s)"


class _Version(argparse.Action):
    """--version: the release the built core states (core/include/sediment/version.hpp), read only when
    asked for, so that --help works before a build."""

    def __call__(self, parser, namespace, values, option_string=None):
        try:
            from .. import _core
        except ImportError:
            parser.exit(2, "sediment --version: the C++ core (sediment._core), which states the release, is not "
                           "built: run `make build` in the repository, or install the package (README, Python route)\n")
        print(f"sediment {_core.VERSION}")
        parser.exit(0)


_NUMBER = r"(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
NEGATIVE_NUMBER = re.compile(rf"^-{_NUMBER}(,-?{_NUMBER})*$")    # -1e-3, or a list that starts with one


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command."""
    parser = argparse.ArgumentParser(prog="sediment", formatter_class=HelpFormatter,
                                     description="SEDIMENT: settling of DEM spheres in fluids with LAMMPS, and "
                                     "sedimentation-test readouts.",
                                     epilog="a test end to end:\n" + "\n".join(f"  {line}" for line in (
                                         plan.EXAMPLES[0], sample.EXAMPLES[1], run.EXAMPLES[0], readout.EXAMPLES[0])) +
                                     "\n\n`sediment COMMAND --help` for a command's options and examples")
    parser.add_argument("--version", action=_Version, nargs=0, help="show the release of the core and exit")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        sub = command.add_parser(commands)
        # A negative number in E notation or a list starting with one (--dt -1e-3,1e-3) is a value, as
        # -0.001 is, so that its option's check names it; argparse's own pattern knows only plain
        # decimals and took it for an option.
        sub._negative_number_matcher = NEGATIVE_NUMBER
        sub.formatter_class = HelpFormatter
        sub.epilog = "examples:\n" + "\n".join(f"  {line}" for line in command.EXAMPLES)
        sub.set_defaults(func=command.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs one command. Errors end with one line on stderr: exit status 2 for a problem with the
    input or the files, 130 when interrupted (Ctrl-C or SIGTERM; a run stops every rank first)."""
    # SIGINT and SIGTERM stop every command alike, through its clean-up, also where SIGINT came in
    # ignored (a background job of a script): `sediment run` takes them so while its run lasts.
    previous = {}
    _RECEIVED.clear()
    if threading.current_thread() is threading.main_thread():    # where Python lets a handler be set
        previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
    unraisable = sys.unraisablehook
    sys.unraisablehook = _quiet_lost_interrupt(unraisable)
    try:
        return _command(argv)
    except KeyboardInterrupt as exc:    # while the command's parts loaded
        print(f"sediment: interrupted by {exc or 'SIGINT'} before the command began; nothing was written: run it "
              "again", file=sys.stderr)
        return 130
    finally:
        sys.unraisablehook = unraisable
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _command(argv: list[str] | None) -> int:
    """`main` with the signals taken."""
    from ..sim.process import RunInterrupted

    args = build_parser().parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)    # as given: a batch passes its options on
    try:
        from .. import _core    # noqa: F401  (every command but --help needs it)
    except ImportError:
        _still_interrupted()    # a signal during the import is not a missing build
        print(f"sediment {args.command}: the C++ core (sediment._core) is not built: run `make build` in the "
              "repository, or install the package (README, Python route)", file=sys.stderr)
        return 2
    stdout = sys.stdout
    sys.stdout = _ReaderMayLeave(stdout)
    outputs = None
    try:
        if getattr(args, "out", None) is None:
            status = args.func(args)
            _still_interrupted()
            return status
        from ..folders import OutputSet

        with OutputSet(args.out, result_set(args), inputs_of(args)) as outputs:
            args.final_out, args.out, args.outputs = args.out, outputs.stage, outputs
            args.publish = lambda: _publish(outputs)
            status = args.func(args)
            args.publish()
        _still_interrupted()
        return status
    except RunInterrupted as exc:    # says what the run left
        print(f"sediment {args.command}: {exc}", file=sys.stderr)
        return 130
    except KeyboardInterrupt as exc:
        return _interrupted(args, outputs, str(exc) or "SIGINT")
    except Exception as exc:
        if _RECEIVED:    # an interrupt a library turned into an error of its own (numpy's import: ImportError)
            return _interrupted(args, outputs, _RECEIVED[0])
        if not isinstance(exc, (ValueError, OSError, RuntimeError)):
            raise
        print(f"sediment {args.command}: error: {exc}", file=sys.stderr)    # SheetError is a ValueError;
        return 2                                                            # OSError: missing, read-only or full files
    finally:
        sys.stdout = stdout


def _interrupted(args: argparse.Namespace, outputs, name: str) -> int:
    """Says what an interrupted command left; exit status 130."""
    if outputs is None:
        left = "files being written were left as *.partial or not written"
        if args.command == "run":
            left += "; sediment run --resume continues a run from its last restart file, --force starts it anew"
    elif outputs.published:
        left = f"after its results were written into {args.final_out}"
    else:
        left = f"{args.final_out} is as it was: nothing of this {outputs.name} was written"
    print(f"sediment {args.command}: interrupted by {name}; {left}", file=sys.stderr)
    return 130


def _publish(outputs) -> None:
    """Publishes a command's set (once: a command may do it before its last words) and says so."""
    if outputs.published:
        return
    _still_interrupted()
    written = outputs.publish()
    if written:
        print(f"wrote {outputs.folder}: " + ", ".join(p.name + ("/" if p.is_dir() else "") for p in written))
    else:
        print(f"wrote nothing into {outputs.folder}: this {outputs.name} writes no file")
    if outputs.dropped:
        print(f"removed {len(outputs.dropped)} file(s) of this {outputs.name}'s previous results that it did not write "
              f"again: {', '.join(outputs.dropped)}")
    asked = [n for n in outputs.removed_also if n not in outputs.dropped]
    if asked:
        print(f"removed {len(asked)} file(s) in {outputs.folder} that this {outputs.name} replaces: {', '.join(asked)}")
    for name, folder in outputs.removed_sets:
        print(f"removed the results of sediment {name} in {folder}: they were made from files this "
              f"{outputs.name} removed")


def result_set(args: argparse.Namespace) -> str:
    """The name of the set of files a command writes: the command, and its study or test (`invert --design`'s
    set is not an inversion's: one does not replace the other's files)."""
    design = ["design"] if getattr(args, "design", None) is not None else []
    return " ".join([args.command] + design + [getattr(args, k) for k in ("study", "test") if getattr(args, k, None)])


def inputs_of(args: argparse.Namespace) -> list[Path]:
    """The files a command's options name (its output folder aside): its results may not replace them."""
    found = []
    for name, value in vars(args).items():
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, Path) and name != "out":
                found.append(item)
    return found


_RECEIVED: list[str] = []    # the signals this command took, whether or not their KeyboardInterrupt got through


def _interrupt(signum: int, _frame: object) -> None:
    _RECEIVED.append(signal.Signals(signum).name)
    raise KeyboardInterrupt(_RECEIVED[-1])


def _quiet_lost_interrupt(report):
    """`report` (Python's report of an exception it cannot raise, one in a finaliser) less our own
    interrupt: a signal that lands in a finaliser is lost there, and `_still_interrupted` stops the
    command for it with its one-line message, so its traceback would only alarm."""
    def hook(unraisable) -> None:
        if not (isinstance(unraisable.exc_value, KeyboardInterrupt) and _RECEIVED):
            report(unraisable)
    return hook


def _still_interrupted() -> None:
    """Raises the interrupt of a signal taken earlier whose KeyboardInterrupt was lost: raised inside a
    finaliser or a library's handler while a module loaded, Python prints it and goes on. The command
    then neither publishes nor ends with 0."""
    if _RECEIVED:
        raise KeyboardInterrupt(_RECEIVED[0])


class _ReaderMayLeave(io.TextIOBase):
    """Standard output that goes on when its reader leaves (`sediment ... | head`): the rest of the
    output goes nowhere, and the command still finishes and writes its files."""

    def __init__(self, stream) -> None:
        self.stream = stream

    def _left(self) -> None:
        os.dup2(os.open(os.devnull, os.O_WRONLY), self.stream.fileno())

    def writable(self) -> bool:
        return True

    def fileno(self) -> int:
        return self.stream.fileno()

    def write(self, text: str) -> int:
        try:
            return self.stream.write(text)
        except BrokenPipeError:
            self._left()
            return len(text)

    def flush(self) -> None:
        try:
            self.stream.flush()
        except BrokenPipeError:
            self._left()
