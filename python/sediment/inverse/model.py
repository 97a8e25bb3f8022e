# SPDX-License-Identifier: GPL-2.0-or-later
"""The inverse's forward model: the test a sheet was read from (`LabTest`), one DEM run of it whose
concentration grid is split into the size bins (`run_forward`), and the instruments' readings of any
other split of the mass among the bins (`ForwardRun.readings`), as that run's hindrance left it."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import _core
from ..constants import (D422_CYLINDER_AREA, D422_CYLINDER_HEIGHT, SIEVE_NOISE, SOIL_PARTICLE_DENSITY,
                         SPHERE_DEPTH_SHARE, SPHERE_DIAMETER, SPHERE_MASS, THERMOMETER_NOISE)
from ..lab.instruments import INSTRUMENTS
from ..lab.psd import PSD
from ..lab.readout import BuoyancySphere, Column, Hydrometer, Suspension
from ..lab.settling import terminal_speeds
from ..lab.sheet import Sheet, standard_reduction
from .grid import SizeGrid

SUBCLASSES = 3            # the forward run's size classes per bin, even in log across it


@dataclass(frozen=True)
class LabTest:
    """What the sheets do not say: the sample, the cylinder and the instruments."""

    mass: float                          # dry specimen in the cylinder [kg]
    particle_density: float = SOIL_PARTICLE_DENSITY    # [kg/m3]
    cylinder_area: float = D422_CYLINDER_AREA          # [m2]
    height: float = D422_CYLINDER_HEIGHT               # suspension height [m]
    hydrometer: Hydrometer = field(default_factory=Hydrometer.astm_152h)
    zero_correction: float = 0.0         # g/L subtracted from each hydrometer reading (composite correction)
    meniscus: float = 0.0                # g/L added for the depth only
    sphere_depth: float | None = None    # centre [m], default SPHERE_DEPTH_SHARE of the height
    sphere_diameter: float = SPHERE_DIAMETER    # [m]
    sphere_mass: float = SPHERE_MASS            # [kg]
    # reading noise per instrument, in the unit the inverse takes its readings in (the instruments' defaults)
    noise: dict = field(default_factory=lambda: {name: i.noise for name, i in INSTRUMENTS.items()}
                                                | {"sieve": SIEVE_NOISE})
    thermometer: float = THERMOMETER_NOISE    # C, standard uncertainty of the temperature record

    @property
    def initial_concentration(self) -> float:
        """c0 [kg/m3 = g/L]."""
        return self.mass / (self.cylinder_area * self.height)

    @property
    def sphere(self) -> BuoyancySphere:
        """The buoyancy sphere, its centre at `sphere_depth` (default SPHERE_DEPTH_SHARE of the height)."""
        depth = SPHERE_DEPTH_SHARE * self.height if self.sphere_depth is None else self.sphere_depth
        return BuoyancySphere(depth, self.sphere_diameter, self.sphere_mass)

    def correction(self, sheet: Sheet) -> np.ndarray:
        """The 152H's composite correction at each reading [g/L]: the sheet's own `blank` column where
        it has one, else the test's zero correction (0 for other instruments)."""
        if not sheet.kind.on_hydrometer_scale:
            return np.zeros(len(sheet.time))
        return np.array(sheet.blank, float) if len(sheet.blank) else np.full(len(sheet.time), self.zero_correction)

    def corrected(self, sheet: Sheet) -> np.ndarray:
        """The sheet's readings after the hydrometer's composite correction."""
        return sheet.reading - self.correction(sheet)

    def record(self) -> dict:
        """Every value the inverse takes from the test, in SI units, for invert.json and the console."""
        values = asdict(self)
        values["hydrometer"] = asdict(self.hydrometer)
        values["sphere_depth"] = self.sphere.depth
        values["volume_m3"] = self.cylinder_area * self.height
        return values


def whole_sample_reading(sheet: Sheet, test: LabTest, water: Suspension) -> float:
    """What the instrument reads with the whole sample in suspension (its unit)."""
    return sheet.kind.whole_sample(test, water)


def solids_signal(sheet: Sheet, test: LabTest, water: Suspension) -> float:
    """How far the whole sample moves the instrument's reading from clear water's (its unit)."""
    return abs(whole_sample_reading(sheet, test, water) - sheet.kind.clear_water(test, water))


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
            out.append(sheet.kind.modelled(column, sheet, t, self.test, self.water))
        return np.concatenate(out) if out else np.empty(0)


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


