# SPDX-License-Identifier: GPL-2.0-or-later
"""Readouts of the hydrometer (ASTM 152H), buoyancy-sphere and pipette tests from layer profiles
(docs/sedimentation-tests.md sections 2-5). SI units throughout: m, s, kg.

A `Column` is the suspension at the reading times: layer edges as depth below the free surface and
the solid volume fraction per layer. Each instrument turns it into a `Readings` table
(t, depth, reading, D, P): D from Stokes' law at the instrument's depth, P = 100 c / c0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from .. import _core
from ..results import Table, write_text
from ..constants import (D422_CYLINDER_AREA, GRAVITY, LAB_TEMPERATURE, NOMINAL_BULB_LENGTH, NOMINAL_BULB_VOLUME,
                         PIPETTE_VOLUME, SCHEDULES, SOIL_PARTICLE_DENSITY, SPHERE_DIAMETER, SPHERE_MASS,
                         WATER_20C_DENSITY, WATER_20C_VISCOSITY)

R_FACTOR = 1 - 1 / 2.65    # 152H: R = (rho_s - rho_w) / 0.6226 in g/L, calibrated for Gs = 2.65


@dataclass(frozen=True)
class Scale:
    """What a hydrometer's stem reads. The 151H and the 152H have the same dimensions and differ only in
    their scale (D422 3.2): the 152H in g/L of soil of Gs 2.65, the 151H in specific gravity, so that a
    151H's R is the 152H's 1000 (R - 1) / 0.6226 g/L (which makes D422's two percent-finer formulas
    agree). Everything after the sheet works on the 152H's g/L."""

    name: str
    unit: str
    water: float       # what the scale reads in water at 20 C
    per_unit: float    # 152H g/L per unit of the scale
    reading_range: str = "reading"       # sediment.plausible's ranges of its readings and blanks
    blank_range: str = "correction"

    @property
    def in_grams(self) -> bool:
        """Whether it reads the 152H's g/L itself (the unit everything after the sheet works in)."""
        return self.water == 0.0 and self.per_unit == 1.0

    def grams(self, reading):
        """A reading of this scale as the 152H's g/L."""
        return (np.asarray(reading, float) - self.water) * self.per_unit

    def as_read(self, grams):
        """The 152H's g/L as this scale reads it."""
        return self.water + np.asarray(grams, float) / self.per_unit

    def quoted(self, grams: float) -> str:
        """A reading [152H g/L] as a message quotes it: on this scale, and in g/L where that differs."""
        if self.in_grams:
            return f"{grams:g}"
        return f"{float(self.as_read(grams)):.5g} ({grams:.3g} g/L of a 152H)"

    def quoted_step(self, grams: float) -> str:
        """A difference of readings [152H g/L] (a noise, a correction) as a message quotes it."""
        if self.in_grams:
            return f"{grams:g} g/L"
        return f"{grams / self.per_unit:.3g} in {self.unit} ({grams:.3g} g/L of a 152H)"


GRAMS = Scale("152H", "g/L", 0.0, 1.0)    # the 152H's scale, whose g/L every sheet's readings become
SPECIFIC_GRAVITY = Scale("151H", "specific gravity", 1.0, 1000.0 / R_FACTOR, "reading_151h", "blank_151h")

