# SPDX-License-Identifier: GPL-2.0-or-later
"""The sedimentation tests' instruments, one class each, and the table of them (`INSTRUMENTS`).

Each class says once what every layer asks of its instrument: its name, the unit of its readings
table, its sheet's columns, its default reading error and the option that states it, where it
reads in the column, how it reads a simulated column, how the standard reduction turns its sheet
into diameters and percents finer, and what it reads of the inverse's forward model. Adding an
instrument is writing one class, registering it below and adding its name to
`constants.INSTRUMENTS` (the command line's list, checked against this table by a test).
The hydrometer's types, 152H and 151H, are a class each (`HYDROMETERS`, the names of
`constants.HYDROMETER_TYPES`), differing in their stem's scale; sieves are a kind of sheet, not an
instrument (lab/sheet.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import Callable, ClassVar, Protocol

import numpy as np

from .. import _core
from ..constants import (BALANCE_NOISE, D422_CYLINDER_AREA, HYDROMETER_NOISE, LAB_TEMPERATURE,
                         PIPETTE_DEPTH, PIPETTE_NOISE, PIPETTE_VOLUME, SCHEDULES, SPHERE_DEPTH_SHARE)
from ..plausible import pipette_mass
from .readout import (GRAMS, SPECIFIC_GRAVITY, BuoyancySphere, Column, Hydrometer, Pipette, Readings, Scale,
                      Suspension, gs_correction)
from .sheetcheck import SheetError, plausible


class Setup(Protocol):
    """What an instrument takes from a test (sediment.inverse.model.LabTest is one)."""

    hydrometer: Hydrometer
    cylinder_area: float
    meniscus: float
    particle_density: float

    @property
    def initial_concentration(self) -> float:
        """c0 [g/L]."""

    @property
    def sphere(self) -> BuoyancySphere:
        """The buoyancy sphere as hung."""

    def correction(self, sheet) -> np.ndarray:
        """A hydrometer sheet's composite correction at each reading [g/L]."""


@dataclass(frozen=True)
class ReadoutSetup:
    """How the instruments read a simulated column (`sediment readout`'s options)."""

    schedule: str = "d422"
    sphere_depth: float | None = None            # centre [m]; None: SPHERE_DEPTH_SHARE of the height
    pipette_depth: float = PIPETTE_DEPTH
    pipette_volume: float = PIPETTE_VOLUME
    cylinder_area: float = D422_CYLINDER_AREA
    hydrometer: Hydrometer | None = None         # None: the nominal 152H


