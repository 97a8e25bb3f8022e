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
import os
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from .. import _core
from ..constants import (BRAVO_CYLINDER_HEIGHT, BRAVO_CYLINDER_WIDTH, D422_CYLINDER_AREA, D422_CYLINDER_HEIGHT,
                         DRAGS, HINDRANCES)
from ..lab.psd import PSD, SizeClasses, discretise
from ..lab.readout import Suspension
from ..results import write_text

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
        if self.drag == "difelice":
            return "difelice (Dallavalle's curve hindered by Di Felice, Bravo et al.)"
        return self.drag + (f", hindered ({self.hindrance})" if self.hindered else ", unhindered")

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
    diameter: np.ndarray = field(default_factory=lambda: np.empty(0))    # per atom [m]
    weight: np.ndarray = field(default_factory=lambda: np.empty(0))
    position: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))

    @property
    def height(self) -> float:
        """Suspension height [m]."""
        return self.cylinder.height

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


def terminal_speed(suspension: Suspension, diameter: float, law: str) -> float:
    """Terminal speed [m/s] of a lone grain of `diameter` under `law` in the suspension's fluid."""
    drag_law = "dallavalle" if law == "difelice" else law    # Di Felice alone is Dallavalle's C_d
    speed, _ = _core.terminal_velocity(drag_law, suspension.fluid_density, suspension.viscosity, 0.0, float(diameter),
                                       suspension.particle_density, suspension.gravity)
    return speed


COLUMN_DIAMETERS = 20    # a column is at least this many of its largest grains tall


def plan(psd: PSD, *, geometry: str = "column", cylinder: Cylinder = Cylinder(), mass: float = 0.060,
         suspension: Suspension = Suspension(), width: float | None = None, classes: int | np.ndarray = 40,
         particles: int | None = 20000, effects: Effects = Effects(), layers: int = 400, t_end: float = 86400.0,
         courant: float = 4.0, seed: int = 1) -> Scene:
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
                  courant, seed)
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


def place(scene: Scene) -> None:
    """Stratified random placement: each class's particles get distinct cells of a grid of about
    cubic cells (as many as the particles) over the sub-volume, one at a random point of each, so
    every class starts uniform at every scale above its spacing. Centres stay one radius inside the
    column. With contacts, overlapping grains are redrawn (see _separate)."""
    rng = np.random.default_rng(scene.seed)
    lateral = 1 if scene.geometry == "slab" else 2
    diameters, weights, positions = [], [], []
    for d, n, w in zip(scene.classes.diameter, scene.classes.count, scene.classes.weight):
        if n == 0:
            continue
        cells = _stratify(rng, int(n), scene.width, scene.height - d, lateral)
        lo = np.array([0.0, 0.0, 0.5 * d])
        positions.append(lo + cells)
        diameters.append(np.full(n, d))
        weights.append(np.full(n, w))
    scene.diameter = np.concatenate(diameters)
    scene.weight = np.concatenate(weights)
    scene.position = np.concatenate(positions)
    if scene.geometry == "slab":                       # (x, 0, height) -> (x, height, 0) in LAMMPS 2d
        scene.position = scene.position[:, [0, 2, 1]]
    if scene.effects.interacting:
        _separate(scene, rng)


