# SPDX-License-Identifier: GPL-2.0-or-later
"""The effects planner (docs/effects.md): screen every effect, measure what screening cannot settle,
decide the cheapest setting within the tolerance, verify it with a run, and report.

1. The reference trial runs every knob at its richest value, replicated with independent seeds where
   the scene takes one (a test): the mean of the replicas estimates the converged answer, their spread
   its sampling error, and every error below is a run's distance from that mean plus twice its
   standard error. Every other run takes a seed of its own, so that its error includes its own sampling.
2. Each knob value still in question (an effect the screening left to measure, every rung of a
   resolution ladder) runs as a trial that differs from the reference in that knob alone: its error
   against the reference and its cost ratio (loop time over the reference's). The scene's other models
   (a test: the drag laws and hindrances of the literature) run at the reference's resolution and are
   reported with their change of every reading; they are not candidates.
3. Every combination of the measured values is priced: predicted error the sum of its knobs' errors
   (each effect moves the observables on its own; errors of separate causes add at worst), predicted
   cost the product of their cost ratios (an effect left out never prices dearer; at equal cost fewer
   effects come first). The cheapest within the tolerance run to verify them, as many at once as
   trials ran; the first in that order that holds is the decision, and the reference the last resort.
"""
from __future__ import annotations

import itertools
import json
import math
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import figures
from ..progress import bar as progress_bar
from ..results import Table, write_text
from ..sim.process import finished_in_turn
from .scenes import Knob, Outcome, prepare
from .screening import INCLUDE, MEASURE, Screen

VERIFY_ATTEMPTS = 3


@dataclass
class Trial:
    """One run of the planner: a setting of every knob, what it gave and how far from the reference."""

    name: str
    settings: dict
    seed: int = 1
    outcome: Outcome = field(default_factory=Outcome)
    errors: dict[str, float] = field(default_factory=dict)
    predicted_error: float | None = None
    predicted_cost: float | None = None

    @property
    def error(self) -> float:
        """The worst error over the observables (inf if the run failed)."""
        return math.inf if self.outcome.failure else max(self.errors.values(), default=0.0)


