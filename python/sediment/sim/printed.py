# SPDX-License-Identifier: GPL-2.0-or-later
"""What a deck prints for Python to read, parsed in this one place: ``SAMPLE v1 v2 ...`` rows,
``RESULT key value key value ...`` lines, ``SERIES name x y`` points and ``SCREEN name value``
numbers (the planner's screening decks). A line is one of them by its first word."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Printed:
    """The lines of one run's output, by kind."""

    samples: np.ndarray
    results: dict[str, float] = field(default_factory=dict)
    series: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    screens: dict[str, float] = field(default_factory=dict)


def parse_printed(text: str) -> Printed:
    """The SAMPLE, RESULT, SERIES and SCREEN lines of a run's output (other lines left alone)."""
    rows: list[list[float]] = []
    out = Printed(np.empty(0))
    for line in text.splitlines():
        words = line.split()
        kind = words[0] if words else ""
        if kind == "SAMPLE":
            rows.append([float(v) for v in words[1:]])
        elif kind == "RESULT":
            out.results.update({k: float(v) for k, v in zip(words[1::2], words[2::2])})
        elif kind == "SERIES" and len(words) == 4:
            out.series.setdefault(words[1], []).append((float(words[2]), float(words[3])))
        elif kind == "SCREEN" and len(words) == 3:
            out.screens[words[1]] = float(words[2])
    out.samples = np.array(rows)
    return out
