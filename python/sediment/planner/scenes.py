# SPDX-License-Identifier: GPL-2.0-or-later
"""The scenes the planner can measure, each as a set of knobs (an effect or a resolution, values
ordered from the richest to the cheapest) and a way to run one setting of them and score it.

- `SampleScene`: a sedimentation test written by `sediment sample`; knobs hindrance (richardson-zaki,
  none), drag (standard, stokes), particles and courant; observables the instruments' readings, errors in
  points of percent finer; the reference replicated with independent seeds (its sampling error), and the
  other drag models of the literature measured against it.
- `DeckScene`: any deck that reads ``variable effect_NAME index yes`` for each effect it can switch
  (and any ladder variables given), prints its observables as ``RESULT``/``SERIES`` lines (as for
  `sediment sweep`) and may print ``SCREEN number value`` lines; errors relative.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _core
from ..results import write_text
from ..sim.deck import deck_text, index_variables
from ..sim.observe import observe, relative_error
from ..sim.printed import parse_printed
from ..sim.process import Runs
from ..sim.run import run_batch
from ..constants import DRAGS, HINDRANCES
from ..sim.scene import FLOW_CELLS_ACROSS, MAX_FLOW_CELLS
from .screening import INCLUDE, MEASURE, OMIT, Screen, SedimentationTest, screen, verdict_of



@dataclass(frozen=True)
class Knob:
    """Something the planner can set: an effect or a resolution, richest value first. For an effect,
    `drops[k]` names the screened effect that going from values[k] to values[k + 1] leaves out."""

    name: str
    values: tuple
    kind: str                 # "effect" or "resolution"
    drops: tuple = ()

    def label(self, value) -> str:
        """name=value, as trials and reports name a setting."""
        return f"{self.name}={value}"


@dataclass
class Outcome:
    """What one run of a setting gave."""

    loop_seconds: float = math.nan
    wall_seconds: float = math.nan
    observations: dict = field(default_factory=dict)    # name: what the scene's error() compares
    failure: str | None = None
    printed: dict[str, float] = field(default_factory=dict)    # SCREEN numbers a deck printed


def prepare(folder: Path) -> Path:
    """A new or empty folder for the planner's runs, its decision or a contact measurement (created);
    ValueError naming it if it holds anything."""
    folder = Path(folder)
    if folder.exists() and any(not p.name.startswith(".sediment") for p in folder.iterdir()):
        raise ValueError(f"{folder} is not empty: the planner writes into a new or empty folder")
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def decided_options(report: Path) -> tuple[dict, dict]:
    """The `sediment sample` options (drag, hindrance, particles, courant) a plan of a sedimentation
    test decided, and the test it was made for, from its report.json."""
    import json

    try:
        content = json.loads(Path(report).read_text())
        decision = content["decision"]["settings"]
        if decision["drag"] not in DRAGS:
            raise ValueError(f"drag '{decision['drag']}'")
        # a plan made before the hindrance was its own choice: hindered only under drag difelice
        hindrance = decision.get("hindrance", "difelice" if decision["drag"] == "difelice" else "none")
        if hindrance not in HINDRANCES:
            raise ValueError(f"hindrance '{hindrance}'")
        particles, courant = decision["particles"], decision["courant"]
        if not (isinstance(particles, int) and particles > 0):
            raise ValueError(f"particles {particles!r}")
        if not (isinstance(courant, (int, float)) and math.isfinite(courant) and courant > 0):
            raise ValueError(f"courant {courant!r}")
        if not isinstance(content.get("scene_options"), dict):
            raise ValueError("test options (scene_options): a plan of an earlier version, or damaged")
        two_way = decision.get("two_way", False)    # switched on by a measurement (--measure-flow) that needed it
        if not isinstance(two_way, bool):
            raise ValueError(f"two_way {two_way!r}")
        flow_cells = decision.get("flow_cells", FLOW_CELLS_ACROSS)    # the grid it was measured on
        if not (isinstance(flow_cells, int) and 4 <= flow_cells <= MAX_FLOW_CELLS and _core.fft_friendly(flow_cells)):
            raise ValueError(f"flow_cells {flow_cells!r}")
        return ({"drag": decision["drag"], "hindrance": hindrance, "particles": particles, "courant": float(courant),
                 "two_way": two_way, "flow_cells": flow_cells}, content["scene_options"])
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{report} is not a plan's report.json: {exc}") from None
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"{report} is not the plan of a sedimentation test (no decided {exc})") from None


# The drag models of the literature the planner measures against its reference (the standard curve with
# Richardson & Zaki's hindrance): (drag, hindrance), Bravo et al.'s model first.
MODELS = (("difelice", "difelice"), ("dallavalle", "richardson-zaki"), ("schiller-naumann", "difelice"),
          ("standard", "garside"), ("standard", "difelice"))


class SampleScene:
    """A sedimentation test (`sediment sample` options) as knobs and runs."""

    unit = "pp"
    screens_from_run = False          # screened from the PSD and the cylinder, before any run

    def __init__(self, test: SedimentationTest, options: dict, particles: list[int], courant: list[float],
                 tolerance: float, replicas: int = 3, models: bool = True):
        self.test = test
        self.options = options              # further keyword arguments of scene.plan
        self.water_record: tuple = ()       # the water's temperature over the test (--temperature-record)
        self.running = Runs()           # runs under way (stopped together on an interrupt)
        if not particles or any(p < 1 for p in particles):
            raise ValueError("the particle ladder needs at least one count >= 1")
        if not courant or any(not c > 0 for c in courant):
            raise ValueError("the courant ladder needs at least one value > 0")
        if replicas < 1:
            raise ValueError("the reference needs at least one run (replicas >= 1)")
        self.replicas = replicas            # reference runs with independent seeds
        for count in (max(particles), min(particles)):    # a scene the test cannot have fails here, not in a run
            self._scene({"drag": "standard", "hindrance": "richardson-zaki", "particles": count,
                         "courant": min(courant)}, 1)
        self.screens = screen(test, tolerance)
        self.knobs = [Knob("hindrance", ("richardson-zaki", "none"), "effect", ("hindered",)),
                      Knob("drag", ("standard", "stokes"), "effect", ("law",)),
                      Knob("particles", tuple(sorted(set(particles), reverse=True)), "resolution"),
                      Knob("courant", tuple(sorted(set(courant))), "resolution")]
        self.models = [{"drag": d, "hindrance": h} for d, h in MODELS] if models else []

    def describe(self, settings: dict) -> str:
        """The `sediment sample` options of a setting."""
        return (f"--drag {settings['drag']} --hindrance {settings['hindrance']} --particles {settings['particles']} "
                f"--courant {settings['courant']:g}" + (" --two-way" if settings.get("two_way") else "")
                + (f" --flow-cells {settings['flow_cells']}" if settings.get("two_way") and "flow_cells" in settings
                   else ""))

    def options_record(self) -> dict:
        """The test besides the knobs, as `sediment sample --plan` checks it."""
        t = self.test
        return dict(self.options, mass=t.mass, particle_density=t.suspension.particle_density,
                    cylinder_area=t.cylinder.area, height=t.cylinder.height, temperature=t.suspension.temperature,
                    temperature_record=[list(r) for r in self.water_record],
                    psd={"diameter_um": (t.psd.diameter * 1e6).tolist(), "percent_finer": t.psd.percent_finer.tolist()})

    def _scene(self, settings: dict, seed: int):
        from ..sim.scene import Effects, plan
        t = self.test
        scene = plan(t.psd, cylinder=t.cylinder, mass=t.mass, suspension=t.suspension, seed=seed,
                     particles=int(settings["particles"]), courant=float(settings["courant"]),
                     effects=Effects(settings["drag"], hindrance=settings["hindrance"],
                                     flow=settings.get("two_way", False)),
                     flow_cells=settings.get("flow_cells", FLOW_CELLS_ACROSS), **self.options)
        scene.water_record = self.water_record
        return scene

    def write(self, settings: dict, folder: Path, seed: int) -> Path:
        """Writes the scene of a setting into `folder`; returns its deck."""
        from ..sim.scenefiles import write
        write(self._scene(settings, seed), Path(folder))
        return Path(folder) / "in.sedimentation"

    def run(self, settings: dict, folder: Path, seed: int) -> Outcome:
        """Writes and runs a setting (one rank) and reads the instruments from its layer file."""
        from ..lab.granulometry import read_all
        from ..lab.readout import Column
        from ..sim.layers import read_layers

        deck = self.write(settings, folder, seed)
        out = run_batch(deck, {"overwrite": "yes"}, ranks=1, check=False, running=self.running)
        outcome = Outcome(sum(s for s, _ in out.loops), out.wall_seconds)
        if out.error:
            outcome.failure = out.error
            return outcome
        layers = read_layers(Path(folder) / "layers.h5")
        if not layers.complete:
            outcome.failure = "the layer file is incomplete"
            return outcome
        readings, _ = read_all(Column.from_layers(layers), list(self.test.instruments),
                               cylinder_area=self.test.cylinder.area)
        outcome.observations = {r.instrument: (r.time, r.percent_finer) for r in readings}
        return outcome

    @staticmethod
    def combine(observations: list[dict]) -> tuple[dict, dict]:
        """The mean readings of replicated runs (the estimate of the converged answer) and the standard
        error of that mean per reading [pp] (the spread of single runs over sqrt(runs); 0 for one run)."""
        mean, error = {}, {}
        for name, (x, _) in observations[0].items():
            y = np.array([o[name][1] for o in observations])
            mean[name] = (x, y.mean(axis=0))
            error[name] = y.std(axis=0, ddof=1) / math.sqrt(len(y)) if len(y) > 1 else np.zeros(len(x))
        return mean, error

    @staticmethod
    def error(run: dict, reference: dict, uncertainty: dict | None = None) -> dict[str, float]:
        """Largest |P - P_ref| [pp] per instrument, over the reading times both have, each reading's
        difference raised by twice the standard error of the reference at it (the distance from the
        converged answer that the reference's own sampling cannot rule out)."""
        errors = {}
        for name, (x_ref, y_ref) in reference.items():
            if name not in run:
                errors[name] = math.inf
                continue
            x, y = run[name]
            common, i, j = np.intersect1d(x, x_ref, return_indices=True)
            margin = 2 * uncertainty[name][j] if uncertainty else 0.0
            errors[name] = float(np.max(np.abs(y[i] - y_ref[j]) + margin)) if len(common) else math.inf
        return errors


# Screening numbers a deck may print (SCREEN name value), the effect each settles, and how: an
# estimate of the relative change of the observables, or a rule on the number itself.
def _hindrance_change(phi: float) -> float:
    return 1 - (1 - phi) ** 4.65            # Richardson & Zaki: the settling speed of the suspension


def _inertial_drag_change(reynolds: float) -> float:
    return 0.15 * reynolds ** 0.687         # Schiller & Naumann's correction to Stokes drag


DECK_SCREENS = {
    "solid_fraction": ("hindered", "initial solid fraction", _hindrance_change),
    "reynolds": ("law", "largest particle Reynolds number", _inertial_drag_change),
    "yield_number": ("yield", "yield number tau_y / (drho g d)", None),
    "grains": ("contacts", "grains in the scene", None),
    "surface_crossings": ("submergence", "grains crossing the free surface", None),
}


class DeckScene:
    """A deck with effect variables (and ladder variables) as knobs and runs."""

    unit = "relative"
    screens_from_run = True           # screened from the SCREEN lines of the reference run

    def __init__(self, deck: Path, observables: list[str], ladders: dict[str, list[str]], tolerance: float,
                 variables: dict[str, str] | None = None, ranks: int = 1):
        self.deck = Path(deck).resolve()
        if not self.deck.is_file():
            raise FileNotFoundError(f"{deck}: no such deck")
        if not observables:
            raise ValueError("nothing to observe: give at least one --observe NAME (a RESULT or SERIES the deck prints)")
        text = deck_text(self.deck)
        effects = re.findall(r"^\s*variable\s+effect_(\w+)\s+index\s+(\S+)", text, re.MULTILINE)
        if not effects:
            raise ValueError(f"{deck}: the deck exposes no effects (no 'variable effect_NAME index yes' lines)")
        for name, default in effects:
            if default not in ("yes", "no"):
                raise ValueError(f"{deck}: effect_{name} must default to yes or no, not '{default}'")
        declared = index_variables(self.deck)
        for name in ladders:
            if name not in declared:
                raise ValueError(f"{deck}: the deck has no 'variable {name} index ...' for the ladder to set")
        self.observables = observables
        self.tolerance = tolerance
        self.running = Runs()           # runs under way (stopped together on an interrupt)
        self.variables = dict(variables or {})
        self.ranks = ranks
        self.knobs = [Knob(name, ("yes", "no"), "effect", (name,)) for name, _ in effects]
        self.knobs += [Knob(name, tuple(values), "resolution") for name, values in ladders.items()]
        self.screens: list[Screen] = []
        self.replicas = 1                   # a deck's runs take no seed: one reference run
        self.models: list[dict] = []

    def options_record(self) -> dict:
        """The deck and the variables every run had."""
        return {"deck": str(self.deck), "variables": self.variables, "ranks": self.ranks}

    def describe(self, settings: dict) -> str:
        """The -var options of a setting."""
        return " ".join(f"-var {name} {value}" for name, value in self._knob_values(settings).items())

    def _knob_values(self, settings: dict) -> dict:
        """The deck variables a setting sets: effect_NAME for an effect, the ladder's own name."""
        resolutions = {k.name for k in self.knobs if k.kind == "resolution"}
        return {k if k in resolutions else f"effect_{k}": v for k, v in settings.items()}

    def _values(self, settings: dict) -> dict:
        """Every deck variable of a run of a setting: those every run has, then the setting's."""
        return dict(self.variables, **self._knob_values(settings))

    def screen_printed(self, printed: dict[str, float]) -> None:
        """Screens the deck's effects from the numbers its reference run printed."""
        effects = {k.name for k in self.knobs if k.kind == "effect"}
        for number, value in printed.items():
            if number not in DECK_SCREENS:
                continue
            effect, label, estimate = DECK_SCREENS[number]
            if effect not in effects and not (effect == "contacts" and "lubrication" in effects):
                continue
            if estimate is not None:
                change = estimate(value)
                verdict = verdict_of(change, self.tolerance)
                reason = f"changes the observables by about {change:.3g} (relative)"
            elif number == "grains":
                change, verdict = None, OMIT if value <= 1 else MEASURE
                reason = "a single grain has nothing to touch" if value <= 1 else f"{value:g} grains may touch"
            elif number == "yield_number":
                change, verdict = None, OMIT if value == 0 else INCLUDE
                reason = "a Newtonian fluid: no yield machinery" if value == 0 else "the yield stress holds or slows the grains"
            else:
                change, verdict = None, OMIT if value == 0 else INCLUDE
                reason = "no grain crosses the surface" if value == 0 else f"{value:g} grains cross the surface"
            targets = [effect] + (["lubrication"] if effect == "contacts" and verdict == OMIT else [])
            for target in targets:
                if target in effects:
                    self.screens.append(Screen(target, target, label, value, change, verdict, reason))

    def write(self, settings: dict, folder: Path, seed: int) -> Path:
        """A deck that runs the planned one with the setting: it defines the index variables first
        (LAMMPS keeps the first definition of an index variable, also in included files), moves to
        the deck's folder, as the trials ran, so that its relative paths hold, and includes it."""
        values = self._values(settings)
        lines = [f"# The setting `sediment plan` decided for {self.deck.name} (and the variables it was planned with).",
                 f"#   lmp_sediment -in {self.deck.name}     (runs {self.deck} in its own folder)"]
        lines += [f"variable        {name} index {value}" for name, value in values.items()]
        lines += [f'shell           cd "{self.deck.parent}"', f'include         "{self.deck}"']
        return write_text(Path(folder) / self.deck.name, "\n".join(lines) + "\n")

    def run(self, settings: dict, folder: Path, seed: int) -> Outcome:
        """Runs the deck from its own folder with the setting as -var pairs."""
        out = run_batch(self.deck, self._values(settings), ranks=self.ranks, check=False, running=self.running)
        outcome = Outcome(sum(s for s, _ in out.loops), out.wall_seconds)
        if out.error:
            outcome.failure = out.error
            return outcome
        try:
            found = observe(out.text, self.observables, None)
        except ValueError as exc:
            outcome.failure = str(exc)
            return outcome
        outcome.observations = found
        outcome.printed = parse_printed(out.text).screens
        return outcome

    @staticmethod
    def combine(observations: list[dict]) -> tuple[dict, None]:
        """The one reference run's observables (a deck runs without a seed)."""
        return observations[0], None

    @staticmethod
    def error(run: dict, reference: dict, uncertainty=None) -> dict[str, float]:
        """Relative error per observable (a series: largest difference over the reference's magnitude)."""
        return {k: relative_error(run[k], ref) if k in run else math.inf for k, ref in reference.items()}
