# SPDX-License-Identifier: GPL-2.0-or-later
"""What accuracy costs in time: one deck run at several time steps (and integrators), each run's
observables compared with an analytic reference or the finest run, against the run time it took.

A deck takes part by reading two index variables and printing what it observes:

    variable dt         index 1e-3              # the swept variable (another name: --parameter)
    variable integrator index nve/sphere/fluid  # only if --integrator is used
    fix      step all ${integrator}
    print    "RESULT name value [name value ...]"        # scalar observables
    fix      s all print 10 "SERIES name $(time) $(...)" # a series: (x, y) rows, e.g. a curve in time

and `--observe hydrometer|buoyancy|pipette` reads the layer file a sedimentation deck writes
(`variable layers_file`): the percent-finer curve the instrument reports is the observable.

Errors: a scalar |y - y_ref| / |y_ref|; a series or curve max |y - y_ref(x)| / max |y_ref| over the
run's x (the reference interpolated, linearly in x, or in log D for a readout curve). A run that
fails (lost atoms, non-finite state) is kept in the table as failed.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import figures
from ..progress import bar as progress_bar
from ..results import Table, write_text
from ..sim.observe import READOUTS, Observation, observe, relative_error
from ..sim.run import run_batch

INTEGRATORS = {"implicit": "nve/sphere/fluid", "explicit": "nve/sphere"}
SAFE_NAMES = {name: getattr(np, name) for name in ("exp", "log", "sqrt", "sin", "cos", "tanh", "pi", "abs")}


@dataclass
class SweepRun:
    """One run of a sweep: the swept value, its cost, what it observed and its errors."""

    integrator: str | None
    value: float                    # of the swept variable
    loop_seconds: float             # LAMMPS's loop time, summed over the deck's runs (start-up excluded)
    wall_seconds: float
    observations: dict[str, Observation] = field(default_factory=dict)
    failure: str | None = None
    errors: dict[str, float] = field(default_factory=dict)

    @property
    def error(self) -> float:
        """The worst relative error over the observables (inf if the run failed)."""
        return math.inf if self.failure else max(self.errors.values(), default=math.nan)


@dataclass
class Sweep:
    """A deck run at several values of one variable, scored against a reference."""

    deck: Path
    parameter: str
    observables: list[str]
    runs: list[SweepRun]
    reference: str                  # "analytic" or a description of the reference run
    tau: float | None = None
    rayleigh: float | None = None

    def cheapest(self, tolerance: float, integrator: str | None = None) -> SweepRun | None:
        """The run with the least loop time whose error is within the tolerance."""
        good = [r for r in self.runs if r.error <= tolerance and (integrator is None or r.integrator == integrator)]
        return min(good, key=lambda r: r.loop_seconds, default=None)

    def table(self, tolerance: float = 0.01) -> Table:
        """One row per run (the swept value, its ratio to tau and the Rayleigh time, loop and wall
        time, status, each observable's value and error); the notes name the cheapest run within
        `tolerance` per integrator."""
        head = ["integrator", self.parameter, "loop_s", "wall_s", "status"]
        if self.tau:
            head.insert(2, f"{self.parameter}_over_tau")
        if self.rayleigh:
            head.insert(2, f"{self.parameter}_over_rayleigh_time")
        head += [f"{n}_value" for n in self.observables] + [f"{n}_error" for n in self.observables] + ["max_error"]
        table = Table(head, notes=self.summary(tolerance))
        for r in self.runs:
            row = [r.integrator or "", f"{r.value:g}"]
            if self.rayleigh:
                row.append(f"{r.value / self.rayleigh:.4g}")
            if self.tau:
                row.append(f"{r.value / self.tau:.4g}")
            row += [f"{r.loop_seconds:.4g}", f"{r.wall_seconds:.4g}", "failed: " + r.failure if r.failure else "ok"]
            row += [(f"{r.observations[n].y[0]:.8g}" if n in r.observations and r.observations[n].x is None else "")
                    for n in self.observables]
            row += [(f"{r.errors[n]:.4g}" if n in r.errors else "") for n in self.observables]
            row.append(f"{r.error:.4g}")
            table.rows.append(row)
        return table

    def summary(self, tolerance: float) -> list[str]:
        """The cheapest run within the tolerance, per integrator, against the 20 % Rayleigh-time rule."""
        lines = [f"reference: {self.reference}; error = worst of {', '.join(self.observables)}"]
        for integrator in sorted({r.integrator for r in self.runs}, key=lambda i: i or ""):
            best = self.cheapest(tolerance, integrator)
            label = integrator or "runs"
            if best is None:
                lines.append(f"{label}: no run within {tolerance * 100:.3g} %")
                continue
            text = (f"{label}: cheapest within {tolerance * 100:.3g} %: {self.parameter} = {best.value:g} "
                    f"(error {best.error:.3g}, loop {best.loop_seconds:.3g} s)")
            if self.rayleigh:
                rule = 0.2 * self.rayleigh
                text += f"; {best.value / rule:.3g}x the 20 % Rayleigh-time step ({rule:.3g} s)"
                text += f", which would take about {best.loop_seconds * best.value / rule:.3g} s of loop time"
            lines.append(text)
        return lines

    def save(self, folder: Path, tolerance: float = 0.01, title: str = "") -> list[Path]:
        """sweep.csv and sweep.png (errors against the swept value and against loop time)."""
        return [write_text(Path(folder) / "sweep.csv", self.table(tolerance).csv()),
                plot(self, Path(folder) / "sweep.png", tolerance, title)]


def parse_reference(text: str) -> tuple[str, str]:
    """'name=expression' -> (name, expression); the expression may use x and numpy's exp, log, sqrt..."""
    name, sep, expression = text.partition("=")
    if not sep or not name.strip() or not expression.strip():
        raise ValueError(f"reference '{text}' must be NAME=VALUE or NAME=EXPRESSION of x")
    return name.strip(), expression.strip()


def evaluate_reference(expression: str, x: np.ndarray | None) -> np.ndarray:
    """Value of a reference expression (numpy functions of x only) at x."""
    try:
        value = eval(expression, {"__builtins__": {}}, dict(SAFE_NAMES, x=x))  # noqa: S307 - the user's own formula
    except Exception as exc:
        raise ValueError(f"reference expression '{expression}' cannot be evaluated: {exc}") from None
    value = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(value)):
        raise ValueError(f"reference expression '{expression}' is not finite")
    return value