@dataclass(frozen=True)
class Suspension:
    """The water and the solids of a sedimentation test, and Stokes' law between them. The default is
    water at 20 C; `at_temperature` gives it at the laboratory's (docs/physics.md 2.2)."""

    fluid_density: float = WATER_20C_DENSITY
    viscosity: float = WATER_20C_VISCOSITY
    particle_density: float = SOIL_PARTICLE_DENSITY
    gravity: float = GRAVITY
    temperature: float | None = LAB_TEMPERATURE    # deg C of the water; None: a fluid given by its properties

    @classmethod
    def at_temperature(cls, celsius: float, particle_density: float = SOIL_PARTICLE_DENSITY,
                       gravity: float = GRAVITY) -> "Suspension":
        """Water at `celsius` (0-40 C) with solids of `particle_density`."""
        return cls(_core.water_density(celsius), _core.water_viscosity(celsius), particle_density, gravity,
                   float(celsius))

    def temperature_text(self) -> str:
        """The water as a deck or report names it."""
        properties = f"density {self.fluid_density:.7g} kg/m3, viscosity {self.viscosity:.5g} Pa s"
        return properties if self.temperature is None else f"{self.temperature:g} C ({properties})"

    @property
    def specific_gravity(self) -> float:
        """Gs = rho_p / 1000 kg/m3 (the hydrometer's definition)."""
        return self.particle_density / 1000.0

    def buoyant_weight(self, diameter: float | np.ndarray) -> float | np.ndarray:
        """(rho_p - rho_f) g pi D^3 / 6 [N]: a grain's weight less its buoyancy, fully immersed."""
        return (self.particle_density - self.fluid_density) * self.gravity * math.pi / 6 * diameter ** 3

    def stokes_speed(self, diameter) -> np.ndarray:
        """Stokes' law, (rho_p - rho_f) g D^2 / (18 mu) [m/s]."""
        return _core.stokes_velocity(self.particle_density, self.fluid_density, self.viscosity, self.gravity, diameter)

    def stokes_diameter(self, depth, time) -> np.ndarray:
        """Largest diameter still present at `depth` after `time`: the one settling depth / time."""
        return np.sqrt(np.asarray(depth) / np.asarray(time) / self.stokes_speed(1.0))

    def stokes_time(self, depth, diameter) -> np.ndarray:
        """Time for a grain of `diameter` to settle through `depth`."""
        return np.asarray(depth) / self.stokes_speed(diameter)

    def mixture_density(self, fraction) -> np.ndarray:
        """Density of the suspension at solid volume fraction `fraction` [kg/m3]."""
        return _core.mixture_density(self.fluid_density, self.particle_density, fraction)


