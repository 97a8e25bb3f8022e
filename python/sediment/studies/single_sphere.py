# SPDX-License-Identifier: GPL-2.0-or-later
"""Case A of the validation (Zhang & Li 2024): one sphere settling from rest in water.

The time-step study is a sweep (sediment.sweep) of the example deck with the drag-implicit and the
explicit integrator, each velocity curve scored against v(t) = v_t (1 - exp(-t / tau)).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _core, figures
from ..constants import GRAVITY
from ..results import Table
from ..sim.paths import REPO_DIR
from . import sweep

DECK = REPO_DIR / "examples" / "single_sphere" / "in.case_a"
DIAMETER, PARTICLE_DENSITY, FLUID_DENSITY, VISCOSITY = 1e-4, 2700.0, 1000.0, 1e-3
YOUNGS_MODULUS, POISSON_RATIO = 30e9, 0.25
TERMINAL_VELOCITY = float(_core.stokes_velocity(PARTICLE_DENSITY, FLUID_DENSITY, VISCOSITY, GRAVITY, DIAMETER))
RELAXATION_TIME = _core.relaxation_time("stokes", FLUID_DENSITY, VISCOSITY, DIAMETER, PARTICLE_DENSITY)
RAYLEIGH_TIME = _core.rayleigh_time(0.5 * DIAMETER, PARTICLE_DENSITY, YOUNGS_MODULUS, POISSON_RATIO)
REFERENCE = {"velocity": f"{TERMINAL_VELOCITY!r} * (1 - exp(-x / {RELAXATION_TIME!r}))"}
TIME_STEPS = (1e-5, 1e-4, 1e-3, 1.5e-3, 2.5e-3, 4e-3, 1e-2)


def exact_velocity(t: np.ndarray) -> np.ndarray:
    """v_t (1 - exp(-t / tau)) of case A."""
    return sweep.evaluate_reference(REFERENCE["velocity"], t)


def case_a_sweep(time_steps=TIME_STEPS, integrators=("implicit", "explicit"), t_end: float = 0.04,
                 work_dir: Path | None = None, progress: bool = True) -> sweep.Sweep:
    """The deck of case A at each time step with each integrator, scored against the exact curve."""
    return sweep.run_sweep(DECK, list(time_steps), ["velocity"], list(integrators), references=REFERENCE,
                           variables={"t_end": t_end}, work_dir=work_dir, tau=RELAXATION_TIME,
                           rayleigh=RAYLEIGH_TIME, progress=progress)


# The runs drawn as velocity curves; the error panels show every run.
SHOWN = {("implicit", 1e-3), ("implicit", 1e-2), ("explicit", 1e-5), ("explicit", 2.5e-3), ("explicit", 4e-3)}


def plot_velocities(result: sweep.Sweep, path: Path) -> Path:
    """Velocity curves of a few runs against the exact curve."""
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    runs = [r for r in result.runs if not r.failure]
    t_fine = np.linspace(0, max(r.observations["velocity"].x[-1] for r in runs), 400)
    ax.plot(t_fine * 1e3, exact_velocity(t_fine) * 1e3, "k-", lw=2.5, alpha=0.35, label="analytic")
    for run in (r for r in runs if (r.integrator, r.value) in SHOWN):
        curve = run.observations["velocity"]
        coarse = len(curve.x) < 40    # few exact samples: markers, not lines between them
        style = "o" if coarse else ("-" if run.integrator == "implicit" else "--")
        ax.plot(curve.x * 1e3, curve.y * 1e3, style, ms=4,
                label=f"{run.integrator}, dt = {run.value:g} s ({run.value / RELAXATION_TIME:.3g} tau)")
    ax.set(xlabel="time [ms]", ylabel="settling velocity [mm/s]",
           title="Case A: 0.1 mm sphere (2700 kg/m3) settling in water")
    ax.set_ylim(0, 1.6 * TERMINAL_VELOCITY * 1e3)
    ax.legend(fontsize=7)
    return figures.save(fig, path)


@dataclass
class CaseA:
    """The time-step study of case A: the sweep of both integrators against the exact curve."""

    sweep: sweep.Sweep
    tolerance: float = 0.01

    def table(self) -> Table:
        """The sweep's table, with the cheapest step within 1 % per integrator."""
        return self.sweep.table(self.tolerance)

    def save(self, folder: Path) -> list[Path]:
        """sweep.csv, sweep.png (errors vs dt and loop time) and case_a_velocity.png."""
        return [*self.sweep.save(folder, self.tolerance, "Case A: velocity error vs dt"),
                plot_velocities(self.sweep, Path(folder) / "case_a_velocity.png")]


def case_a_study(work_dir: Path | None = None, progress: bool = True) -> CaseA:
    """Runs the time-step study of case A (the runs' files in `work_dir`, or a temporary folder)."""
    return CaseA(case_a_sweep(work_dir=work_dir, progress=progress))
