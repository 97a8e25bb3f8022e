# SPDX-License-Identifier: GPL-2.0-or-later
"""A sedimentation test as a LAMMPS scene (docs/sedimentation-tests.md section 1): the sample's PSD
discretised into size classes, a representative sub-volume of the cylinder (a 3D periodic column or
Bravo et al.'s 2D slab), stratified random placement, and a LAMMPS data file with a ready deck.

The deck settles the grains with drag and buoyancy onto a floor where they stop, and writes the layer
file the readouts need. Its time step follows the physics: the fastest grain still in suspension
crosses at most `courant` layers per step, so the step doubles each time the column has been
cleared of the grains fast enough to need the smaller one (steps per doubling: layers / courant).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from ..constants import (BRAVO_CYLINDER_HEIGHT, BRAVO_CYLINDER_WIDTH, D422_CYLINDER_AREA, D422_CYLINDER_HEIGHT,
                         DRAGS, HINDRANCES, SPECIMEN_MASS, SWIRL_LENGTH)
from ..lab.psd import PSD, SizeClasses, discretise, log_classes
from ..lab.readout import Suspension
from ..lab.settling import terminal_speed
from .placement import place

GEOMETRIES = ("column", "slab")


@dataclass(frozen=True)
class Cylinder:
    """The sedimentation cylinder: inner cross-section and suspension height."""

    area: float = D422_CYLINDER_AREA
    height: float = D422_CYLINDER_HEIGHT

    @classmethod
    def bravo(cls) -> "Cylinder":
        """Bravo et al. (2015): H = 0.457 m, B = 0.0635 m."""
        return cls(math.pi / 4 * BRAVO_CYLINDER_WIDTH ** 2, BRAVO_CYLINDER_HEIGHT)

    @property
    def diameter(self) -> float:
        """Inner diameter [m]."""
        return math.sqrt(4 * self.area / math.pi)




@dataclass(frozen=True)
class Effects:
    """What the scene simulates beyond buoyancy. drag difelice carries its own hindrance (Di Felice's)."""

    drag: str = "standard"          # one of DRAGS; readouts assume Stokes, so the difference shows
    contacts: bool = False          # Hertz contacts between grains and with the floor
    lubrication: bool = False       # squeeze film between close grains (implies contacts)
    hindrance: str = "richardson-zaki"    # one of HINDRANCES
    # "mixture": buoyancy from the local suspension density on top of the hindrance's plain-buoyancy form,
    # as some models take a measured exponent (the error budget's row; docs/physics.md 3)
    buoyancy: str = "plain"
    # two-way coupling: the flow the grains drive (fix fluid/flow), in a column FLOW_SWIRLS swirls wide
    flow: bool = False

    def __post_init__(self) -> None:
        if self.buoyancy not in ("plain", "mixture"):
            raise ValueError(f"buoyancy must be plain or mixture, not '{self.buoyancy}'")
        if self.drag not in DRAGS:
            raise ValueError(f"drag must be one of {', '.join(DRAGS)}, not '{self.drag}'")
        if self.hindrance not in HINDRANCES:
            raise ValueError(f"hindrance must be one of {', '.join(HINDRANCES)}, not '{self.hindrance}'")
        if self.drag == "difelice":    # Bravo et al.'s model: its hindrance is part of it
            object.__setattr__(self, "hindrance", "difelice")
        else:
            _core.DragModel(self.drag, 1000.0, 1e-3, hindrance=self.hindrance)    # refuses a pair that does not go

    @property
    def hindered(self) -> bool:
        """Whether the drag follows the local concentration."""
        return self.hindrance != "none"

    def describe(self) -> str:
        """The drag in words, as decks and reports name it."""
        coupled = ", two-way (fix fluid/flow)" if self.flow else ""
        if self.drag == "difelice":
            return "difelice (Dallavalle's curve hindered by Di Felice, Bravo et al.)" + coupled
        return self.drag + (f", hindered ({self.hindrance})" if self.hindered else ", unhindered") + coupled

    def fix_arguments(self) -> str:
        """The law, hindrance and concentration keywords of fix fluid/drag."""
        if self.drag == "difelice":
            return "law difelice concentration c_conc"
        if self.hindered:
            return f"law {self.drag} hindrance {self.hindrance} concentration c_conc"
        return f"law {self.drag}"

    @property
    def interacting(self) -> bool:
        """Whether grains interact (contacts or lubrication), which needs real grains."""
        return self.contacts or self.lubrication


# Two-way coupling (`--two-way`): the column is FLOW_SWIRLS swirls wide (Segre et al.'s 40 a phi^-1/3 at
# the start, a the mass-mean radius), the flow's grid FLOW_CELLS_ACROSS cubic cells across it by
# default (Scene.flow_cells), and each step carries a parcel at most FLOW_COURANT cells at the grid's largest
# velocity, taken as FLOW_PEAK times the root mean square that the independent start drives: the
# largest of some 1e5 nodes of a Gaussian field. Sample 2 (docs/effects.md): 12 mm, 16 x 16 x 480.
FLOW_SWIRLS = 3
FLOW_CELLS_ACROSS = 16
# The largest grid `plan` writes: fix fluid/flow holds about FLOW_BYTES_PER_CELL a cell (the column and
# its mirror image, three fields; sample 2's 16 x 16 x 480 took 47 MB with its 20 000 parcels), so
# 2^22 cells take some 1.3 GB, and sample 3's 16 x 16 x 3072 is a fifth of it.
MAX_FLOW_CELLS = 2**22
FLOW_BYTES_PER_CELL = 300
FLOW_COURANT = 0.5
FLOW_PEAK = 4.5
# The swirls outlast the grains that drive them: no stage's step is more than twice the last's, as the
# settling schedule's. Sample 2 without that limit: the step went from 0.052 to 0.47 s at 185 s while
# the grid's largest velocity was still 1.6 mm/s (0.8 allowed), and the next steps carried the parcels
# 19 cells.


@dataclass
class Scene:
    """Everything `write` needs; built by `plan`."""

    psd: PSD
    classes: SizeClasses
    suspension: Suspension
    cylinder: Cylinder
    geometry: str
    width: float                    # column: side of the square section; slab: across the cylinder
    thickness: float                # out of plane: the column side, or the slab thickness
    mass: float                     # whole sample [kg]
    effects: Effects
    layers: int
    t_end: float
    courant: float
    seed: int
    # diameters [m] splitting the layers into size classes (the grid's `classes`): the layer file then
    # holds each class's fraction too, as the inverse model reads them
    tag_classes: tuple[float, ...] = ()
    # whether grains land on a floor and build a deposit there (the test's column); False for a triply
    # periodic box, where grains meet only each other (the reduced scene of --measure-contacts)
    floor: bool = True
    # the water's temperature over the test, (time [s], temperature [C]) pairs, linear between them:
    # the run re-issues the fluid at each frame where it has moved by more than DRIFT_STEP since the
    # last (a laboratory's day); empty: the suspension's water throughout
    water_record: tuple[tuple[float, float], ...] = ()
    # two-way coupling: fix fluid/flow's cells across the column (flow_grid), and those whose flow sets the
    # steps (None: the same; a grid check runs on its measurement's steps, as the one-way twin it shares)
    flow_cells: int = FLOW_CELLS_ACROSS
    flow_step_cells: int | None = None
    diameter: np.ndarray = field(default_factory=lambda: np.empty(0))    # per atom [m]
    weight: np.ndarray = field(default_factory=lambda: np.empty(0))
    position: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))

    @property
    def height(self) -> float:
        """Suspension height [m]."""
        return self.cylinder.height

    @property
    def parcels(self) -> bool:
        """Whether some atom stands for several real grains (a weight other than 1)."""
        return not np.all(self.weight == 1)

    @property
    def dimension(self) -> int:
        """2 for the slab, 3 for the column."""
        return 2 if self.geometry == "slab" else 3

    @property
    def volume(self) -> float:
        """Volume of the simulated sub-volume [m3]."""
        return self.width * self.thickness * self.height

    @property
    def volume_fraction(self) -> float:
        """Share of the cylinder the sub-volume stands for."""
        return self.volume / (self.cylinder.area * self.cylinder.height)

    @property
    def initial_concentration(self) -> float:
        """Solids per volume of suspension [kg/m3]."""
        return self.mass / (self.cylinder.area * self.cylinder.height)

    def stages(self) -> list[tuple[float, int]]:
        """(time step, steps) per stage up to t_end. Until the largest grains can have left the
        column (H / v_max) the step is courant layers / v_max; after a time t only grains slower
        than H / t can remain, so each following stage, as long as the time before it, takes a step
        twice the last. Stages are whole numbers of frames; the last one's step is shortened so that
        the run ends at t_end, not up to a stage of frames beyond it."""
        if self.effects.interacting:                  # contacts set the step everywhere
            dt = self.contact_time_step()
            return [(dt, math.ceil(self.t_end / dt))]
        if self.effects.flow:
            return self._flow_stages(self._settling_stages())
        return self._settling_stages()

    def _settling_stages(self) -> list[tuple[float, int]]:
        every = self.frame_steps()
        steps = FRAMES_PER_STAGE * every
        v_max = self.largest_terminal_speed()
        time, dt, result = 0.0, self.height / v_max / steps, []
        while time < self.t_end * (1 - 1e-12):
            n = min(steps, every * math.ceil((self.t_end - time) / (dt * every)))
            if time + n * dt > self.t_end:
                dt = (self.t_end - time) / n
            result.append((dt, n))
            time += n * dt
            if time >= self.height / v_max * (1 - 1e-12):
                dt = time / steps
        return result

    def _flow_stages(self, stages: list[tuple[float, int]]) -> list[tuple[float, int]]:
        """Each stage of the settling steps again, in as many steps as keep the flow the grains still
        falling at its start drive to FLOW_COURANT cells a step (flow_time_step), at most twice the last
        stage's step: the same stage ends, a whole number of frames."""
        out, time, every, last = [], 0.0, self.frame_steps(), math.inf
        for dt, steps in stages:
            limit = min(self.flow_time_step(time), 2 * last)
            n = steps if dt <= limit else every * math.ceil(steps * dt / limit / every)
            last = dt * steps / n
            out.append((last, n))
            time += dt * steps
        return out

    def flow_grid(self, cells: int | None = None) -> tuple[int, int]:
        """Cells of fix fluid/flow's grid across the column and along its height: cubic cells,
        flow_cells (or `cells`) across (a width `plan` makes a whole number of them up the height)."""
        across = cells or self.flow_cells
        return across, round(self.height * across / self.width)

    def flow_speed(self, time: float = 0.0, cells: int | None = None) -> float:
        """Root mean square of the fluid velocity [m/s] that the grains placed independently drive on the
        flow's grid, from those still falling at `time` (each class's share of the column its terminal
        speed has not yet cleared): each parcel stirs the fluid with sqrt(w S(0)) grains' buoyant weight,
        so the force density's fluctuation has the spectrum n <F^2> on every wave k, and the Stokes flow
        of a wave is (I - k k / k^2) f / (mu k^2), read through the kernel (a Gaussian of one cell) on
        both sides. The column is taken periodic in z: in sample 2's column the parcels read 1.06 times
        this after two steps, in a column of 12 cm, whose mirror images weigh more, 1.4 times. On a grid
        of `cells` across if given."""
        f, c = self.suspension, self.classes
        across, up = self.flow_grid(cells)
        cell = self.width / across
        speed = np.array([terminal_speed(f, d, self.effects.drag) for d in c.diameter])
        falling = c.count * np.clip(1 - speed * time / self.height, 0, 1)
        if not falling.any():
            return 0.0
        structure = _core.hard_sphere_structure_factor(self.volume_fraction_of_solids)
        noise = np.sum(falling * c.weight * structure * f.buoyant_weight(c.diameter) ** 2) / self.volume
        k = [2 * np.pi * np.fft.fftfreq(n, cell) for n in (across, across, up)]
        kx, ky, kz = np.meshgrid(*k, indexing="ij")
        k2 = kx ** 2 + ky ** 2 + kz ** 2
        k2[0, 0, 0] = np.inf
        kernel = np.exp(-k2 * cell ** 2)              # exp(-k^2 sigma^2 / 2) on each side
        variance = noise * np.sum((1 - kz ** 2 / k2) * kernel ** 2 / (f.viscosity ** 2 * k2 ** 2)) / self.volume
        return float(math.sqrt(variance))

    def flow_time_step(self, time: float = 0.0) -> float:
        """The longest step [s] at which the grid's largest velocity (FLOW_PEAK times flow_speed) carries
        a parcel FLOW_COURANT cells: past a cell a step the flow cannot follow the density it is solved
        from (fix fluid/flow's doc page, Stability); on the grid of flow_step_cells if set."""
        cells = self.flow_step_cells or self.flow_cells
        speed = self.flow_speed(time, cells)
        cell = self.width / cells
        return math.inf if speed == 0 else FLOW_COURANT * cell / (FLOW_PEAK * speed)

    @property
    def volume_fraction_of_solids(self) -> float:
        """The suspension's initial solid fraction."""
        return self.initial_concentration / self.suspension.particle_density

    def frame_steps(self) -> int:
        """Steps between layer frames: FRAMES_PER_STAGE frames per stage."""
        if self.effects.interacting:
            return max(1, math.ceil(self.t_end / self.contact_time_step() / 400))
        return max(1, math.ceil(self.layers / self.courant / FRAMES_PER_STAGE))

    def largest_terminal_speed(self) -> float:
        """Terminal speed of the largest grain present under the scene's drag law [m/s]."""
        return terminal_speed(self.suspension, self.classes.diameter[self.classes.count > 0].max(), self.effects.drag)

    def contact_modulus(self) -> float:
        """Young's modulus of the grains' contacts [Pa]: with a floor, `contact_modulus` for the fastest
        grain at its terminal speed and the whole deposit's buoyant weight (docs/effects.md section 5);
        without one, `meeting_modulus` for the grains' meetings in suspension. The largest overlap is
        measured during the run (compute contact/overlap) and the run stops at twice the tolerance."""
        f = self.suspension
        if not self.floor:
            present = self.classes.diameter[self.classes.count > 0]
            modulus = meeting_modulus(f, present, np.array([terminal_speed(f, d, self.effects.drag) for d in present]))
            if not modulus > 0:
                raise ValueError(f"the grains of this box ({present.min() * 1e6:.4g} um) settle at one speed and never "
                                 "meet: there are no contacts to resolve")
            return modulus
        pressure = self.initial_concentration * self.height * (1 - f.fluid_density / f.particle_density) * f.gravity
        return contact_modulus(f.particle_density, self.largest_terminal_speed(), pressure)

    def contact_time_step(self) -> float:
        """A fifth of the Rayleigh time of the smallest grain at the contact modulus."""
        radius = 0.5 * self.classes.diameter[self.classes.count > 0].min()
        return 0.2 * _core.rayleigh_time(radius, self.suspension.particle_density, self.contact_modulus(),
                                         POISSON_RATIO)

    def simulated_psd(self) -> PSD:
        """The PSD the scene's particles stand for."""
        return self.classes.simulated_psd()