@dataclass(frozen=True)
class Column:
    """Solid fraction per layer at a series of times, layers ordered from the surface down."""

    depth_edges: np.ndarray     # [layers + 1], increasing from the surface (0) down
    time: np.ndarray            # [frames] s
    fraction: np.ndarray        # [frames, layers]
    suspension: Suspension = field(default_factory=Suspension)
    slab_thickness: float = 0.0  # > 0 for a 2d slab (the pipette samples a circle)
    # [frames, 2] the water's density and viscosity per frame where it changed over the test (a
    # temperature record); None: `suspension`'s water throughout
    water: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.fraction.shape != (len(self.time), len(self.depth_edges) - 1):
            raise ValueError(f"fraction has shape {self.fraction.shape}, expected "
                             f"({len(self.time)}, {len(self.depth_edges) - 1})")
        if np.any(np.diff(self.time) <= 0):
            raise ValueError("frame times must increase")
        if self.water is not None and np.asarray(self.water).shape != (len(self.time), 2):
            raise ValueError(f"water has shape {np.asarray(self.water).shape}, expected ({len(self.time)}, 2)")

    @classmethod
    def from_layers(cls, layers, surface: float | None = None, fraction: np.ndarray | None = None) -> "Column":
        """The column of a layer file (sediment.layers.LayerFile) below a free surface at
        coordinate `surface` along the layer axis (default: the top of the layers); `fraction`
        [frames, layers] in the file's order instead of its total (e.g. a sum of its class columns)."""
        attrs = layers.attributes
        missing = [k for k in ("fluid_density", "fluid_viscosity", "particle_density") if k not in attrs]
        if missing:
            raise ValueError(f"{layers.path}: readouts need {', '.join(missing)} in the layer file "
                             "(fix layers/hdf5 ... fluid ID particle_density RHO)")
        z_edges = layers.layer_lo + layers.layer_thickness * np.arange(len(layers.centres) + 1)
        top = z_edges[-1] if surface is None else surface
        if not z_edges[0] < top <= z_edges[-1]:
            raise ValueError(f"{layers.path}: a free surface at {top:g} m leaves no layer below it (the layers span "
                             f"{z_edges[0]:g} to {z_edges[-1]:g} m)")
        depth = (top - z_edges)[::-1]                      # from the top layer down
        keep = depth[1:] > 0                               # layers (partly) below the surface
        edges = np.clip(np.concatenate([depth[:-1][keep][:1], depth[1:][keep]]), 0.0, None)
        fraction = (layers.total if fraction is None else fraction)[:, ::-1][:, keep]
        suspension = Suspension(attrs["fluid_density"], attrs["fluid_viscosity"], attrs["particle_density"],
                                temperature=None)
        water = getattr(layers, "fluid", None)
        if water is not None and np.all(water == water[0]):
            water = None    # one water throughout: the attributes say it
        return cls(edges, np.asarray(layers.time, float), fraction, suspension, attrs.get("slab_thickness", 0.0), water)

    @cached_property
    def _fall_rate(self) -> np.ndarray:
        """Per frame, (rho_p - rho_f) / mu integrated over time from the start [s kg / (m3 Pa s)]: the water
        linear between frames (the trapezoid), and the first frame's water before it."""
        rate = (self.suspension.particle_density - self.water[:, 0]) / self.water[:, 1]
        steps = 0.5 * (rate[1:] + rate[:-1]) * np.diff(self.time)
        return self.time[0] * rate[0] + np.concatenate([[0.0], np.cumsum(steps)])

    def fluid_density_at(self, t: float) -> float:
        """The water's density at time t, as the frames recorded it (linear between frames)."""
        if self.water is None:
            return self.suspension.fluid_density
        return float(np.interp(t, self.time, self.water[:, 0]))

    def suspension_at(self, t: float) -> Suspension:
        """The suspension at time t: its water's density then, with the viscosity that gives Stokes' law
        the fall of a grain over 0..t in the water as it changed (its speed goes as (rho_p - rho_f) / mu:
        that ratio's mean over the time), so that `stokes_diameter(depth, t)` is the grain that fell
        `depth` by then."""
        if self.water is None:
            return self.suspension
        here = self.fluid_density_at(t)
        mean_rate = float(np.interp(t, self.time, self._fall_rate)) / t if t > 0 else \
            (self.suspension.particle_density - self.water[0, 0]) / self.water[0, 1]
        return replace(self.suspension, fluid_density=here,
                       viscosity=(self.suspension.particle_density - here) / mean_rate, temperature=None)

    def water_text(self) -> str | None:
        """How the water changed over the frames, for a report; None where it did not."""
        if self.water is None:
            return None
        mu = self.water[:, 1]
        return (f"the water changed over the test (viscosity {mu.min():.4g}-{mu.max():.4g} Pa s, density "
                f"{self.water[:, 0].min():.6g}-{self.water[:, 0].max():.6g} kg/m3, as the run's frames record it): "
                "each reading is reduced with the water its grains fell through (the mean of (rho_p - rho_f) / mu "
                "over its time), and the 152H's less its blank in the water of its time")

    @property
    def height(self) -> float:
        """Depth of the column below the free surface [m]."""
        return float(self.depth_edges[-1])

    def initial_concentration(self) -> float:
        """c0 [kg/m3]: solids per volume of suspension in the first frame."""
        widths = np.diff(self.depth_edges)
        return float(self.suspension.particle_density * np.sum(self.fraction[0] * widths) / self.height)

    def at(self, t: float) -> np.ndarray:
        """Solid fraction per layer at time t, linear between frames."""
        if not self.time[0] <= t <= self.time[-1]:
            raise ValueError(f"time {t:g} s outside the frames ({self.time[0]:g} .. {self.time[-1]:g} s)")
        if len(self.time) == 1:
            return self.fraction[0]
        k = min(int(np.searchsorted(self.time, t, side="right")) - 1, len(self.time) - 2)
        w = (t - self.time[k]) / (self.time[k + 1] - self.time[k])
        return (1 - w) * self.fraction[k] + w * self.fraction[k + 1]

    def density(self, t: float) -> np.ndarray:
        """Suspension density rho_f + (rho_p - rho_f) phi per layer [kg/m3]."""
        return _core.mixture_density(self.fluid_density_at(t), self.suspension.particle_density, self.at(t))

    def mass_profile(self, t: float):
        """The integral of the suspension density from the surface to a depth [kg/m2] at time t, as a
        function of the depth (the profile summed once): exact for layer-wise constant density
        (linear inside a layer); clear fluid below the column."""
        cumulative = np.concatenate([[0.0], np.cumsum(self.density(t) * np.diff(self.depth_edges))])

        def above(depth):
            depth = np.asarray(depth, float)
            inside = np.interp(depth, self.depth_edges, cumulative)
            return inside + np.maximum(depth - self.height, 0.0) * fluid_density
        fluid_density = self.fluid_density_at(t)
        return above

    def weighted_mean(self, t: float, centre: float, radius: float, disc: bool = False) -> float:
        """Mean solid fraction over a sphere (or, in a 2d slab, a disc) centred at `centre` depth,
        with the exact share of each layer."""
        a = np.clip(self.depth_edges[:-1] - centre, -radius, radius)
        b = np.clip(self.depth_edges[1:] - centre, -radius, radius)
        if disc:
            def area_below(u):
                return u * np.sqrt(radius ** 2 - u ** 2) + radius ** 2 * np.arcsin(u / radius)
            weights = area_below(b) - area_below(a)
        else:
            weights = np.pi * (radius ** 2 * (b - a) - (b ** 3 - a ** 3) / 3)
        if weights.sum() <= 0:
            raise ValueError(f"depth {centre:g} m is outside the column (0 .. {self.height:g} m)")
        return float(np.sum(weights * self.at(t)) / weights.sum())


