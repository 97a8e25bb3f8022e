# SPDX-License-Identifier: GPL-2.0-or-later
"""What two-way coupling changes in a sedimentation test, measured (docs/effects.md section 3, "The
papers' one-way assumption").

The screening bounds the swirls from above with Segre et al.'s measurements. This measures them: the
test's column of parcels FLOW_SWIRLS swirls wide and the cylinder's height, placed independently,
under `fix fluid/flow` (each parcel stirring the fluid as its real grains do), and its one-way twin:
the same data file, deck and schedule, with the fluid at rest (`-var flow no`; the flow may shorten the
two-way run's steps, fix fluid/flow's cfl, and the readings are taken at the instruments' times). A draw is the
pair; the readings' changes are paired per draw, so the parcels' sampling error, which both share,
drops out of the change. Draws with independent seeds give its standard error, and the first draw
run again on a coarser grid on the same schedule (its twin, the same, run again beside it) shows what
the grid changes.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np

from .. import _core
from ..results import Table
from ..sim.process import Runs, results_of
from ..sim.run import run_batch
from ..sim.scene import Effects, Scene, plan
from ..sim.scenefiles import write
from .screening import SedimentationTest


@dataclass
class FlowMeasurement:
    """The readings of every draw, two-way and one-way, per instrument."""

    scene: Scene | None                 # the first draw's (its width, grid, parcels and steps)
    seeds: list[int]
    times: dict[str, np.ndarray] = field(default_factory=dict)       # reading times [s] per instrument
    two_way: dict[str, np.ndarray] = field(default_factory=dict)     # [draw, reading] percent finer
    one_way: dict[str, np.ndarray] = field(default_factory=dict)
    loop_seconds: list[tuple[float, float]] = field(default_factory=list)    # per draw: two-way, one-way
    check: FlowMeasurement | None = None    # the first draw on a coarser grid (measure_flow's check_cells)

    def changes(self) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Per instrument: reading times, the mean change two-way minus one-way [pp] and its standard
        error (the spread of the draws' changes over sqrt(draws); nan for one draw)."""
        out = {}
        for name, times in self.times.items():
            change = self.two_way[name] - self.one_way[name]
            error = (change.std(axis=0, ddof=1) / math.sqrt(len(change)) if len(change) > 1
                     else np.full(len(times), np.nan))
            out[name] = (times, change.mean(axis=0), error)
        return out

    def largest(self) -> tuple[str, float, float, float]:
        """The reading whose mean change is largest: instrument, time [s], change and standard error [pp]."""
        best = ("", math.nan, 0.0, math.nan)
        for name, (times, change, error) in self.changes().items():
            k = int(np.argmax(np.abs(change)))
            if abs(change[k]) >= abs(best[2]):
                best = (name, float(times[k]), float(change[k]), float(error[k]))
        return best

    def grid_check(self) -> tuple[int, int, float, float] | None:
        """The first draw's change at the largest reading on its grid and on the check's: (cells across,
        the check's, change, the check's change) [pp]; None without a check."""
        if self.check is None or self.scene is None or self.check.scene is None:
            return None
        name, at, _, _ = self.largest()
        k = int(np.flatnonzero(self.times[name] == at)[0])
        change = self.two_way[name][0, k] - self.one_way[name][0, k]
        coarse = self.check.two_way[name][0, k] - self.check.one_way[name][0, k]
        return self.scene.flow_cells, self.check.scene.flow_cells, float(change), float(coarse)

    def verdict(self, tolerance: float) -> str:
        """Whether the one-way assumption holds at `tolerance` [pp]: the largest mean change with two
        standard errors either way, within or beyond it, or not resolved by these draws."""
        _, _, change, error = self.largest()
        if len(self.seeds) < 2:
            return "not resolved: one draw gives no standard error (--flow-seeds 2 or more)"
        margin = 2 * error if math.isfinite(error) else math.inf
        if abs(change) + margin <= tolerance:
            return "holds: two-way coupling moves no reading beyond the tolerance"
        if abs(change) - margin > tolerance:
            return ("fails: two-way coupling moves a reading beyond the tolerance (simulate it: sediment sample "
                    "--two-way)")
        return "not resolved: the change is within two standard errors of the tolerance (more draws: --flow-seeds)"

    def table(self) -> Table:
        """Every reading: instrument, time, mean one-way and two-way percent finer, change, standard error."""
        table = Table(["instrument", "time_min", "one_way", "two_way", "change_pp", "standard_error_pp"],
                      notes=[f"{len(self.seeds)} draws (seeds {', '.join(map(str, self.seeds))}), each two-way and "
                             "its one-way twin; changes paired per draw"])
        for name, (times, change, error) in self.changes().items():
            for k, t in enumerate(times):
                table.add(name, f"{t / 60:.4g}", f"{self.one_way[name][:, k].mean():.3f}",
                          f"{self.two_way[name][:, k].mean():.3f}", f"{change[k]:+.3f}", f"{error[k]:.3f}")
        return table