@dataclass
class Plan:
    """The planner's evidence and decision for one scene."""

    scene_name: str
    unit: str                         # "pp" or "relative"
    tolerance: float
    knobs: list[Knob]
    screens: list[Screen]
    reference: Trial
    trials: list[Trial]               # one-knob variations of the reference
    verified: list[Trial]             # the candidates run to verify them, in order
    decision: Trial
    fixed: dict[str, tuple]           # knob -> (value, estimated error, reason) settled by screening
    candidates: list[tuple[dict, float, float]]    # every priced combination (settings, error, cost)
    command: str = ""
    scene_options: dict = field(default_factory=dict)    # what the scene was, besides the knobs
    replicas: list[Trial] = field(default_factory=list)     # the reference's runs (the first is `reference`)
    uncertainty: dict | None = None      # standard error of the reference's mean per observable and reading
    models: list[Trial] = field(default_factory=list)       # the scene's other models, against the reference
    converged: dict = field(default_factory=dict)    # the reference's mean observables (the converged estimate)

    def sampling_error(self) -> tuple[float, float]:
        """The largest standard error of the reference's mean and of one run at the reference's resolution
        over every reading [the scene's unit] (0, 0 without replicas)."""
        if not self.uncertainty or len(self.replicas) < 2:
            return 0.0, 0.0
        mean = max(float(np.max(e)) for e in self.uncertainty.values())
        return mean, mean * math.sqrt(len(self.replicas))

    def run_sampling(self, t: Trial) -> float | None:
        """The sampling error of a reading for one run of a trial [the scene's unit]: one run's at the
        reference's parcels, scaled by the square root of the parcel ratio (None without replicas)."""
        _, one = self.sampling_error()
        if not one or "particles" not in t.settings:
            return None
        return one * math.sqrt(self.reference.settings["particles"] / t.settings["particles"])

    def model_changes(self, t: Trial) -> dict[str, list[list[float]]]:
        """A model's change of every reading against the reference's mean: {observable: [[x, change], ...]}."""
        changes = {}
        for name, (x_ref, y_ref) in self.converged.items():
            if name not in t.outcome.observations:
                continue
            x, y = t.outcome.observations[name]
            _, i, j = np.intersect1d(x, x_ref, return_indices=True)
            changes[name] = [[float(x[a]), float(y[a] - y_ref[b])] for a, b in zip(i, j)]
        return changes

    def model_table(self) -> Table:
        """Each other model's change of the readings against the reference, per observable."""
        names = sorted(self.reference.errors)
        table = Table(["model", *[f"change_{n}" for n in names], "max_change", "loop_s"],
                      notes=[f"against the reference ({_describe(self.reference.settings)}), each change raised by "
                             "twice the standard error of the reference's mean"])
        for t in self.models:
            table.add(_model_name(t), *[f"{t.errors.get(n, math.nan):.4g}" for n in names], f"{t.error:.4g}",
                      f"{t.outcome.loop_seconds:.4g}")
        return table

    @property
    def speedup(self) -> float:
        """Reference loop time over the decision's."""
        return self.reference_seconds / self.decision.outcome.loop_seconds

    @property
    def reference_seconds(self) -> float:
        """The reference's loop time: the mean of its runs."""
        return _mean_loop(self.replicas or [self.reference])

    def table(self) -> Table:
        """Per knob value: what it leaves out, the screening number, estimated and measured change,
        cost ratio, verdict; then the effects that are not knobs, with their screening."""
        unit = "pp" if self.unit == "pp" else "rel"
        table = Table(["knob", "value", "leaves_out", "screening_number", "screening_value", f"estimated_change_{unit}",
                       f"measured_change_{unit}", "cost_ratio", "verdict"], notes=self.notes())
        for knob, value, s, trial in self._rows():
            chosen = self.decision.settings[knob.name]
            why = self.fixed[knob.name][2] if knob.name in self.fixed else "measured"
            table.add(knob.name, value, s.label if s else "", s.number if s else "", f"{s.value:.4g}" if s else "",
                      f"{s.change:.3g}" if s and s.change is not None else "", f"{trial.error:.3g}" if trial else "",
                      self._cost(trial), ("chosen" if chosen == value else f"keep {chosen}") + f" ({why})")
        for s in self._other_screens():
            table.add(s.effect, "", s.label, s.number, f"{s.value:.4g}", f"{s.change:.3g}" if s.change is not None else "",
                      "", "", f"{s.verdict}: {s.reason}")
        return table

    def text(self) -> str:
        """A terminal's view: one short row per knob value, then the other effects and the decision."""
        unit = "pp" if self.unit == "pp" else "rel"
        table = Table(["knob", "value", f"estimated_{unit}", f"measured_{unit}", "cost_ratio", ""])
        for knob, value, screen, trial in self._rows():
            chosen = self.decision.settings[knob.name]
            mark = "<- chosen" if chosen == value else (f"screened: keep {chosen}" if knob.name in self.fixed else "")
            table.add(knob.name, value, "" if screen is None or screen.change is None else f"{screen.change:.3g}",
                      f"{trial.error:.3g}" if trial else "", self._cost(trial), mark)
        lines = [f"{k} screened: {why}" for k, (_, _, why) in self.fixed.items()]
        lines += [f"{s.effect} ({s.number} {s.value:.3g}): {s.verdict}: {s.reason}" for s in self._other_screens()]
        return table.text() + "\n".join(lines + self.notes()) + "\n"

    def _rows(self):
        """(knob, value, the screen of what the value leaves out, its one-knob trial) per non-reference value."""
        screens = {s.effect: s for s in self.screens}
        for knob in self.knobs:
            for k, value in enumerate(knob.values[1:]):
                screen = screens.get(knob.drops[k]) if k < len(knob.drops) else None
                trial = next((t for t in self.trials if t.settings[knob.name] == value), None)
                yield knob, value, screen, trial

    def _other_screens(self) -> list[Screen]:
        """The screened effects that no knob switches."""
        knobbed = {d for k in self.knobs for d in k.drops}
        return [s for s in self.screens if s.effect not in knobbed]

    def _cost(self, trial: Trial | None) -> str:
        if trial is None or trial.outcome.failure:
            return ""
        return f"{trial.outcome.loop_seconds / self.reference_seconds:.3g}"

    def notes(self) -> list[str]:
        """The decision in words."""
        d, r = self.decision, self.reference
        unit = "pp" if self.unit == "pp" else "(relative)"
        lines = [f"reference (richest): {_describe(r.settings)}, loop {self.reference_seconds:.3g} s"]
        if len(self.replicas) > 1:
            mean, one = self.sampling_error()
            lines.append(f"reference: the mean of {len(self.replicas)} runs with independent seeds; sampling error of "
                         f"a reading up to {one:.3g} {unit} for one run, {mean:.3g} {unit} for the mean (standard "
                         "errors); every error is a run's distance from that mean plus twice its standard error")
        lines += [
                 f"decision: {_describe(d.settings)}: error {d.error:.3g} {unit} (tolerance {self.tolerance:g}), "
                 f"loop {d.outcome.loop_seconds:.3g} s, {self.speedup:.3g}x faster than the reference"]
        if self.command:
            lines.append(f"as options: {self.command}")
        spread = self.run_sampling(d)
        if spread:
            lines.append(f"decision: its deck is the verified run (seed {d.seed}); another seed would move a reading by "
                         f"about {spread:.3g} {unit} (one standard error at its parcel count)")
        if d is r and d.error > self.tolerance:
            lines.append(f"no setting holds the tolerance: one run of the reference itself lies {d.error:.3g} {unit} "
                         "from the converged estimate (its sampling error); plan with more particles at the top of "
                         "the ladder, or more replicas")
        for t in self.verified:
            if t is not d:
                verdict = "rejected" if t.error > self.tolerance else "also within the tolerance"
                lines.append(f"verified, {verdict}: {_describe(t.settings)} (predicted {t.predicted_error:.3g}, "
                             f"measured {t.error:.3g}, loop {t.outcome.loop_seconds:.3g} s)")
        for s in self._other_screens():
            if s.verdict == MEASURE:
                estimate = "no estimate" if s.change is None else f"estimated change {s.change:.3g} {unit}"
                lines.append(f"not measurable in this scene: {s.label} ({estimate}): left out")
        for t in self.models:
            lines.append(f"other model {_model_name(t)}: " + ("failed: " + t.outcome.failure if t.outcome.failure else
                         f"changes a reading by up to {t.error:.3g} {unit} against the reference"))
        return lines

    def trial_table(self) -> Table:
        """Every run: its settings, loop time, errors per observable."""
        names = sorted(self.reference.errors) or sorted(self.reference.outcome.observations)
        table = Table(["trial", *[k.name for k in self.knobs], "seed", "loop_s", "status",
                       *[f"error_{n}" for n in names], "max_error", "sampling_error", "predicted_error",
                       "predicted_cost_ratio"])
        for t in [*self.replicas, *self.trials, *self.verified, *self.models]:
            sampling = self.run_sampling(t)
            table.add(t.name, *[t.settings[k.name] for k in self.knobs], t.seed, f"{t.outcome.loop_seconds:.4g}",
                      "failed: " + t.outcome.failure if t.outcome.failure else "ok",
                      *[f"{t.errors.get(n, math.nan):.4g}" for n in names], f"{t.error:.4g}",
                      "" if sampling is None else f"{sampling:.4g}",
                      "" if t.predicted_error is None else f"{t.predicted_error:.4g}",
                      "" if t.predicted_cost is None else f"{t.predicted_cost:.4g}")
        return table

    def as_dict(self) -> dict:
        """Everything in the report, for scripts (report.json)."""
        def trial(t: Trial) -> dict:
            return {"name": t.name, "settings": t.settings, "seed": t.seed, "loop_seconds": t.outcome.loop_seconds,
                    "sampling_error": self.run_sampling(t),
                    "failure": t.outcome.failure, "errors": t.errors, "error": t.error if math.isfinite(t.error) else None,
                    "predicted_error": t.predicted_error, "predicted_cost_ratio": t.predicted_cost}
        return {"scene": self.scene_name, "unit": self.unit, "tolerance": self.tolerance,
                "knobs": [{"name": k.name, "kind": k.kind, "values": list(k.values)} for k in self.knobs],
                "screening": [s.__dict__ for s in self.screens], "fixed": {k: {"value": v, "estimated_error": e, "reason": w} for k, (v, e, w) in self.fixed.items()},
                "reference": trial(self.reference), "trials": [trial(t) for t in self.trials],
                "verified": [trial(t) for t in self.verified], "decision": trial(self.decision),
                "speedup": self.speedup, "command": self.command, "scene_options": self.scene_options,
                "replicas": [trial(t) for t in self.replicas],
                "models": [dict(trial(t), changes=self.model_changes(t)) for t in self.models],
                "reference_standard_error": {k: np.asarray(v).tolist() for k, v in (self.uncertainty or {}).items()},
                "candidates": [{"settings": s, "predicted_error": e, "predicted_cost_ratio": c}
                               for s, e, c in self.candidates]}

    def save(self, folder: Path) -> list[Path]:
        """effects.csv, trials.csv, report.json, plan.png."""
        folder = Path(folder)
        return [write_text(folder / "effects.csv", self.table().csv()),
                write_text(folder / "trials.csv", self.trial_table().csv()),
                *([write_text(folder / "models.csv", self.model_table().csv())] if self.models else []),
                write_text(folder / "report.json", json.dumps(self.as_dict(), indent=1, default=str) + "\n"),
                self.plot(folder / "plan.png")]

    def plot(self, path: Path) -> Path:
        """Error against cost: every priced candidate, the measured trials, the decision."""
        plt = figures.pyplot()
        fig, ax = plt.subplots(figsize=(7.5, 5))
        floor = self.tolerance / 100
        costs = [c for _, _, c in self.candidates]
        ax.scatter(costs, [max(e, floor) for _, e, _ in self.candidates], s=12, color="0.7",
                   label="candidates (predicted)")
        ax.scatter([], [], marker="o", color="C0", label="one knob changed (measured)")
        ref = self.reference_seconds
        for t in self.trials:
            if not t.outcome.failure:
                ax.scatter(t.outcome.loop_seconds / ref, max(t.error, floor), marker="o", color="C0")
                ax.annotate(t.name, (t.outcome.loop_seconds / ref, max(t.error, floor)), fontsize=7,
                            xytext=(3, 3), textcoords="offset points")
        for t in self.verified:
            if t.outcome.failure:
                continue
            if t is self.decision:
                color, label = "C2", "decision (verified)"
            else:
                color, label = ("C3", "rejected on verification") if t.error > self.tolerance else ("C1", "verified, dearer")
            ax.scatter(t.outcome.loop_seconds / ref, max(t.error, floor), marker="s", color=color, s=50, label=label)
        ax.scatter([1.0], [floor], marker="*", s=120, color="k", label="reference (error 0)")
        ax.axhline(self.tolerance, color="g", ls="--", lw=1, label=f"tolerance {self.tolerance:g}")
        ax.set(xscale="log", yscale="log", xlabel="loop time / reference's",
               ylabel="largest error of a reading [pp]" if self.unit == "pp" else "largest relative error",
               title=f"{self.scene_name}: error against cost")
        ax.legend(fontsize=7)
        return figures.save(fig, path)


