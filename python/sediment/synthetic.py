"""Layer profiles built analytically, without a simulation: each size class of a PSD leaves the
top of an initially uniform column at its Stokes velocity (no hindrance, no deposit). The readouts
must recover the PSD from these; they are also a quick preview of a test before running DEM."""
from __future__ import annotations

import numpy as np

from .psd import PSD
from .readout import Column, Fluid


def stokes_column(psd: PSD, height: float, times, initial_concentration: float, fluid: Fluid = Fluid(),
                  layers: int = 2000, classes: int = 600) -> Column:
    """Column of `layers` over `height` [m] at `times` [s]; `initial_concentration` in kg/m3."""
    lo = psd.diameter[0]
    hi = psd.diameter[-1]
    bins = np.exp(np.linspace(np.log(lo), np.log(hi), classes + 1))
    diameter = np.sqrt(bins[1:] * bins[:-1])
    share = np.diff(psd.at(bins)) / 100.0
    share[0] += psd.at(lo) / 100.0     # mass below the table's first diameter settles with the finest class
    speed = (fluid.particle_density - fluid.density) * fluid.gravity * diameter ** 2 / (18 * fluid.viscosity)
    edges = np.linspace(0.0, height, layers + 1)
    phi0 = initial_concentration / fluid.particle_density
    times = np.asarray(times, float)
    fraction = np.empty((len(times), layers))
    for k, t in enumerate(times):
        front = np.minimum(speed * t, height)[:, None]      # class k is present below its front
        covered = np.clip(edges[1:] - np.maximum(edges[:-1], front), 0.0, None) / np.diff(edges)
        fraction[k] = phi0 * share @ covered
    return Column(edges, times, fraction, fluid)
