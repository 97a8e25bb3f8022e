# SPDX-License-Identifier: GPL-2.0-or-later
"""The inverse's fit of the bins' shares to the linearised readings and sieves (docs/inverse.md):
shares >= 0 summing to 1, a smoothness penalty between the pinned edges, and a placement prior in the
tails, where no reading or sieve says how the known mass is spread."""
from __future__ import annotations

import math

import numpy as np

from .grid import SizeGrid

SMOOTHNESS = np.geomspace(1e-6, 1e2, 17)    # penalty weights tried, largest that still fits the noise
PLACEMENT_POINT = 1.0     # a tail bin's share off its prior by this many points costs one unit of chi-square
# the band's draws take the smoothness weight log-uniform over this many decades below the chosen one: the
# discrepancy principle picks the smoothest PSD that fits, and rougher ones fit the data as well
ROUGHNESS_DECADES = 2.0
TAIL_CONCENTRATION = 0.3  # the band's draws of a tail's placement: Dirichlet, mostly near one bin or another


def penalty(grid: SizeGrid) -> np.ndarray:
    """Second derivatives in log d of the mass densities (share per log width) of the bins between the
    finest and the coarsest pinned edge, scaled by their mean log width cubed: second differences of
    the shares for even bins."""
    smooth = grid.smooth()
    width = np.log(grid.edges / grid.lower)
    centre = 0.5 * (np.log(grid.edges) + np.log(grid.lower))
    rows = np.zeros((max(len(smooth) - 2, 0), grid.bins))
    if not len(rows):
        return rows
    scale = width[smooth].mean() ** 3
    for r, (a, b, c) in enumerate(zip(smooth[:-2], smooth[1:-1], smooth[2:])):
        left, right = centre[b] - centre[a], centre[c] - centre[b]
        weights = (2 / (left * (left + right)), -2 / (left * right), 2 / (right * (left + right)))
        for k, w in zip((a, b, c), weights):
            rows[r, k] = scale * w / width[k]
    return rows


def even_placement(grid: SizeGrid, tail: np.ndarray) -> np.ndarray:
    """A tail's mass spread evenly in log d across its bins."""
    width = np.log(grid.edges / grid.lower)[tail]
    return width / width.sum()


def placement_rows(grid: SizeGrid, weights: dict[str, np.ndarray], strength: float = 1.0) -> np.ndarray:
    """Rows (x_k - w_k sum of the tail's x) for each tail of two bins or more, in units of
    PLACEMENT_POINT / strength: linear in the shares, so the tail's total stays free for the data to set."""
    rows = []
    for which in ("fine", "coarse"):
        tail = grid.tail(which)
        if len(tail) < 2:
            continue
        w = weights[which]
        for k, wk in zip(tail, w):
            row = np.zeros(grid.bins)
            row[tail] = -wk
            row[k] += 1.0
            rows.append(strength * 100.0 / PLACEMENT_POINT * row)
    return np.array(rows).reshape(-1, grid.bins)


def draw_placement(grid: SizeGrid, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """A draw of each tail's placement for the band: mostly near one bin or another, so that the band
    covers every placement the data allow; even in log d on average, so that narrow bins (those just
    beyond the extreme cuts) are drawn as often as their width says, not as often as a wide one."""
    out = {}
    for which in ("fine", "coarse"):
        tail = grid.tail(which)
        concentration = TAIL_CONCENTRATION * len(tail) * even_placement(grid, tail)
        out[which] = rng.dirichlet(concentration) if len(tail) > 1 else np.ones(len(tail))
    return out


def end_placement(grid: SizeGrid, end: int) -> dict[str, np.ndarray]:
    """Each tail's mass all in one of its ends: its finest bin (`end` 0) or its coarsest (-1)."""
    placement = {}
    for which in ("fine", "coarse"):
        weights = np.zeros(len(grid.tail(which)))
        weights[end] = 1.0
        placement[which] = weights
    return placement


def fit(jacobian: np.ndarray, base: np.ndarray, shares0: np.ndarray, data: np.ndarray, sigma: np.ndarray,
        grid: SizeGrid, smoothness: float | None = None, prior_draw: np.ndarray | None = None,
        placement: dict[str, np.ndarray] | None = None, placement_strength: float = 1.0
        ) -> tuple[np.ndarray, float, float]:
    """The shares that fit the linearised data, >= 0, summing to 1, with the largest smoothness penalty
    whose chi-square stays within the data's count (or the one given); returns the shares, the
    chi-square and the penalty weight.

    With `prior_draw` (one standard normal number per penalty row) the penalty aims at it instead of
    zero, and with `placement` the tails' mass is spread as drawn: with data drawn from their noise, that
    makes the answer a draw of the PSDs the data and the priors allow (randomise-then-optimise). Without,
    each tail's mass is spread evenly in log d. `placement_strength` scales the placement's rows (an
    extreme placement held firmly, so that it is not a compromise with the data where they hardly see it)."""
    from scipy.optimize import lsq_linear

    n = len(shares0)
    a = jacobian / sigma[:, None]
    b = (data - base + jacobian @ shares0) / sigma
    total = 1e4 * np.ones((1, n))
    smooth = penalty(grid)
    if placement is None:
        placement = {which: even_placement(grid, grid.tail(which)) for which in ("fine", "coarse")}
    tails = placement_rows(grid, placement, placement_strength)

    def solve(weight: float) -> tuple[np.ndarray, float]:
        matrix = np.vstack([a, total, math.sqrt(weight) * smooth * n, tails])
        target = np.concatenate([b, [1e4], np.zeros(len(smooth)) if prior_draw is None else prior_draw,
                                 np.zeros(len(tails))])
        x = lsq_linear(matrix, target, bounds=(0.0, np.inf), method="bvls").x
        return x, float(np.sum((a @ x - b) ** 2))

    if smoothness is not None:
        x, chi2 = solve(smoothness)
        return x, chi2, smoothness
    best = None
    for weight in SMOOTHNESS:
        x, chi2 = solve(weight)
        if best is None or chi2 <= max(len(b), 1.05 * best[1]):
            best = (x, chi2, weight)
    return best
