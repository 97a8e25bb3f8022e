# SPDX-License-Identifier: GPL-2.0-or-later
"""Spheres settling in Bingham clay suspensions (Valentik & Whitmore 1965; case C).

Runs examples/valentik_whitmore/in.sphere for every row of a CSV with the columns
suspension, rho_f, eta_B, tau_y, d, rho_p, v_ter_measured (SI units), and compares the simulated
terminal velocity with the law's analytic one (a check of the code) and with the measured one
(a property of the law).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _core, figures
from ..progress import bar as progress_bar
from ..results import Table, write_text
from ..constants import GRAVITY
from ..csvfile import number, read_csv
from ..plausible import refusal
from ..sim.paths import REPO_DIR
from ..sim.run import run_batch

DECK = REPO_DIR / "examples" / "valentik_whitmore" / "in.sphere"
STOKES_MARGIN = 3.0    # a measured speed this many times Stokes' at eta_B: no plastic viscosity in Pa s
COLUMNS = ("suspension", "rho_f", "eta_B", "tau_y", "d", "rho_p", "v_ter_measured")


@dataclass
class Sphere:
    """A sphere of the Valentik & Whitmore table and its suspension (SI units)."""

    suspension: str
    rho_f: float
    eta_B: float
    tau_y: float
    d: float
    rho_p: float
    measured: float


@dataclass
class Settling:
    """One sphere settled under one law."""

    sphere: Sphere
    law: str
    analytic: float     # terminal velocity of the law [m/s]
    regime: str         # 'moving', 'at_rest' or 'at_jump'
    simulated: float    # speed at the end of the run [m/s]

    @property
    def code_error(self) -> float:
        """(simulated - analytic) / analytic (0 when both are at rest)."""
        return 0.0 if self.analytic == 0 else self.simulated / self.analytic - 1.0

    @property
    def law_error(self) -> float:
        """(analytic - measured) / measured."""
        return self.analytic / self.sphere.measured - 1.0


# each column's quantity in sediment.plausible, for the range and the unit slip of a value
QUANTITIES = {"rho_f": "fluid_density", "eta_B": "viscosity", "tau_y": "yield_stress", "d": "ball_diameter",
              "rho_p": "solid_density", "v_ter_measured": "settling_speed"}


def read_spheres(path: Path) -> list[Sphere]:
    """Reads the spheres of a Valentik & Whitmore CSV, refusing implausible or malformed rows with the line."""
    table = read_csv(path, "spheres CSV")
    missing = [c for c in COLUMNS if c not in table.header]
    if missing:
        raise ValueError(f"{table.path}: missing column(s) {', '.join(missing)} (expected {', '.join(COLUMNS)})")
    spheres = []
    for line, row in table.rows:
        cells = dict(zip(table.header, row))
        where = table.where(line)
        values = {c: number(cells[c].strip(), c, where) for c in COLUMNS[1:]}
        for column, quantity in QUANTITIES.items():
            reason = refusal(values[column], quantity)
            if reason is not None:
                raise ValueError(f"{where}: {column} {reason}")
        if values["rho_p"] <= values["rho_f"]:
            raise ValueError(f"{where}: the sphere (rho_p {values['rho_p']:g}) does not sink in the suspension "
                             f"(rho_f {values['rho_f']:g})")
        # the yield stress and inertia only slow a sphere: it falls at most at Stokes' speed for eta_B
        stokes = (values["rho_p"] - values["rho_f"]) * GRAVITY * values["d"] ** 2 / (18 * values["eta_B"])
        fell = values["v_ter_measured"]
        if fell > STOKES_MARGIN * stokes:
            raise ValueError(f"{where}: the sphere fell at {fell:g} m/s, {fell / stokes:.3g} times Stokes' speed at eta_B {values['eta_B']:g} Pa s ({stokes:.3g} m/s), which a yield "
                             f"stress and inertia only lower: is eta_B in mPa s? ({values['eta_B']:g} mPa s is "
                             f"{values['eta_B'] * 1e-3:g} Pa s)")
        spheres.append(Sphere(cells["suspension"].strip(), values["rho_f"], values["eta_B"], values["tau_y"], values["d"],
                              values["rho_p"], values["v_ter_measured"]))
    if not spheres:
        raise ValueError(f"{table.path}: no spheres")
    return spheres


def settle(sphere: Sphere, law: str = "bingham", steps: int = 2000) -> Settling:
    """Runs the deck for five times the law's time to 99 % of the terminal speed (or 1 s at rest)."""
    args = (law, sphere.rho_f, sphere.eta_B, sphere.tau_y, sphere.d, sphere.rho_p, GRAVITY)
    speed, regime = _core.terminal_velocity(*args)
    t_end = 5 * _core.time_to_fraction(*args, 0.99) if speed > 0 else 1.0
    out = run_batch(DECK, {"d": sphere.d, "rho_p": sphere.rho_p, "rho_f": sphere.rho_f, "tau_y": sphere.tau_y,
                           "eta_B": sphere.eta_B, "law": law, "t_end": t_end, "dt": t_end / steps})
    return Settling(sphere, law, speed, regime, out.results["speed"])


