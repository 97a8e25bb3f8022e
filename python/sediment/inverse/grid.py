# SPDX-License-Identifier: GPL-2.0-or-later
"""The inverse's size bins (docs/inverse.md, the method): where the readings cut the sample, where the
sieves pin it, the texture classes' limits, and the two tails no reading resolves.

Bin k holds the mass between edge k - 1 (the floor for the first) and edge k; the last edge is the top,
the largest grain of the specimen (100 % finer). Each edge has a basis:

- ``reading``: a reading's cut diameter (the reading takes whole bins, whatever the PSD inside them);
- ``sieve``: a sieve's opening (its percent passing constrains the fit);
- ``between``: between two pinned edges, where the answer is the smoothest the data allow;
- ``coarse tail``: above the coarsest reading or sieve that is short of 100 %, below the top: the mass
  there is known, its placement is not;
- ``fine tail``: below the finest reading's cut: likewise;
- ``top``: the largest sieve the whole specimen passes (2 mm without a sieve sheet: D422 and D7928
  test the part passing it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MERGE = 1.03              # readings' cut diameters closer than this ratio share a bin edge
NEAR = 1.015              # other edges closer than this to an edge already kept are left out
MIN_BINS = 4              # a grid coarser than this leaves a PSD of its readings' few diameters
TOP = 2e-3                # [m] the specimen's largest grain without a sieve sheet (D422's, D7928's split)
FLOOR = 10.0              # the finest bin reaches down this many times below the lowest edge
# the texture classes' limits (USDA, ISO 14688-1), so that the fractions are read at edges
CLASS_LIMITS = (2e-6, 50e-6, 63e-6)
# ASTM sieve openings [m]: the coarse tail's edges where no sieve sheet gives them
SIEVE_SERIES = (75e-6, 106e-6, 150e-6, 250e-6, 425e-6, 850e-6)
EDGE_STEPS = (1.12, 1.25)   # the tails' first edges beyond the extreme cuts, as ratios to them


@dataclass(frozen=True)
class SizeGrid:
    """Bin edges [m] (the last the top) with their basis, and the finest bin's lower end."""

    edges: np.ndarray
    basis: np.ndarray          # str per edge (module docstring)
    floor: float

    @property
    def bins(self) -> int:
        """How many bins: one below each edge."""
        return len(self.edges)

    @property
    def lower(self) -> np.ndarray:
        """Each bin's lower end."""
        return np.concatenate([[self.floor], self.edges[:-1]])

    @property
    def pinned(self) -> np.ndarray:
        """Edges a reading or a sieve constrains."""
        return np.isin(self.basis, ("reading", "sieve"))

    def _pinned_edges(self) -> np.ndarray:
        """Indices of the pinned edges below the top."""
        return np.flatnonzero(self.pinned[:-1])

    def tail(self, which: str) -> np.ndarray:
        """Indices of the bins of the coarse or fine tail (the bins whose upper edge is in it, and for
        the coarse tail the top bin above it)."""
        pinned = self._pinned_edges()
        if which == "fine":
            return np.arange(pinned[0] + 1)
        return np.arange(pinned[-1] + 1, self.bins)

    def smooth(self) -> np.ndarray:
        """Indices of the bins between the finest and the coarsest pinned edge: the smoothness penalty's."""
        pinned = self._pinned_edges()
        return np.arange(pinned[0] + 1, pinned[-1] + 1)

    def cumulative(self, diameters: np.ndarray) -> np.ndarray:
        """The matrix that takes the bins' shares to the fraction finer than each diameter (linear in
        log d within a bin, as `psd_of` draws the PSD)."""
        x = np.log(np.concatenate([[self.floor], self.edges]))
        rows = np.zeros((len(diameters), self.bins))
        for r, d in enumerate(np.log(np.asarray(diameters, float))):
            k = int(np.clip(np.searchsorted(x, d, side="right") - 1, 0, self.bins - 1))
            rows[r, :k] = 1.0
            rows[r, k] = np.clip((d - x[k]) / (x[k + 1] - x[k]), 0.0, 1.0)
        return rows