def run_forward(psd: PSD, grid: SizeGrid, test: LabTest, water: Suspension, t_end: float, folder: Path,
                particles: int, courant: float, seed: int) -> ForwardRun:
    """Writes and runs the test with `psd`, its layers split into the grid's bins."""
    from ..sim.layers import read_layers
    from ..sim.run import run_batch
    from ..sim.scene import Cylinder, Effects, plan
    from ..sim.scenefiles import write

    scene = plan(psd, cylinder=Cylinder(test.cylinder_area, test.height), mass=test.mass, suspension=water,
                 classes=class_bounds(grid), particles=particles, courant=courant, seed=seed, effects=Effects(),
                 t_end=t_end)
    scene.tag_classes = tuple(float(d) for d in grid.edges[:-1])
    write(scene, folder, force=True)    # the inverse's own working run: a new inversion replaces it
    out = run_batch(folder / "in.sedimentation", {"overwrite": "yes"}, check=False)
    if out.error:
        raise RuntimeError(f"the forward run in {folder} failed: {out.error}")
    layers = read_layers(folder / "layers.h5")
    bins = np.stack([layers.column(f"class_{k}") for k in range(grid.bins)])
    solids = bins[:, 0].sum(axis=1)
    return ForwardRun(layers, bins, solids / solids.sum(), water, test)


def class_bounds(grid: SizeGrid) -> np.ndarray:
    """The forward run's size classes: each bin split into SUBCLASSES even in log, so that every bin has
    grains across its width and none of another bin."""
    outer = np.concatenate([[grid.floor], grid.edges])
    parts = [np.geomspace(a, b, SUBCLASSES + 1)[:-1] for a, b in zip(outer[:-1], outer[1:])]
    return np.concatenate(parts + [outer[-1:]])


def psd_of(shares: np.ndarray, grid: SizeGrid, name: str = "") -> PSD:
    """The PSD of bin shares: percent finer at the edges, 0 at the floor, 100 at the top."""
    cumulative = np.clip(100 * np.cumsum(shares)[:-1], 0, 100)
    percent = np.concatenate([[0.0], cumulative, [100.0]])
    return PSD(np.concatenate([[grid.floor], grid.edges]), np.maximum.accumulate(percent), name)


def cut_diameters(sheets: list[Sheet], times: list[np.ndarray], test: LabTest, water: Suspension) -> np.ndarray:
    """The diameter each reading cuts in the forward model: the grains whose hindered terminal speed (the
    standard drag curve, Richardson & Zaki at the solids finer than them, the reading's own percent
    finer) takes them past the instrument's depth by the reading's time in the run's water. The
    standard reduction's Stokes diameter at the effective time gives that speed."""
    out = []
    for sheet, t in zip(sheets, times):
        run_sheet = replace(sheet, time=t, temperature=np.full(len(t), np.nan))
        reduced = standard_reduction(run_sheet, water, test.initial_concentration, test.hydrometer,
                                     test.cylinder_area, test.sphere, test.meniscus, test.correction(sheet))
        for d_stokes, p in zip(reduced.diameter, np.clip(reduced.percent, 0.0, 100.0)):
            voidage = 1.0 - test.initial_concentration / test.particle_density * p / 100.0
            out.append(settling_diameter(water, float(water.stokes_speed(d_stokes)), d_stokes, voidage,
                                         "richardson-zaki"))
    return np.array(out)


def settling_diameter(water: Suspension, speed: float, stokes: float, voidage: float = 1.0,
                      hindrance: str = "none") -> float:
    """The diameter whose terminal speed on the standard drag curve (hindered at `voidage`) is `speed`,
    found within a factor of two of its Stokes diameter `stokes`."""
    low, high = math.log(0.5 * stokes), math.log(2.0 * stokes)
    for _ in range(40):    # bisection in log d: the speed rises with the diameter
        middle = 0.5 * (low + high)
        moving = terminal_speeds(water, np.array([math.exp(middle)]), "standard", voidage, hindrance)[0]
        low, high = (middle, high) if moving < speed else (low, middle)
    return math.exp(0.5 * (low + high))
