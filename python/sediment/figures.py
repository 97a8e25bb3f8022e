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


def design_errors(rows, path: Path, title: str) -> Path:
    """`sediment invert --design`'s figure: each design's worst error of the recovered PSD against the
    sample mass, from `design_test`'s rows (design, mass [kg], readings, mean, worst [pp])."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name in dict.fromkeys(r[0] for r in rows):
        mine = [r for r in rows if r[0] == name]
        ax.plot([r[1] * 1e3 for r in mine], [r[4] for r in mine], "o-", label=name)
    ax.set(xlabel="sample mass [g]", ylabel="worst error of the recovered PSD [pp]", yscale="log", title=title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save(fig, path)
