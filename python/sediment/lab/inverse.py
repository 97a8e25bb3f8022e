# SPDX-License-Identifier: GPL-2.0-or-later
"""From a laboratory's readings to the sample's PSD (docs/inverse.md).

The readings of a test are nearly linear in the mass of each size class: classes settle on their own
but for the hindrance, which the whole suspension sets. So:

1. The sheets' standard reduction gives a first PSD.
2. Each reading cuts the sample at one diameter (`cut_diameters`: the grains the forward model's
   hindered drag carries past the instrument's depth by the reading's time); the bins' edges are
   those cuts, with edges added where cuts are far apart (`bin_edges`), so that a reading takes whole
   bins whatever the PSD's shape inside them.
3. One DEM run of the test with that PSD (the forward model's best physics: standard drag curve,
   Richardson & Zaki's hindrance, the water at the sheet's mean temperature), its size classes
   `SUBCLASSES` per bin, writes each bin's layer fractions (the grid's `classes`) and the two tails'.
   Scaling each bin's layers gives the column of any other mass split among the bins, as that run's
   hindrance left it.
4. The instruments read those columns at the sheet's times (each time mapped to the run's water by
   the temperature record: a grain falls sum(dt / mu) alike), linearised in the bins' masses: a
   constrained least squares (masses >= 0, so the cumulative PSD never falls; their sum the sample's
   mass; a smoothness penalty on the interior bins' mass densities chosen so that the fit reaches
   the readings' noise) gives new masses, two Gauss-Newton steps on the exact readings.
5. A new run with the new PSD updates the hindrance; rounds go on until the PSD moves by less than
   0.2 points (at most `rounds`).
6. The band: the central 95 % of draws of the PSDs the sheets allow (readings, forward model and
   thermometer drawn from their noise, the penalty aiming at a draw of its prior), with the physics'
   band of an error budget if given.

Assumptions: the sample mass and particle density are known; within a bin the PSD keeps the shape of
the run's PSD; the hindrance of a round's run holds for the fit of that round; the temperature
record maps times in the Stokes regime. Only the diameters between the finest and the coarsest cut
are reported; between two cuts the answer is the smoothest the readings allow, so a step there is
rounded. Where the sheet is not a sedimenting suspension of the given sample, its chi-square says so.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import _core, figures
from ..results import Table, write_text
from .psd import PSD
from .readout import BuoyancySphere, Column, Hydrometer, Pipette, Suspension, gs_correction
from .sheet import Sheet, check_sheet, standard_reduction

CONVERGED = 0.2           # points of percent finer between rounds
MERGE = 1.03              # readings' cut diameters closer than this ratio share a bin edge
SUBCLASSES = 3            # the forward run's size classes per bin, even in log across it
MIN_BINS = 4              # a grid coarser than this leaves a PSD of its readings' few diameters
SMOOTHNESS = np.geomspace(1e-6, 1e2, 17)    # penalty weights tried, largest that still fits the noise


@dataclass(frozen=True)
class LabTest:
    """What the sheets do not say: the sample, the cylinder and the instruments."""

    mass: float = 0.060                  # dry sample [kg]
    particle_density: float = 2650.0     # [kg/m3]
    cylinder_area: float = 27.8e-4       # [m2]
    height: float = 0.36                 # suspension height [m]
    hydrometer: Hydrometer = field(default_factory=Hydrometer.astm_152h)
    zero_correction: float = 0.0         # g/L subtracted from each hydrometer reading (composite correction)
    meniscus: float = 0.0                # g/L added for the depth only
    sphere_depth: float | None = None    # centre [m], default 0.3 of the height
    sphere_diameter: float = 0.025       # [m]
    sphere_mass: float = 0.020           # [kg]
    # reading noise: 152H read to 0.5 g/L; a balance to 1 mg; pipette sample masses to 0.1 mg (as g/L of 25 mL)
    noise: dict = field(default_factory=lambda: {"hydrometer": 0.25, "buoyancy": 1e-3, "pipette": 0.1e-3 / 0.025})
    thermometer: float = 0.5             # C, standard uncertainty of the temperature record

    @property
    def initial_concentration(self) -> float:
        """c0 [kg/m3 = g/L]."""
        return self.mass / (self.cylinder_area * self.height)

    @property
    def sphere(self) -> BuoyancySphere:
        """The buoyancy sphere, its centre at `sphere_depth` (default 0.3 of the height)."""
        depth = 0.3 * self.height if self.sphere_depth is None else self.sphere_depth
        return BuoyancySphere(depth, self.sphere_diameter, self.sphere_mass)

    def corrected(self, sheet: Sheet) -> np.ndarray:
        """The sheet's readings after the hydrometer's zero correction."""
        return sheet.reading - (self.zero_correction if sheet.instrument == "hydrometer" else 0.0)


def whole_sample_reading(sheet: Sheet, test: LabTest, water: Suspension) -> float:
    """What the instrument reads with the whole sample in suspension (its unit)."""
    c0 = test.initial_concentration
    if sheet.instrument == "hydrometer":
        return c0 / gs_correction(test.particle_density / 1000.0)
    if sheet.instrument == "pipette":
        return c0
    rho = water.mixture_density(c0 / test.particle_density)
    return (test.sphere_mass - rho * test.sphere.volume) * 1e3


def solids_signal(sheet: Sheet, test: LabTest, water: Suspension) -> float:
    """How far the whole sample moves the instrument's reading from clear water's (its unit)."""
    clear = (test.sphere_mass - water.fluid_density * test.sphere.volume) * 1e3 if sheet.instrument == "buoyancy" else 0.0
    return abs(whole_sample_reading(sheet, test, water) - clear)


def effective_times(sheet: Sheet, reference: Suspension, offset: float = 0.0) -> np.ndarray:
    """Each reading's time on a run in water at the reference's temperature: the same fall, sum of
    dt / mu, under the sheet's temperature record (linear between readings, the first reading's before
    it; plus `offset` C); the reading times when none was recorded."""
    if not np.isfinite(sheet.temperature).any():
        return sheet.time
    recorded = np.isfinite(sheet.temperature)
    times, temps = sheet.time[recorded], sheet.temperature[recorded] + offset
    grid = np.unique(np.concatenate([[0.0], np.linspace(0.0, sheet.time[-1], 2000), sheet.time]))
    temperature = np.clip(np.interp(grid, times, temps), 0.0, 40.0)
    rate = reference.viscosity / np.array([_core.water_viscosity(t) for t in temperature])
    elapsed = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(grid))])
    return np.interp(sheet.time, grid, elapsed)


@dataclass
class ForwardRun:
    """One DEM run of the test with the bins' layers: their columns scale into the column of any split."""

    layers: object                       # LayerFile
    bins: np.ndarray                     # fraction [bins, frames, layers] of each bin, the file's order
    masses: np.ndarray                   # each bin's share of the run's solids
    water: Suspension
    test: LabTest

    def column(self, shares: np.ndarray) -> Column:
        """The column of a split of the sample's mass among the bins (shares summing to about 1)."""
        scale = np.divide(shares, self.masses, out=np.zeros(len(shares)), where=self.masses > 0)
        fraction = np.tensordot(scale, self.bins, axes=1)
        column = Column.from_layers(self.layers, fraction=fraction)
        return replace(column, suspension=self.water)

    def readings(self, shares: np.ndarray, sheets: list[Sheet], times: list[np.ndarray]) -> np.ndarray:
        """Every sheet's modelled readings, in order, for a split of the mass."""
        column = self.column(shares)
        out = []
        for sheet, t in zip(sheets, times):
            if sheet.instrument == "hydrometer":
                out.append(self.test.hydrometer.read(column, t, cylinder_area=self.test.cylinder_area).reading)
            elif sheet.instrument == "pipette":
                out.append(np.array([Pipette(z).read(column, [ti]).reading[0] for z, ti in zip(sheet.depth, t)]))
            else:
                # the balance reads the sphere in the water at each reading's temperature
                sphere = self.test.sphere
                recorded = np.where(np.isfinite(sheet.temperature), sheet.temperature, self.water.temperature or 20.0)
                water = np.array([_core.water_density(c) for c in recorded])
                out.append(sphere.read(column, t).reading - (water - self.water.fluid_density) * sphere.volume * 1e3)
        return np.concatenate(out)


