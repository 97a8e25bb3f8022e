# SPDX-License-Identifier: GPL-2.0-or-later
"""Layer profiles built analytically, without a simulation: each size class of a PSD leaves the
top of an initially uniform column at its Stokes velocity (no hindrance, no deposit). The readouts
must recover the PSD from these; they are also a quick preview of a test before running DEM."""
from __future__ import annotations

import numpy as np

from .psd import PSD, log_classes
from .readout import Column, Suspension


def stokes_column(psd: PSD, height: float, times, initial_concentration: float, suspension: Suspension = Suspension(),
                  layers: int = 2000, classes: int = 600) -> Column:
    """An analytic column in which every size class leaves the top at its Stokes speed.

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

    Returns
    -------
    Column
    """
    diameter, share = log_classes(psd, psd.diameter[0], psd.diameter[-1], classes)
    share[0] += psd.percent_finer[0] / 100.0    # mass below the table's first diameter settles with the finest class
    speed = suspension.stokes_speed(diameter)
    edges = np.linspace(0.0, height, layers + 1)
    phi0 = initial_concentration / suspension.particle_density
    times = np.asarray(times, float)
    fraction = np.empty((len(times), layers))
    for k, t in enumerate(times):
        front = np.minimum(speed * t, height)[:, None]      # class k is present below its front
        covered = np.clip(edges[1:] - np.maximum(edges[:-1], front), 0.0, None) / np.diff(edges)
        fraction[k] = phi0 * share @ covered
    return Column(edges, times, fraction, suspension)
