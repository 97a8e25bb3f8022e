# SPDX-License-Identifier: GPL-2.0-or-later
"""What contacts and lubrication change in a sedimentation test, measured on a reduced real-grain
scene (docs/effects.md section 5).

The whole test with real grains in contact is out of reach: the contact step is a fifth of the
Rayleigh time of the finest grain in contact (1e-7 s for 2.6 um), against 86 400 s of settling.
What contacts can do to the readings they do in suspension, where grains settling at different
speeds meet (the bed stays below the instruments; the screening checks that). A reduced scene keeps
those meetings: the test's grains above a cut diameter (the step grows with the finest grain in
contact), each class at its real number concentration, in a triply periodic box (a homogeneous
suspension away from the floor and the surface), for the time the slowest of them takes to fall a
given number of box heights. A grain that touches nothing falls at its terminal speed exactly, so
each class's mean speed over the window against its terminal speed is what contacts (and the
squeeze films, with lubrication) do to it. The readings change follows as in the screening: the
analytic column read with every class at its measured speed (classes below the cut unchanged).

The DEM contact is ballistic: two grains touch when their centres come within a diameter, whereas in
a real suspension the flow carries most of the smaller grain round the larger one (the screening's
interception efficiency). So the measured change bounds what contacts do from above; the estimate
for the same classes without that efficiency (`encounters(..., interception=False)`) is its
prediction, reported beside it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

import numpy as np

from ..lab.psd import PSD
from ..lab.settling import terminal_speeds
from ..results import Table, write_text
from ..sim.process import Runs
from ..sim.run import run_batch
from ..sim.scene import OVERLAP_TOLERANCE, Cylinder, Effects, plan
from ..sim.scenefiles import pair_lines, write_data
from .screening import ReadingModel, SedimentationTest, encounters


@dataclass(frozen=True)
class ReducedScene:
    """The reduced real-grain scene: which grains, how large a box, how long."""

    smallest: float = 20e-6     # cut diameter [m]: grains below it are left out
    width: float = 0.5e-3       # box side [m]
    height: float = 5e-3        # box height [m] (periodic)
    fall: float = 0.5           # box heights the slowest grain falls while measured
    lubrication: bool = False
    classes: int = 12
    seed: int = 1

    def __post_init__(self) -> None:
        if not (self.smallest > 0 and self.width > 0 and self.height > 0 and self.fall > 0):
            raise ValueError("the cut diameter, box width and height and the fall must be > 0")
        if self.classes < 2:
            raise ValueError("the reduced scene needs at least 2 size classes")


@dataclass
class ContactMeasurement:
    """Per class of the reduced scene: grains, mean speed against the terminal speed (with its standard
    error) and the ballistic estimate; the run's step, steps, loop time and largest overlap; and the
    largest change of a reading the measured speeds make."""

    setup: ReducedScene
    diameter: np.ndarray
    grains: np.ndarray
    speed_ratio: np.ndarray
    standard_error: np.ndarray
    estimated_ratio: np.ndarray
    time_step: float
    steps: int
    loop_seconds: float
    largest_overlap: float
    change: float

    def table(self) -> Table:
        """One row per class."""
        s = self.setup
        table = Table(["diameter_um", "grains", "speed_over_terminal", "standard_error", "ballistic_estimate"], notes=[
            f"reduced scene: grains above {s.smallest * 1e6:.3g} um in a periodic box of {s.width * 1e3:.3g} x "
            f"{s.width * 1e3:.3g} x {s.height * 1e3:.3g} mm, contacts{' and lubrication' if s.lubrication else ''}, "
            f"{self.steps} steps of {self.time_step:.3g} s (loop {self.loop_seconds:.1f} s); largest overlap "
            f"{100 * self.largest_overlap:.2f} % of a diameter",
            f"readings at the measured speeds move by up to {self.change:.3g} points of percent finer"])
        for row in zip(self.diameter * 1e6, self.grains, self.speed_ratio, self.standard_error, self.estimated_ratio):
            table.add(f"{row[0]:.4g}", int(row[1]), f"{row[2]:.5f}", f"{row[3]:.2g}", f"{row[4]:.5f}")
        return table


def coarse_part(psd: PSD, smallest: float) -> tuple[PSD, float]:
    """The PSD of the grains above `smallest`, renormalised, and the mass share they hold."""
    lo, hi = psd.span()
    if not lo <= smallest < hi:
        raise ValueError(f"the cut diameter {smallest * 1e6:.3g} um must lie within the PSD's span "
                         f"({lo * 1e6:.3g}-{hi * 1e6:.3g} um)")
    below = float(psd.at([smallest])[0])
    keep = psd.diameter > smallest
    diameter = np.concatenate([[smallest], psd.diameter[keep]])
    finer = (np.concatenate([[below], psd.percent_finer[keep]]) - below) / (100.0 - below) * 100.0
    return PSD(diameter, np.minimum(finer, 100.0), f"{psd.name} above {smallest * 1e6:.3g} um"), 1.0 - below / 100.0


def measure_contacts(test: SedimentationTest, setup: ReducedScene, folder: Path, ranks: int = 1,
                     running: Runs | None = None,
                     on_progress: Callable[[int, int], None] | None = None) -> ContactMeasurement:
    """Runs the reduced scene in `folder` and measures each class's speed (see the module).

    `on_progress(done, total)` is called with the steps run so far, of the relaxation and the
    measured window together, as LAMMPS prints its thermo rows (a hundred per window)."""
    coarse, share = coarse_part(test.psd, setup.smallest)
    s = test.suspension
    mass = test.initial_concentration * share * setup.width ** 2 * setup.height
    scene = plan(coarse, cylinder=Cylinder(setup.width ** 2, setup.height), mass=mass, suspension=s,
                 width=setup.width, classes=setup.classes, particles=None, seed=setup.seed,
                 effects=Effects("standard", contacts=True, lubrication=setup.lubrication, hindrance="none"),
                 t_end=1.0)
    scene = replace(scene, floor=False)    # a triply periodic box: the contacts hold the grains' meetings only
    dt = scene.contact_time_step()
    slowest = float(terminal_speeds(s, np.array([scene.diameter.min()]))[0])
    steps = math.ceil(setup.fall * setup.height / slowest / dt)
    folder.mkdir(parents=True, exist_ok=True)
    write_data(scene, folder / "reduced.data")
    write_text(folder / "in.reduced", _deck(scene, dt, steps))
    relax = _relaxation_steps(steps)
    out = run_batch(folder / "in.reduced", ranks=ranks, running=running,
                    on_line=None if on_progress is None else _step_counter(relax, steps, on_progress))

    frame = (folder / "displacements.txt").read_text().split("ITEM: ATOMS")[-1].split("\n", 1)[1]
    rows = np.loadtxt(frame.splitlines(), ndmin=2)
    diameter = np.unique(rows[:, 1])
    terminal = terminal_speeds(s, diameter)
    window = steps * dt
    ratio, error, grains = [], [], []
    for d, v in zip(diameter, terminal):
        fall = -rows[rows[:, 1] == d, 2] / window / v
        grains.append(fall.size)
        ratio.append(fall.mean())
        error.append(fall.std(ddof=1) / math.sqrt(fall.size) if fall.size > 1 else math.nan)
    ratio = np.array(ratio)

    reduced = SedimentationTest(coarse, s, test.cylinder, test.mass * share, test.instruments)
    d_est, _, _, delay = encounters(reduced, interception=False)
    estimated = 1.0 / (1.0 + np.interp(np.log(diameter), np.log(d_est), delay))
    model = ReadingModel(test, lambda d: terminal_speeds(s, d))
    at = lambda d: np.where(d >= setup.smallest, np.interp(np.log(d), np.log(diameter), ratio), 1.0)    # noqa: E731
    change = model.change(lambda d: terminal_speeds(s, d) * at(d))
    overlaps = [float(v) for v in _thermo_column(out.text, "c_overlap")]
    return ContactMeasurement(setup, diameter, np.array(grains), ratio, np.array(error), estimated, dt, steps,
                              sum(t for t, _ in out.loops), max(overlaps, default=0.0), change)


def _thermo_column(text: str, name: str) -> list[str]:
    """The values of one thermo column over every run in LAMMPS's output."""
    values, column = [], None
    for line in text.splitlines():
        words = line.split()
        if words and words[0] == "Step":
            column = words.index(name) if name in words else None
        elif column is not None and len(words) > column and words[0].isdigit():
            values.append(words[column])
        else:
            column = None if line.startswith("Loop time") else column
    return values