def switch_on(plan_folder: Path, scene, measured: FlowMeasurement, tolerance: float) -> None:
    """Puts two-way coupling into a plan whose measurement found it moves a reading beyond the
    tolerance: the decision's settings get two_way (`sediment sample --plan` then writes the column
    under the flow), its deck in decision/ is rewritten so, and report.json records the measurement."""
    import json

    from ..results import write_text

    report_path = Path(plan_folder) / "report.json"
    report = json.loads(report_path.read_text())
    decision = report["decision"]
    decision["settings"]["two_way"] = True
    if measured.scene is not None:    # the grid it was measured on
        decision["settings"]["flow_cells"] = measured.scene.flow_cells
    name, at, change, error = measured.largest()
    report["two_way"] = {"seeds": measured.seeds, "instrument": name, "time_s": at, "change_pp": change,
                         "standard_error_pp": error if math.isfinite(error) else None, "tolerance_pp": tolerance,
                         "verdict": measured.verdict(tolerance)}
    scene.write(decision["settings"], Path(plan_folder) / "decision", decision["seed"])
    write_text(report_path, json.dumps(report, indent=1, default=str) + "\n")


def flow_scene(test: SedimentationTest, seed: int, **options) -> Scene:
    """The two-way column of the test (`sediment sample --two-way` with these `plan` options)."""
    return plan(test.psd, cylinder=test.cylinder, mass=test.mass, suspension=test.suspension, seed=seed,
                effects=Effects(flow=True), **options)


def measure_draw(test: SedimentationTest, scene: Scene, folder: Path, running: Runs | None = None,
                 on_progress: Callable[[int, int], None] | None = None) -> tuple[dict, dict, tuple[float, float]]:
    """Runs one draw in `folder` (its one-way twin in one/, the column in two/, one rank each) and reads
    both: (two-way readings, one-way readings, their loop seconds), readings as {instrument: (times,
    percent finer)}. `on_progress(done, total)` follows the two-way run's steps."""
    seconds = {}
    for kind, flow in (("one", "no"), ("two", "yes")):
        where = Path(folder) / kind
        write(scene, where)
        reader = _step_counter(on_progress) if kind == "two" and on_progress is not None else None
        try:
            out = run_batch(where / "in.sedimentation", {"flow": flow, "overwrite": "yes"}, running=running,
                            on_line=reader)
        except RuntimeError as exc:
            if "the scene runs away" not in str(exc):
                raise
            # the steps were planned from the start's flow; swirls that outgrow it cannot be followed
            raise RuntimeError(f"seed {scene.seed}'s column: the swirls outgrew the steps planned from the start's "
                               f"flow ({scene.flow_speed() * 1e3:.3g} mm/s rms), and the run stopped before its "
                               f"result went wrong: this column cannot be measured at these steps (a finer grid, "
                               f"--flow-cells, plans shorter ones; docs/effects.md section 3).\n  {exc}") from None
        seconds[kind] = sum(s for s, _ in out.loops)
    return (*read_draw(test, folder), (seconds["two"], seconds["one"]))


