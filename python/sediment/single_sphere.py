"""Case A of the validation (Zhang & Li 2024): one sphere settling from rest in water.

Runs the example deck with the drag-implicit and the explicit integrator at several time steps
and compares each velocity curve with v(t) = v_t (1 - exp(-t / tau)).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import figures
from .paths import REPO_DIR
from .run import run_batch

DECK = REPO_DIR / "examples" / "single_sphere" / "in.case_a"
DIAMETER, PARTICLE_DENSITY, FLUID_DENSITY, VISCOSITY, GRAVITY = 1e-4, 2700.0, 1000.0, 1e-3, 9.81
TERMINAL_VELOCITY = (PARTICLE_DENSITY - FLUID_DENSITY) * GRAVITY * DIAMETER**2 / (18 * VISCOSITY)
RELAXATION_TIME = PARTICLE_DENSITY * DIAMETER**2 / (18 * VISCOSITY)


@dataclass
class Run:
    integrator: str     # "implicit" or "explicit"
    dt: float
    time: np.ndarray
    velocity: np.ndarray    # settling speed (positive downwards)
    wall_seconds: float

    @property
    def error(self) -> float:
        """Largest |v - v_exact| / v_t over the run."""
        return float(np.max(np.abs(self.velocity - exact_velocity(self.time))) / TERMINAL_VELOCITY)


def exact_velocity(t: np.ndarray) -> np.ndarray:
    return TERMINAL_VELOCITY * (1.0 - np.exp(-t / RELAXATION_TIME))


def run_case_a(integrator: str, dt: float, t_end: float = 0.04, samples: int = 300) -> Run:
    style = {"implicit": "nve/sphere/fluid", "explicit": "nve/sphere"}[integrator]
    steps = max(1, round(t_end / dt))
    out = run_batch(DECK, {"integrator": style, "dt": repr(dt), "steps": steps,
                           "every": max(1, steps // samples)})
    return Run(integrator, dt, out.samples[:, 0], -out.samples[:, 2], out.wall_seconds)


# The runs drawn as velocity curves; the error panel shows every run.
SHOWN = {("implicit", 1e-3), ("implicit", 1e-2), ("explicit", 1e-5), ("explicit", 2.5e-3), ("explicit", 4e-3)}


def plot_case_a(runs: list[Run], path: Path) -> None:
    plt = figures.pyplot()

    fig, (ax_v, ax_e) = plt.subplots(1, 2, figsize=(11, 4.2))
    t_fine = np.linspace(0, max(r.time[-1] for r in runs), 400)
    ax_v.plot(t_fine * 1e3, exact_velocity(t_fine) * 1e3, "k-", lw=2.5, alpha=0.35, label="analytic")
    for run in (r for r in runs if (r.integrator, r.dt) in SHOWN):
        coarse = len(run.time) < 40    # few exact samples: markers, not lines between them
        style = "o" if coarse else ("-" if run.integrator == "implicit" else "--")
        ax_v.plot(run.time * 1e3, run.velocity * 1e3, style, ms=4,
                  label=f"{run.integrator}, dt = {run.dt:g} s ({run.dt / RELAXATION_TIME:.3g} tau)")
    ax_v.set(xlabel="time [ms]", ylabel="settling velocity [mm/s]",
             title="Case A: 0.1 mm sphere (2700 kg/m3) settling in water")
    ax_v.set_ylim(0, 1.6 * TERMINAL_VELOCITY * 1e3)
    ax_v.legend(fontsize=7)
    for integrator, marker in (("implicit", "o"), ("explicit", "s")):
        sel = [r for r in runs if r.integrator == integrator]
        ax_e.loglog([r.dt / RELAXATION_TIME for r in sel], [max(r.error, 1e-17) for r in sel], marker + "-",
                    label=integrator)
    ax_e.axvline(2.0, color="r", ls=":", label="explicit limit dt = 2 tau")
    ax_e.set(xlabel="dt / tau", ylabel="max |v - v_exact| / v_t", title="Velocity error vs time step")
    ax_e.legend(fontsize=8)
    figures.save(fig, path)


def case_a_study(out_dir: Path) -> list[Run]:
    """Runs the time-step study of case A and writes its table and figure into out_dir."""
    plan = [("implicit", dt) for dt in (1e-5, 1e-4, 1e-3, 1.5e-3, 1e-2)] + \
           [("explicit", dt) for dt in (1e-5, 1e-4, 1e-3, 2.5e-3, 4e-3)]
    from tqdm import tqdm

    runs = [run_case_a(integrator, dt) for integrator, dt in tqdm(plan, desc="case A runs", unit="run")]
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "case_a_errors.csv", "w") as f:
        f.write("integrator,dt_s,dt_over_tau,max_velocity_error_over_vt,wall_s\n")
        for r in runs:
            f.write(f"{r.integrator},{r.dt:g},{r.dt / RELAXATION_TIME:.4g},{r.error:.3e},{r.wall_seconds:.3f}\n")
    plot_case_a(runs, out_dir / "case_a_velocity.png")
    return runs