def net_weight(sphere: Sphere) -> float:
    """The sphere's weight less its buoyancy in the suspension [N]."""
    return (sphere.rho_p - sphere.rho_f) * GRAVITY * math.pi / 6 * sphere.d ** 3


def law_speeds(spheres: list[Sphere], law: str, **constants: float) -> np.ndarray:
    """Terminal speeds [m/s] of the spheres under a law, from the physics core (0 for a sphere held at
    rest); `constants`: yield_weight and yield_rise for law bingham."""
    out = np.empty(len(spheres))
    for i, s in enumerate(spheres):
        model = _core.DragModel(law, s.rho_f, s.eta_B, s.tau_y, **constants)
        out[i] = model.steady_speed(s.d, net_weight(s))[0]
    return out


@dataclass
class LawScore:
    """A law's terminal speeds against the measured ones."""

    law: str
    errors: np.ndarray       # predicted / measured - 1, one per sphere

    @property
    def median(self) -> float:
        """Median of |error|."""
        return float(np.median(np.abs(self.errors)))

    @property
    def mean(self) -> float:
        """Mean of |error|."""
        return float(np.mean(np.abs(self.errors)))

    @property
    def worst(self) -> float:
        """Largest |error|."""
        return float(np.max(np.abs(self.errors)))

    @property
    def held(self) -> int:
        """Spheres the law holds at rest (every one of Valentik & Whitmore's moved)."""
        return int(np.sum(self.errors == -1.0))


def score_law(spheres: list[Sphere], law: str, **constants: float) -> LawScore:
    """The law's error on each sphere's measured terminal speed."""
    measured = np.array([s.measured for s in spheres])
    return LawScore(law, law_speeds(spheres, law, **constants) / measured - 1.0)


# The fit of law bingham's two constants (docs/physics.md 4.1): least squares on the logarithm of the
# force balance at the measured speed, F(v_measured) / W, with a soft-L1 loss of scale 0.1 (a sphere
# whose force is off by more than about 10 % counts less than its square: the spheres just above the
# critical yield number move at speeds no Bingham law predicts to within a factor of two).
FIT_LOSS_SCALE = 0.1


def fit_bingham(spheres: list[Sphere]) -> dict[str, float]:
    """Law bingham's yield_weight and yield_rise fitted on the spheres (see FIT_LOSS_SCALE)."""
    from scipy.optimize import least_squares

    weights = np.array([net_weight(s) for s in spheres])

    def residuals(x: np.ndarray) -> np.ndarray:
        forces = [_core.DragModel("bingham", s.rho_f, s.eta_B, s.tau_y, yield_weight=x[0], yield_rise=x[1])
                  .force(s.d, s.measured) for s in spheres]
        return np.log(np.array(forces) / weights)

    solution = least_squares(residuals, x0=[0.1, 5.0], bounds=([1e-4, 0.0], [10.0, 100.0]), loss="soft_l1",
                             f_scale=FIT_LOSS_SCALE, x_scale=[0.01, 1.0])
    if not solution.success:
        raise RuntimeError(f"the fit of law bingham did not converge: {solution.message}")
    return {"yield_weight": float(solution.x[0]), "yield_rise": float(solution.x[1])}