def check_deck(deck: Path, parameter: str, integrators: list[str] | None) -> None:
    """Refuses a deck that does not read the variables the sweep sets."""
    text = Path(deck).read_text()
    for name in [parameter] + (["integrator"] if integrators else []):
        if not re.search(rf"^\s*variable\s+{re.escape(name)}\s+index\s", text, re.MULTILINE):
            raise ValueError(f"{deck}: the deck has no 'variable {name} index ...' for the sweep to set")
    unknown = [i for i in integrators or [] if i not in INTEGRATORS]
    if unknown:
        raise ValueError(f"unknown integrator '{unknown[0]}' (expected {' or '.join(INTEGRATORS)})")


def deck_number(value: float) -> str:
    """The value as a LAMMPS -var: whole numbers without a decimal point, so that a variable a style
    reads as an integer (a refresh interval, a count) takes them; others exactly (repr)."""
    return str(int(value)) if float(value).is_integer() and abs(value) < 2**53 else repr(value)


def run_sweep(deck: Path, values: list[float], observables: list[str], integrators: list[str] | None = None,
              parameter: str = "dt", references: dict[str, str] | None = None,
              variables: dict[str, object] | None = None, ranks: int = 1, work_dir: Path | None = None,
              tau: float | None = None, rayleigh: float | None = None, progress: bool = True) -> Sweep:
    """Runs the deck at each value of the swept variable (and each integrator) and scores each run.

    Parameters
    ----------
    deck : Path
        A deck with ``variable NAME index ...`` for the swept variable.
    values : list of float
        Values of the swept variable (> 0).
    observables : list of str
        ``RESULT``/``SERIES`` names the deck prints, or hydrometer, buoyancy, pipette (read from the
        layer file the deck writes to ``${layers_file}``).
    integrators : list of str, optional
        ``"implicit"`` and/or ``"explicit"``, passed as ``-var integrator``.
    parameter : str
        The deck variable swept.
    references : dict, optional
        Analytic references per observable (a number, or an expression of x); without one for
        every observable the reference is the run with the smallest value (the implicit one if
        both integrators ran it).
    variables : dict, optional
        Further ``-var`` pairs for every run.
    ranks : int
        MPI ranks per run.
    work_dir : Path, optional
        Where the runs' files go.
    tau, rayleigh : float, optional
        Relaxation and Rayleigh times, for the ratios and the figure's marks.
    progress : bool
        Show a progress bar.

    Returns
    -------
    Sweep
        Runs (failed ones kept with their message), errors, loop times.
    """
    deck = Path(deck).resolve()
    if not deck.is_file():
        raise FileNotFoundError(f"{deck}: no such deck")
    if not values or not all(math.isfinite(v) and v > 0 for v in values):
        raise ValueError(f"the {parameter} values must be finite and > 0")
    if not observables:
        raise ValueError("nothing to observe: give at least one --observe NAME")
    check_deck(deck, parameter, integrators)
    references = references or {}
    stray = sorted(set(references) - set(observables))
    if stray:
        raise ValueError(f"a reference for '{stray[0]}', which is not observed")
    work_dir = Path(work_dir or deck.parent / "sweep")
    work_dir.mkdir(parents=True, exist_ok=True)
    plan = [(i, v) for i in (integrators or [None]) for v in sorted(set(values))]
    if progress:
        plan_iter = progress_bar(plan, desc=f"sweep {deck.name}", unit="run")
    else:
        plan_iter = plan
    runs = []
    for integrator, value in plan_iter:
        run_vars = dict(variables or {}, **{parameter: deck_number(value)})
        if integrator:
            run_vars["integrator"] = INTEGRATORS[integrator]
        layers_file = None
        if any(n in READOUTS for n in observables):
            layers_file = work_dir / f"layers_{integrator or 'run'}_{value:g}.h5"
            layers_file.unlink(missing_ok=True)
            run_vars["layers_file"] = str(layers_file)
        out = run_batch(deck, run_vars, ranks=ranks, check=False)
        run = SweepRun(integrator, value, sum(t for t, _ in out.loops), out.wall_seconds)
        if out.error:
            run.failure = out.error
        else:
            run.observations = observe(out.text, observables, layers_file)
            if any(not np.all(np.isfinite(o.y)) for o in run.observations.values()):
                run.failure = "non-finite observable"
        runs.append(run)
    sweep = Sweep(deck, parameter, observables, runs, "analytic", tau, rayleigh)
    _score(sweep, references)
    return sweep


