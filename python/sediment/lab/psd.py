# SPDX-License-Identifier: GPL-2.0-or-later
"""Particle-size distributions: the input table, its interpolation and its discretisation into size
classes (docs/sedimentation-tests.md section 1, Bravo et al. eq. 15)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..csvfile import CsvError, read_csv


class PSDError(ValueError):
    """A PSD table that cannot be used, with the reason and the row."""


@dataclass(frozen=True)
class PSD:
    """Percent finer by mass against diameter; linear in log(diameter) between rows."""

    diameter: np.ndarray        # [m], strictly increasing
    percent_finer: np.ndarray   # [%], non-decreasing, within 0..100
    name: str = ""

    def __post_init__(self) -> None:
        d, p = np.asarray(self.diameter, float), np.asarray(self.percent_finer, float)
        where = f"{self.name}: " if self.name else ""
        if d.ndim != 1 or d.size < 2 or p.shape != d.shape:
            raise PSDError(f"{where}a PSD needs at least two rows of (diameter, percent finer)")
        if not np.all(np.isfinite(d)) or not np.all(np.isfinite(p)):
            raise PSDError(f"{where}diameters and percents must be numbers")
        if d[0] <= 0:
            raise PSDError(f"{where}diameters must be > 0 (row 1: {d[0] * 1e6:g} um)")
        bad = np.flatnonzero(np.diff(d) <= 0)
        if bad.size:
            raise PSDError(f"{where}diameters must increase: row {bad[0] + 2} ({d[bad[0] + 1] * 1e6:.10g} um) "
                           f"after row {bad[0] + 1} ({d[bad[0]] * 1e6:.10g} um)")
        outside = np.flatnonzero((p < 0) | (p > 100))
        if outside.size:
            raise PSDError(f"{where}percent finer must be within 0..100: row {outside[0] + 1} has {p[outside[0]]:g}")
        falls = np.flatnonzero(np.diff(p) < 0)
        if falls.size:
            raise PSDError(f"{where}percent finer must not decrease with diameter: row {falls[0] + 2} "
                           f"({p[falls[0] + 1]:g} %) after row {falls[0] + 1} ({p[falls[0]]:g} %)")
        object.__setattr__(self, "diameter", d)
        object.__setattr__(self, "percent_finer", p)

    def span(self) -> tuple[float, float]:
        """The diameters between which the mass lies: the last row at 0 % and the first at 100 %
        (or the table's ends)."""
        p = self.percent_finer
        lo = self.diameter[np.argmax(p > 0) - 1] if p[0] == 0 else self.diameter[0]
        hi = self.diameter[np.argmax(p >= 100)] if p[-1] >= 100 else self.diameter[-1]
        return float(lo), float(hi)

    def at(self, diameter) -> np.ndarray:
        """Percent finer at the given diameters [m] (flat beyond the table)."""
        return np.interp(np.log(np.asarray(diameter, float)), np.log(self.diameter), self.percent_finer)


# `sediment invert`'s psd.csv: its first two columns are the PSD
INVERSE_COLUMNS = ("diameter_um", "percent_finer", "low", "high", "measured", "basis")
NOT_FITTING = "NOT CONSISTENT"    # the first line of an inversion's files whose fit fails
MIN_DIAMETER_UM = 0.01       # below this a diameter_um column was written in another unit
MAX_DIAMETER_LOW_UM = 5.0     # a table ending below this was written in mm, not um


def read_psd(path: str | Path) -> PSD:
    """Reads a particle-size distribution table.

    Parameters
    ----------
    path : str or Path
        CSV with the columns ``diameter_um,percent_finer`` (as in examples/granulometry/psd).

    Returns
    -------
    PSD
        Diameters [m] and percent finer by mass, interpolated linearly in log(diameter).

    Raises
    ------
    PSDError
        The file is missing, empty or malformed, with the line and the reason.
    """
    try:
        table = read_csv(path, "PSD file")
    except CsvError as exc:
        raise PSDError(str(exc)) from None
    path = table.path
    refused = next((line.strip() for line in table.comments if line.lstrip().startswith(f"# {NOT_FITTING}")), None)
    if refused:
        raise PSDError(f"{path}: written by an inversion whose fit does not explain its sheets ('{refused[2:60]}...'): "
                       "it is no PSD of the sample")
    if table.header != ["diameter_um", "percent_finer"] and table.header != list(INVERSE_COLUMNS):
        raise PSDError(f"{path}: header must be 'diameter_um,percent_finer' (two columns, or the columns of `sediment "
                       f"invert`'s psd.csv), not '{','.join(table.header)}'")
    if not table.rows:
        raise PSDError(f"{path}: no rows below the header")
    try:
        values = np.array([table.numbers("diameter_um"), table.numbers("percent_finer")]).T
    except CsvError as exc:
        raise PSDError(f"{exc} (every row needs two numbers: diameter in um, percent finer)") from None
    smallest = float(values[:, 0].min())
    if 0 < smallest < MIN_DIAMETER_UM:
        raise PSDError(f"{path}: the diameter_um column starts at {smallest:g} um, below {MIN_DIAMETER_UM} um "
                       "(10 nm): write micrometres, not metres or millimetres")
    largest = float(values[:, 0].max())
    if largest < MAX_DIAMETER_LOW_UM:
        raise PSDError(f"{path}: the largest diameter is {largest:g} um; a sedimentation test's PSD reaches tens of "
                       "um: if these are millimetres (sieve sizes), write micrometres (x 1000)")
    if values[:, 1].max() <= 1.0:
        raise PSDError(f"{path}: percent finer tops out at {values[:, 1].max():g}: write percent (0-100), "
                       "not fractions (0-1)")
    return PSD(values[:, 0] * 1e-6, values[:, 1], name=str(path))


@dataclass(frozen=True)
class SizeClasses:
    """Discrete diameters with the particle count and mass fraction of each. Each simulated particle
    stands for `weight` real ones of its class (1: the real count)."""

    diameter: np.ndarray        # [m] class diameters phi_k
    mass_fraction: np.ndarray   # of the input PSD, sums to the fraction of mass within the classes
    count: np.ndarray           # simulated particles per class (>= 1 where mass > 0)
    weight: np.ndarray          # real particles per simulated one, per class
    edges: np.ndarray           # [m] the classes' bounds (one more than classes)

    def represented_grains(self) -> float:
        """Real grains the simulated particles stand for."""
        return float(np.sum(self.count * self.weight))

    def simulated_mass_fraction(self) -> np.ndarray:
        """Mass fraction of each class among the grains the simulation stands for."""
        mass = self.count * self.weight * self.diameter ** 3
        return mass / mass.sum()

    def simulated_psd(self) -> PSD:
        """The PSD the particles actually have: percent finer at the upper edge of each class."""
        cumulative = 100 * np.concatenate([[0.0], np.cumsum(self.simulated_mass_fraction())])
        return PSD(self.edges, np.minimum(cumulative, 100.0), name="simulated")


def log_bounds(lo: float, hi: float, classes: int) -> np.ndarray:
    """The bounds of `classes` log-equal classes from lo to hi."""
    return np.exp(np.linspace(np.log(lo), np.log(hi), classes + 1))


def log_classes(psd: PSD, lo: float, hi: float, classes: int) -> tuple[np.ndarray, np.ndarray]:
    """Diameters at the centres of `classes` log-equal bins between lo and hi, and the mass fraction
    of the PSD in each bin."""
    return classes_between(psd, log_bounds(lo, hi, classes))


def classes_between(psd: PSD, bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Diameters at the log centres of the classes between increasing `bounds`, and the mass fraction of
    the PSD in each."""
    return np.sqrt(bounds[1:] * bounds[:-1]), np.diff(psd.at(bounds)) / 100.0


def discretise(psd: PSD, classes: int | np.ndarray, sample_mass: float, particle_density: float,
               volume_fraction: float, particles: int | None = None) -> SizeClasses:
    """Bravo et al. eq. 15 on `classes` log-spaced diameters spanning the PSD: class k holds the mass
    between its lower and upper mid-points, n_k = 6 M dw_k / (rho_p pi phi_k^3) scaled by the
    simulated fraction of the cylinder; every class with mass keeps at least one particle.

    With `particles`, about that many are simulated as parcels of equal real mass (n_k in proportion
    to dw_k, at least one), each standing for the real n_k / (simulated n_k) particles: the simulated
    PSD is then the discretised one exactly, and every class is sampled alike.

    Parameters
    ----------
    psd : PSD
        The input distribution.
    classes : int or array
        Number of log-spaced size classes spanning the PSD, or the classes' bounds [m] (increasing).
    sample_mass : float
        Dry mass of the whole sample [kg].
    particle_density : float
        Solid density [kg/m3].
    volume_fraction : float
        Simulated fraction of the cylinder's volume.
    particles : int, optional
        Parcels to simulate; None for real grains.

    Returns
    -------
    SizeClasses
        Diameter, real and simulated counts and weight per class.
    """
    if np.ndim(classes) == 0:
        if classes < 2:
            raise PSDError("need at least 2 size classes")
        bounds = log_bounds(*psd.span(), int(classes))
    else:
        bounds = np.asarray(classes, float)
        if len(bounds) < 3 or not np.all(np.diff(bounds) > 0) or bounds[0] <= 0:
            raise PSDError("class bounds must be at least 3 increasing diameters > 0")
    classes = len(bounds) - 1
    if not (sample_mass > 0 and particle_density > 0 and 0 < volume_fraction <= 1):
        raise PSDError("sample mass and particle density must be > 0, the simulated fraction within (0, 1]")
    if particles is not None and particles < classes:
        raise PSDError(f"{particles} particles cannot sample {classes} size classes: give at least one per class")
    diameter, fraction = classes_between(psd, bounds)
    exact = 6 * sample_mass * fraction / (particle_density * np.pi * diameter ** 3) * volume_fraction
    if particles is None:
        count = np.where(fraction > 0, np.maximum(np.rint(exact), 1), 0).astype(np.int64)
    else:
        count = np.where(fraction > 0, np.maximum(np.rint(particles * fraction / fraction.sum()), 1), 0).astype(np.int64)
    weight = np.divide(exact, count, out=np.ones_like(exact), where=count > 0) if particles else np.ones_like(exact)
    return SizeClasses(diameter=diameter, mass_fraction=fraction, count=count, weight=weight, edges=bounds)
