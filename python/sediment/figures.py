# SPDX-License-Identifier: GPL-2.0-or-later
"""Figures written to files, with matplotlib's file-only backend (no display needed)."""
from __future__ import annotations

from pathlib import Path

from .results import write_atomic


def pyplot():
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path: Path, dpi: int = 120, tight: bool = True) -> Path:
    """Writes `fig` to `path` (format from its suffix) atomically and closes it."""
    if tight:
        fig.tight_layout()
    path = Path(path)
    try:
        write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".")))
    finally:
        pyplot().close(fig)
    return path
