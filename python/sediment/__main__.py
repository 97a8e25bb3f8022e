# SPDX-License-Identifier: GPL-2.0-or-later
"""`python -m sediment`: the command line. SIGINT and SIGTERM are taken before anything loads, so
that a signal at once ends with exit 130 and one line, as later ones do."""
import signal
import sys


def _interrupt(signum: int, _frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


for _signal in (signal.SIGINT, signal.SIGTERM):
    signal.signal(_signal, _interrupt)
_began = False
try:
    from .cli import main

    _began = True
    status = main()
    # the command is over: a signal from here on, through the interpreter's shutdown (which gives the
    # signals back their default, killing the process without a word), changes nothing it did
    for _signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(_signal, signal.SIG_IGN)
    sys.exit(status)
except KeyboardInterrupt as exc:    # while the command's parts loaded, or a second signal as it ended
    left = ("as the command ended (its own message says what it left)" if _began else
            "before the command began; nothing was written: run it again")
    print(f"sediment: interrupted by {exc} {left}", file=sys.stderr)
    sys.exit(130)