def linearise(run: ForwardRun, shares: np.ndarray, sheets: list[Sheet],
              times: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The modelled readings of a split of the mass and their derivatives by each bin's share
    (forward differences of 1e-3)."""
    base = run.readings(shares, sheets, times)
    step = 1e-3
    jac = np.empty((len(base), len(shares)))
    for k in range(len(shares)):
        moved = shares.copy()
        moved[k] += step
        jac[:, k] = (run.readings(moved, sheets, times) - base) / step
    return base, jac


def run_forward(psd: PSD, edges: np.ndarray, test: LabTest, water: Suspension, t_end: float, folder: Path,
                particles: int, courant: float, seed: int) -> ForwardRun:
    """Writes and runs the test with `psd`, its layers split at `edges`."""
    from ..sim.layers import read_layers
    from ..sim.run import run_batch
    from ..sim.scene import Cylinder, Effects, plan, write

    scene = plan(psd, cylinder=Cylinder(test.cylinder_area, test.height), mass=test.mass, suspension=water,
                 classes=class_bounds(edges), particles=particles, courant=courant, seed=seed, effects=Effects(),
                 t_end=t_end)
    scene.tag_classes = tuple(float(d) for d in edges)
    write(scene, folder, force=True)    # the inverse's own working run: a new inversion replaces it
    out = run_batch(folder / "in.sedimentation", {"overwrite": "yes"}, check=False)
    if out.error:
        raise RuntimeError(f"the forward run in {folder} failed: {out.error}")
    layers = read_layers(folder / "layers.h5")
    bins = np.stack([layers.column(f"class_{k}") for k in range(len(edges) + 1)])
    solids = bins[:, 0].sum(axis=1)
    return ForwardRun(layers, bins, solids / solids.sum(), water, test)


def class_bounds(edges: np.ndarray) -> np.ndarray:
    """The forward run's size classes: each bin of `psd_of` split into SUBCLASSES even in log, so that
    every bin has grains across its width and none of another bin."""
    outer = np.concatenate([[edges[0] / 3], edges, [edges[-1] ** 2 / edges[-2]]])
    parts = [np.geomspace(a, b, SUBCLASSES + 1)[:-1] for a, b in zip(outer[:-1], outer[1:])]
    return np.concatenate(parts + [outer[-1:]])


def psd_of(shares: np.ndarray, edges: np.ndarray, name: str = "") -> PSD:
    """The PSD of bin shares: percent finer at the edges, the finest bin down to a third of the first
    edge, the coarsest as wide in log as the bin below it."""
    cumulative = 100 * np.cumsum(shares)[:-1]
    diameter = np.concatenate([[edges[0] / 3], edges, [edges[-1] ** 2 / edges[-2]]])
    percent = np.concatenate([[0.0], np.clip(cumulative, 0, 100), [100.0]])
    return PSD(diameter, np.maximum.accumulate(percent), name)


def first_guess(points_d: np.ndarray, points_p: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Bin shares from the standard reduction's points (sorted, made non-decreasing, within 0-100),
    mixed with a tenth of an even split so that every bin has mass for the run to scale."""
    order = np.argsort(points_d)
    d, p = points_d[order], np.clip(np.maximum.accumulate(np.clip(points_p[order], 0, 100)), 0, 100)
    at_edges = np.interp(np.log(edges), np.log(d), p, left=p[0], right=p[-1])
    shares = np.diff(np.concatenate([[0.0], at_edges, [100.0]])) / 100.0
    shares = np.maximum(shares, 0.0)
    return 0.9 * shares / shares.sum() + 0.1 / len(shares)


def cut_diameters(sheets: list[Sheet], readings: list[np.ndarray], times: list[np.ndarray], test: LabTest,
                  water: Suspension) -> np.ndarray:
    """The diameter each reading cuts in the forward model: the grains whose hindered terminal speed (the
    standard drag curve, Richardson & Zaki at the solids finer than them, the reading's own percent
    finer) takes them past the instrument's depth by the reading's time in the run's water. The
    standard reduction's Stokes diameter at the effective time gives that speed."""
    from ..planner.screening import terminal_speeds

    out = []
    for sheet, reading, t in zip(sheets, readings, times):
        run_sheet = replace(sheet, time=t, reading=reading, temperature=np.full(len(t), np.nan))
        stokes, percent = standard_reduction(run_sheet, water, test.initial_concentration, test.hydrometer,
                                             test.cylinder_area, test.sphere, test.meniscus)
        for d_stokes, p in zip(stokes, np.clip(percent, 0.0, 100.0)):
            speed = water.stokes_speed(d_stokes)
            voidage = 1.0 - test.initial_concentration / test.particle_density * p / 100.0
            low, high = math.log(0.5 * d_stokes), math.log(2.0 * d_stokes)
            for _ in range(40):    # bisection in log d: the hindered speed rises with the diameter
                middle = 0.5 * (low + high)
                moving = terminal_speeds(water, np.array([math.exp(middle)]), "standard", voidage, "richardson-zaki")[0]
                low, high = (middle, high) if moving < speed else (low, middle)
            out.append(math.exp(0.5 * (low + high)))
    return np.array(out)


def bin_edges(cuts: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """Bin edges at the readings' cut diameters, so that a reading takes whole bins whatever the PSD's
    shape within them (cuts closer than MERGE share their geometric mean), gaps wider than a `bins`-point
    log grid from the finest to the coarsest cut filled evenly in log, and one more edge above the
    coarsest (the earliest readings see the grains just coarser than their own cut pass). Returns the
    edges and whether each is a cut."""
    cuts = np.sort(cuts)
    ratio = (cuts[-1] / cuts[0]) ** (1.0 / max(bins - 1, 1))
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
    edges, cut = [kept[0]], [True]
    for a, b in zip(kept[:-1], kept[1:]):
        parts = max(int(math.ceil(math.log(b / a) / math.log(ratio) - 1e-9)), 1)
        edges += list(np.geomspace(a, b, parts + 1)[1:])
        cut += [False] * (parts - 1) + [True]
    return np.array(edges + [edges[-1] * ratio]), np.array(cut + [False])


def _penalty(edges: np.ndarray) -> np.ndarray:
    """Second derivatives in log d of the interior bins' mass densities (share per log width; the tails
    are free), scaled by the mean log width cubed: second differences of the shares for even bins."""
    x = np.log(edges)
    width = np.diff(x)
    centre = 0.5 * (x[1:] + x[:-1])
    scale = width.mean() ** 3
    rows = np.zeros((max(len(width) - 2, 0), len(width) + 2))
    for r in range(len(width) - 2):
        left, right = centre[r + 1] - centre[r], centre[r + 2] - centre[r + 1]
        weights = (2 / (left * (left + right)), -2 / (left * right), 2 / (right * (left + right)))
        for j, w in enumerate(weights):
            rows[r, 1 + r + j] = scale * w / width[r + j]
    return rows


def fit(jacobian: np.ndarray, base: np.ndarray, shares0: np.ndarray, data: np.ndarray, sigma: np.ndarray,
        edges: np.ndarray, smoothness: float | None = None,
        prior_draw: np.ndarray | None = None) -> tuple[np.ndarray, float, float]:
    """The shares that fit the linearised readings, >= 0, summing to 1, with the largest smoothness
    penalty whose chi-square stays within the readings' count (or the one given); returns the shares,
    the chi-square and the penalty weight. With `prior_draw` (one standard normal number per penalty
    row) the penalty aims at it instead of zero: with data drawn from their noise, that makes the answer
    a draw of the PSD the readings and the smoothness prior allow (randomise-then-optimise)."""
    from scipy.optimize import lsq_linear

    n = len(shares0)
    a = jacobian / sigma[:, None]
    b = (data - base + jacobian @ shares0) / sigma
    total = 1e4 * np.ones((1, n))
    penalty = _penalty(edges)

    def solve(weight: float) -> tuple[np.ndarray, float]:
        matrix = np.vstack([a, total, math.sqrt(weight) * penalty * n])
        target = np.concatenate([b, [1e4], np.zeros(len(penalty)) if prior_draw is None else prior_draw])
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


@dataclass
class Inversion:
    """The recovered PSD with its band, the standard reduction, the fit and its verdict."""

    edges: np.ndarray            # [m]
    percent: np.ndarray          # recovered percent finer at the edges
    low: np.ndarray
    high: np.ndarray
    measured: np.ndarray         # whether each edge is a reading's cut diameter (else between readings)
    reduction: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]]    # instrument, time, D, P
    fit_rows: list[tuple[str, float, float, float, float]]             # instrument, time, measured, model, sigma
    chi2: float
    rounds: int
    smoothness: float
    resolution: str
    notes: list[str] = field(default_factory=list)

    @property
    def reduced_chi2(self) -> float:
        """Chi-square per reading."""
        return self.chi2 / max(len(self.fit_rows), 1)

    @property
    def consistent(self) -> bool:
        """Whether some PSD explains the sheet within the readings' noise (chi-square per reading < 4)."""
        return self.reduced_chi2 < 4.0

    def psd(self) -> PSD:
        """The recovered PSD between the finest and the coarsest reading's diameters."""
        return PSD(self.edges, self.percent, "recovered")

    def table(self) -> Table:
        """Percent finer with its band at each bin edge, and whether a reading resolves it (1) or it lies
        between the readings' diameters (0)."""
        table = Table(["diameter_um", "percent_finer", "low", "high", "measured"], notes=self.notes)
        for d, p, low, high, measured in zip(self.edges * 1e6, self.percent, self.low, self.high, self.measured):
            table.add(float(d), float(p), float(low), float(high), int(measured))
        return table

    def save(self, folder: Path) -> list[Path]:
        """psd.csv, reduction.csv, fit.csv, invert.json, invert.png."""
        folder = Path(folder)
        reduction = Table(["instrument", "time_min", "diameter_um", "percent_finer"])
        for name, t, d, p in self.reduction:
            for row in zip(t / 60, d * 1e6, p):
                reduction.add(name, *map(float, row))
        fitted = Table(["instrument", "time_min", "measured", "simulated", "residual_sigma"])
        for name, t, measured, model, sigma in self.fit_rows:
            fitted.add(name, t / 60, measured, model, (model - measured) / sigma)
        summary = {"psd": {"diameter_um": (self.edges * 1e6).tolist(), "percent_finer": self.percent.tolist(),
                           "low": self.low.tolist(), "high": self.high.tolist(),
                           "measured": self.measured.astype(int).tolist()},
                   "chi2_per_reading": self.reduced_chi2, "consistent": self.consistent, "rounds": self.rounds,
                   "smoothness": self.smoothness, "resolution": self.resolution, "notes": self.notes}
        return [write_text(folder / "psd.csv", self.table().csv()),
                write_text(folder / "reduction.csv", reduction.csv()),
                write_text(folder / "fit.csv", fitted.csv()),
                write_text(folder / "invert.json", json.dumps(summary, indent=1) + "\n"),
                self.plot(folder / "invert.png")]

    def plot(self, path: Path) -> Path:
        """The recovered PSD with its band and the standard reduction; the fit's residuals."""
        plt = figures.pyplot()
        fig, (ax, res) = plt.subplots(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [3, 2]})
        d = self.edges * 1e6
        ax.fill_between(d, self.low, self.high, color="C0", alpha=0.25, label="band")
        ax.plot(d, self.percent, "C0-", label="recovered PSD")
        ax.plot(d[self.measured], self.percent[self.measured], "C0o", ms=4, label="at a reading's diameter")
        ax.plot(d[~self.measured], self.percent[~self.measured], "o", mec="C0", mfc="white", ms=4,
                label="between readings")
        for k, (name, _, dd, p) in enumerate(self.reduction):
            ax.plot(dd * 1e6, p, "s", ms=5, color=f"C{k + 1}", label=f"standard reduction ({name})")
        ax.set(xscale="log", xlabel="diameter [um]", ylabel="percent finer [%]", ylim=(0, 100),
               title="the sample's PSD from the sheet")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        for k, name in enumerate(dict.fromkeys(r[0] for r in self.fit_rows)):
            rows = [r for r in self.fit_rows if r[0] == name]
            res.plot([r[1] / 60 for r in rows], [(r[3] - r[2]) / r[4] for r in rows], "o-", ms=4, label=name)
        res.axhline(0, color="k", lw=0.8)
        res.set(xscale="log", xlabel="time [min]", ylabel="(simulated - measured) / noise",
                title=f"fit: chi2 per reading {self.reduced_chi2:.2g}")
        res.legend(fontsize=8)
        res.grid(alpha=0.3)
        return figures.save(fig, path)


