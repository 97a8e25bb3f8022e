# SPDX-License-Identifier: GPL-2.0-or-later
"""Screening: each candidate effect of a sedimentation test with its dimensionless number and an
estimate of how far it can move the readings, before anything is simulated (docs/effects.md section 2).

An effect that acts through the settling speed is estimated one way for all: each size class of the
PSD settles at its speed with and without the effect in an analytic column (lab.synthetic), the
instruments read both columns at their schedules, and the estimate is the largest change of any
reading in points of percent finer. The column keeps its initial concentration for the hindrance and
its initial grain counts for the collisions (both only fall as grains leave), which errs high; it
has no deposit and no parcels, which the runs have.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .. import _core
from ..constants import BOLTZMANN, INSTRUMENTS, LAB_TEMPERATURE, PIPETTE_DEPTH, SPECIMEN_MASS, SWIRL_LENGTH, SWIRL_SPEED
from ..lab.granulometry import read_all
from ..lab.instruments import instrument
from ..lab.psd import PSD, log_classes
from ..lab.readout import SCHEDULES, Pipette, Suspension
from ..lab.settling import terminal_speeds
from ..lab.synthetic import settling_column
from ..sim.scene import Cylinder

BED_PACKING = 0.6             # solid fraction of a settled silt bed (random loose to close packing 0.55-0.64)
FILM_REBOUND_STOKES = 10.0    # approach Stokes number below which a squeeze film stops a rebound (Gondret et al. 2002)

INCLUDE, OMIT, MEASURE, REPORT = "include", "omit", "measure", "report only"

# Estimated changes at most OMIT_BELOW x tolerance are dropped without a run; at least INCLUDE_ABOVE x
# tolerance are kept without one: a margin of four either way on estimates that came within 10 % of
# the measured changes for the five samples of docs/effects.md.
OMIT_BELOW = 0.25
INCLUDE_ABOVE = 4.0
# Not so the swirls' estimate, built on Segre et al.'s steady swirls: in the test's column under the
# flow (docs/effects.md section 3) samples 2, 4, 1 and 5 (30 g/L) moved a reading 1.9, 5.8, 6.2 and 23
# times as far as it said. It bounds nothing, so two-way coupling is never omitted on it: it is
# reported, for --measure-flow to measure.
SWIRL_MEASURED_OVER_ESTIMATE = (1.9, 23.0)


@dataclass(frozen=True)
class SedimentationTest:
    """What the planner needs to know of a test: the sample, the water, the cylinder, the instruments."""

    psd: PSD
    suspension: Suspension = Suspension()
    cylinder: Cylinder = Cylinder()
    mass: float = SPECIMEN_MASS
    instruments: tuple[str, ...] = INSTRUMENTS

    @property
    def initial_concentration(self) -> float:
        """c0 [kg/m3]."""
        return self.mass / (self.cylinder.area * self.cylinder.height)

    @property
    def solid_fraction(self) -> float:
        """phi0 = c0 / rho_p."""
        return self.initial_concentration / self.suspension.particle_density


@dataclass(frozen=True)
class Screen:
    """One effect screened: its number, the estimated change of the readings and the verdict."""

    effect: str            # key, as the planner's trials and the deck options name it
    label: str
    number: str            # what `value` is
    value: float
    change: float | None   # estimated largest change of a reading [percentage points], if estimable
    verdict: str           # include, omit, measure, report only
    reason: str


class ReadingModel:
    """The instruments reading analytic columns of one test: `change(speed)` is the largest
    difference of any reading [percentage points] from the readings at the reference speeds."""

    def __init__(self, test: SedimentationTest, reference_speed):
        self.test = test
        pipette = Pipette(PIPETTE_DEPTH).default_times(test.suspension)
        self.times = np.unique(np.concatenate([[0.0], np.array(SCHEDULES["d422"] + SCHEDULES["bravo"]) * 60.0,
                                               pipette]))
        column = self._column(reference_speed)
        self.reference: dict[str, np.ndarray] = {}
        self.reading_times: dict[str, np.ndarray] = {}    # s, each instrument's
        for name in test.instruments:    # one at a time: an instrument that cannot read this test is named
            try:
                found, _ = read_all(column, [name], cylinder_area=test.cylinder.area)
            except ValueError as exc:
                raise ValueError(f"the {name} cannot read this test ({exc}): plan without it (--instruments)") from None
            self.reference.update({r.instrument: r.percent_finer for r in found})
            self.reading_times.update({r.instrument: r.time for r in found})

    def _column(self, speed):
        t = self.test
        return settling_column(t.psd, t.cylinder.height, self.times, t.initial_concentration, t.suspension,
                               layers=1200, classes=300, speed=speed)

    def readings(self, speed) -> dict[str, np.ndarray]:
        """Each instrument's readings [percent finer] when the classes settle at `speed(d)`."""
        found, _ = read_all(self._column(speed), list(self.test.instruments), cylinder_area=self.test.cylinder.area)
        return {r.instrument: r.percent_finer for r in found}

    def largest_change(self, readings: dict[str, np.ndarray]) -> float:
        """max |P - P_reference| over the instruments' `readings`."""
        return max(float(np.max(np.abs(p - self.reference[name]))) for name, p in readings.items())

    def change(self, speed) -> float:
        """max |P - P_reference| over the instruments' readings when the classes settle at `speed(d)`."""
        return self.largest_change(self.readings(speed))

    def spread_readings(self, speed, spread) -> dict[str, np.ndarray]:
        """Each instrument's readings when each class's speed is spread by the fraction `spread(d)` (a
        Gaussian's standard deviation) about `speed(d)`: the mean of the readings at speed (1 +- spread),
        which holds the spread's variance."""
        faster = self.readings(lambda d: speed(d) * (1 + spread(d)))
        slower = self.readings(lambda d: speed(d) * (1 - spread(d)))
        return {name: 0.5 * (faster[name] + slower[name]) for name in faster}

    def spread_change(self, speed, spread) -> float:
        """The largest change of a reading when each class's speed is spread by the fraction `spread(d)`."""
        return self.largest_change(self.spread_readings(speed, spread))


