# SPDX-License-Identifier: GPL-2.0-or-later
"""The error budget of a simulated sedimentation test (docs/error-budget.md): how far each instrument's
readings move [points of percent finer] when one modelling choice that the literature or the laboratory
leaves uncertain is changed, against the best physics (the standard drag curve with Richardson & Zaki's
hindrance, water at the recorded temperature).

Every simulated choice runs the same scene with the same placement (seed) as the reference, so the
change is the choice's and not sampling; the sampling error itself is a row of its own, from replicas
with independent seeds. The laboratory reduces every run as it would the real test: with water at the
recorded temperature (the composite correction of the hydrometer takes out the density of the water and
dispersant, so only the settling feels them). The cylinder wall and Brownian motion are not simulated
(the sub-volume is periodic; grains carry no thermal noise): their rows are analytic estimates.

Rows of three kinds: the uncertainties of the best physics ("physical"; their root sum of squares is the
band a readout can put around a simulated reading), the literature's other models ("model": how far
each lies from the best physics, e.g. Bravo et al.'s), and the resolution ("numerical").
"""
from __future__ import annotations

import json
import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import figures
from ..constants import (BOLTZMANN, D422_CYLINDER_HEIGHT, INSTRUMENTS, LAB_TEMPERATURE, PIPETTE_DEPTH, SPECIMEN_MASS,
                         SPHERE_DEPTH_SHARE)
from ..lab.granulometry import read_all
from ..lab.psd import PSD
from ..lab.readout import SCHEDULES, Column, Suspension
from ..lab.settling import terminal_speeds
from ..planner.scenes import SampleScene
from ..progress import bar as progress_bar
from ..results import Table, write_text
from ..sim.layers import read_layers
from ..sim.process import finished_in_turn
from ..sim.run import run_batch
from ..sim.scene import Cylinder, Effects, plan
from ..sim.scenefiles import write

# 5 g/L of sodium hexametaphosphate (125 mL of a 40 g/L solution in 1000 mL, ASTM D422 and D7928): an
# estimate, not a measurement: the solute's mass less the water it displaces at an apparent specific
# volume of about 0.4 mL/g gives +3 kg/m3; a dilute electrolyte's viscosity rises by about 1 %.
DISPERSANT_DENSITY_RISE = 3.0      # kg/m3
DISPERSANT_VISCOSITY_RATIO = 1.01


@dataclass(frozen=True)
class Choice:
    """One modelling choice changed against the reference."""

    key: str
    label: str
    # "physical": an uncertainty of the best physics (its rows make the band); "model": another model of
    # the literature, how far it lies from the best physics; "numerical": the resolution
    kind: str
    effects: dict = field(default_factory=dict)    # Effects fields that differ from the reference
    temperature: float = 0.0      # water warmer (+) or colder (-) than recorded [C]
    dispersant: bool = False
    drag_factor: float = 1.0      # the fluid's viscosity times this: the low-Re drag times this
    courant_factor: float = 1.0


CHOICES = (
    Choice("curve", "drag curve: 1 % more drag (the standard curve against Davies's fit below Re = 4)", "physical",
           drag_factor=1.01),
    Choice("exponent", "hindrance exponent: Garside & Al-Dibouni's 5.1 instead of Richardson & Zaki's 4.7",
           "physical", {"hindrance": "garside"}),
    Choice("warmer", "water 1 C warmer than recorded", "physical", temperature=1.0),
    Choice("colder", "water 1 C colder than recorded", "physical", temperature=-1.0),
    Choice("dispersant", "5 g/L sodium hexametaphosphate (estimated +3 kg/m3, +1 % viscosity)", "physical",
           dispersant=True),
    Choice("courant", "time step: 4 times the reference's Courant number", "numerical", courant_factor=4.0),
    Choice("dallavalle", "drag curve: Dallavalle's instead of the standard curve", "model", {"drag": "dallavalle"}),
    Choice("voidage", "hindrance function: Di Felice's instead of Richardson & Zaki's", "model",
           {"hindrance": "difelice"}),
    Choice("mixture", "mixture buoyancy on top of the measured exponent", "model", {"buoyancy": "mixture"}),
    Choice("bravo", "Bravo et al.'s model (Dallavalle's curve, Di Felice's hindrance)", "model",
           {"drag": "difelice"}),
)