def _check_bins(bins: int) -> None:
    if bins < MIN_BINS:
        raise ValueError(f"--bins {bins}: give at least {MIN_BINS} size bins")


def invert(sheets: list[Sheet], test: LabTest, folder: Path, *, bins: int = 24, particles: int = 20000,
           courant: float = 4.0, rounds: int = 4, draws: int = 64, seed: int = 1,
           budget_band: float = 0.0) -> Inversion:
    """Recovers the PSD the sheets were read from (the method above).

    Parameters
    ----------
    sheets : list of Sheet
        The readings (any of hydrometer, pipette, buoyancy sphere, one sheet each or several).
    test : LabTest
        Sample mass, particle density, cylinder and instruments.
    folder : Path
        Where the forward runs go.
    bins : int
        Size bins between the finest and the coarsest reading's diameters.
    particles, courant : int, float
        Resolution of the forward runs (`sediment sample`'s defaults).
    rounds : int
        Forward runs at most.
    draws : int
        Draws of the PSDs the sheets allow, for the band (their central 95 %).
    budget_band : float
        Points of percent finer the physics' uncertainty adds (an error budget's physical total).
    """
    if not sheets:
        raise ValueError("no sheet to invert")
    _check_bins(bins)
    recorded = np.concatenate([s.temperature[np.isfinite(s.temperature)] for s in sheets])
    mean_temperature = float(recorded.mean()) if len(recorded) else 20.0
    water = Suspension.at_temperature(mean_temperature, test.particle_density)
    c0 = test.initial_concentration
    signals = [solids_signal(sheet, test, water) for sheet in sheets]
    for sheet, signal in zip(sheets, signals):
        # the tolerance: twice the reading's noise, and 2 % of the solids' signal for the sampling of a real
        # suspension (a pipette's first samples can draw a little more than the mean)
        check_sheet(sheet, whole_sample_reading(sheet, test, water), max(2 * test.noise[sheet.instrument], 0.02 * signal))
    corrected = [test.corrected(sheet) for sheet in sheets]
    reduction = []
    for sheet, reading in zip(sheets, corrected):
        d, p = standard_reduction(replace(sheet, reading=reading), water, c0, test.hydrometer, test.cylinder_area,
                                  test.sphere, test.meniscus)
        reduction.append((sheet.instrument, sheet.time, d, p))
    diameters = np.concatenate([d for _, _, d, _ in reduction])
    times = [effective_times(s, water) for s in sheets]
    edges, at_cut = bin_edges(cut_diameters(sheets, corrected, times, test, water), bins)
    reported = edges[:-1]
    shares = first_guess(diameters, np.concatenate([p for *_, p in reduction]), edges)
    data = np.concatenate(corrected)
    sigma = np.concatenate([np.full(len(s.time), test.noise[s.instrument]) for s in sheets])
    # the readings' times in water 1 C warmer: the runs reach the latest, and the band's thermometer
    # offset (below) is linear in the readings there
    warmer = [effective_times(s, water, 1.0) for s in sheets]
    t_end = 1.02 * max(t[-1] for t in warmer)

    previous = None
    weight = None
    reading_sigma = sigma
    for round_number in range(1, rounds + 1):
        # every bin keeps some mass in the run, so that its columns can be scaled to any share
        spread = 0.8 * shares + 0.2 / len(shares)
        run = run_forward(psd_of(spread, edges), edges, test, water, t_end, folder / f"round{round_number}",
                          particles, courant, seed)
        if round_number == 1:
            # the forward model's own sampling error: the same PSD with another placement; its rms
            # difference per instrument (over sqrt 2) adds to each reading's noise
            other = run_forward(psd_of(spread, edges), edges, test, water, t_end, folder / "sampling", particles,
                                courant, seed + 1)
            gap = run.readings(shares, sheets, times) - other.readings(shares, sheets, times)
            start = 0
            model_sigma = np.empty(len(data))
            for sheet, signal in zip(sheets, signals):
                n = len(sheet.time)
                # and at least the resolution's 0.2 points of percent finer (the time step's, error budget)
                model_sigma[start:start + n] = max(math.sqrt(np.mean(gap[start:start + n] ** 2) / 2), 0.002 * signal)
                start += n
            sigma = np.sqrt(reading_sigma ** 2 + model_sigma ** 2)
        for _ in range(2):    # Gauss-Newton on this run's columns
            base, jac = linearise(run, shares, sheets, times)
            shares, chi2, weight = fit(jac, base, shares, data, sigma, edges)
        percent = 100 * np.cumsum(shares)[:-1]
        if previous is not None and np.max(np.abs(percent - previous)) < CONVERGED:
            break
        previous = percent
    model, jac = linearise(run, shares, sheets, times)
    chi2 = float(np.sum(((model - data) / sigma) ** 2))
    # The band: draws of the PSDs the sheets allow, each fit again with the readings drawn from their
    # noise (and the forward model's), the thermometer's offset drawn, and the smoothness penalty aiming
    # at a draw of its prior (randomise-then-optimise). An offset moves every reading's time alike; its
    # effect on the readings is taken as linear (the readings with the record 1 C warmer).
    per_degree = run.readings(shares, sheets, warmer) - model
    rng = np.random.default_rng(seed)
    penalty_rows = len(_penalty(edges))
    draws_percent = []
    for _ in range(draws):
        noisy = data + rng.normal(0.0, sigma) - rng.normal(0.0, test.thermometer) * per_degree
        x, _, _ = fit(jac, model, shares, noisy, sigma, edges, weight, rng.normal(0.0, 1.0, penalty_rows))
        draws_percent.append(100 * np.cumsum(x)[:-1])
    percent = 100 * np.cumsum(shares)[:-1]
    low, high = np.percentile(draws_percent, [2.5, 97.5], axis=0) if draws > 1 else (percent, percent)
    below = np.sqrt(np.maximum(percent - low, 0.0) ** 2 + budget_band ** 2)
    above = np.sqrt(np.maximum(high - percent, 0.0) ** 2 + budget_band ** 2)
    rows = []
    start = 0
    for sheet in sheets:
        n = len(sheet.time)
        rows += [(sheet.instrument, float(t), float(m), float(f), float(s))
                 for t, m, f, s in zip(sheet.time, data[start:start + n], model[start:start + n], sigma[start:start + n])]
        start += n
    resolution = (f"{particles} parcels, Courant {courant:g}, standard drag curve + Richardson & Zaki, water at "
                  f"{mean_temperature:.3g} C")
    inside = slice(0, len(reported))
    percent, below, above = percent[inside], below[inside], above[inside]
    result = Inversion(reported, percent, np.clip(percent - below, 0, 100), np.clip(percent + above, 0, 100),
                       at_cut[inside], reduction,
                       rows, chi2, round_number, float(weight), resolution)
    result.notes.append(f"forward model: {resolution}; {round_number} round(s)")
    result.notes.append("measured 1: a reading's cut diameter; measured 0: between the readings' diameters, where the "
                        "value and its band are those of the smoothest PSDs the readings allow (a step there is not seen)")
    if not result.consistent:
        result.notes.append(f"NOT CONSISTENT: chi-square per reading {result.reduced_chi2:.3g} (>= 4): no PSD of this "
                            "sample under this physics gives these readings within their noise: a misread, a "
                            "flocculated sample, or a wrong sample mass or particle density")
    flagged = [r for r in rows if abs(r[3] - r[2]) > 4 * r[4]]
    for name, t, measured, modelled, s in flagged:
        result.notes.append(f"reading {name} at {t / 60:g} min is {abs(modelled - measured) / s:.1f} noise units off the "
                            "fit: check it")
    return result