def coarser_cells(scene: Scene) -> int | None:
    """The grid check's cells across for a two-way column: of the coarser grids of cubic cells over the
    same width and height whose sizes the FFTs take (fix fluid/flow's cells are cubes), the one nearest
    three quarters of the scene's cells (16 x 16 x 480: 12 x 12 x 360); at least 4 across, None if
    there is none."""
    cells, up = scene.flow_grid()
    sizes = [n for n in range(4, cells) if (up * n) % cells == 0 and _core.fft_friendly(n)
             and _core.fft_friendly(up * n // cells)]
    return min(sizes, key=lambda n: abs(n - 0.75 * cells)) if sizes else None


def draw_name(seed: int, check_cells: int | None = None) -> str:
    """The folder of a draw in a measurement: seed_N, or seed_N_cells_M for the grid check's."""
    return f"seed_{seed}" + (f"_cells_{check_cells}" if check_cells is not None else "")


def measure_flow(test: SedimentationTest, seeds: list[int], folder: Path, jobs: int = 1, running: Runs | None = None,
                 draw: Callable | None = None, check_cells: int | None = None, **options) -> FlowMeasurement:
    """The draws of `seeds` in folder/seed_N, `jobs` at once (`draw(test, scene, folder)` runs one:
    measure_draw by default), gathered into a FlowMeasurement. With `check_cells`, the first draw's
    parcels also run with that many cells across at the first draw's steps (their twin with them), in
    folder/seed_N_cells_M: the measurement's `check`. A draw that fails stops the others (through
    `running`) and raises."""
    from concurrent.futures import ThreadPoolExecutor

    draw = draw or (lambda test, scene, where: measure_draw(test, scene, where, running=running))
    scenes = [flow_scene(test, seed, **options) for seed in seeds]
    folders = [Path(folder) / draw_name(seed) for seed in seeds]
    if check_cells is not None:
        # the same parcels, width, frames and steps: its twin is the first draw's, run again
        scenes.append(replace(scenes[0], flow_cells=check_cells, flow_step_cells=scenes[0].flow_cells))
        folders.append(Path(folder) / draw_name(seeds[0], check_cells))
    with ThreadPoolExecutor(max_workers=max(1, min(jobs, len(scenes)))) as pool:
        futures = [pool.submit(draw, test, scene, where) for scene, where in zip(scenes, folders)]
        try:
            results = results_of(futures)
        except BaseException:    # Ctrl-C or a failed draw: stop the others too
            if running is not None:
                running.stop()
            raise
    measured = gather(scenes[0], seeds, results[:len(seeds)])
    if check_cells is not None:
        measured.check = gather(scenes[-1], seeds[:1], results[len(seeds):])
    return measured


def gather(scene: Scene | None, seeds: list[int],
           results: list[tuple[dict, dict, tuple[float, float]]]) -> FlowMeasurement:
    """The draws' (two-way readings, one-way readings, loop seconds) as one FlowMeasurement."""
    measured = FlowMeasurement(scene, list(seeds))
    for two, one, seconds in results:
        measured.loop_seconds.append(seconds)
        for name, (times, finer) in two.items():
            measured.times[name] = times
            for kind, value in (("two_way", finer), ("one_way", one[name][1])):
                rows = getattr(measured, kind)
                rows[name] = np.vstack([rows[name], value]) if name in rows else np.atleast_2d(value)
    return measured


def read_draw(test: SedimentationTest, folder: Path) -> tuple[dict, dict]:
    """The readings of a draw that has run: (two-way, one-way) from folder/two and folder/one."""
    return _readings(test, Path(folder) / "two" / "layers.h5"), _readings(test, Path(folder) / "one" / "layers.h5")


def _readings(test: SedimentationTest, layers_file: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    from ..lab.granulometry import read_all
    from ..lab.readout import Column
    from ..sim.layers import read_layers

    layers = read_layers(layers_file)
    if not layers.complete:
        raise RuntimeError(f"{layers_file}: the run's frames stop before the end of the test")
    found, _ = read_all(Column.from_layers(layers), list(test.instruments), cylinder_area=test.cylinder.area)
    return {r.instrument: (np.asarray(r.time, float), np.asarray(r.percent_finer, float)) for r in found}


def _step_counter(report: Callable[[int, int], None]) -> Callable[[str], None]:
    """A reader of a `sediment sample` deck's output reporting (step, steps) at each thermo row."""
    total = [0]

    def read(line: str) -> None:
        planned = re.match(r"SEDIMENT plan steps (\d+)", line)
        if planned:
            total[0] = int(planned.group(1))
            return
        words = line.split()
        if total[0] and len(words) >= 3 and words[0].isdigit():
            report(min(int(words[0]), total[0]), total[0])

    return read