def size_grid(cuts: np.ndarray, bins: int, sieves: np.ndarray = np.empty(0), top: float = TOP) -> SizeGrid:
    """The bins of an inversion.

    Edges at the readings' cut diameters (cuts closer than MERGE share their geometric mean), gaps wider
    than a `bins`-point log grid from the finest to the coarsest cut filled evenly in log; the sieves'
    openings and the texture classes' limits below the top; without sieves, the ASTM series in the
    coarse tail; the top last. The finest bin reaches down to a tenth of the lowest edge (grains that
    hardly move in a day: where within it they lie changes no reading).
    """
    if bins < MIN_BINS:
        raise ValueError(f"--bins {bins}: give at least {MIN_BINS} size bins")
    cuts = np.sort(np.asarray(cuts, float))
    clusters = [[cuts[0]]]
    for d in cuts[1:]:
        if d > clusters[-1][0] * MERGE:
            clusters.append([d])
        else:
            clusters[-1].append(d)
    kept = [float(np.exp(np.mean(np.log(c)))) for c in clusters]
    if len(kept) < 2:
        raise ValueError(f"the readings cut the sample at one diameter only ({kept[0] * 1e6:.3g} um): an inversion "
                         "needs readings at two times or depths at least")
    if kept[-1] * MERGE >= top:
        raise ValueError(f"the coarsest reading cuts the sample at {kept[-1] * 1e6:.4g} um, at or above its largest "
                         f"grain ({top * 1e6:.4g} um): check the sieve sheet or the readings' times")
    ratio = (cuts[-1] / cuts[0]) ** (1.0 / max(bins - 1, 1))
    edges, basis = [kept[0]], ["reading"]
    for a, b in zip(kept[:-1], kept[1:]):
        parts = max(int(math.ceil(math.log(b / a) / math.log(ratio) - 1e-9)), 1)
        edges += list(np.geomspace(a, b, parts + 1)[1:])
        basis += ["between"] * (parts - 1) + ["reading"]
    extra = [(float(s), "sieve") for s in sieves if s < top / NEAR]
    extra += [(d, "between") for d in CLASS_LIMITS if d < top / NEAR]
    if not len(sieves):
        extra += [(d, "between") for d in SIEVE_SERIES if d < top / NEAR]
    # the fine tail in two bins at least: where below the finest cut its mass lies is for the data to say
    extra.append((min(kept[0], CLASS_LIMITS[0]) / 2, "between"))
    # narrow bins just outside the extreme cuts: a hydrometer's bulb spans cuts from about 0.8 to 1.25 times
    # its reading's, so how the tails' mass lies there moves the extreme readings, and a steep mode just
    # beyond a cut must be a placement the band can reach
    extra += [(kept[-1] * f, "between") for f in EDGE_STEPS if kept[-1] * f < top / NEAR]
    extra += [(kept[0] / f, "between") for f in EDGE_STEPS]
    for d, kind in sorted(extra, key=lambda e: (e[1] != "sieve", e[0])):    # sieves first: they pin
        near = np.abs(np.log(np.array(edges) / d)) < math.log(NEAR)
        if near.any():
            k = int(np.argmax(near))
            if kind == "sieve" and basis[k] == "between":
                edges[k], basis[k] = d, "sieve"
            continue
        edges.append(d)
        basis.append(kind)
    order = np.argsort(edges)
    edges_array, basis_array = np.array(edges)[order], np.array(basis, dtype=object)[order]
    pinned = np.flatnonzero(np.isin(basis_array, ("reading", "sieve")))
    below, above = np.arange(len(edges_array)) < pinned[0], np.arange(len(edges_array)) > pinned[-1]
    basis_array[below] = "fine tail"
    basis_array[above] = "coarse tail"
    return SizeGrid(np.append(edges_array, top), np.append(basis_array, "top").astype(str), edges_array[0] / FLOOR)