class Instrument:
    """One instrument. Subclasses set the class attributes and the methods."""

    name: ClassVar[str]
    heading: ClassVar[str]                       # the readings table's column of its readings
    columns: ClassVar[tuple[str, ...]]           # its sheet's columns, and those a sheet may add
    optional: ClassVar[tuple[str, ...]]
    noise: ClassVar[float]                       # default reading error, in the inverse's unit of its readings
    noise_unit: ClassVar[str]
    noise_option: ClassVar[str]
    noise_as_read: ClassVar[bool] = True         # its option states the noise in the unit the inverse reads
    on_hydrometer_scale: ClassVar[bool] = False  # read on a 152H/151H scale, less a composite correction
    reading_falls_with_solids: ClassVar[bool] = False
    beyond_whole_hint: ClassVar[str] = ""        # what else to check when a reading exceeds the whole sample's

    def simulated(self, column: Column, setup: ReadoutSetup) -> tuple[Callable[[Column, np.ndarray], Readings],
                                                                       np.ndarray]:
        """How it reads a simulated column, its readings named as this instrument, and its reading times
        [s] on the setup's schedule."""
        read, times = self.physical(column, setup)
        return lambda c, t: replace(read(c, t), instrument=self.name, heading=self.heading), times

    def physical(self, column: Column, setup: ReadoutSetup) -> tuple[Callable[[Column, np.ndarray], Readings],
                                                                      np.ndarray]:
        """The physical instrument's read (lab/readout.py) and the reading times [s]."""
        raise NotImplementedError

    def deepest(self, height: float) -> float:
        """The deepest point it senses [m below the surface] in a column of `height`, at its defaults."""
        raise NotImplementedError

    def nominal_depth(self, test: Setup) -> float:
        """The depth Stokes' law takes for it, nominally [m]."""
        raise NotImplementedError

    def sheet_readings(self, path: Path, lines: list[int], values: dict[str, np.ndarray],
                       pipette_volume: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Its sheet's (checked) readings in the inverse's unit, the depths (pipette) and blanks (hydrometer)."""
        raise NotImplementedError

    def reduce(self, sheet, waters: list[Suspension], gs: float, c0: float, hydrometer: Hydrometer,
               cylinder_area: float, sphere: BuoyancySphere, meniscus: float,
               applied: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The standard reduction's depth [m] and percent finer of each reading."""
        raise NotImplementedError

    def whole_sample(self, test: Setup, water: Suspension) -> float:
        """What it reads with the whole sample in suspension (its unit)."""
        raise NotImplementedError

    def clear_water(self, test: Setup, water: Suspension) -> float:
        """What it reads in clear water (its unit)."""
        return 0.0

    def modelled(self, column: Column, sheet, times: np.ndarray, test: Setup, water: Suspension) -> np.ndarray:
        """Its readings of the forward model's column at the sheet's (effective) times."""
        raise NotImplementedError

    def linear(self, test: Setup, temperature: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Reading = offset + slope x percent finer, as its standard reduction inverts it, per reading."""
        raise NotImplementedError

    def sheet_unit(self) -> str:
        """The unit of its readings as the sheet gives them."""
        return self.noise_unit

    def noise_text(self, noise: float) -> str:
        """A reading error as its noise option states it."""
        return f"{noise:g} {self.noise_unit}"

    def check_sheet(self, sheet, values: np.ndarray, whole: float) -> np.ndarray:
        """Refuses what only this instrument's sheet can get wrong; returns which readings follow the one
        before them at the same place (the solids there only fall)."""
        return np.ones(len(values), bool)


class HydrometerTest(Instrument):
    """A hydrometer, D422/D7928; each type a subclass with its stem's scale. The 151H and the 152H have the
    same dimensions (D422 3.2), so they float alike; everything after the sheet works on the 152H's g/L."""

    name = "hydrometer"
    heading = "R [g/L]"
    columns = ("time_min", "reading", "temperature_C")
    optional = ("blank",)
    noise = HYDROMETER_NOISE
    noise_unit = "g/L"
    noise_option = "--hydrometer-noise"
    on_hydrometer_scale = True
    type_name: ClassVar[str]
    scale: ClassVar[Scale]               # what its stem reads, and how that becomes the 152H's g/L
    other_scale_hint: ClassVar[str]      # what a sheet on the other type's scale should have given

    def physical(self, column, setup):
        """The hydrometer (default the nominal 152H) on the schedule's times."""
        read = partial((setup.hydrometer or Hydrometer.astm_152h()).read, cylinder_area=setup.cylinder_area)
        return read, np.array(SCHEDULES[setup.schedule]) * 60.0

    def deepest(self, height):
        """The nominal 152H's bulb bottom at a zero reading."""
        h = Hydrometer.astm_152h()
        return h.scale_zero + h.bulb_length

    def nominal_depth(self, test):
        """The 152H's bulb centre, nominally."""
        return 0.15

    def sheet_readings(self, path, lines, values, pipette_volume):
        """Readings and blanks on its scale as the 152H's g/L."""
        reading, scale = values["reading"], self.scale
        gravities = bool(np.all((reading > 0.95) & (reading < 1.15)))
        if gravities == scale.in_grams:
            raise SheetError(f"{path}: the readings ({reading.min():g}-{reading.max():g}) look like "
                             + self.other_scale_hint)
        plausible(path, lines, values, "reading", scale.reading_range)
        blank = np.empty(0)
        if "blank" in values:
            blank = values["blank"]
            if not np.isfinite(blank).all():
                missing = ", ".join(str(lines[k]) for k in np.flatnonzero(~np.isfinite(blank)))
                raise SheetError(f"{path}: no blank on line(s) {missing}: give the composite correction beside every "
                                 "reading, or drop the column and give --zero-correction")
            plausible(path, lines, values, "blank", scale.blank_range)
            blank = scale.grams(blank)
        return scale.grams(reading), np.empty(0), blank

    def reduce(self, sheet, waters, gs, c0, hydrometer, cylinder_area, sphere, meniscus, applied):
        """D7928: H_m at the reading plus the meniscus; 100 a (R - correction) / c0."""
        depth = hydrometer.effective_depth(sheet.reading + meniscus, cylinder_area)
        return depth, 100 * gs_correction(gs) * (sheet.reading - applied) / c0

    def whole_sample(self, test, water):
        """c0 / a, the whole sample's reading in the 152H's g/L."""
        return test.initial_concentration / gs_correction(test.particle_density / 1000.0)

    def modelled(self, column, sheet, times, test, water):
        """The 152H floating in the companion cylinder's liquid with the column's solids."""
        # The instrument floats in the companion cylinder's liquid (water and dispersant at the reading's
        # temperature: what the composite correction and the meniscus read there) with the solids, so its
        # bulb sits where the sheet's reading puts it (D7928's H_m at the reading as read plus the meniscus).
        liquid = test.correction(sheet) + test.meniscus    # the liquid's reading at its surface [g/L]
        out = np.empty(len(times))
        for value in np.unique(liquid):
            at = liquid == value
            density = float(test.hydrometer.liquid_density(value))
            read = test.hydrometer.read(replace(column, suspension=replace(water, fluid_density=density)),
                                        times[at], cylinder_area=test.cylinder_area).reading
            out[at] = read - value
        return out

    def linear(self, test, temperature):
        """R = c0 P / (100 a)."""
        per_percent = test.initial_concentration / (100 * gs_correction(test.particle_density / 1000.0))
        return np.zeros(len(temperature)), np.full(len(temperature), per_percent)

    def sheet_unit(self):
        """Its scale's unit (g/L or specific gravity)."""
        return self.scale.unit

    def noise_text(self, noise):
        """The noise on its scale."""
        return self.scale.quoted_step(noise)


class Hydrometer152H(HydrometerTest):
    """ASTM 152H: grams of soil of Gs 2.65 per litre of suspension, 0 in water at 20 C."""

    type_name = "152H"
    scale = GRAMS
    other_scale_hint = "specific gravities: a 151H's sheet needs --hydrometer-type 151H"


class Hydrometer151H(HydrometerTest):
    """ASTM 151H: the suspension's specific gravity, 1 in water at 20 C; its R is the 152H's
    1000 (R - 1) / 0.6226 g/L, which makes D422's two percent-finer formulas agree."""

    type_name = "151H"
    scale = SPECIFIC_GRAVITY
    other_scale_hint = "a 152H's g/L, not the specific gravities of a 151H (--hydrometer-type 151H)"


class BuoyancyTest(Instrument):
    """A sphere hung from a balance at a fixed depth (Bardet & Young 1997; Bravo et al. 2015)."""

    name = "buoyancy"
    heading = "m_app [g]"
    columns = ("time_min", "apparent_mass_g")
    optional = ("temperature_C",)
    noise = BALANCE_NOISE
    noise_unit = "g"
    noise_option = "--balance-noise"
    reading_falls_with_solids = True
    beyond_whole_hint = (", the sphere's own mass and diameter (--sphere-mass, --sphere-diameter: what it reads in "
                         "clear water follows from them)")

    def physical(self, column, setup):
        """The sphere at its depth (default a share of the height) on Bravo et al.'s times with D422's."""
        depth = SPHERE_DEPTH_SHARE * column.height if setup.sphere_depth is None else setup.sphere_depth
        # D422's schedule leaves its first hour nearly unread: the sphere reads on Bravo et al.'s times with it
        schedule = "bravo" if setup.schedule == "d422" else setup.schedule
        return BuoyancySphere(depth).read, np.array(SCHEDULES[schedule]) * 60.0

    def deepest(self, height):
        """The default sphere's bottom."""
        return SPHERE_DEPTH_SHARE * height + 0.0125

    def nominal_depth(self, test):
        """The sphere's centre."""
        return test.sphere.depth

    def sheet_readings(self, path, lines, values, pipette_volume):
        """The balance's apparent masses [g]."""
        plausible(path, lines, values, "apparent_mass_g", "apparent_mass_g")
        return values["apparent_mass_g"], np.empty(0), np.empty(0)

    def reduce(self, sheet, waters, gs, c0, hydrometer, cylinder_area, sphere, meniscus, applied):
        """The sphere's depth; the solids around it from its apparent mass in the reading's water."""
        water = np.array([w.fluid_density for w in waters])
        return np.full(len(sheet.time), sphere.depth), 100 * sphere.solids(sheet.reading * 1e-3, water, gs) / c0

    def whole_sample(self, test, water):
        """The apparent mass [g] in the whole sample's suspension."""
        rho = water.mixture_density(test.initial_concentration / test.particle_density)
        return (test.sphere.mass - rho * test.sphere.volume) * 1e3

    def clear_water(self, test, water):
        """The apparent mass [g] in clear water."""
        return (test.sphere.mass - water.fluid_density * test.sphere.volume) * 1e3

    def modelled(self, column, sheet, times, test, water):
        """The sphere read in the column, weighed in the water at each reading's temperature."""
        # the balance reads the sphere in the water at each reading's temperature
        sphere = test.sphere
        recorded = np.where(np.isfinite(sheet.temperature), sheet.temperature, water.temperature or LAB_TEMPERATURE)
        density = np.array([_core.water_density(c) for c in recorded])
        return sphere.read(column, times).reading - (density - water.fluid_density) * sphere.volume * 1e3

    def linear(self, test, temperature):
        """The apparent mass falls with the solids around the sphere, from its clear-water value."""
        sphere, c0, gs = test.sphere, test.initial_concentration, test.particle_density / 1000.0
        fluid = np.array([_core.water_density(t) for t in temperature])
        return ((sphere.mass - fluid * sphere.volume) * 1e3,
                np.full(len(temperature), -c0 / 100 * sphere.volume * (gs - 1) / gs * 1e3))


class PipetteTest(Instrument):
    """Samples drawn at a fixed depth, dried and weighed (the sheet's masses as g/L of the sample)."""

    name = "pipette"
    heading = "c [g/L]"
    columns = ("time_min", "depth_cm", "mass_g")
    optional = ("temperature_C",)
    noise = PIPETTE_NOISE / (PIPETTE_VOLUME * 1e3)
    noise_unit = "g/L"
    noise_option = "--pipette-noise"
    noise_as_read = False    # the option is in g of a sample, the inverse reads g/L

    def physical(self, column, setup):
        """The pipette at its depth on the Stokes times of 50 to 2 um there."""
        pipette = Pipette(setup.pipette_depth, setup.pipette_volume)
        return pipette.read, pipette.default_times(column.suspension)

    def deepest(self, height):
        """The default sample's bottom."""
        return PIPETTE_DEPTH + (3 * PIPETTE_VOLUME / (4 * math.pi)) ** (1 / 3)

    def nominal_depth(self, test):
        """The default tip depth."""
        return PIPETTE_DEPTH

    def sheet_readings(self, path, lines, values, pipette_volume):
        """The samples' dry masses as g/L of the sample, and their depths."""
        plausible(path, lines, values, "depth_cm", "depth_cm")
        plausible(path, lines, values, "mass_g", pipette_mass(pipette_volume))
        return values["mass_g"] / (pipette_volume * 1e3), values["depth_cm"] / 100.0, np.empty(0)

    def reduce(self, sheet, waters, gs, c0, hydrometer, cylinder_area, sphere, meniscus, applied):
        """Each sample's depth; 100 c / c0."""
        return sheet.depth, 100 * sheet.reading / c0

    def whole_sample(self, test, water):
        """c0 [g/L]."""
        return test.initial_concentration

    def modelled(self, column, sheet, times, test, water):
        """The column sampled at each reading's depth."""
        return np.array([Pipette(z).read(column, [t]).reading[0] for z, t in zip(sheet.depth, times)])

    def linear(self, test, temperature):
        """c = c0 P / 100."""
        n = len(temperature)
        return np.zeros(n), np.full(n, test.initial_concentration / 100)

    def check_sheet(self, sheet, values, whole):
        """Refuses masses far below what any sample holds (kg for g); samples compare at one depth only."""
        if values.max() < 0.005 * whole:
            raise SheetError(f"{sheet.label}: every sample weighs under 0.5 % of what the whole sample in suspension "
                             f"gives ({whole:.4g} g): mass_g is in grams (masses in kg?), or the sample mass is wrong")
        return np.r_[True, np.diff(sheet.depth) == 0]    # a sample deeper down holds more than the one above it


# The tables of them: the hydrometer's types in constants.HYDROMETER_TYPES' order (the first the default),
# the instruments in constants.INSTRUMENTS' (the readouts' and the reports' order)
HYDROMETERS: dict[str, HydrometerTest] = {h.type_name: h for h in (Hydrometer152H(), Hydrometer151H())}
INSTRUMENTS: dict[str, Instrument] = {i.name: i for i in (HYDROMETERS["152H"], BuoyancyTest(), PipetteTest())}


def hydrometer(type_name: str) -> HydrometerTest:
    """The hydrometer of a type; an unknown type is refused with the valid ones."""
    try:
        return HYDROMETERS[type_name]
    except KeyError:
        raise ValueError(f"unknown hydrometer type '{type_name}': the types are {', '.join(HYDROMETERS)}") from None


def instrument(name: str, hydrometer_type: str = "152H") -> Instrument:
    """The instrument of a name (a hydrometer of `hydrometer_type`); an unknown name is refused with the
    valid ones."""
    if name == HydrometerTest.name:
        return hydrometer(hydrometer_type)
    try:
        return INSTRUMENTS[name]
    except KeyError:
        raise ValueError(f"unknown instrument '{name}': the instruments are {', '.join(INSTRUMENTS)}") from None
