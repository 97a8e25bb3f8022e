# SPDX-License-Identifier: GPL-2.0-or-later
"""`python -m sediment`: the command line. SIGINT and SIGTERM are taken before anything loads, so
that a signal at once ends with exit 130 and one line, as later ones do."""
import signal
import sys


def _interrupt(signum: int, _frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


for _signal in (signal.SIGINT, signal.SIGTERM):
    signal.signal(_signal, _interrupt)
try:
    from .cli import main
except KeyboardInterrupt as exc:
    print(f"sediment: interrupted by {exc} before the command began; nothing was written", file=sys.stderr)
    sys.exit(130)
sys.exit(main())