FRAMES_PER_STAGE = 20
MAX_PARTICLES = 10_000_000
POISSON_RATIO = 0.3
OVERLAP_TOLERANCE = 0.01    # largest contact overlap / diameter the soft contacts are made for
# Steps between restart files at least. Rank 0 writes one in about 7 ms for 10 000 parcels (Output
# 0.015-0.017 s with the main job's two, 0.001 s without, benchmarks/planner.py --scaling), as long
# as some 16 of its 0.43 ms steps, and both scale with the parcels: 2000 apart keeps them under 1 %
# of a run's steps (a twentieth of a run is more past 40 000 steps). A run shorter than that writes
# none, and a killed one starts again from the beginning.
RESTART_SPACING = 2000
# LAMMPS sorts the atoms (in memory, layer by layer) every SORT_EVERY steps and at each run's start: a
# restart file at another step gives the resumed run another order of its atoms, whose sums (the
# flow's, the grid's) then differ by round-off, which a two-way column's flow grows (by 1.4 in a
# fraction within 3000 steps). Restart files come at multiples of it (RESTART_SPACING is one).
SORT_EVERY = 1000
# The most loaded contact of a settled bed carries more than the deposit's mean pressure on one grain's
# cross-section (floor contacts lie farther apart than a diameter, and force chains): 2.2 times it in
# the overdamped bed of benchmarks/contact_step.py (settled overlap 1.70 % under the mean load).
LOAD_CONCENTRATION = 3.0