def _describe(settings: dict) -> str:
    return ", ".join(f"{k}={v}" for k, v in settings.items())


def _model_name(t: Trial) -> str:
    """An other model's drag and hindrance, as the report names it."""
    return _describe({k: t.settings[k] for k in ("drag", "hindrance") if k in t.settings})


def _mean_loop(runs: list[Trial]) -> float:
    """The mean loop time of runs of one setting [s]."""
    return float(np.mean([r.outcome.loop_seconds for r in runs]))


def pin(scene, pins: dict[str, str]) -> None:
    """Fixes knobs at the user's values (NAME=VALUE): they are no longer planned, and the reference
    runs with them."""
    knobs = {k.name: k for k in scene.knobs}
    for name, text in pins.items():
        if name not in knobs:
            raise ValueError(f"unknown effect or resolution '{name}': this scene has {', '.join(knobs)}")
        knob = knobs[name]
        if knob.kind == "effect":
            value = next((v for v in knob.values if str(v) == text), None)
            if value is None:
                raise ValueError(f"{name} takes {', '.join(str(v) for v in knob.values)}, not '{text}'")
        elif isinstance(knob.values[0], (int, float)):
            try:
                number = float(text)
            except ValueError:
                number = math.nan
            if not (math.isfinite(number) and number > 0):
                raise ValueError(f"{name} is a resolution: it takes a number > 0, not '{text}'")
            value = type(knob.values[0])(number)
        else:
            value = text
        knobs[name] = replace(knob, values=(value,), drops=())
    scene.knobs = list(knobs.values())


