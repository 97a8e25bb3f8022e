# SPDX-License-Identifier: GPL-2.0-or-later
"""Layer profiles built analytically, without a simulation: each size class of a PSD leaves the
top of an initially uniform column at its own constant speed (Stokes' law unless told otherwise; no
deposit). The readouts must recover the PSD from the Stokes column; they are also a quick preview of
a test before running DEM, and with other speeds (a drag law, hindrance) the effects planner's
estimate of how much an effect moves the readings."""
from __future__ import annotations

from typing import Callable

import numpy as np

from .psd import PSD, log_classes
from .readout import Column, Suspension


def settling_column(psd: PSD, height: float, times, initial_concentration: float, suspension: Suspension = Suspension(),
                    layers: int = 2000, classes: int = 600,
                    speed: Callable[[np.ndarray], np.ndarray] | None = None) -> Column:
    """An analytic column in which every size class leaves the top at a constant speed.

    Parameters
    ----------
    psd : PSD
        The distribution of the uniformly mixed sample.
    height : float
        Column height [m].
    times : array_like
        Frame times [s].
    initial_concentration : float
        Solids per volume at the start [kg/m3].
    suspension : Suspension
        Water and solids (Stokes' law).
    layers, classes : int
        Layers of the column, size classes of the PSD.
    speed : callable, optional
        Settling speed [m/s] of an array of diameters [m]; default Stokes' law.

    Returns
    -------
    Column
    """
    diameter, share = log_classes(psd, psd.diameter[0], psd.diameter[-1], classes)
    share[0] += psd.percent_finer[0] / 100.0    # mass below the table's first diameter settles with the finest class
    speed = (speed or suspension.stokes_speed)(diameter)
    edges = np.linspace(0.0, height, layers + 1)
    phi0 = initial_concentration / suspension.particle_density
    times = np.asarray(times, float)
    fraction = np.empty((len(times), layers))
    for k, t in enumerate(times):
        front = np.minimum(speed * t, height)[:, None]      # class k is present below its front
        covered = np.clip(edges[1:] - np.maximum(edges[:-1], front), 0.0, None) / np.diff(edges)
        fraction[k] = phi0 * share @ covered
    return Column(edges, times, fraction, suspension)
