# SPDX-License-Identifier: GPL-2.0-or-later
"""Progress bars (tqdm) for long work."""
from __future__ import annotations

from .folders import signals_held


def bar(iterable=None, **options):
    """A tqdm bar, made with SIGINT and SIGTERM held back: a bar half made by a signal fails again as
    it is collected, with a traceback after the command's own message."""
    from tqdm import tqdm

    with signals_held():
        return tqdm(iterable, **options)