def encounters(test: SedimentationTest, classes: int = 120,
               interception: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The grain-grain contacts of grains settling through the column, per size class, counted with
    the initial real grain numbers. Class j grains lie in the tube pi (r_i + r_j)^2 |v_i - v_j| / v_i
    swept per metre of fall; of these the fraction E = 1 - 3 / (2 (1 + q)) + 1 / (2 (1 + q)^3)
    (Stokes-flow interception, q = small / large radius) touches instead of being carried round
    (without `interception` every one touches, as DEM contacts without the flow do). In
    contact the pair settles at (xi_i v_i + xi_j v_j) / (xi_i + xi_j) (Stokes resistances xi ~ r)
    until it has slid past, a time (r_i + r_j) / |v_i - v_j|, which costs grain i a distance r_j
    (gains it, when j is the faster).

    Returns (diameters, mass shares, contacts per grain over the column height, fraction of the fall
    time lost to them)."""
    t = test
    lo, hi = t.psd.span()
    diameter, share = log_classes(t.psd, lo, hi, classes)
    share[0] += t.psd.percent_finer[0] / 100.0
    speed = terminal_speeds(t.suspension, diameter)
    number = share * t.initial_concentration / (t.suspension.particle_density * math.pi / 6 * diameter ** 3)
    r = 0.5 * diameter
    q = np.minimum(r[:, None], r[None, :]) / np.maximum(r[:, None], r[None, :])
    efficiency = 1 - 1.5 / (1 + q) + 0.5 / (1 + q) ** 3 if interception else 1.0
    touching = efficiency * math.pi * (r[:, None] + r[None, :]) ** 2 * number[None, :]
    closing = (speed[:, None] - speed[None, :]) / speed[:, None]
    contacts = t.cylinder.height * (touching * np.abs(closing)).sum(axis=1)
    delay = (touching * closing * r[None, :]).sum(axis=1)
    return diameter, share, contacts, delay


def lowest_sensed_depth(test: SedimentationTest) -> float:
    """The deepest point any instrument senses [m below the surface]: the hydrometer's bulb bottom
    at a zero reading, the buoyancy sphere's bottom, the pipette sample's bottom."""
    return max(instrument(name).deepest(test.cylinder.height) for name in test.instruments)


def swirl_spread(test: SedimentationTest, depth: float, classes: int = 120) -> tuple[np.ndarray, np.ndarray, float]:
    """How far the swirls of the suspension spread each class's arrival at `depth`, as a fraction of its
    fall: sqrt(2 int D dt) / depth over the class's fall time depth / v. The swirls' dispersion is
    D = dV 2 xi, with dV = SWIRL_SPEED phi^1/3 V (1 - exp(-W / (60 a phi^-1/3))), Segre et al.'s cut-off
    by the cylinder's width W, and 2 xi = SWIRL_LENGTH a phi^-1/3 (at most W), for the fraction phi, mass-mean speed
    V and radius a of the grains still above `depth` (a class has left when it has fallen `depth`).
    Errs high: the swirls also weaken as the column stratifies (Tee et al. 2002, PRL 89 054501).

    Returns (diameters, spreads, the fluctuation dV / V at the start)."""
    lo, hi = test.psd.span()
    diameter, share = log_classes(test.psd, lo, hi, classes)
    share = share / share.sum()
    speed = terminal_speeds(test.suspension, diameter)
    order = np.argsort(-speed)    # the classes in the order they leave
    d, w, v = diameter[order], share[order], speed[order]
    left = depth / v
    # while class m is the fastest still falling: the grains of classes m, m + 1, ... remain
    remaining = np.cumsum(w[::-1])[::-1]
    mean_speed = np.cumsum((w * v)[::-1])[::-1] / remaining
    mean_radius = np.cumsum((w * d / 2)[::-1])[::-1] / remaining
    phi = test.solid_fraction * remaining
    fluctuation = SWIRL_SPEED * phi ** (1 / 3) * mean_speed \
        * (1 - np.exp(-test.cylinder.diameter / (60 * mean_radius * phi ** (-1 / 3))))
    dispersion = fluctuation * np.minimum(SWIRL_LENGTH * mean_radius * phi ** (-1 / 3), test.cylinder.diameter)
    spread = np.sqrt(2 * np.cumsum(dispersion * np.diff(left, prepend=0.0))) / depth
    back = np.argsort(order)
    return diameter, spread[back], float(fluctuation[0] / mean_speed[0])


def swirl_spread_of(test: SedimentationTest, depth: float = PIPETTE_DEPTH) -> tuple[Callable, float, float]:
    """`swirl_spread` as a function of the diameter (capped at 0.9, where a class would stop), its largest
    value, and the fluctuation dV / V at the start."""
    diameter, spreads, fluctuation = swirl_spread(test, depth)
    def spread(d):
        return np.minimum(np.interp(np.log(d), np.log(diameter), spreads), 0.9)
    return spread, float(spreads.max()), fluctuation


def verdict_of(change: float, tolerance: float) -> str:
    """omit, include or measure, for an estimated change against the tolerance."""
    if change <= OMIT_BELOW * tolerance:
        return OMIT
    return INCLUDE if change >= INCLUDE_ABOVE * tolerance else MEASURE


def screen(test: SedimentationTest, tolerance: float = 0.5) -> list[Screen]:
    """Every candidate effect of a sedimentation test, screened against `tolerance` [percentage points]."""
    if not tolerance > 0:
        raise ValueError(f"the tolerance must be > 0 percentage points, not {tolerance:g}")
    s, t = test.suspension, test
    single = lambda d: terminal_speeds(s, d)    # noqa: E731 - the reference speeds (the standard curve)
    model = ReadingModel(test, single)
    lo, hi = t.psd.span()
    phi = t.solid_fraction
    screens = []

    v_max = float(terminal_speeds(s, np.array([hi]))[0])
    reynolds = s.fluid_density * v_max * hi / s.viscosity
    change = model.change(s.stokes_speed)
    screens.append(Screen("law", "drag beyond Stokes (the standard drag curve)", "largest particle Reynolds number",
                          reynolds, change, verdict_of(change, tolerance),
                          f"Stokes' law instead of the standard curve moves a reading by up to {change:.3g} pp"))

    change = model.change(lambda d: terminal_speeds(s, d, "standard", 1 - phi, "richardson-zaki"))
    screens.append(Screen("hindered", "hindered settling (Richardson & Zaki)", "initial solid fraction",
                          phi, change, verdict_of(change, tolerance),
                          f"settling {100 * (1 - (1 - phi) ** 4.7):.3g} % slower at phi0 = {phi:.3g} moves a "
                          f"reading by up to {change:.3g} pp (at phi0 throughout: phi falls as grains leave)"))

    diameter, share, contacts, delay = encounters(test)
    slower = lambda d: single(d) / (1 + np.interp(np.log(d), np.log(diameter), delay))    # noqa: E731
    change = model.change(slower)
    bed = t.mass / (s.particle_density * t.cylinder.area * BED_PACKING)
    clearance = t.cylinder.height - lowest_sensed_depth(test) - bed
    in_bed = (f"the bed ({bed * 1e3:.3g} mm) stays {clearance * 1e3:.3g} mm below the deepest instrument"
              if clearance > 0 else f"the bed ({bed * 1e3:.3g} mm) reaches the deepest instrument")
    verdict = verdict_of(change, tolerance) if clearance > 0 else MEASURE
    screens.append(Screen("contacts", "contacts between grains and with the bed", "contacts per grain (mass mean)",
                          float(share @ contacts / share.sum()), change, verdict,
                          f"grains touch up to {contacts.max():.3g} times in their fall, losing up to "
                          f"{100 * delay.max():.2g} % of their speed, which moves a reading by up to {change:.3g} pp; "
                          + in_bed))

    closing = v_max - float(terminal_speeds(s, np.array([lo]))[0])    # the largest grain onto the finest
    film = s.particle_density * hi * closing / (9 * s.viscosity)
    screens.append(Screen("lubrication", "lubrication (squeeze films between close grains)",
                          "approach Stokes number of the largest grain", film, None,
                          verdict if verdict != INCLUDE else MEASURE,
                          f"films act only in the contacts above; gaps close at up to {closing:.3g} m/s, and at "
                          f"St = {film:.3g} "
                          f"{'<' if film < FILM_REBOUND_STOKES else '>='} {FILM_REBOUND_STOKES:g} they "
                          f"{'stop every rebound' if film < FILM_REBOUND_STOKES else 'let grains rebound'}"))

    tau = float(_core.relaxation_time("standard", s.fluid_density, s.viscosity, hi, s.particle_density))
    first = float(model.times[1])
    screens.append(Screen("inertia", "particle inertia", "relaxation time / first reading time", tau / first, None,
                          INCLUDE, f"the largest grain reaches its terminal speed in {tau:.3g} s; DEM integrates "
                          "inertia at no extra cost"))

    drho = s.particle_density - s.fluid_density
    kelvin = 273.15 + (s.temperature if s.temperature is not None else LAB_TEMPERATURE)
    d_unit = (6 * BOLTZMANN * kelvin / (math.pi * drho * s.gravity)) ** 0.25    # Pe = 1
    peclet = (lo / d_unit) ** 4
    below = float(t.psd.at(np.array([d_unit]))[0])
    screens.append(Screen("brownian", "Brownian motion", "Peclet number of the smallest grain", peclet, None, REPORT,
                          f"{below:.3g} % of the mass is finer than {d_unit * 1e6:.3g} um (Pe < 1), where diffusion "
                          "competes with settling; not simulated"))

    ratio = hi / t.cylinder.diameter
    change = model.change(lambda d: single(d) / (1 + 2.1 * d / t.cylinder.diameter))
    screens.append(Screen("wall", "cylinder wall (Ladenburg)", "largest diameter / cylinder diameter", ratio, change,
                          REPORT, f"the wall slows grains by up to {100 * 2.1 * ratio:.2g} %, moving a reading by up "
                          f"to {change:.3g} pp; not simulated (the sub-volume is periodic)"))

    spread, widest, fluctuation = swirl_spread_of(test)
    change = model.spread_change(single, spread)
    screens.append(Screen("two-way", "two-way coupling (the flow the grains drive)",
                          "velocity fluctuation / mean settling speed, 2.0 phi0^1/3", fluctuation, change,
                          REPORT,
                          f"a homogeneous suspension settles as its hindrance says with or without the flow it "
                          f"drives (deck check suspension_flow); what the flow adds is its swirls (Segre et al. "
                          f"1997), which spread each class's arrival at {100 * PIPETTE_DEPTH:g} cm by up to "
                          f"{100 * widest:.2g} % of its fall and move a reading by up to {change:.3g} pp on "
                          f"their steady strength (in the test's column the flow moved readings "
                          f"{SWIRL_MEASURED_OVER_ESTIMATE[0]:g} to {SWIRL_MEASURED_OVER_ESTIMATE[1]:g} times as far "
                          "as such estimates: it bounds nothing); not simulated in the planner's sub-volume, two "
                          "grains across and too narrow for the swirls: --measure-flow measures it in a column of "
                          "parcels three swirls wide under fix fluid/flow, against its one-way twin"))

    screens.append(Screen("yield", "yield stress (Bingham)", "yield number tau_y / (drho g d)", 0.0, 0.0, OMIT,
                          "water is Newtonian: the yield machinery is never needed"))
    screens.append(Screen("surface", "partial submergence at the free surface", "grains crossing the surface", 0.0,
                          0.0, OMIT, "every grain starts below the surface and settles away from it"))
    return screens