@dataclass
class Readings:
    """What one instrument read at its reading times, and the PSD points it gives (named, with its
    table's heading, by the instrument's class in lab/instruments.py)."""

    instrument: str
    time: np.ndarray        # s
    depth: np.ndarray       # m, the depth Stokes' law uses
    reading: np.ndarray     # instrument units (152H: g/L; sphere: apparent mass g; pipette: g/L)
    diameter: np.ndarray    # m
    percent_finer: np.ndarray
    band: float = 0.0       # pp either side that the physics' uncertainty puts around each reading (error budget)
    heading: str = "reading"    # the table's column of the readings, with their unit

    def table(self) -> Table:
        """Time [min], depth [cm], reading, diameter [um] and percent finer per reading (with a band: its
        low and high ends)."""
        banded = ["low", "high"] if self.band > 0 else []
        table = Table(["time_min", "depth_cm", self.heading, "diameter_um", "percent_finer", *banded])
        for row in zip(self.time / 60, self.depth * 100, self.reading, self.diameter * 1e6, self.percent_finer):
            ends = [row[-1] - self.band, row[-1] + self.band] if self.band > 0 else []
            table.add(*map(float, row), *ends)
        return table

    def save(self, folder: Path) -> list[Path]:
        """<instrument>.csv."""
        return [write_text(Path(folder) / f"{self.instrument}.csv", self.table().csv())]