def plan_effects(scene, out: Path, tolerance: float, jobs: int = 2, seed: int = 1, measure_all: bool = False,
                 progress: bool = True, name: str = "scene") -> Plan:
    """Screens, measures, decides and verifies; writes the trial runs under ``out/runs`` and the
    chosen scene under ``out/decision``.

    Parameters
    ----------
    scene : SampleScene or DeckScene
        The knobs and how to run them.
    out : Path
        Output folder, new or empty (`sediment plan` gives it a stage it publishes as one set).
    tolerance : float
        Largest error allowed (pp of percent finer for a test, relative for a deck).
    jobs : int
        Trials run at once (one rank each).
    seed : int
        Placement seed of the first reference run (a test); the other runs take the seeds after it, each
        its own, so the report is reproducible.
    measure_all : bool
        Measure every effect, also those the screening settled.
    progress : bool
        Show a progress bar.

    Returns
    -------
    Plan
    """
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"the tolerance must be > 0, not {tolerance:g}")
    if jobs < 1:
        raise ValueError("jobs must be >= 1")
    return _plan(scene, prepare(Path(out)), tolerance, jobs, seed, measure_all, progress, name)


def _plan(scene, out: Path, tolerance: float, jobs: int, seed: int, measure_all: bool, progress: bool,
          name: str) -> Plan:
    """plan_effects, into the empty folder `out`."""
    runs, decided = prepare(out / "runs"), prepare(out / "decision")
    seeds = itertools.count(seed)      # every run its own placement: errors include each run's sampling
    reference = Trial("reference", {k.name: k.values[0] for k in scene.knobs}, next(seeds))
    replicas = [reference] + [Trial(f"reference-{k + 1}", dict(reference.settings), next(seeds))
                              for k in range(1, scene.replicas)]
    if scene.screens_from_run:        # a deck prints its screening numbers: run it first
        _run_all(scene, [reference], runs, 1, progress, "reference")
        scene.screen_printed(reference.outcome.printed)
    screens = {s.effect: s for s in scene.screens}
    fixed: dict[str, tuple] = {}      # knob -> (value, estimated error, why) when screening settled it
    trials: list[Trial] = []
    for knob in scene.knobs:
        settled = None if measure_all else _screened(knob, screens)
        if settled is not None:
            fixed[knob.name] = settled
            continue
        trials += [Trial(knob.label(v), dict(reference.settings, **{knob.name: v}), next(seeds)) for v in knob.values[1:]]
    models = [Trial("model=" + "+".join(str(v) for v in m.values()), dict(reference.settings, **m), next(seeds))
              for m in scene.models]
    first = [] if scene.screens_from_run else replicas
    _run_all(scene, first + trials + models, runs, jobs, progress, "measure")
    failed = next((r for r in replicas if r.outcome.failure), None)
    if failed is not None:
        raise RuntimeError(f"the reference run {failed.name} failed: {failed.outcome.failure}")
    converged, uncertainty = scene.combine([r.outcome.observations for r in replicas])
    # the reference's loop time: the mean of its runs, which ran alongside the others
    reference_loop = _mean_loop(replicas)
    for t in trials + models + replicas:    # a replica's error: how far one run of the reference lies
        if not t.outcome.failure:
            t.errors = scene.error(t.outcome.observations, converged, uncertainty)

    options = {}                      # knob -> [(value, error, cost ratio)]
    for knob in scene.knobs:
        if knob.name in fixed:
            value, estimate, _ = fixed[knob.name]
            options[knob.name] = [(value, estimate, 1.0)]
            continue
        # Leaving an effect out does not make a step dearer: a ratio above 1 is timing noise.
        ceiling = 1.0 if knob.kind == "effect" else math.inf
        options[knob.name] = [(knob.values[0], 0.0, 1.0)] + [
            (t.settings[knob.name], t.error, min(ceiling, t.outcome.loop_seconds / reference_loop))
            for t in trials if t.settings[knob.name] != knob.values[0] and not t.outcome.failure]
    candidates = []
    for combo in itertools.product(*options.values()):
        settings = dict(zip(options, (v for v, _, _ in combo)))
        candidates.append((settings, sum(e for _, e, _ in combo), math.prod(c for _, _, c in combo)))
    # Cheapest first; at equal cost, the one that simulates fewer effects (a scene simulates only the
    # effects it calls for), then the smaller error.
    effects = [k for k in scene.knobs if k.kind == "effect"]
    candidates.sort(key=lambda c: (c[2], sum(len(k.values) - 1 - k.values.index(c[0][k.name]) for k in effects), c[1]))
    # The cheapest candidates within the tolerance are verified `jobs` at a time (alike in load to the
    # measured trials, so their loop times compare); the first in that order that holds is the decision.
    within = [c for c in candidates if c[1] <= tolerance][:VERIFY_ATTEMPTS]
    verified: list[Trial] = []
    decision = None
    while within and decision is None:
        batch, within = within[:jobs], within[jobs:]
        if batch[0][0] == reference.settings:
            decision = reference
            break
        batch = [Trial(f"decision-{len(verified) + k + 1}", settings, next(seeds), predicted_error=error,
                       predicted_cost=cost)
                 for k, (settings, error, cost) in enumerate(batch) if settings != reference.settings]
        _run_all(scene, batch, runs, jobs, progress, "verify")
        for trial in batch:
            if not trial.outcome.failure:
                trial.errors = scene.error(trial.outcome.observations, converged, uncertainty)
            verified.append(trial)
        decision = next((t for t in batch if t.error <= tolerance), None)
    if decision is None:
        decision = reference
    scene.write(decision.settings, decided, decision.seed)    # the decided deck is the run that was verified
    plan = Plan(name, scene.unit, tolerance, scene.knobs, scene.screens, reference, trials, verified, decision, fixed,
                candidates, scene.describe(decision.settings), scene.options_record(), replicas, uncertainty, models,
                converged)
    plan.save(out)
    return plan


