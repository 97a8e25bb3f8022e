# SPDX-License-Identifier: GPL-2.0-or-later
"""Why the inverse differs from the standard reduction (docs/inverse.md, the corrections): the same
sheets fitted again under models that switch the forward model's effects on one at a time, from the
standard reduction's own assumptions to the full model, each read at the standard reduction's
diameters, so that the changes add up exactly to the difference.

The stages, in order (each keeps the ones before it):

0. ``fit``: the standard reduction's model itself (each reading is the concentration at the
   instrument's depth of the grains finer than its Stokes diameter at the reading's own temperature),
   fitted as the inverse fits (smoothness, sieves, tails): what the fit alone moves;
1. ``temperature record``: the water's viscosity along the test's temperature record, not the
   reading's alone;
2. ``drag curve``: the standard drag curve's terminal speeds instead of Stokes' law;
3. ``instrument body``: the instrument as a body in the column (the hydrometer floating where the
   buoyancy of its bulb and stem in the suspension holds it, the sphere's and the pipette's volumes)
   instead of a point at its depth;
4. ``hindrance``: the DEM run (Richardson & Zaki's hindrance, and the run's own discreteness): the
   inverse's answer.

Stages 0-3 settle each bin at constant speeds, exactly (no DEM), so the breakdown costs a few fits.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .. import figures
from ..lab.psd import PSD
from ..lab.readout import Column, Suspension
from ..lab.settling import terminal_speeds
from ..lab.sheet import Reduction, Sheet
from ..lab.synthetic import settling_column
from ..results import Table
from .fit import fit
from .grid import SizeGrid
from .model import ForwardRun, LabTest, linearise, psd_of, settling_diameter

EFFECTS = ("fit", "temperature record", "drag curve", "instrument body", "hindrance")
# the mean settling speed of dilute polydisperse spheres of one density falls as 1 + S phi, S = -5.3 +- 1.1 (90 %
# confidence) measured at phi 0.13-2.5 % (X-ray attenuation, J. Fluid Mech.; docs/inverse.md)
MEASURED_HINDRANCE = (-5.3 - 1.1, -5.3 + 1.1)
LAYERS = 800              # the analytic columns' layers (0.45 mm in a 36 cm suspension)


@dataclass
class Breakdown:
    """Per reading: the standard reduction's diameter and percent finer, the change each effect makes (in
    EFFECTS' order), the inverse's percent finer at that diameter and its band (all of the whole sample)."""

    instrument: list[str]
    time: np.ndarray          # s
    diameter: np.ndarray      # m, the standard reduction's
    standard: np.ndarray      # percent finer
    changes: np.ndarray       # [readings, effects]
    low: np.ndarray
    high: np.ndarray

    @property
    def inverse(self) -> np.ndarray:
        """The inverse's percent finer at the standard reduction's diameters: the standard plus every change."""
        return self.standard + self.changes.sum(axis=1)

    def table(self) -> Table:
        """corrections.csv."""
        names = [e.replace(" ", "_") for e in EFFECTS]
        table = Table(["instrument", "time_min", "diameter_um", "standard_percent", *names, "inverse_percent", "low",
                       "high"],
                      notes=["each effect's column: how far switching it on (after those to its left) moves percent "
                             "finer at the standard reduction's diameter; standard_percent plus them all is "
                             "inverse_percent, whose band is low-high (sediment.inverse.breakdown)"])
        for k, name in enumerate(self.instrument):
            table.add(name, float(self.time[k] / 60), float(self.diameter[k] * 1e6), float(self.standard[k]),
                      *map(float, self.changes[k]), float(self.inverse[k]), float(self.low[k]), float(self.high[k]))
        return table

    def summary(self) -> dict:
        """For invert.json: each effect's mean change and its range over the readings, and the rows."""
        effects = {name: {"mean": float(self.changes[:, k].mean()), "min": float(self.changes[:, k].min()),
                          "max": float(self.changes[:, k].max())} for k, name in enumerate(EFFECTS)}
        total = self.inverse - self.standard
        return {"effects": effects, "total": {"mean": float(total.mean()), "min": float(total.min()),
                                              "max": float(total.max())},
                "rows": [{"instrument": name, "time_min": float(self.time[k] / 60),
                          "diameter_um": float(self.diameter[k] * 1e6), "standard_percent": float(self.standard[k]),
                          "changes": dict(zip(EFFECTS, map(float, self.changes[k]))),
                          "inverse_percent": float(self.inverse[k]), "band": [float(self.low[k]), float(self.high[k])]}
                         for k, name in enumerate(self.instrument)]}

    def hindrance_band(self, water: Suspension, diameter: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """How far below and above the answer the measured hindrance's spread puts it at each diameter
        [points]: the hindrance's change scaled by the measured slopes over the model's (Richardson & Zaki
        at a dilute 1 %), taken between the readings' diameters (the nearest reading's beyond them)."""
        dilute = 0.01
        free, hindered = (terminal_speeds(water, np.array([1e-5]), "standard", 1.0 - phi, "richardson-zaki")[0]
                          for phi in (0.0, dilute))
        model = (hindered / free - 1.0) / dilute
        order = np.argsort(self.diameter)
        change = np.interp(np.log(diameter), np.log(self.diameter[order]),
                           self.changes[order, EFFECTS.index("hindrance")])
        shifts = np.array([(slope / model - 1.0) * change for slope in MEASURED_HINDRANCE])
        return np.maximum(-shifts.min(axis=0), 0.0), np.maximum(shifts.max(axis=0), 0.0)

    def line(self) -> str:
        """The console's line: how far the inverse is from the standard reduction and what makes it."""
        total = self.inverse - self.standard
        parts = ", ".join(f"{name} {self.changes[:, k].mean():+.2f}" for k, name in enumerate(EFFECTS))
        return (f"against the standard reduction at its diameters: {total.mean():+.2f} points on average ({total.min():+.2f} "
                f"to {total.max():+.2f} at single readings); by effect (mean): {parts} (corrections.csv)")

    def plot(self, path):
        """Each reading's change, effect after effect, against its diameter (one line per instrument and
        stage), with the inverse's band."""
        plt = figures.pyplot()
        fig, ax = plt.subplots(figsize=(8, 4.5))
        names = np.array(self.instrument)
        for m, instrument in enumerate(dict.fromkeys(self.instrument)):
            rows = np.flatnonzero(names == instrument)
            rows = rows[np.argsort(self.diameter[rows])]
            d = self.diameter[rows] * 1e6
            ax.fill_between(d, (self.low - self.standard)[rows], (self.high - self.standard)[rows], color="0.5",
                            alpha=0.18, lw=0, label="the inverse's band" if m == 0 else None)
            cumulative = np.cumsum(self.changes[rows], axis=1)
            for k, name in enumerate(EFFECTS):
                label = f"+ {name} (mean {self.changes[:, k].mean():+.2f})" if m == 0 else None
                ax.plot(d, cumulative[:, k], "-" + "osD^v"[m % 5], ms=3.5, color=f"C{k}", label=label)
            ax.plot([], [], "k" + "osD^v"[m % 5], ms=4, ls="", label=instrument)
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set(xscale="log", xlabel="standard reduction's diameter [um]",
               ylabel="inverse - standard reduction [points]",
               title="what moves the inverse from the standard reduction, effect after effect")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        return figures.save(fig, path)


def breakdown(sheets: list[Sheet], reduction: list[Reduction], times: list[np.ndarray], test: LabTest,
              water: Suspension, grid: SizeGrid, data: np.ndarray, sigma: np.ndarray, sieve_rows: np.ndarray,
              shares: np.ndarray, share: float, band: tuple[np.ndarray, np.ndarray, np.ndarray]) -> Breakdown:
    """The inverse's answer (the final `shares` of the specimen, `share` of the sample) taken apart
    effect by effect (module docstring). `data`, `sigma` and `sieve_rows` as the inverse fitted them;
    `reduction` unscaled (of the specimen); `band`: the inverse's diameters, low and high."""
    depth = np.concatenate([r.depth for r in reduction])
    effective = np.concatenate(times)
    diameters = [np.concatenate([r.diameter for r in reduction]),
                 np.asarray(water.stokes_diameter(depth, effective), float),
                 drag_curve_diameters(water, depth, effective)]

    def solve(model) -> np.ndarray:
        x = shares
        for _ in range(2):    # the body's readings are nearly linear in the shares: two Gauss-Newton steps
            base, jac = model(x)
            x, _, _ = fit(np.vstack([jac, sieve_rows]), np.concatenate([base, sieve_rows @ x]), x, data, sigma, grid)
        return x

    stages = [solve(lambda x, d=d: point_readings(x, d, sheets, reduction, test, grid)) for d in diameters]
    body = AnalyticRun.of(grid, test, water, np.unique(np.concatenate([[0.0], effective])))
    stages.append(solve(lambda x: linearise(body, x, sheets, times)))
    stages.append(shares)
    at = diameters[0]
    standard = np.concatenate([r.percent for r in reduction]) * share
    percent = np.array([psd_of(x, grid).at(at) * share for x in stages])
    changes = np.diff(np.vstack([standard, percent]), axis=0).T
    instruments = [s.instrument for s in sheets for _ in s.time]
    result = Breakdown(instruments, np.concatenate([s.time for s in sheets]), at, standard, changes, at, at)
    return breakdown_band(result, *band)


def breakdown_band(result: Breakdown, diameter: np.ndarray, low: np.ndarray, high: np.ndarray) -> Breakdown:
    """The breakdown with the inverse's band (`low`, `high` at `diameter`) read at its readings' diameters."""
    at = np.log(result.diameter)
    return replace(result, low=np.interp(at, np.log(diameter), low), high=np.interp(at, np.log(diameter), high))


def drag_curve_diameters(water: Suspension, depth: np.ndarray, time: np.ndarray) -> np.ndarray:
    """The diameters whose terminal speed on the standard drag curve (no hindrance) is depth / time."""
    return np.array([settling_diameter(water, z / t, float(water.stokes_diameter(z, t))) for z, t in zip(depth, time)])


def finer_in_bins(grid: SizeGrid, diameter: np.ndarray) -> np.ndarray:
    """[readings, bins]: the part of each bin (its mass even in log d) finer than each diameter."""
    lower, upper = np.log(grid.lower), np.log(grid.edges)
    return np.clip((np.log(diameter)[:, None] - lower) / (upper - lower), 0.0, 1.0)


def point_readings(shares: np.ndarray, diameter: np.ndarray, sheets: list[Sheet], reduction: list[Reduction],
                   test: LabTest, grid: SizeGrid) -> tuple[np.ndarray, np.ndarray]:
    """The readings of instruments that read the concentration at their depth of the grains finer than
    `diameter` (one per reading), as the standard reduction reads them back, and their derivatives by
    the shares (exact: the readings are linear in them)."""
    finer = finer_in_bins(grid, diameter)
    # reading = offset + slope x percent finer, as each instrument's standard reduction inverts it
    offset, slope = [], []
    for sheet, r in zip(sheets, reduction):
        at, by = sheet.kind.linear(test, r.temperature)
        offset.append(at)
        slope.append(by)
    offset, slope = np.concatenate(offset), np.concatenate(slope)
    jac = slope[:, None] * 100 * finer
    return offset + jac @ shares, jac


@dataclass
class AnalyticRun(ForwardRun):
    """A forward run without the DEM: each bin (its mass even in log d) settles at the standard drag curve's
    terminal speeds with no hindrance, in a column of LAYERS layers with a frame at each reading."""

    edges: np.ndarray = None
    times: np.ndarray = None

    @classmethod
    def of(cls, grid: SizeGrid, test: LabTest, water: Suspension, times: np.ndarray) -> "AnalyticRun":
        """Each bin's fraction [bins, frames, layers] of the test's column at `times` [s]."""
        columns = [settling_column(PSD(np.array([a, b]), np.array([0.0, 100.0])), test.height, times,
                                   test.initial_concentration, water, layers=LAYERS, classes=16,
                                   speed=lambda d: terminal_speeds(water, d))
                   for a, b in zip(grid.lower, grid.edges)]
        bins = np.stack([c.fraction for c in columns])
        return cls(None, bins, np.ones(grid.bins), water, test, columns[0].depth_edges, np.asarray(times, float))

    def column(self, shares: np.ndarray) -> Column:
        """The column of a split of the sample's mass among the bins."""
        return Column(self.edges, self.times, np.tensordot(shares, self.bins, axes=1), self.water)