@dataclass(frozen=True)
class Hydrometer:
    """A hydrometer as a cylindrical bulb under a cylindrical stem, with its scale on the stem. It reads
    as its marks are made, by where it floats: the 152H's R is (rho - rho_w) / 0.6226 of the uniform
    liquid that floats it there (water at 20 C, soil of Gs 2.65), so its marks crowd down the stem as
    1 / rho does. Where the marks are, as the depth of the bulb's centre below a reading's graduation
    (D7928's H_r), is linear in R, as laboratories calibrate it: the surface crosses the stem at
    `scale_zero - scale_step R` above the bulb top, or, with a laboratory's `calibration` (rows of
    reading [g/L] and H_r [m]), linear between and beyond its rows. The two differ by 0.06 cm at most
    on the 152H, a depth; a reading taken from the linear marks would be up to 0.4 g/L off."""

    bulb_length: float      # L2 [m]
    bulb_volume: float      # VB [m3]
    stem_area: float        # [m2]
    mass: float             # [kg]
    scale_zero: float       # L1 at R = 0 [m]
    scale_step: float       # decrease of L1 per unit of R [m per g/L]
    calibration: tuple[tuple[float, float], ...] = ()    # (R [g/L], H_r [m]) by increasing R; () the linear scale

    @classmethod
    def astm_152h(cls, bulb_length=NOMINAL_BULB_LENGTH, bulb_volume=NOMINAL_BULB_VOLUME, scale_zero=0.105, scale_at_50=0.023,
                  water_density=WATER_20C_DENSITY) -> "Hydrometer":
        """The nominal 152H of ASTM D422. Stem area and mass follow from the calibration: it floats
        with the surface at L1(R) in a uniform suspension of density rho_w + 0.6226 R."""
        return cls._floating(bulb_length, bulb_volume, scale_zero, (scale_zero - scale_at_50) / 50.0, water_density)

    @classmethod
    def _floating(cls, bulb_length, bulb_volume, scale_zero, step, water_density=WATER_20C_DENSITY,
                  calibration: tuple[tuple[float, float], ...] = ()) -> "Hydrometer":
        """The stem and mass with which the bulb top floats `scale_zero - step R` deep in a uniform
        suspension of density rho_w + 0.6226 R (exactly at R = 0 and 50)."""
        scale_at_50 = scale_zero - 50.0 * step
        rho50 = water_density + R_FACTOR * 50.0
        stem = (rho50 - water_density) * bulb_volume / (water_density * scale_zero - rho50 * scale_at_50)
        mass = water_density * (bulb_volume + stem * scale_zero)
        return cls(bulb_length, bulb_volume, stem, mass, scale_zero, step, calibration)

    @classmethod
    def measured(cls, bulb_length, bulb_volume, stem_diameter, mass, scale_zero, scale_at_50) -> "Hydrometer":
        """An instrument measured in the laboratory (stem diameter, mass, scale marks)."""
        return cls(bulb_length, bulb_volume, np.pi / 4 * stem_diameter ** 2, mass, scale_zero,
                   (scale_zero - scale_at_50) / 50.0)

    @classmethod
    def calibrated(cls, readings, distances, bulb_volume: float = NOMINAL_BULB_VOLUME,
                   bulb_length: float = NOMINAL_BULB_LENGTH) -> "Hydrometer":
        """A 152H from a laboratory's calibration (D7928 9.x: the distance H_r [m] from the graduation of
        each reading [g/L] to the bulb's centre; at least two readings, the distance falling as the
        reading rises). The scale reads the rows, linear between and beyond them; the instrument
        floats as the straight line through its first and last rows says (a uniform stem)."""
        readings, distances = np.asarray(readings, float), np.asarray(distances, float)
        order = np.argsort(readings)
        readings, distances = readings[order], distances[order]
        if len(readings) < 2 or np.any(np.diff(readings) <= 0):
            raise ValueError("a hydrometer calibration needs at least two distinct readings")
        if np.any(np.diff(distances) >= 0):
            raise ValueError("a hydrometer calibration's distance to the bulb's centre must fall as the reading rises "
                             "(a higher reading is a graduation lower on the stem)")
        step = (distances[0] - distances[-1]) / (readings[-1] - readings[0])
        scale_zero = distances[0] + step * readings[0] - bulb_length / 2
        lowest = distances[-1] - bulb_length / 2
        if lowest <= 0:
            raise ValueError(f"the {readings[-1]:g} g/L graduation lies {distances[-1] * 100:.3g} cm above the bulb's "
                             f"centre, inside a bulb of {bulb_length * 100:.3g} cm: check the calibration's distances "
                             "(cm, to the bulb's centre) or the bulb's length")
        return cls._floating(bulb_length, bulb_volume, scale_zero, step,
                             calibration=tuple(zip(readings.tolist(), distances.tolist())))

    def centre_distance(self, reading):
        """H_r [m]: from the graduation of `reading` [g/L] to the bulb's centre."""
        reading = np.asarray(reading, float)
        if not self.calibration:
            return self.scale_zero + self.bulb_length / 2 - self.scale_step * reading
        r, h = np.array(self.calibration).T
        inside = np.interp(reading, r, h)
        below = h[0] + (reading - r[0]) * (h[1] - h[0]) / (r[1] - r[0])
        above = h[-1] + (reading - r[-1]) * (h[-1] - h[-2]) / (r[-1] - r[-2])
        return np.where(reading < r[0], below, np.where(reading > r[-1], above, inside))

    @staticmethod
    def liquid_density(reading) -> np.ndarray:
        """The density [kg/m3] of the uniform liquid in which a 152H reads `reading` [g/L]."""
        return WATER_20C_DENSITY + R_FACTOR * np.asarray(reading, float)

    def reading_floating(self, top) -> np.ndarray:
        """What the stem reads with the bulb's top `top` [m] below the surface. The marks are where the
        instrument the maker had in mind floats in the liquid of each reading: a distance alpha / rho -
        beta from the bulb's top, through the R = 0 and R = 50 marks of the scale (for an instrument made
        as the marks say, the reading of the uniform liquid that floats it there)."""
        light, heavy = self.liquid_density(0.0), self.liquid_density(50.0)
        alpha = self.scale_step * 50.0 / (1.0 / light - 1.0 / heavy)
        beta = alpha / light - self.scale_zero
        density = alpha / (np.asarray(top, float) + beta)
        return (density - WATER_20C_DENSITY) / R_FACTOR

    def blank(self, fluid_density: float) -> float:
        """What the stem reads floating in clear water of `fluid_density` (the companion cylinder's reading,
        D7928's composite correction without a dispersant): 0 in water at 20 C, where the marks are made."""
        top = (self.mass / fluid_density - self.bulb_volume) / self.stem_area
        return float(self.reading_floating(top))

    def effective_depth(self, reading, cylinder_area: float = D422_CYLINDER_AREA):
        """D7928's H_m [m]: the bulb's centre below the surface at `reading` (corrected for the
        meniscus), less the rise of the surface as the bulb enters, V_B / 2A."""
        return self.centre_distance(reading) - self.bulb_volume / (2 * cylinder_area)

    def describe(self, scale: Scale = GRAMS) -> str:
        """The instrument as the console echoes it, its readings on `scale`."""
        def at(grams: float) -> str:
            return f"{float(scale.as_read(grams)):.5g}{' g/L' if scale.in_grams else ''}"
        points = self.calibration or ((0.0, float(self.centre_distance(0.0))),
                                      (50.0, float(self.centre_distance(50.0))))
        where = "calibrated" if self.calibration else f"nominal {scale.name} of D422"
        marks = ", ".join(f"{h * 100:.4g} cm at {at(r)}" for r, h in points)
        return f"{where}: H_r {marks}; bulb {self.bulb_volume * 1e6:.3g} mL, {self.bulb_length * 100:.3g} cm"

    def bulb_top_depth(self, column: Column, t: float, cylinder_area: float = D422_CYLINDER_AREA) -> float:
        """Depth of the bulb top where the hydrostatic force on the immersed stem and bulb equals the
        weight, in the column as the instrument leaves it: the suspension beside each level is lifted by
        the instrument's volume below it, so that at depth s it is the column's from s - V(s) / A, V(s)
        the instrument's volume above s (at the bulb's centre V_B / 2 A shallower: D7928's H_m). The
        force is linear in the depth between the points where either end of the bulb meets a layer
        edge: the first of those where it reaches the weight brackets the root exactly."""
        bulb_area = self.bulb_volume / self.bulb_length
        stem_share, bulb_share = self.stem_area / cylinder_area, bulb_area / cylinder_area
        lifted_bulb = self.bulb_length * (1.0 - bulb_share)    # the bulb's span in the column's own depths
        above = column.mass_profile(t)

        def excess(y):
            origin = y * (1.0 - stem_share)    # the column's depth of the suspension now at the bulb's top
            return (self.stem_area * above(origin) / (1.0 - stem_share)
                    + bulb_area * (above(origin + lifted_bulb) - above(origin)) / (1.0 - bulb_share) - self.mass)
        points = np.unique(np.clip(np.concatenate([column.depth_edges, column.depth_edges - lifted_bulb])
                                   / (1.0 - stem_share), 0.0, column.height))
        force = excess(points)
        if force[0] > 0:
            raise ValueError("the hydrometer would float with its bulb out of the suspension")
        if force[-1] < 0:
            raise ValueError("the hydrometer sinks to the bottom: column too short or suspension too light")
        k = int(np.argmax(force >= 0))
        if k == 0:
            return float(points[0])
        share = -force[k - 1] / (force[k] - force[k - 1])
        return float(points[k - 1] + share * (points[k] - points[k - 1]))

    def stokes_depth(self, top, cylinder_area: float = D422_CYLINDER_AREA, level_rise: bool = True):
        """The depth Stokes' law takes for a bulb whose top is at `top`: its centre, with `level_rise`
        as D422 takes it, L = L1 + (L2 - VB / A_c) / 2 (the bulb lifts the surface by VB / A_c)."""
        return top + 0.5 * (self.bulb_length - (self.bulb_volume / cylinder_area if level_rise else 0.0))

    def read(self, column: Column, times_s, cylinder_area: float = D422_CYLINDER_AREA, level_rise: bool = True) -> Readings:
        """Readings at the given times. The Stokes depth is the bulb centre; with `level_rise` it is
        taken as in D422, L = L1 + (L2 - VB / A_c) / 2: the bulb lifts the surface by VB / A_c."""
        bulb_area = self.bulb_volume / self.bulb_length
        if not cylinder_area > bulb_area:
            raise ValueError(f"a cylinder of {cylinder_area * 1e4:.3g} cm2 is no wider than the hydrometer's bulb "
                             f"({bulb_area * 1e4:.3g} cm2)")
        c0 = column.initial_concentration()
        a = gs_correction(column.suspension.specific_gravity)
        rows = []
        for t in times_s:
            water = column.suspension_at(t)
            top = self.bulb_top_depth(column, t, cylinder_area)
            reading = float(self.reading_floating(top))
            depth = self.stokes_depth(top, cylinder_area, level_rise)
            # the percent finer from the reading less the blank of the water at its time, as a laboratory
            # takes it less its companion cylinder's
            rows.append((t, depth, reading, water.stokes_diameter(depth, t),
                         _percent((reading - self.blank(water.fluid_density)) * a, c0)))
        return _readings(rows)