def contact_modulus(particle_density: float, fastest_speed: float, deposit_pressure: float) -> float:
    """Young's modulus [Pa] of the softest Hertz contact keeping the overlap within OVERLAP_TOLERANCE of
    the diameter both when a grain lands on the floor at `fastest_speed` (undamped impact) and under
    LOAD_CONCENTRATION times the buoyant weight of the deposit per area, `deposit_pressure` [Pa],
    pressing one grain's cross-section (static Hertz contact)."""
    impact = _core.hertz_modulus_for_overlap("wall", particle_density, fastest_speed, OVERLAP_TOLERANCE,
                                             POISSON_RATIO)
    load = _core.hertz_modulus_for_load(LOAD_CONCENTRATION * deposit_pressure, OVERLAP_TOLERANCE, POISSON_RATIO)
    return max(impact, load)


def meeting_modulus(suspension: Suspension, diameter: np.ndarray, speed: np.ndarray) -> float:
    """Young's modulus [Pa] of the softest Hertz contact keeping the overlap within OVERLAP_TOLERANCE of
    the smaller diameter where grains settling at their terminal speeds `speed` meet, with no floor and
    no deposit (a triply periodic suspension), for every pair of sizes d_s and d_b = b d_s, b >= 1:
    - head on at the difference of their speeds: as much, relative to d_s, as a grain landing on a
      wall at that speed with its mass over the square root of its radius scaled by
      b^3 / (1 + b^3) sqrt((1 + b) / b), the ratio for the pair's reduced mass and radius (0.71 for
      equal grains, at most 1.11 near b = 3);
    - the larger riding on the smaller, the two falling together at the speed where their drags carry
      both weights (each drag taken linear in the speed, W v / v_t: exact in Stokes' regime), which
      leaves the larger pressing with F = W_b (1 - v_c / v_b): as much as the smaller pressed on a wall
      by F, with the pair's radius, sqrt((1 + b) / b) times stiffer."""
    order = np.argsort(diameter)
    d, v = np.asarray(diameter, float)[order], np.asarray(speed, float)[order]
    small, large = np.triu_indices(len(d))
    ratio = d[large] / d[small]
    f = suspension
    wall_per_speed2 = _core.hertz_modulus_for_overlap("wall", f.particle_density, 1.0, OVERLAP_TOLERANCE, POISSON_RATIO)
    impact = wall_per_speed2 * (v[large] - v[small]) ** 2 * ratio ** 3 / (1 + ratio ** 3) * np.sqrt((1 + ratio) / ratio)
    weight = f.buoyant_weight(d)
    together = (weight[large] + weight[small]) / (weight[large] / v[large] + weight[small] / v[small])
    pressing = np.abs(weight[large] * (1 - together / v[large]))    # rising grains (lighter than the fluid) push up
    wall_per_pressure = _core.hertz_modulus_for_load(1.0, OVERLAP_TOLERANCE, POISSON_RATIO)
    riding = wall_per_pressure * pressing / d[small] ** 2 * np.sqrt((1 + ratio) / ratio)
    return float(max(impact.max(), riding.max()))


