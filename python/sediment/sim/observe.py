# SPDX-License-Identifier: GPL-2.0-or-later
"""The observables of a run as the planner and the sweeps compare them (below both): the values and
series a deck printed, and the instruments' readings of the layer file it wrote; and the relative
error of one run's against a reference's."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..constants import INSTRUMENTS
from ..lab.granulometry import read_all
from ..lab.readout import Column
from .layers import read_layers
from .printed import parse_printed

READOUTS = INSTRUMENTS    # the observables an instrument reads


@dataclass
class Observation:
    """One observable of one run: a scalar (x is None) or y over x."""
    y: np.ndarray
    x: np.ndarray | None = None


def observe(text: str, names: list[str], layers_file: Path | None) -> dict[str, Observation]:
    """The observables of one run, from what the deck printed and the layer file it wrote."""
    printed = parse_printed(text)
    results, series = printed.results, printed.series
    found: dict[str, Observation] = {}
    readouts = [n for n in names if n in READOUTS]
    if readouts:
        found.update(_readout_curves(layers_file, readouts))
    for name in names:
        if name in readouts:
            continue
        if name in results:
            found[name] = Observation(np.array([results[name]]))
        elif name in series:
            xy = np.array(series[name])
            found[name] = Observation(xy[:, 1], xy[:, 0])
        else:
            printed = sorted(set(results) | set(series))
            raise ValueError(f"the deck printed no RESULT or SERIES '{name}' (it printed: {', '.join(printed) or 'none'})")
    return found


def _readout_curves(layers_file: Path | None, instruments: list[str]) -> dict[str, Observation]:
    if layers_file is None or not layers_file.is_file():
        raise ValueError(f"readout observables need the deck's layer file ({layers_file}): does it write one?")
    readings, _ = read_all(Column.from_layers(read_layers(layers_file)), instruments)
    return {r.instrument: Observation(r.percent_finer, r.diameter) for r in readings}


def relative_error(run: Observation, ref: Observation, log_x: bool = False) -> float:
    """Relative error of a run: |run / reference - 1| for a scalar; for a series, the largest
    |run - reference| (the reference interpolated at the run's x, in log x for readouts) over the
    reference's largest magnitude."""
    if run.x is None:
        return float(abs(run.y[0] - ref.y[0]) / abs(ref.y[0])) if ref.y[0] != 0 else float(abs(run.y[0]))
    assert ref.x is not None
    order = np.argsort(ref.x)
    rx, ry = ref.x[order], ref.y[order]
    x = run.x
    inside = (x >= rx[0]) & (x <= rx[-1])
    if not inside.any():
        raise ValueError("a series does not overlap its reference (different x ranges)")
    if log_x:
        expected = np.interp(np.log(x[inside]), np.log(rx), ry)
    else:
        expected = np.interp(x[inside], rx, ry)
    scale = np.max(np.abs(ry))
    return float(np.max(np.abs(run.y[inside] - expected)) / (scale if scale > 0 else 1.0))
