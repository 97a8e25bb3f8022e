# SPDX-License-Identifier: GPL-2.0-or-later
"""What a value given on the command line or in an input file can plausibly be, and the unit slip
that most likely explains one that is not (docs/inputs.md): every quantity a command takes, its
range from physics or laboratory practice, and the units it is often written in by mistake.

A value outside its range is refused; where the value read in another unit lands inside the range,
the message names that unit and the value to give instead (25 L for a 25 mL pipette: give 2.5e-05)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Range:
    """A quantity's plausible values in the unit it is given in, why, and its likely slips: (another
    unit, the value in `unit` of a number written in it)."""

    unit: str
    low: float
    high: float
    why: str
    slips: tuple[tuple[str, Callable[[float], float]], ...] = ()

    def refusal(self, value: float, slips: bool = True) -> str | None:
        """Why `value` is implausible, naming the slip that would explain it (with `slips`); None if it is
        plausible."""
        if self.low <= value <= self.high:
            return None
        unit = f" {self.unit}" if self.unit else ""
        span = f"{self.low:g} to {self.high:g}" if self.low < 0 else f"{self.low:g}-{self.high:g}"
        return f"{value:g}{unit} is not within {span}{unit}: {self.why}" + (self.slip(value) if slips else "")

    def slip(self, value: float) -> str:
        """Every unit slip that would explain `value` (where two do, the user knows which unit they used),
        each as '; written in ...? that is ...: give ...', or ''."""
        unit = f" {self.unit}" if self.unit else ""
        meant = [(name, convert(value)) for name, convert in self.slips]
        return "".join(f"; written in {name}? that is {v:.6g}{unit}: give {v:.6g}" for name, v in meant
                       if self.low <= v <= self.high)


def _times(factor: float) -> Callable[[float], float]:
    return lambda value: value * factor


def _fahrenheit(value: float) -> float:
    return (value - 32.0) * 5.0 / 9.0


GRAMS = ("g", _times(1e-3))
G_PER_CM3 = ("g/cm3", _times(1e3))
CM, MM, UM = ("cm", _times(1e-2)), ("mm", _times(1e-3)), ("um", _times(1e-6))
PERCENT = ("percent", _times(1e-2))

RANGES: dict[str, Range] = {
    # the sample and the suspension
    "specimen_mass": Range("kg", 0.01, 0.2, "a sedimentation test's dry specimen is 10-200 g: 50 g of a fine soil, "
                           "up to 100-200 g of a sandy one", (GRAMS,)),
    "particle_density": Range("kg/m3", 1010.0, 22600.0, "grains settle in water only if denser than it, and no solid "
                              "is denser than osmium; a soil's are about 2650", (G_PER_CM3,)),
    "solid_density": Range("kg/m3", 100.0, 22600.0, "a solid sphere: a foam's 100 to osmium's 22600", (G_PER_CM3,)),
    "fluid_density": Range("kg/m3", 500.0, 3000.0, "a liquid: a light oil's 500 to a heavy mud's 3000", (G_PER_CM3,)),
    "paste_density": Range("kg/m3", 1000.0, 3000.0, "a paste: water's 1000 to a dense backfill's 3000", (G_PER_CM3,)),
    "concentration": Range("g/L", 0.5, 500.0, "solids in a sedimentation test: tens of g/L", (("kg/L or g/cm3", _times(1e3)),)),
    "temperature": Range("C", 0.0, 40.0, "the water correlations' range", (("F", _fahrenheit),
                                                                          ("K", lambda value: value - 273.15))),
    "water_viscosity": Range("Pa s", 2e-4, 0.02, "water and its solutions: 0.65-1.8 mPa s from 40 to 0 C",
                             (("mPa s (cP)", _times(1e-3)),)),
    "viscosity": Range("Pa s", 1e-5, 1000.0, "a gas's 1e-5 to a thick paste's hundreds", (("mPa s (cP)", _times(1e-3)),)),
    "yield_stress": Range("Pa", 0.0, 1e4, "a mud's or paste's yield stress is at most a few kPa", (("mPa", _times(1e-3)),)),
    "solid_fraction": Range("", 0.0, 0.63, "a volume fraction below random close packing, 0.64", (PERCENT,)),
    # the cylinder and the instruments
    "cylinder_area": Range("m2", 5e-4, 0.05, "a sedimentation cylinder of 2.5-25 cm across; D422's is 27.8 cm2",
                           (("cm2", _times(1e-4)), ("mm2", _times(1e-6)))),
    "suspension_height": Range("m", 0.05, 2.0, "a settling column of 5 cm to 2 m; D422's 1000 mL is 0.36 m", (CM, MM)),
    "suspension_volume": Range("L", 0.2, 5.0, "a sedimentation cylinder holds 0.5-2 L (D422's: 1 L)"),
    "column_width": Range("m", 1e-6, 0.3, "a simulated column's side: a few grains to the cylinder's width", (MM, UM)),
    "instrument_depth": Range("m", 0.005, 2.0, "a depth below the suspension's surface in a settling column", (CM, MM)),
    "surface": Range("m", -10.0, 10.0, "the free surface's coordinate in the layer file: within metres of its origin",
                     (MM,)),
    "pipette_volume": Range("m3", 1e-5, 5e-5, "a pipette draws 10-50 mL (ASTM D422: 25 mL)",
                            (("L", _times(1e-3)), ("mL", _times(1e-6)))),
    "sphere_diameter": Range("m", 0.005, 0.06, "a buoyancy sphere fits the cylinder: 5-60 mm across", (MM, CM)),
    "sphere_mass": Range("kg", 5e-4, 1.0, "a buoyancy sphere of 5-60 mm: about a gram to a kilogram", (GRAMS,)),
    "bulb_length": Range("m", 0.05, 0.3, "a hydrometer's bulb (152H: 0.14 m)", (CM, MM)),
    "bulb_volume": Range("m3", 1e-5, 3e-4, "a hydrometer's bulb (152H: 67 cm3)", (("cm3 (mL)", _times(1e-6)),)),
    "stem_diameter": Range("m", 1e-3, 0.03, "a hydrometer's stem (152H: about 6 mm)", (MM, CM)),
    "hydrometer_mass": Range("kg", 0.01, 0.3, "a hydrometer (152H: about 70 g)", (GRAMS,)),
    "scale_mark": Range("m", 0.0, 0.3, "a scale mark's distance from the bulb's top (152H: 0.105 m for R = 0)", (CM, MM)),
    "correction": Range("g/L", -10.0, 20.0, "a 152H's composite correction is a few g/L (dispersant, temperature, "
                        "meniscus)"),
    "meniscus": Range("g/L", -5.0, 5.0, "a 152H's meniscus is about 1 g/L"),
    "water_content": Range("", 0.0, 0.5, "a hygroscopic (air-dry) water content, a fraction of the oven-dry mass: "
                           "0.005-0.1 for most soils", (PERCENT,)),
    "suspension_volume_m3": Range("m3", 2e-4, 5e-3, "a sedimentation cylinder holds 0.5-2 L (D422's: 1 L)",
                                  (("L", _times(1e-3)), ("mL", _times(1e-6)))),
    "split": Range("mm", 0.02, 150.0, "a sieve of 20 um to 150 mm; D422 splits at 2.0 mm", (("um", _times(1e-3)),
                                                                                          ("m", _times(1e3)))),
    # the noise of a reading
    "hydrometer_noise": Range("g/L", 0.01, 5.0, "a 152H is read to 0.5-1 g/L"),
    "balance_noise": Range("g", 1e-6, 1.0, "a balance resolves a microgram to a gram"),
    "pipette_noise": Range("g", 1e-6, 0.01, "a pipette sample is weighed to 1 ug-10 mg"),
    "sieve_noise": Range("points", 0.01, 10.0, "a sieve's percent passing is known to a fraction of a point"),
    "thermometer": Range("C", 0.01, 5.0, "a laboratory thermometer: 0.1-1 C"),
    # the simulation and the studies
    "t_end": Range("s", 60.0, 3e6, "a sedimentation test lasts minutes to a month (D422: a day)",
                   (("h", _times(3600.0)), ("min", _times(60.0)))),
    "contact_cut": Range("um", 0.1, 1e4, "a grain of 0.1 um to 10 mm", (("m", _times(1e6)), ("mm", _times(1e3)))),
    "test_tolerance": Range("points", 0.01, 20.0, "points of percent finer"),
    "relative_tolerance": Range("", 1e-9, 0.5, "a relative error: 0.01 is 1 %", (PERCENT,)),
    "time_scale": Range("s", 1e-15, 1e6, "a relaxation or contact time"),
    "time_step": Range("s", 1e-12, 0.1, "a DEM time step"),
    # single spheres and pastes
    "sphere_size": Range("m", 1e-8, 0.5, "a sphere of 10 nm to 0.5 m", (UM, MM)),
    "ball_diameter": Range("m", 5e-4, 0.2, "a ball dropped into a paste or mud: 0.5 mm to 20 cm", (MM, CM)),
    "fall_height": Range("m", 0.0, 10.0, "a ball's fall in a laboratory", (MM, CM)),
    "slump_length": Range("m", 0.005, 1.0, "a slump cylinder is 0.1-0.3 m tall", (MM, CM)),
    "gravity": Range("m/s2", 0.1, 100.0, "gravity: the Moon's 1.6 to a centrifuge's 10 g", (("cm/s2", _times(1e-2)),)),
    "youngs_modulus": Range("Pa", 1e4, 1.2e12, "a soft rubber's 10 kPa to diamond's 1.2 TPa",
                            (("GPa", _times(1e9)), ("MPa", _times(1e6)))),
    "poisson_ratio": Range("", -0.99, 0.5, "an isotropic solid's, above -1 (where its shear modulus is infinite) "
                           "and at most 0.5", (PERCENT,)),
    "restitution": Range("", 0.05, 0.95, "the restitutions the tsuji damping is solved for; steel on steel is "
                         "about 0.6", (PERCENT,)),
    "settling_speed": Range("m/s", 1e-7, 30.0, "a sphere's settling speed", (("mm/s", _times(1e-3)), ("cm/s", _times(1e-2)))),
    # the columns of a sheet (the units the sheet's header names)
    "time_min": Range("min", 0.05, 10080.0, "a sedimentation test is read from seconds after the start to a week",
                      (("s", _times(1 / 60)), ("h", _times(60.0)))),
    "record_time_min": Range("min", 0.0, 10080.0, "a temperature record of a test lasting up to a week",
                             (("s", _times(1 / 60)),)),
    "reading": Range("g/L", -5.0, 60.0, "a 152H's scale runs from -5 to 60 g/L"),
    "reading_151h": Range("", 0.995, 1.04, "a 151H's scale runs from 0.995 to 1.038 (specific gravity)"),
    "blank_151h": Range("", 0.99, 1.0125, "a 151H in the control cylinder (water and dispersant) reads about 1.000 "
                        "to 1.006"),
    "depth_cm": Range("cm", 1.0, 200.0, "a pipette's depth in a settling column", (("m", _times(100.0)), ("mm", _times(0.1)))),
    "calibration_cm": Range("cm", 0.5, 40.0, "a hydrometer's graduation lies a few to 25 cm above its bulb's centre "
                            "(152H: 10-21 cm)", (("mm", _times(0.1)), ("m", _times(100.0)))),
    "apparent_mass_g": Range("g", 0.1, 5000.0, "what a balance shows for a buoyancy sphere in a suspension",
                             (("kg", _times(1e3)), ("mg", _times(1e-3)))),
}


def refusal(value: float, quantity: str) -> str | None:
    """Why a value of a quantity (a key of RANGES) is implausible, or None."""
    return RANGES[quantity].refusal(value)


def check(value: float, quantity: str, name: str) -> float:
    """The value, or a ValueError naming it (`name`: the option or column) and the likely slip."""
    reason = refusal(value, quantity)
    if reason is not None:
        raise ValueError(f"{name} {reason}")
    return value


def pipette_mass(volume: float) -> Range:
    """The dry solids of one pipette sample of `volume` [m3] [g]: at most 300 g/L of it."""
    return Range("g", 0.0, 300.0 * volume * 1e3, f"the solids of a {volume * 1e6:g} mL sample of at most 300 g/L",
                 (("mg", _times(1e-3)),))


def sphere_density(mass: float, diameter: float) -> str | None:
    """Why a buoyancy sphere of `mass` [kg] and `diameter` [m] cannot be one (it would float, or be denser
    than any solid), or None."""
    density = mass / (math.pi / 6 * diameter ** 3)
    if 1100.0 <= density <= 22600.0:
        return None
    return (f"a sphere of {diameter * 1e3:g} mm and {mass * 1e3:g} g would be {density:.4g} kg/m3, "
            + ("lighter than the suspension it must sink in" if density < 1100 else "denser than any solid")
            + ": check --sphere-mass [kg] and --sphere-diameter [m]")
