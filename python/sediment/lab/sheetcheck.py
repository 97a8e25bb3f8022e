# SPDX-License-Identifier: GPL-2.0-or-later
"""What refuses a sheet's row: `SheetError`, and the plausible range of a column's values
(sediment.plausible), below both the sheets (lab/sheet.py) and the instruments that read them."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..plausible import RANGES, Range


class SheetError(ValueError):
    """A sheet that cannot be a record of a sedimentation test, with the reason and the row."""


def plausible(path: Path, lines: list[int], values: dict[str, np.ndarray], column: str,
               quantity: str | Range) -> None:
    """Refuses the first value of a column outside its quantity's plausible range (blank cells aside),
    naming the line and the likely unit slip; where the column's other values are plausible, the value
    may be misread rather than in another unit, and the message gives theirs first."""
    bounds = RANGES[quantity] if isinstance(quantity, str) else quantity
    column_values = values[column]
    fine = np.array([math.isfinite(v) and bounds.refusal(v) is None for v in column_values])
    for line, value in zip(lines, column_values):
        reason = bounds.refusal(value) if math.isfinite(value) else None
        if reason is None:
            continue
        if fine.sum() >= 2:    # the others read as the column's unit: this one may be misread
            others, slip = column_values[fine], bounds.slip(value)
            reason = (f"{bounds.refusal(value, slips=False)}; the column's other rows read {others.min():g} to "
                      f"{others.max():g}{' ' + bounds.unit if bounds.unit else ''}: check this one"
                      + (f" (or{slip[1:]})" if slip else ""))
        raise SheetError(f"{path}, line {line}: {column} {reason}")