def _screened(knob: Knob, screens: dict[str, Screen]) -> tuple | None:
    """(value, estimated error, reason) when the screening settles an effect knob: the cheapest value
    that only leaves out effects screened as negligible, if the next step leaves out one screened as
    needed (or there is none); None when a step in between needs measuring."""
    if knob.kind != "effect" or not knob.drops or any(d not in screens for d in knob.drops):
        return None
    estimate, reasons = 0.0, []
    for k, dropped in enumerate(knob.drops):
        s = screens[dropped]
        if s.verdict == MEASURE:
            return None
        if s.verdict == INCLUDE:
            return knob.values[k], estimate, "; ".join(reasons + [f"needs {s.label}: {s.reason}"])
        estimate += s.change or 0.0
        reasons.append(f"without {s.label}: {s.reason}")
    return knob.values[-1], estimate, "; ".join(reasons)


STUCK_AFTER_STOP = 120.0    # s: a trial whose thread outlives its stopped run by this much is a bug


def _trials_ended(futures) -> None:
    """Waits for the trials' threads once their runs are stopped. One that does not end (once seen, under
    load: a Ctrl-C the plan then waited on for ever) is a bug: every thread's stack goes to stderr, and
    the process ends with 130 rather than hang (the next command in the folder clears its stage)."""
    import faulthandler
    import os
    from concurrent.futures import wait

    # (a trial cancelled before it began is never 'done' to wait(): only those that began are waited on)
    if not wait([f for f in futures if not f.cancelled()], timeout=STUCK_AFTER_STOP).not_done:
        return
    print(f"sediment plan: a trial's thread did not end {STUCK_AFTER_STOP:g} s after its run was stopped; the "
          "threads' stacks follow (please report them); exiting", file=sys.stderr, flush=True)
    faulthandler.dump_traceback(file=sys.stderr, all_threads=True)
    os._exit(130)


def _run_all(scene, trials: list[Trial], runs: Path, jobs: int, progress: bool, what: str) -> None:
    """Runs the trials, `jobs` at a time, with a progress bar."""
    if not trials:
        return
    bar = None
    if progress:
        bar = progress_bar(total=len(trials), desc=f"plan: {what}", unit="run")
    pool = ThreadPoolExecutor(max_workers=jobs)
    futures: dict = {}    # filled one by one: a Ctrl-C while the trials are submitted finds those submitted
    try:
        for t in trials:
            futures[pool.submit(scene.run, t.settings, runs / t.name, t.seed)] = t
        for future in finished_in_turn(futures):
            futures[future].outcome = future.result()
            if bar is not None:
                bar.update()
    except BaseException:             # Ctrl-C, SIGTERM or a failed trial: no run outlives the plan
        pool.shutdown(wait=False, cancel_futures=True)
        scene.running.stop()
        _trials_ended(futures)
        raise
    finally:
        pool.shutdown(wait=True)
    if bar is not None:
        bar.close()