@dataclass
class SpheresStudy:
    """Terminal velocities of spheres in Bingham suspensions: simulated, the law's, measured."""

    results: list[Settling]

    def table(self) -> Table:
        """One row per sphere and law, with the code's and the law's errors."""
        table = Table(["law", "susp", "d [mm]", "rho_p", "measured", "law", "simulated", "sim/law-1", "law/meas-1",
                       "regime"])
        for r in self.results:
            s = r.sphere
            table.add(r.law, s.suspension, f"{s.d * 1e3:.1f}", f"{s.rho_p:.0f}", f"{s.measured:.3f}",
                      f"{r.analytic:.4f}", f"{r.simulated:.4f}", f"{r.code_error:+.1e}", f"{r.law_error:+.1%}",
                      r.regime)
        table.notes.append(f"worst |simulated/law - 1| = {max(abs(r.code_error) for r in self.results):.1e}")
        return table

    def save(self, folder: Path) -> list[Path]:
        """terminal_velocities.csv and terminal_velocities.png."""
        rows = Table(["law", *COLUMNS, "v_law", "regime", "v_simulated", "simulated_vs_law", "law_vs_measured"])
        for r in self.results:
            s = r.sphere
            rows.add(r.law, s.suspension, s.rho_f, s.eta_B, s.tau_y, s.d, s.rho_p, s.measured, r.analytic, r.regime,
                     r.simulated, f"{r.code_error:+.2e}", f"{r.law_error:+.4f}")
        return [write_text(Path(folder) / "terminal_velocities.csv", rows.csv()),
                plot(self.results, Path(folder) / "terminal_velocities.png")]


def study(csv_path: Path, laws=("bingham", "zhang-li"), progress: bool = True) -> SpheresStudy:
    """Settles every sphere of the CSV under every law."""

    spheres = read_spheres(csv_path)
    plan = [(s, law) for law in laws for s in spheres]
    return SpheresStudy([settle(s, law) for s, law in progress_bar(plan, desc="spheres", unit="run", disable=not progress)])


def plot(results: list[Settling], path: Path) -> Path:
    """Simulated and analytic against measured terminal velocities."""
    plt = figures.pyplot()

    laws = sorted({r.law for r in results})
    fig, axes = plt.subplots(1, len(laws), figsize=(5.2 * len(laws), 4.6), squeeze=False)
    suspensions = sorted({r.sphere.suspension for r in results})
    markers = "osD^v<>ph*"
    for ax, law in zip(axes[0], laws):
        top = 0.0
        for i, name in enumerate(suspensions):
            sel = [r for r in results if r.law == law and r.sphere.suspension == name]
            if not sel:
                continue
            s = sel[0].sphere
            ax.plot([r.sphere.measured for r in sel], [r.simulated for r in sel], markers[i % len(markers)],
                    mfc="none", ms=7, label=f"{name}: tau_y {s.tau_y:g} Pa, eta_B {s.eta_B:g} Pa s")
            top = max(top, *(r.sphere.measured for r in sel), *(r.simulated for r in sel))
        ax.plot([0, 1.1 * top], [0, 1.1 * top], "k-", lw=0.8, label="simulated = measured")
        for factor in (0.7, 1.3):
            ax.plot([0, 1.1 * top], [0, 1.1 * top * factor], "k:", lw=0.6, label="+-30 %" if factor > 1 else None)
        ax.set(xlabel="measured terminal velocity [m/s]", ylabel="simulated terminal velocity [m/s]",
               title=f"Valentik & Whitmore (1965), law {law}", xlim=(0, 1.1 * top), ylim=(0, 1.1 * top))
        ax.legend(fontsize=7, title="suspension", title_fontsize=7)
    return figures.save(fig, path)