def _score(sweep: Sweep, references: dict[str, str]) -> None:
    ok = [r for r in sweep.runs if not r.failure]
    if not ok:
        raise RuntimeError("every run failed; nothing to compare: " + str(sweep.runs[0].failure))
    finest = None
    if set(references) != set(sweep.observables):
        finest = min(ok, key=lambda r: (r.value, r.integrator != "implicit"))
        described = f"{sweep.parameter} = {finest.value:g}" + (f" ({finest.integrator})" if finest.integrator else "")
        sweep.reference = described if not references else f"analytic for {', '.join(references)}; else {described}"
    for run in sweep.runs:
        if run.failure:
            continue
        for name in sweep.observables:
            obs = run.observations[name]
            if name in references:
                ref = Observation(evaluate_reference(references[name], obs.x) * np.ones_like(obs.y), obs.x)
            else:
                ref = finest.observations[name]
            run.errors[name] = relative_error(obs, ref, log_x=name in READOUTS)


def plot(sweep: Sweep, path: Path, tolerance: float, title: str = "") -> Path:
    """Error against the swept variable (rules marked) and against loop time (Pareto front)."""
    plt = figures.pyplot()
    fig, (ax_d, ax_t) = plt.subplots(1, 2, figsize=(11, 4.4))
    ok = [r for r in sweep.runs if not r.failure]
    floor = min((r.error for r in ok if r.error > 0), default=1e-16) / 10
    top = max((r.error for r in ok if math.isfinite(r.error)), default=1.0) * 10
    for integrator, marker in ((None, "o"), ("implicit", "o"), ("explicit", "s")):
        sel = [r for r in sweep.runs if r.integrator == integrator]
        if not sel:
            continue
        label = integrator or "runs"
        good = [r for r in sel if not r.failure and r.error > 0]
        failed = [r for r in sel if r.failure]
        line, = ax_d.loglog([r.value for r in good], [r.error for r in good], marker + "-", label=label)
        ax_t.loglog([r.loop_seconds for r in good], [r.error for r in good], marker, color=line.get_color(), label=label)
        for r in good:
            ax_t.annotate(f"{r.value:.2g}", (r.loop_seconds, r.error), fontsize=6, xytext=(3, 3),
                          textcoords="offset points")
        if failed:
            ax_d.loglog([r.value for r in failed], [top] * len(failed), "x", color=line.get_color(), ms=8,
                        label=f"{label}: failed")
    front = _pareto([r for r in ok if r.error > 0])
    if len(front) > 1:
        ax_t.loglog([r.loop_seconds for r in front], [r.error for r in front], "k:", lw=1, label="Pareto front")
    for ax in (ax_d, ax_t):
        ax.axhline(tolerance, color="g", ls="--", lw=1, label=f"{tolerance * 100:.3g} % error")
    if sweep.rayleigh:
        ax_d.axvline(0.2 * sweep.rayleigh, color="m", ls="-.", label="20 % Rayleigh time")
        fine = min(ok, key=lambda r: r.value, default=None)
        if fine is not None:    # loop time scales with the step count
            ax_t.axvline(fine.loop_seconds * fine.value / (0.2 * sweep.rayleigh), color="m", ls="-.",
                         label="at 20 % Rayleigh time (from step count)")
    if sweep.tau:
        ax_d.axvline(2 * sweep.tau, color="r", ls=":", label="explicit limit 2 tau")
    ax_d.set(xlabel=sweep.parameter + (" [s]" if sweep.parameter == "dt" else ""), ylabel="relative error", title=title or sweep.deck.name)
    ax_t.set(xlabel="loop time [s]", ylabel="relative error", title="error vs cost (labels: " + sweep.parameter + ")")
    ax_d.set_ylim(floor, top * 3)
    ax_t.set_ylim(floor, top * 3)
    ax_d.legend(fontsize=7)
    ax_t.legend(fontsize=7)
    return figures.save(fig, path)


def _pareto(runs: list[SweepRun]) -> list[SweepRun]:
    front, best = [], math.inf
    for r in sorted(runs, key=lambda r: r.loop_seconds):
        if r.error < best:
            front.append(r)
            best = r.error
    return front