# The designs `design_test` compares: instruments and their reading times [min] (the pipette at 10 cm).
DESIGNS = {
    "152H, D422 times": [("hydrometer", (2, 5, 15, 30, 60, 250, 1440))],
    "152H, D7928 times": [("hydrometer", (1, 2, 4, 15, 30, 60, 240, 1440))],
    "pipette at 10 cm": [("pipette", None)],
    "buoyancy sphere, Bravo et al.'s times": [("buoyancy", (0.5, 1, 2, 4, 15, 30, 60, 120, 240, 480))],
    "152H (D7928) + pipette": [("hydrometer", (1, 2, 4, 15, 30, 60, 240, 1440)), ("pipette", None)],
}


def design_test(psd: PSD, folder: Path, masses=(0.030, 0.045, 0.060, 0.080), designs: dict = DESIGNS,
                test: LabTest = LabTest(), bins: int = 12, draws: int = 24, particles: int = 20000,
                seed: int = 1) -> list[tuple[str, float, int, float, float]]:
    """Which instrument, reading times and sample mass recover `psd` best: for each mass a forward run of
    the test, each design's readings of it with their noise drawn `draws` times and fitted as `invert`
    fits (linearised at the truth), and the error of the recovered PSD at the bin edges against the
    truth. Returns (design, mass, readings, mean error, worst error) [pp], the mean over the draws of each
    draw's mean and worst absolute error (NaN, with no readings, where the instrument cannot read that
    mass, e.g. a suspension beyond the 152H's scale). The hindrance's own uncertainty, which grows with the mass, is
    not in it (docs/error-budget.md: the exponent row)."""
    _check_bins(bins)
    water = Suspension.at_temperature(20.0, test.particle_density)
    rng = np.random.default_rng(seed)
    results = []
    for mass in masses:
        trial = replace(test, mass=mass)
        # the edges from the Stokes diameters the designs' readings resolve, as `invert` takes them
        scales = [d for parts in designs.values() for d in _design_diameters(parts, trial, water)]
        edges = np.geomspace(min(scales), max(scales), bins)
        truth = np.diff(np.concatenate([[0.0], psd.at(edges), [100.0]])) / 100.0
        spread = 0.8 * truth + 0.2 / len(truth)
        run = run_forward(psd_of(spread, edges), edges, trial, water, 1.02 * 86400, folder / f"mass{mass * 1e3:g}g",
                          particles, 4.0, seed)
        for name, parts in designs.items():
            sheets = _design_sheets(parts, trial, water)
            times = [s.time for s in sheets]
            try:
                base, jac = linearise(run, truth, sheets, times)
            except ValueError:    # e.g. a suspension denser than the 152H's scale: it cannot read this mass
                results.append((name, mass, 0, math.nan, math.nan))
                continue
            sigma = np.concatenate([np.full(len(s.time), trial.noise[s.instrument]) for s in sheets])
            mean_errors, worst_errors = [], []
            for _ in range(draws):
                noisy = base + rng.normal(0.0, sigma)
                x, _, _ = fit(jac, base, truth, noisy, sigma, edges)
                error = np.abs(100 * (np.cumsum(x) - np.cumsum(truth))[:-1])
                mean_errors.append(error.mean())
                worst_errors.append(error.max())
            results.append((name, mass, len(base), float(np.mean(mean_errors)), float(np.mean(worst_errors))))
    return results


def _design_sheets(parts, test: LabTest, water: Suspension) -> list[Sheet]:
    """The sheets of a design (readings unset: the forward run reads them)."""
    sheets = []
    for instrument, minutes in parts:
        if instrument == "pipette":
            time = np.sort(Pipette(0.10).default_times(water))
            depth = np.full(len(time), 0.10)
        else:
            time = np.array(minutes, float) * 60
            depth = np.empty(0)
        sheets.append(Sheet(instrument, Path(instrument), time, np.zeros(len(time)), np.full(len(time), 20.0), depth))
    return sheets


def _design_diameters(parts, test: LabTest, water: Suspension) -> list[float]:
    """The Stokes diameters a design's readings resolve, at the instruments' nominal depths."""
    out = []
    for sheet in _design_sheets(parts, test, water):
        depth = {"hydrometer": 0.15, "pipette": 0.10, "buoyancy": test.sphere.depth}[sheet.instrument]
        out += list(water.stokes_diameter(depth, sheet.time))
    return out