@dataclass(frozen=True)
class BuoyancySphere:
    """A sphere hung from a balance at a fixed centre depth (Bardet & Young 1997). The default is the
    Teflon sphere of 25 mm and 20 g, so the apparent mass is what the balance shows (11.8 g in water)."""

    depth: float
    diameter: float = SPHERE_DIAMETER
    mass: float = SPHERE_MASS    # its own mass [kg]; shifts the apparent mass, not the percent finer

    @property
    def volume(self) -> float:
        """[m3]."""
        return np.pi / 6 * self.diameter ** 3

    def solids(self, apparent, fluid_density, specific_gravity: float):
        """Solids per volume [kg/m3] around the sphere from its apparent mass [kg] in water of
        `fluid_density` (Gs from water at 1000 kg/m3)."""
        in_water = self.mass - fluid_density * self.volume
        return (in_water - apparent) / self.volume * specific_gravity / (specific_gravity - 1)

    def read(self, column: Column, times_s) -> Readings:
        """Apparent mass [g] of the sphere at each time, with the diameter and percent finer it gives."""
        _fits(column, self.depth, self.diameter / 2, "buoyancy sphere")
        volume = self.volume
        c0 = column.initial_concentration()
        rows = []
        for t in times_s:
            suspension = column.suspension_at(t)
            phi = column.weighted_mean(t, self.depth, self.diameter / 2)
            rho = suspension.mixture_density(phi)
            apparent = self.mass - rho * volume
            concentration = self.solids(apparent, suspension.fluid_density, suspension.specific_gravity)
            rows.append((t, self.depth, apparent * 1e3, suspension.stokes_diameter(self.depth, t),
                         _percent(concentration, c0)))
        return _readings(rows)