def _relaxation_steps(steps: int) -> int:
    """Grains start at rest: 2 % of the window before it opens, which for these scenes is some hundred
    relaxation times of the largest grain (sample 5: 0.095 s against 7.5e-4 s)."""
    return max(10, steps // 50)


def _step_counter(relax: int, steps: int, report: Callable[[int, int], None]) -> Callable[[str], None]:
    """A reader of the reduced deck's output that reports (steps done, relax + steps) at each thermo row.
    The deck runs `relax` steps, resets the step to 0 and runs the window: a row's step counts from
    the start of the run it belongs to; rows stand between a "Step" header and the "Loop time" line."""
    done_before, in_rows = [0], [False]

    def read(line: str) -> None:
        words = line.split()
        if line.startswith("Loop time"):
            done_before[0], in_rows[0] = relax, False
        elif words[:1] == ["Step"]:
            in_rows[0] = True
        elif in_rows[0] and words and words[0].isdigit():
            report(min(done_before[0] + int(words[0]), relax + steps), relax + steps)

    return read


def _deck(scene, dt: float, steps: int) -> str:
    s = scene.suspension
    d_max = float(scene.diameter.max())
    relax = _relaxation_steps(steps)
    return "\n".join([
        "# Reduced real-grain scene of `sediment plan --measure-contacts` (sediment.planner.contacts)",
        "units           si",
        "atom_style      sphere",
        "boundary        p p p",
        "fix             weights all property/atom d_weight",
        "read_data       reduced.data fix weights NULL Weights",
        # a thin skin: the films reach an eighth of a diameter past contact, and the pairs within reach of a
        # skin of half a diameter were three times those in reach; a grain moves under 1e-3 of a diameter a step
        f"neighbor        {0.1 * d_max:.6g} bin",
        "comm_modify     vel yes    # ghosts within the pair reach and the skin, as LAMMPS finds them",
        f"fix             grav all gravity {s.gravity:.12g} vector 0 0 -1",
        f"fix             water all fluid density {s.fluid_density:.12g} viscosity {s.viscosity:.12g}",
        "fix             buoy all fluid/buoyancy water",
        "fix             drag all fluid/drag water law standard",
        *pair_lines(scene),
        "fix             step all nve/sphere/fluid",
        "compute         overlap all contact/overlap",
        "variable        overlap equal c_overlap",
        f"fix             overlap_guard all halt 100 v_overlap > {2 * OVERLAP_TOLERANCE:g} error hard message yes",
        f"timestep        {dt:.17g}",
        "thermo_style    custom step time c_overlap",
        "thermo_modify   flush yes    # each row at once: the progress bar follows them",
        f"thermo          {max(1, steps // 100)}",
        f"run             {relax}",
        "reset_timestep  0",
        "compute         moved all displace/atom",
        f"dump            moved all custom {steps} displacements.txt id diameter c_moved[3]",
        "dump_modify     moved format float %.17g first no",
        f"run             {steps}",
        "",
    ])