@dataclass
class Budget:
    """The budget of one test: the largest change of each instrument's readings per row."""

    name: str
    reference: str
    rows: list[tuple[str, str, str, dict]]    # key, label, kind, {instrument: pp}
    # the test it is the budget of: its PSD (diameter_um, percent_finer), mass [kg] and temperature [C]
    made_for: dict = field(default_factory=dict)

    def physical_total(self) -> dict[str, float]:
        """Root sum of squares of the physical rows per instrument (both temperature rows count as one,
        the larger: they are one uncertain quantity)."""
        changes = {k: c for k, _, kind, c in self.rows if kind == "physical"}
        pairs = (("warmer", "colder"),)
        total = {}
        for name in INSTRUMENTS:
            terms = []
            for key, change in changes.items():
                pair = next((p for p in pairs if key in p), None)
                if pair and key != pair[0]:
                    continue
                value = max(changes.get(k, {}).get(name, 0.0) for k in pair) if pair else change.get(name, 0.0)
                terms.append(value)
            total[name] = float(math.sqrt(sum(t * t for t in terms)))
        return total

    def table(self) -> Table:
        """Each row's largest change per instrument, then the physical total."""
        table = Table(["row", "kind", *[f"{n}_pp" for n in INSTRUMENTS], "choice"],
                      notes=[f"{self.name}: largest change of a reading against {self.reference}"])
        for key, label, kind, change in self.rows:
            table.add(key, kind, *[f"{change.get(n, math.nan):.3g}" for n in INSTRUMENTS], label)
        total = self.physical_total()
        table.add("physical", "total", *[f"{total[n]:.3g}" for n in INSTRUMENTS],
                  "root sum of squares of the physical rows")
        return table

    def as_dict(self) -> dict:
        """Everything in the table, for scripts (budget.json)."""
        return {"sample": self.name, "reference": self.reference,
                "rows": [{"row": k, "label": label, "kind": kind, "change_pp": c} for k, label, kind, c in self.rows],
                "physical_total_pp": self.physical_total(), "made_for": self.made_for}


def _readings(layer_file: Path, lab: Suspension, cylinder: Cylinder) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The instruments' readings of a run, reduced as the laboratory would (water at the recorded temperature)."""
    layers = read_layers(layer_file)
    if not layers.complete:
        raise RuntimeError(f"{layer_file} is incomplete")
    column = replace(Column.from_layers(layers), suspension=lab)
    found, _ = read_all(column, list(INSTRUMENTS), cylinder_area=cylinder.area)
    return {r.instrument: (np.asarray(r.time), np.asarray(r.percent_finer)) for r in found}


def brownian_change(psd: PSD, lab: Suspension,
                    depths=(PIPETTE_DEPTH, SPHERE_DEPTH_SHARE * D422_CYLINDER_HEIGHT)) -> float:
    """Largest change of a reading from Brownian motion [pp], estimated: a grain's arrival at the
    sensing depth L is spread by sqrt(2 D L / v) about L / v (Stokes-Einstein D, Stokes v), which
    blurs the diameter a reading resolves by half that relative spread; the reading moves by the
    PSD's slope dP / d ln D times it, at every depth and reading time of the schedules."""
    times = np.array(sorted(set(SCHEDULES["d422"] + SCHEDULES["bravo"]))) * 60.0
    kelvin = 273.15 + (lab.temperature if lab.temperature is not None else LAB_TEMPERATURE)
    worst = 0.0
    for depth in depths:
        d = np.asarray(lab.stokes_diameter(depth, times), float)
        diffusion = BOLTZMANN * kelvin / (3 * math.pi * lab.viscosity * d)
        spread = np.sqrt(2 * diffusion / (lab.stokes_speed(d) * depth)) / 2
        h = 0.01
        slope = (psd.at(d * math.exp(h)) - psd.at(d * math.exp(-h))) / (2 * h)
        worst = max(worst, float(np.max(np.abs(slope) * spread)))
    return worst


def wall_change(psd: PSD, lab: Suspension, cylinder: Cylinder) -> float:
    """Largest change of a reading from the cylinder wall [pp], estimated: Ladenburg's slowing
    1 / (1 + 2.1 d / D) of each grain, read from analytic columns (as the planner's screening)."""
    from ..planner.screening import ReadingModel, SedimentationTest

    test = SedimentationTest(psd, lab, cylinder)
    single = lambda d: terminal_speeds(lab, d)    # noqa: E731
    model = ReadingModel(test, single)
    return model.change(lambda d: single(d) / (1 + 2.1 * d / cylinder.diameter))


