# SPDX-License-Identifier: GPL-2.0-or-later
"""`python -m sediment` and the installed `sediment` command: the command line. SIGINT and SIGTERM are
taken before the command's parts load, so that a signal at once ends with exit 130 and one line, as
later ones do."""
import signal
import sys

_received: list[str] = []


def _interrupt(signum: int, _frame: object) -> None:
    _received.append(signal.Signals(signum).name)
    raise KeyboardInterrupt(_received[-1])


def command_line() -> None:
    """Loads and runs the command; exits with its status."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, _interrupt)
    began = False
    try:
        try:
            from .cli import main
        except Exception:    # an import the signal broke: numpy turns the interrupt into an ImportError
            if not _received:
                raise
            raise KeyboardInterrupt(_received[0]) from None
        began = True
        status = main()
        # the command is over: a signal from here on, through the interpreter's shutdown (which gives the
        # signals back their default, killing the process without a word), changes nothing it did
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
        sys.exit(status)
    except KeyboardInterrupt as exc:    # while the command's parts loaded, or a second signal as it ended
        left = ("as the command ended (its own message says what it left)" if began else
                "before the command began; nothing was written: run it again")
        print(f"sediment: interrupted by {exc} {left}", file=sys.stderr)
        sys.exit(130)


if __name__ == "__main__":
    command_line()