COLUMN_DIAMETERS = 20    # a column is at least this many of its largest grains tall


def swirl_length(psd: PSD, solids: float) -> float:
    """Segre et al.'s correlation length of the swirls, SWIRL_LENGTH a phi^-1/3 [m], for the mass-mean
    radius a of the sample and its solid fraction."""
    lo, hi = psd.span()
    diameter, share = log_classes(psd, lo, hi, 120)
    radius = 0.5 * float(share @ diameter / share.sum())
    return SWIRL_LENGTH * radius * solids ** (-1 / 3)


def plan(psd: PSD, *, geometry: str = "column", cylinder: Cylinder = Cylinder(), mass: float = SPECIMEN_MASS,
         suspension: Suspension = Suspension(), width: float | None = None, classes: int | np.ndarray = 40,
         particles: int | None = 20000, effects: Effects = Effects(), layers: int = 400, t_end: float = 86400.0,
         courant: float = 4.0, seed: int = 1, flow_cells: int = FLOW_CELLS_ACROSS) -> Scene:
    """The scene of a test: sub-volume, classes, particles and their placement.

    Parameters
    ----------
    psd : PSD
        The sample's distribution.
    geometry : {"column", "slab"}
        3D periodic column, or Bravo et al.'s 2D slab of the axial section.
    cylinder : Cylinder
        Cross-section and suspension height.
    mass : float
        Dry sample mass [kg].
    suspension : Suspension
        Water and solids.
    width : float, optional
        Column side or slab width [m]; default two largest diameters (the slab: the cylinder).
    classes : int or array
        Size classes (Bravo et al. eq. 15) spanning the PSD, or their bounds [m].
    particles : int or None
        Equal-mass parcels to simulate (compute concentration/grid weight); None: real grains at the
        real concentration of the sub-volume (required with contacts or lubrication).
    effects : Effects
        Drag law and the effects on request.
    layers : int
        Layers of the concentration grid.
    t_end : float
        Simulated time [s].
    courant : float
        Layers the fastest grain in suspension may cross per step (4: within 0.25 points of percent
        finer of 1 for the five samples of docs/effects.md).
    seed : int
        Placement seed.
    flow_cells : int
        With effects.flow: fix fluid/flow's cubic cells across the column, a size the FFTs take (default
        16; docs/effects.md section 3 measures what 8 to 24 change).

    Returns
    -------
    Scene
    """
    if geometry not in GEOMETRIES:
        raise ValueError(f"geometry must be one of {', '.join(GEOMETRIES)}, not '{geometry}'")
    if effects.interacting and particles is not None:
        raise ValueError("contacts and lubrication need real grains: use --real-grains (no parcels)")
    if not (mass > 0 and layers >= 10 and t_end > 0 and courant > 0):
        raise ValueError("mass and end time must be > 0, layers >= 10, courant > 0")
    if not suspension.particle_density > suspension.fluid_density:
        raise ValueError(f"grains of {suspension.particle_density:g} kg/m3 do not settle in water of "
                         f"{suspension.fluid_density:g} kg/m3")
    d_largest = psd.span()[1]
    if cylinder.height < COLUMN_DIAMETERS * d_largest:
        raise ValueError(f"a column of {cylinder.height:g} m is not tall enough for grains of {d_largest * 1e6:.3g} um "
                         f"(at least {COLUMN_DIAMETERS} diameters)")
    solids = mass / (cylinder.area * cylinder.height) / suspension.particle_density
    if solids >= 0.5:
        raise ValueError(f"{mass:g} kg of solids would fill {solids:.0%} of the {cylinder.area * cylinder.height * 1e3:.3g} L "
                         "suspension: a sedimentation test holds a few percent (50-60 g in 1 L)")
    d_max = psd.span()[1]
    if effects.flow:
        if geometry != "column" or effects.interacting:
            raise ValueError("two-way coupling is simulated in a column of parcels or grains without contacts "
                             "(--geometry column, no --contacts or --lubrication)")
        swirl = FLOW_SWIRLS * swirl_length(psd, solids)
        width = swirl if width is None else width
        if not (flow_cells >= 4 and (flow_cells > MAX_FLOW_CELLS or _core.fft_friendly(flow_cells))):
            raise ValueError(f"the flow's grid needs 4 or more cells across, a product of 2, 3 and 5 (the sizes "
                             f"LAMMPS's FFTs take), not {flow_cells}")
        # cubic cells, flow_cells across, a whole number up the height that the FFTs take
        up = math.ceil(cylinder.height * flow_cells / width)
        if flow_cells ** 2 * up > MAX_FLOW_CELLS:
            cells = flow_cells ** 2 * up
            raise ValueError(f"fix fluid/flow's grid would be {flow_cells} x {flow_cells} x {up} cells ({cells:.3g}, "
                             f"about {cells * FLOW_BYTES_PER_CELL / 1e9:.2g} GB), beyond {MAX_FLOW_CELLS:.3g}: this "
                             f"PSD's swirls make a column {width * 1e3:.3g} mm wide, {cylinder.height / width:.3g} "
                             "times as tall; take fewer --flow-cells or a shorter --height")
        while not _core.fft_friendly(up):
            up += 1
        width = cylinder.height * flow_cells / up
    if geometry == "slab":
        width = cylinder.diameter if width is None else width
        thickness = d_max
    else:
        width = 2 * d_max if width is None else width
        thickness = width
    if not 0 < width <= (cylinder.diameter if geometry == "slab" else math.sqrt(cylinder.area)):
        raise ValueError(f"sub-volume width {width:g} m does not fit the cylinder ({cylinder.diameter:g} m across)")
    fraction = width * thickness / cylinder.area
    size_classes = discretise(psd, classes, mass, suspension.particle_density, fraction, particles)
    if size_classes.count.sum() > MAX_PARTICLES:
        raise ValueError(f"{size_classes.count.sum():.3g} real grains in this sub-volume (more than {MAX_PARTICLES:.0e}): "
                         "simulate parcels (--particles) or a smaller sub-volume (--width, --height)")
    scene = Scene(psd, size_classes, suspension, cylinder, geometry, width, thickness, mass, effects, layers, t_end,
                  courant, seed, flow_cells=flow_cells)
    _check_runnable(scene)
    place(scene)
    return scene


LAMMPS_MAX_STEPS = 2**31 - 1    # LAMMPS's largest run (and restart or thermo interval), in steps


def _check_runnable(scene: Scene) -> None:
    """Refuses a scene whose deck LAMMPS cannot run: a stage or an interval beyond its step limit."""
    every = scene.frame_steps()
    stages = scene.stages() if every <= LAMMPS_MAX_STEPS else [(0.0, every)]
    longest = max(max(n for _, n in stages), every)
    if longest <= LAMMPS_MAX_STEPS:
        return
    if scene.effects.interacting:
        fix = (f"contacts set a step of {scene.contact_time_step():.3g} s (a fifth of the smallest grain's Rayleigh "
               "time): shorten --t-end, or measure what contacts change with `sediment plan --measure-contacts` (a "
               "reduced scene)")
    else:
        fix = f"--courant {scene.courant:g} is far too small: raise it (the default is 4)"
    raise ValueError(f"this scene needs {longest:.3g} steps in one run, beyond LAMMPS's {LAMMPS_MAX_STEPS} (and "
                     f"beyond any computer's time): {fix}")