def error_budget(psd: PSD, folder: Path, *, particles: int = 20000, courant: float = 2.0, replicas: int = 3,
                 temperature: float = LAB_TEMPERATURE, mass: float = SPECIMEN_MASS, cylinder: Cylinder = Cylinder(),
                 seed: int = 1, jobs: int = 2, progress: bool = True, choices=CHOICES, name: str = "",
                 **options) -> Budget:
    """Runs the reference and every choice of one test under `folder` and returns its budget.

    Parameters
    ----------
    psd : PSD
        The sample.
    folder : Path
        Where the runs go (one subfolder each).
    particles, courant : int, float
        The reference's resolution.
    replicas : int
        Reference runs with independent seeds, for the sampling row.
    temperature : float
        The recorded water temperature [C]: the reference's water and every reduction's.
    mass, cylinder, seed, options
        The test, as for `sim.scene.plan`.
    jobs : int
        Runs at once.
    name : str
        The sample's name in the report (default: the PSD's).
    """
    name = name or psd.name or "sample"
    if replicas < 2:
        raise ValueError("the sampling row needs at least 2 replicas")
    lab = Suspension.at_temperature(temperature)
    reference = Effects()
    runs: dict[str, tuple] = {}    # key: (effects, suspension, courant, seed)
    for k in range(replicas):
        runs["reference" if k == 0 else f"replica-{k + 1}"] = (reference, lab, courant, seed + k)
    for c in choices:
        water = Suspension.at_temperature(temperature + c.temperature) if c.temperature else lab
        if c.dispersant:
            water = replace(water, fluid_density=water.fluid_density + DISPERSANT_DENSITY_RISE,
                            viscosity=water.viscosity * DISPERSANT_VISCOSITY_RATIO, temperature=None)
        if c.drag_factor != 1.0:
            water = replace(water, viscosity=water.viscosity * c.drag_factor, temperature=None)
        runs[c.key] = (replace(reference, **c.effects), water, courant * c.courant_factor, seed)

    def one(key: str) -> dict:
        effects, water, step, placement = runs[key]
        scene = plan(psd, cylinder=cylinder, mass=mass, suspension=water, particles=particles, courant=step,
                     effects=effects, seed=placement, **options)
        write(scene, folder / key)
        out = run_batch(folder / key / "in.sedimentation", {"overwrite": "yes"}, ranks=1, check=False)
        if out.error:
            raise RuntimeError(f"run {key} of {name} failed: {out.error}")
        return _readings(folder / key / "layers.h5", lab, cylinder)

    bar = None
    if progress:
        bar = progress_bar(total=len(runs), desc=f"budget {name}", unit="run")
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {key: pool.submit(one, key) for key in runs}
        for _ in finished_in_turn(futures.values()):
            if bar is not None:
                bar.update()
    if bar is not None:
        bar.close()
    results = {key: future.result() for key, future in futures.items()}    # in the runs' order, as before
    ref = results["reference"]
    rows = []
    for c in choices:
        rows.append((c.key, c.label, c.kind, SampleScene.error(results[c.key], ref)))
    sampled = [results[k] for k in results if k == "reference" or k.startswith("replica-")]
    spread = {n: float(np.max(np.std([r[n][1] for r in sampled], axis=0, ddof=1))) for n in ref}
    rows.append(("parcels", f"sampling: one standard error of a reading at {particles} parcels ({replicas} seeds)",
                 "numerical", spread))
    wall = wall_change(psd, lab, cylinder)
    rows.append(("wall", "cylinder wall (Ladenburg; analytic, not simulated)", "physical",
                 {n: wall for n in INSTRUMENTS}))
    brownian = brownian_change(psd, lab)
    rows.append(("brownian", "Brownian motion (front spread; analytic, not simulated)", "physical",
                 {n: brownian for n in INSTRUMENTS}))
    described = f"standard drag curve + Richardson & Zaki, water at {temperature:g} C, {particles} parcels, Courant {courant:g}"
    made_for = {"diameter_um": (psd.diameter * 1e6).tolist(), "percent_finer": psd.percent_finer.tolist(),
                "mass_kg": mass, "temperature_C": temperature}
    return Budget(name, described, rows, made_for)