@dataclass(frozen=True)
class Pipette:
    """A sample of `volume` drawn around the tip at a fixed depth: a sphere of that volume; in a 2d
    slab (the cylinder's axial section) its section through the axis, a circle of the same radius."""

    depth: float
    volume: float = PIPETTE_VOLUME

    def read(self, column: Column, times_s) -> Readings:
        """Solids concentration [g/L] drawn at each time, with the diameter and percent finer it gives."""
        disc = column.slab_thickness > 0
        radius = (3 * self.volume / (4 * np.pi)) ** (1 / 3)
        _fits(column, self.depth, radius, f"{self.volume * 1e6:.3g} mL pipette sample")
        c0 = column.initial_concentration()
        rows = []
        for t in times_s:
            suspension = column.suspension_at(t)
            concentration = suspension.particle_density * column.weighted_mean(t, self.depth, radius, disc=disc)
            rows.append((t, self.depth, concentration, suspension.stokes_diameter(self.depth, t),
                         _percent(concentration, c0)))
        return _readings(rows)

    def default_times(self, suspension: Suspension) -> np.ndarray:
        """Stokes times of 50, 20, 10, 5 and 2 um at the pipette depth."""
        return suspension.stokes_time(self.depth, np.array([50, 20, 10, 5, 2]) * 1e-6)


def gs_correction(specific_gravity: float) -> float:
    """The 152H's correction a for grains of another Gs: solids [g/L] = a R (a = 1 at Gs 2.65)."""
    return 1.65 * specific_gravity / (2.65 * (specific_gravity - 1))


def _percent(concentration: float, initial: float) -> float:
    return 100 * concentration / initial if initial > 0 else float("nan")    # no solids: undefined


def _readings(rows: list[tuple]) -> Readings:
    data = np.array(rows, float).reshape(-1, 5)
    return Readings("", *(data[:, k] for k in range(5)))    # the registry names them (lab/instruments.py)


def _fits(column: Column, depth: float, radius: float, what: str) -> None:
    """Refuses an instrument region (a sphere of `radius` centred `depth` below the surface) that
    leaves the column."""
    if not radius <= depth <= column.height - radius:
        raise ValueError(f"the {what} (radius {radius * 100:.3g} cm) centred {depth * 100:.3g} cm deep does not fit "
                         f"in the {column.height * 100:.3g} cm column")