def _stratify(rng: np.random.Generator, n: int, width: float, height: float, lateral: int) -> np.ndarray:
    """n points, one in each of n distinct cells of a grid over [0, width]^lateral x [0, height]."""
    side = (width ** lateral * height / n) ** (1 / (lateral + 1))
    across = max(1, round(width / side))
    rows = math.ceil(n / across ** lateral)
    chosen = rng.choice(across ** lateral * rows, size=n, replace=False)
    index = [chosen % across, (chosen // across) % across if lateral == 2 else np.zeros(n, int),
             chosen // across ** lateral]
    sizes = [width / across, width / across if lateral == 2 else 0.0, height / rows]
    return np.column_stack([(index[k] + rng.random(n)) * sizes[k] for k in range(3)])


def _separate(scene: Scene, rng: np.random.Generator, attempts: int = 200) -> None:
    """Redraws overlapping grains (the smaller of each pair) anywhere in the sub-volume until none overlap."""
    from scipy.spatial import cKDTree

    radius = 0.5 * scene.diameter
    vertical = 1 if scene.geometry == "slab" else 2
    periodic = [scene.width, scene.thickness, 4 * scene.height]     # vertical: never wraps
    if scene.geometry == "slab":
        periodic = [scene.width, 4 * scene.height, scene.thickness]
    for _ in range(attempts):
        points = scene.position.copy()
        points[:, vertical] += scene.height    # keep inside [0, boxsize)
        points[:, 0] %= scene.width
        if scene.geometry == "column":
            points[:, 1] %= scene.width
        tree = cKDTree(points, boxsize=periodic)
        pairs = tree.query_pairs(2 * radius.max(), output_type="ndarray")
        if len(pairs):
            gap = np.linalg.norm(_periodic_delta(points[pairs[:, 0]] - points[pairs[:, 1]], periodic), axis=1)
            pairs = pairs[gap < radius[pairs[:, 0]] + radius[pairs[:, 1]]]
        if not len(pairs):
            return
        move = np.unique(np.where(radius[pairs[:, 0]] <= radius[pairs[:, 1]], pairs[:, 0], pairs[:, 1]))
        scene.position[move, 0] = rng.random(len(move)) * scene.width
        if scene.geometry == "column":
            scene.position[move, 1] = rng.random(len(move)) * scene.width
        scene.position[move, vertical] = radius[move] + rng.random(len(move)) * (scene.height - 2 * radius[move])
    raise ValueError("could not place the grains without overlaps: the sub-volume is too crowded")


def _periodic_delta(delta: np.ndarray, box: list[float]) -> np.ndarray:
    box = np.asarray(box)
    return delta - box * np.rint(delta / box)


SAMPLE_FILES = ("sample.data", "in.sedimentation", "input_psd.csv", "simulated_psd.csv", "classes.csv")


def write(scene: Scene, out: Path, layer_file: str = "layers.h5", force: bool = False) -> list[Path]:
    """Writes the scene: data file, deck and PSD tables, together (under the folder's lock, staged and
    then moved into place).

    Parameters
    ----------
    scene : Scene
        From `plan`.
    out : Path
        Output folder (created).
    layer_file : str
        Name of the layer file the deck writes.
    force : bool
        Delete the files of a run in `out` whose inputs this scene changes (its layer file, restart
        files, logs), instead of refusing.

    Returns
    -------
    list of Path
        The files written.
    """
    import shutil

    from ..folders import folder_lock

    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} exists and is not a folder")
    with folder_lock(out, "sample"):
        stage = out / f".sample.{os.getpid()}"
        shutil.rmtree(stage, ignore_errors=True)
        stage.mkdir()
        try:
            _write_files(scene, [stage / n for n in SAMPLE_FILES], layer_file)
            for name in runs_replaced(out, stage / "in.sedimentation", layer_file, force):
                (out / name).unlink()
            for name in SAMPLE_FILES:
                os.replace(stage / name, out / name)
        finally:
            shutil.rmtree(stage, ignore_errors=True)
    return [out / n for n in SAMPLE_FILES]


def runs_replaced(out: Path, deck: Path, layer_file: str = "layers.h5", force: bool = False) -> list[str]:
    """The files of a run in `out` (layer file, restart files, logs) that a new `deck` of another scene
    makes stale, to delete with `force`; ValueError naming them without it. A run read the deck and
    data file in place: new ones would leave its frames beside the tables of another test."""
    from .run import RUN_OUTPUTS, inputs_id

    results = [p.name for p in (out / layer_file, out / (layer_file + ".partial"), *(out / n for n in RUN_OUTPUTS))
               if p.exists()]
    here = out / "in.sedimentation"
    if not results or (here.is_file() and inputs_id(here) == inputs_id(deck)):
        return []
    if not force:
        raise ValueError(f"{out} holds a run of another scene ({', '.join(results)}): its frames would stand beside "
                         "tables of this one; sample into another --out, or give --force to delete that run's files")
    return results


def _write_files(scene: Scene, paths: list[Path], layer_file: str) -> None:
    """sample.data, in.sedimentation, input_psd.csv, simulated_psd.csv and classes.csv, at `paths`."""
    write_data(scene, paths[0])
    write_text(paths[1], _deck(scene, paths[0].name, layer_file))
    _write_psd(scene.psd, paths[2])
    _write_psd(scene.simulated_psd(), paths[3])
    c = scene.classes
    write_text(paths[4], "diameter_um,input_mass_fraction,simulated_mass_fraction,particles,weight\n" + "".join(
        f"{d * 1e6:.6g},{m:.6g},{s:.6g},{n},{w:.6g}\n"
        for d, m, s, n, w in zip(c.diameter, c.mass_fraction, c.simulated_mass_fraction(), c.count, c.weight)))


def _write_psd(psd: PSD, path: Path) -> None:
    """The table as read_psd reads it: 12 digits, or 17 where 12 would merge two diameters."""
    diameter = psd.diameter * 1e6
    digits = 12 if len(np.unique([f"{d:.12g}" for d in diameter])) == len(diameter) else 17
    write_text(path, "diameter_um,percent_finer\n" + "".join(
        f"{d:.{digits}g},{p:.12g}\n" for d, p in zip(diameter, psd.percent_finer)))


def write_data(scene: Scene, path: Path) -> None:
    """The scene's LAMMPS data file: one atom type, diameters, density, positions and the Weights section."""
    lo, hi = scene_box(scene)
    n = len(scene.diameter)
    lines = [f"SEDIMENT sedimentation test: {n} grains ({scene.geometry})", "",
             f"{n} atoms", "1 atom types", ""]
    lines += [f"{lo[k]:.17g} {hi[k]:.17g} {a}lo {a}hi" for k, a in enumerate("xyz")]
    lines += ["", "Atoms # sphere", ""]
    rho = scene.suspension.particle_density
    lines += [f"{i + 1} 1 {d:.17g} {rho:.17g} {x:.17g} {y:.17g} {z:.17g}"
              for i, (d, (x, y, z)) in enumerate(zip(scene.diameter, scene.position))]
    lines += ["", "Weights", ""]
    lines += [f"{i + 1} {w:.17g}" for i, w in enumerate(scene.weight)]
    write_text(path, "\n".join(lines) + "\n")


def scene_box(scene: Scene) -> tuple[list[float], list[float]]:
    """The simulation box (lo, hi per axis) of the scene."""
    if scene.geometry == "slab":
        return [0.0, 0.0, -0.5 * scene.thickness], [scene.width, scene.height, 0.5 * scene.thickness]
    return [0.0, 0.0, 0.0], [scene.width, scene.width, scene.height]


def _deck(scene: Scene, data: str, layer_file: str) -> str:
    e, f = scene.effects, scene.suspension
    slab = scene.geometry == "slab"
    up = "y" if slab else "z"
    gravity = "0 -1 0" if slab else "0 0 -1"
    d_max = float(scene.diameter.max())
    stages = scene.stages()
    frames_every = scene.frame_steps()
    segments = _segments(scene, stages, frames_every)
    total_steps = sum(n for _, n in stages)
    c = scene.classes
    when = datetime.now(timezone.utc).strftime("%Y-%m-%d")
    lines = [
        f"# Sedimentation test written by `sediment sample` ({when}): {scene.psd.name or 'PSD'}",
        f"# {scene.geometry} {scene.width:.4g} x {scene.thickness:.4g} x {scene.height:.4g} m of a cylinder of "
        f"{scene.cylinder.area * 1e4:.4g} cm2 x {scene.cylinder.height:.4g} m (fraction {scene.volume_fraction:.3g}),",
        f"# {len(scene.diameter)} atoms in {int(np.sum(c.count > 0))} size classes standing for {c.represented_grains():.4g} grains "
        f"({scene.mass * 1e3:.4g} g sample, c0 = {scene.initial_concentration:.4g} kg/m3).",
        f"# Water at {f.temperature_text() if not scene.water_record else _record_text(scene.water_record)}; "
        f"effects: drag ({e.describe()}), buoyancy"
        f"{', contacts' if e.contacts or e.lubrication else ', deposit on the floor (no contacts)'}"
        f"{', lubrication' if e.lubrication else ''}.",
        f"# {len(stages)} stages, {total_steps} steps to {scene.t_end:g} s; layer frames every {frames_every} steps.",
        "#",
        "#   sediment run in.sedimentation        (or: lmp_sediment -in in.sedimentation)",
        "#   sediment run --resume in.sedimentation   continues a killed run from its last restart file",
        f"variable        layers_file index {layer_file}",
        "variable        overwrite index no    # yes: replace a layer file of another run (sediment run --force)",
        f"variable        t_end equal {scene.t_end:.12g}",
        "variable        dt_scale index 1    # multiplies every stage's time step (sediment sweep ... --parameter dt_scale)",
        "variable        field_every index 1    # steps between refreshes of the concentration field the hindered drag reads",
        "variable        resume index no     # yes: start from ${restart_file} (sediment run --resume)",
        "variable        restart_file index restart.a.bin",
        "variable        timing index no     # yes: LAMMPS's timing breakdown after each stage (where the time goes)",
        "",
    ]
    if not e.interacting:    # set before the box (and before read_restart), so in both branches below
        lines.append("newton          off    # no pair forces: no forces on ghosts to send back each step")
    lines += [
        "# The weights (real grains each atom stands for) come from the data file, or back from the restart file.",
        'if "${resume} == yes" then "read_restart ${restart_file}" "fix weights all property/atom d_weight" else &',
        '  "units si" "dimension ' + str(scene.dimension) + '" "atom_style sphere" "boundary ' + ('p f p' if slab else 'p p f')
        + '" "processors ' + ('* 1 1' if slab else '* * 1') + '" "fix weights all property/atom d_weight" &',
        f'  "read_data {data} fix weights NULL Weights"',
        f"# ranks side by side ({'* 1 1' if slab else '* * 1'}): each keeps its share of the grains as they settle",
        f"neighbor        {d_max:.6g} bin",
        f"atom_modify     sort 1000 {scene.height / scene.layers:.6g}    # neighbours in memory, layer by layer",
    ]
    if e.interacting:    # pair forces need ghosts within a contact or film reach and the skin, as LAMMPS finds them
        lines.append("comm_modify     vel yes")
    else:                # no pair forces, no ghosts needed: a cutoff far below any grain copies none
        # (each ghost is sent to the next rank every step) and keeps LAMMPS from warning of a zero one
        lines.append(f"comm_modify     cutoff {1e-9 * min(scene.width, scene.thickness):.6g}")
    lines += [
        "",
        f"fix             grav all gravity {f.gravity:.12g} vector {gravity}",
        _fluid_line(segments[0][2] or f),    # the record's first water, if any: the layer file keeps it
        f"compute         conc all concentration/grid layers {up} {scene.layers} bounds 0 {scene.height:.12g}"
        f"{f' thickness {scene.thickness:.12g}' if slab else ''} weight d_weight every ${{field_every}}"
        + (" classes " + " ".join(f"{d:.12g}" for d in scene.tag_classes) if scene.tag_classes else ""),
        "fix             buoy all fluid/buoyancy water"
        + (f" mixture c_conc {f.particle_density:.12g}" if e.buoyancy == "mixture" else ""),
    ]
    lines.append(f"fix             drag all fluid/drag water {e.fix_arguments()}")
    if e.interacting:
        lines += pair_lines(scene)
        lines += [f"fix             floor all wall/gran granular {contact_model(scene)} {up}plane 0 NULL",
                  "fix             step all nve/sphere/fluid",
                  "# Soft contacts, made for overlaps up to "
                  f"{OVERLAP_TOLERANCE:.0%} of a diameter: the largest is reported, and twice that stops the run.",
                  "compute         overlap all contact/overlap",
                  "variable        overlap equal c_overlap",
                  f"fix             overlap_guard all halt 100 v_overlap > {2 * OVERLAP_TOLERANCE:g} error hard message yes"]
    else:
        lines.append(f"fix             step all nve/sphere/fluid floor {up} 0.0")
    lines += [
        f"fix             layers all layers/hdf5 $(round({frames_every}/v_dt_scale)+(round({frames_every}/v_dt_scale)<1)) "
        f"${{layers_file}} c_conc fluid water particle_density {f.particle_density:.12g} overwrite ${{overwrite}} &",
        "                end_time ${t_end}    # complete only when the frames reach the end of the test",
        "",
        "thermo_style    custom step time dt f_layers" + (" c_overlap" if e.interacting else ""),
        f"thermo          {frames_every * 5}",
        "thermo_modify   norm no flush yes    # each row at once: the progress bar follows them",
        f'print           "SEDIMENT plan steps $(ceil({total_steps}/v_dt_scale)) t_end {scene.t_end:.12g}"',
        "# Two restart files in turn (one is always complete); each stage runs up to its last step, so a",
        "# resumed run skips the stages it has done and finishes the one it was in. One every twentieth of",
        f"# the run, and {RESTART_SPACING} steps apart at least: rank 0 writes each one, in several steps' time.",
        # max(a, b) written out: LAMMPS formulas have no two-argument max (its max() reduces a compute).
        f"variable        restart_every equal ceil({total_steps}/20/v_dt_scale)",
        f"restart         $(v_restart_every+(v_restart_every<{RESTART_SPACING})*({RESTART_SPACING}-v_restart_every)) "
        "restart.a.bin restart.b.bin",
        "variable        stage_end equal 0",
    ]
    for dt, steps, water, first in segments:
        # the time step set once per stage: LAMMPS adds up the time at each change, and the parts of a
        # stage then end on the same times as the whole stage would
        commands = ([f'"{_fluid_line(water)}"'] if water is not None else []) \
            + ([f'"timestep $({dt:.17g}*v_dt_scale)"'] if first else []) + ['"run ${stage_end} upto post ${timing}"']
        lines += [f"variable        stage_end equal $(v_stage_end+ceil({steps}/v_dt_scale))",
                  f'if "$(step) < ${{stage_end}}" then {" ".join(commands)}']
    return "\n".join(lines) + "\n"


DRIFT_STEP = 0.05    # C: the water's record is followed in steps of this


def _record_text(record: tuple[tuple[float, float], ...]) -> str:
    temperatures = [t for _, t in record]
    return (f"{min(temperatures):g}-{max(temperatures):g} C as its record over {record[-1][0] / 3600:.3g} h goes (the fluid "
            f"re-issued as it moves by {DRIFT_STEP:g} C)")


def _fluid_line(water: Suspension) -> str:
    return f"fix             water all fluid density {water.fluid_density:.12g} viscosity {water.viscosity:.12g}"


def _segments(scene: Scene, stages: list[tuple[float, int]],
              every: int) -> list[tuple[float, int, Suspension | None, bool]]:
    """The deck's runs (time step, steps, water, whether a stage begins): each stage whole, or, with a
    water record, split at the frames where the record has moved by more than DRIFT_STEP since the last
    change, each part with the water at its middle."""
    if not scene.water_record:
        return [(dt, steps, None, True) for dt, steps in stages]
    times, temperatures = (np.array(v, float) for v in zip(*scene.water_record))

    def water_at(t: float) -> Suspension:
        return Suspension.at_temperature(float(np.interp(t, times, temperatures)), scene.suspension.particle_density,
                                         scene.suspension.gravity)

    out, start = [], 0.0
    for dt, steps in stages:
        frames = np.arange(0, steps, every)
        middle = start + (frames + 0.5 * every) * dt
        level = np.interp(middle, times, temperatures)
        begin = 0    # the frame the current part starts at
        for k in range(1, len(frames) + 1):
            if k == len(frames) or abs(level[k] - level[begin]) > DRIFT_STEP:
                end = steps if k == len(frames) else frames[k]
                out.append((dt, int(end - frames[begin]), water_at(start + 0.5 * (frames[begin] + end) * dt), begin == 0))
                begin = k
        start += steps * dt
    return out


def contact_model(scene: Scene) -> str:
    """The grains' contact model as pair_coeff granular takes it: Hertz at the scene's soft modulus."""
    return (f"hertz/material {scene.contact_modulus():.6g} 0.3 {POISSON_RATIO:g} tangential mindlin NULL 1.0 0.5 "
            "damping tsuji")


def pair_lines(scene: Scene) -> list[str]:
    """The deck's pair_style and pair_coeff lines: the contacts, with the squeeze films overlaid."""
    if scene.effects.lubrication:
        return ["pair_style      hybrid/overlay granular lubricate/fluid water inner 0.01 outer 0.5 limit yes",
                f"pair_coeff      * * granular {contact_model(scene)}", "pair_coeff      * * lubricate/fluid"]
    return ["pair_style      granular", f"pair_coeff      * * {contact_model(scene)}"]


def describe(scene: Scene) -> str:
    """A short report: particles, classes, and the PSD actually simulated against the input."""
    c = scene.classes
    stages = scene.stages()
    sim = scene.simulated_psd()
    worst = float(np.max(np.abs(sim.percent_finer - scene.psd.at(c.edges))))
    lines = [f"{len(scene.diameter)} particles in {int(np.sum(c.count > 0))} size classes "
             f"({c.diameter[0] * 1e6:.3g}-{c.diameter[-1] * 1e6:.3g} um), standing for {c.represented_grains():.4g} real grains "
             f"({'weights ' + f'{c.weight.min():.3g}-{c.weight.max():.3g}' if not np.all(c.weight == 1) else 'real grains'})",
             f"sub-volume: {scene.geometry} {scene.width * 1e3:.4g} x {scene.thickness * 1e3:.4g} x "
             f"{scene.height * 1e3:.4g} mm = {scene.volume_fraction:.3g} of the cylinder; "
             f"c0 = {scene.initial_concentration:.4g} kg/m3",
             f"simulated PSD vs input at the class edges: max difference {worst:.2f} percentage points",
             f"time: {len(stages)} stages, {sum(n for _, n in stages)} steps to {scene.t_end:g} s "
             f"(dt {stages[0][0]:.3g} .. {stages[-1][0]:.3g} s)"]
    first, last = scene.psd.percent_finer[0], scene.psd.percent_finer[-1]
    if first > 0 or last < 100:
        lines.append(f"note: the PSD table runs from {first:g} to {last:g} % finer; the {first + 100 - last:g} % of the "
                     "mass outside its diameters is not simulated, and the simulated PSD is renormalised to 100 %")
    if scene.effects.interacting:
        lines.append(f"contacts: E = {scene.contact_modulus():.3g} Pa, the softest keeping overlaps within "
                     f"{OVERLAP_TOLERANCE:.0%} (fastest grain's impact, {LOAD_CONCENTRATION:g}x the deposit's weight "
                     f"per grain); largest overlap in the thermo output, the run stops at {2 * OVERLAP_TOLERANCE:.0%}")
        lines.append(f"contacts: dt = {stages[0][0]:.3g} s (Rayleigh time / 5 of the smallest grain): "
                     f"{stages[0][1]:.3g} steps x {len(scene.diameter)} particles")
    return "\n".join(lines)