def save(budgets: list[Budget], folder: Path) -> list[Path]:
    """budget.csv (every sample's rows), budget.json, budget.png."""
    folder = Path(folder)
    table = Table(["sample", "row", "kind", *[f"{n}_pp" for n in INSTRUMENTS], "choice"])
    for b in budgets:
        for key, label, kind, change in b.rows:
            table.add(b.name, key, kind, *[f"{change.get(n, math.nan):.3g}" for n in INSTRUMENTS], label)
        total = b.physical_total()
        table.add(b.name, "physical", "total", *[f"{total[n]:.3g}" for n in INSTRUMENTS],
                  "root sum of squares of the physical rows")
    paths = [write_text(folder / "budget.csv", table.csv()),
             write_text(folder / "budget.json", json.dumps([b.as_dict() for b in budgets], indent=1) + "\n")]
    paths.append(plot(budgets, folder / "budget.png"))
    return paths


def plot(budgets: list[Budget], path: Path) -> Path:
    """One panel per sample: each row's largest change per instrument."""
    plt = figures.pyplot()
    fig, axes = plt.subplots(1, len(budgets), figsize=(3.2 * len(budgets) + 2.5, 4.5), sharey=True, squeeze=False)
    keys = [k for k, *_ in budgets[0].rows] + ["physical"]
    y = np.arange(len(keys))
    for ax, b in zip(axes[0], budgets):
        changes = {k: c for k, _, _, c in b.rows}
        changes["physical"] = b.physical_total()
        for n, name in enumerate(INSTRUMENTS):
            ax.barh(y + (n - 1) * 0.27, [changes[k].get(name, 0.0) for k in keys], height=0.27, label=name)
        ax.set(title=b.name, xlabel="largest change of a reading [pp]", xscale="log", xlim=(1e-3, 30))
        ax.grid(axis="x", alpha=0.3)
    axes[0][0].set_yticks(y, keys)
    axes[0][0].invert_yaxis()
    axes[0][-1].legend(fontsize=8)
    fig.suptitle("Error budget: change of the readings per modelling choice, against the best physics")
    return figures.save(fig, path)


def budget_entry(budget_file: Path, sample: str | None = None) -> dict:
    """The budget of one sample in a budget.json (its physical totals checked: points of percent finer)."""
    what = f"{budget_file} is not a budget.json of `sediment budget`"
    try:
        content = json.loads(Path(budget_file).read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{what}: {exc}") from None
    if not (isinstance(content, list) and content and all(isinstance(b, dict) and isinstance(b.get("sample"), str)
                                                          and isinstance(b.get("physical_total_pp"), dict)
                                                          for b in content)):
        raise ValueError(f"{what}: a list of samples, each with its physical_total_pp, was expected")
    if sample is None and len(content) > 1:
        raise ValueError(f"{budget_file} holds {len(content)} samples ({', '.join(b['sample'] for b in content)}): "
                         "name one")
    chosen = content[0] if sample is None else next((b for b in content if b["sample"] == sample), None)
    if chosen is None:
        raise ValueError(f"{budget_file} has no sample '{sample}'")
    try:
        band = {k: float(v) for k, v in chosen["physical_total_pp"].items()}
    except (TypeError, ValueError):
        band = {}
    if not band or not all(math.isfinite(v) and 0 <= v <= 100 for v in band.values()):
        raise ValueError(f"{what}: the physical totals of '{chosen['sample']}' are not points of percent finer "
                         "(numbers from 0 to 100)")
    return chosen | {"physical_total_pp": band}


def band_of(budget_file: Path, sample: str | None = None) -> dict[str, float]:
    """The physical total of a budget (budget.json), per instrument [pp]: the band the physical
    uncertainty puts around a simulated reading of that test."""
    return budget_entry(budget_file, sample)["physical_total_pp"]


def made_for_psd(entry: dict) -> PSD | None:
    """The PSD a budget entry was made for, where it records one (budgets of SEDIMENT 0.1.0 before this)."""
    made = entry.get("made_for") or {}
    try:
        return PSD(np.asarray(made["diameter_um"], float) * 1e-6, np.asarray(made["percent_finer"], float))
    except (KeyError, TypeError, ValueError):
        return None
