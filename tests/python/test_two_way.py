# SPDX-License-Identifier: GPL-2.0-or-later
"""The test's column under two-way coupling: `sediment sample --two-way` (sediment.sim.scene, Effects.flow)
and `sediment plan --measure-flow` (sediment.planner.flow)."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from sediment import _core, cli
from sediment.constants import SWIRL_LENGTH
from sediment.lab.psd import read_psd
from sediment.planner.flow import FlowMeasurement, coarser_cells, measure_flow
from sediment.planner.screening import SedimentationTest
from sediment.sim import scene as sc
from sediment.sim.scenefiles import STRATIFICATION, write

REPO = Path(__file__).resolve().parents[2]
SAMPLE2 = REPO / "examples" / "granulometry" / "psd" / "sample2.csv"


@pytest.fixture(scope="module")
def column():
    return sc.plan(read_psd(SAMPLE2), effects=sc.Effects(flow=True))


def test_the_column_is_three_swirls_wide_in_cubic_cells_the_ffts_take(column):
    across, tall = column.flow_grid()
    swirl = sc.swirl_length(column.psd, column.volume_fraction_of_solids)
    assert swirl == pytest.approx(SWIRL_LENGTH * 29.5e-6 * 0.0226 ** (-1 / 3), rel=0.05)    # a = 29.5 um: 4.2 mm
    # the fewest cubic cells up the height that the FFTs take, at most three swirls' width each 16
    fewest = math.ceil(column.height * 16 / (3 * swirl))
    assert _core.fft_friendly(tall) and not any(_core.fft_friendly(n) for n in range(fewest, tall))
    assert (across, column.width / across) == (16, pytest.approx(column.height / tall, rel=1e-12))
    assert 2.85 * swirl < column.width <= 3 * swirl


def test_another_grid_keeps_cubic_cells_and_a_check_grid_keeps_the_parcels(column):
    """--flow-cells 12 plans the same width on 12 x 12 x 360 cubic cells; the grid check of a
    measurement (coarser_cells: 12 for 16) reruns the first draw's very parcels on its grid at the first
    draw's steps, so that its one-way twin is the first draw's and the grid is all that differs."""
    twelve = sc.plan(read_psd(SAMPLE2), effects=sc.Effects(flow=True), flow_cells=12)
    assert twelve.flow_grid() == (12, 360) and twelve.width == pytest.approx(column.width)
    # over 480 cells up a check grid's must be whole and a size the FFTs take: 12 x 12 x 360
    assert [coarser_cells(dataclasses.replace(column, flow_cells=n, width=column.height * n / up))
            for n, up in ((16, 480), (24, 480), (8, 480), (16, 125), (4, 480))] == [12, 18, 6, None, None]
    check = dataclasses.replace(column, flow_cells=coarser_cells(column), flow_step_cells=16)
    assert check.flow_grid() == (12, 360) and check.position is column.position
    assert check.stages() == column.stages()
    assert sum(n for _, n in twelve.stages()) < sum(n for _, n in column.stages())    # its own, larger steps


def test_the_parcels_start_independent_so_their_counts_fluctuate_as_the_grains(column):
    """The flow is driven by the fluctuation of the grains' density: the counts of parcels in the
    cells of a quarter of the width are Poisson (dispersion 1), not the stratified start's (a half)."""
    cells = np.floor(column.position / (column.width / 4)).astype(int)
    _, counts = np.unique(cells[:, 0] + 4 * cells[:, 1] + 16 * cells[:, 2], return_counts=True)
    assert counts.var() / counts.mean() == pytest.approx(1.0, abs=0.15)
    stratified = sc.plan(read_psd(SAMPLE2), width=column.width)
    cells = np.floor(stratified.position / (column.width / 4)).astype(int)
    _, counts = np.unique(cells[:, 0] + 4 * cells[:, 1] + 16 * cells[:, 2], return_counts=True)
    assert counts.var() / counts.mean() < 0.6    # 0.51


def test_each_stage_keeps_the_flow_within_its_courant_number_and_ends_where_the_settling_stage_does(column):
    flow_stages, settling = column.stages(), column._settling_stages()
    assert len(flow_stages) == len(settling)
    time, last, every = 0.0, math.inf, column.frame_steps()
    for (dt, n), (dt_settle, n_settle) in zip(flow_stages, settling):
        assert dt * n == pytest.approx(dt_settle * n_settle, rel=1e-12) and n % every == 0
        assert dt <= min(dt_settle, column.flow_time_step(time), 2 * last) * (1 + 1e-12)
        time, last = time + dt * n, dt
    assert time == pytest.approx(column.t_end, rel=1e-12)
    # the first step: the grid's largest velocity (4.5 rms) carries a parcel half a cell (less the
    # rounding of the stage to whole frames)
    carried = flow_stages[0][0] * sc.FLOW_PEAK * column.flow_speed(0.0) / (column.width / 16)
    assert 0.49 < carried <= 0.5


def test_the_start_drives_the_flow_the_schedule_estimates(column, tmp_path):
    """The parcels at their terminal slip after two steps of the first stage: the fluid velocity they
    read (fix fluid/flow, the column's mirror images included) has the root mean square flow_speed
    estimates on the periodic grid (4.55 against 4.30 mm/s), and the grid's largest velocity is
    FLOW_PEAK = 4.5 times that estimate within a fifth (4.33)."""
    from sediment.sim.run import run_batch
    from sediment.sim.scenefiles import write_data

    write_data(column, tmp_path / "column.data")
    across, tall = column.flow_grid()
    f = column.suspension
    (tmp_path / "in.start").write_text(f"""units si
atom_style sphere
boundary p p f
fix weights all property/atom d_weight
read_data column.data fix weights NULL Weights
comm_modify cutoff 1e-9
fix grav all gravity {f.gravity!r} vector 0 0 -1
fix water all fluid density {f.fluid_density!r} viscosity {f.viscosity!r}
fix buoy all fluid/buoyancy water
fix drag all fluid/drag water law standard
fix flow all fluid/flow water grid {across} {across} {tall} column 0 {column.height!r} weight d_weight every 1
fix step all nve/sphere/fluid
timestep {column.stages()[0][0]!r}
run 2
write_dump all custom u.txt id f_flow[1] f_flow[2] f_flow[3] modify format float %.10g
print "RESULT peak $(f_flow[5])"
""")
    out = run_batch(tmp_path / "in.start")
    u = np.loadtxt(tmp_path / "u.txt", skiprows=9)[:, 1:]
    estimate = column.flow_speed(0.0)
    assert np.sqrt((u ** 2).sum(axis=1).mean()) == pytest.approx(estimate, rel=0.12)
    assert out.results["peak"] == pytest.approx(sc.FLOW_PEAK * estimate, rel=0.2)


def test_the_deck_runs_the_flow_or_its_one_way_twin(column, tmp_path):
    from sediment.sim.run import run_batch

    write(column, tmp_path)
    deck = (tmp_path / "in.sedimentation").read_text()
    across, tall = column.flow_grid()
    assert "variable        flow index yes" in deck
    assert (f'if "${{flow}} == yes" then "fix             flow all fluid/flow water grid {across} {across} {tall} '
            f'column 0 {column.height:.12g} weight d_weight stratification ${{stratification}} cfl {sc.FLOW_COURANT:g}"') in deck
    assert 'if "$(v_reached) == 0" then &' in deck
    assert f"variable        stratification index {STRATIFICATION} " in deck
    assert f"fix             step all nve/sphere/fluid floor z 0.0 surface z {column.height:.12g}" in deck
    typo = run_batch(tmp_path / "in.sedimentation", {"flow": "yse"}, check=False)
    assert typo.returncode == 2 and "variable flow must be yes or no, not yse" in typo.text
    typo = run_batch(tmp_path / "in.sedimentation", {"stratification": "grain"}, check=False)
    assert typo.returncode == 2 and "variable stratification must be parcels or grains, not grain" in typo.text
    assert "fluid/flow" not in (write(sc.plan(read_psd(SAMPLE2)), tmp_path / "one") and
                                (tmp_path / "one" / "in.sedimentation").read_text())


@pytest.mark.parametrize("options, message", [
    ({"geometry": "slab"}, "two-way coupling is simulated in a column"),
    ({"flow_cells": 14}, "a product of 2, 3 and 5"),
    ({"flow_cells": 3}, "4 or more cells across"),
    ({"flow_cells": 64}, r"grid would be 64 x 64 x 1850 cells \(7.58e\+06, about 2.3 GB\), beyond 4.19e\+06"),
    ({"particles": None, "effects": sc.Effects(flow=True, contacts=True)}, "two-way coupling is simulated in a column"),
])
def test_a_two_way_scene_it_cannot_simulate_is_refused(options, message):
    options.setdefault("effects", sc.Effects(flow=True))
    with pytest.raises(ValueError, match=message):
        sc.plan(read_psd(SAMPLE2), **options)


@pytest.mark.parametrize("arguments, message", [
    (["--screen-only", "--flow-seeds", "2"], "--flow-seeds sets the draws of --measure-flow: give both"),
    (["--screen-only", "--flow-cells", "12"], "--flow-cells sets the draws of --measure-flow: give both"),
    (["--screen-only", "--measure-flow", "--flow-cells", "14"], "a product of 2, 3 and 5 (the sizes LAMMPS's FFTs"),
    (["--screen-only", "--measure-flow", "--flow-cells", "1000"], "grid would be 1000 x 1000 x 28906 cells"),
    (["--screen-only", "--measure-flow", "--flow-seeds", "1000000000"], "at most 100 draws"),
    (["--screen-only", "--measure-flow", "--flow-seeds", "0"], "--flow-seeds: must be >= 1, got 0"),
    (["--screen-only", "--measure-flow", "--geometry", "slab"], "two-way coupling is simulated in a column"),
])
def test_plan_refuses_a_flow_measurement_it_cannot_make_before_running_anything(arguments, message, tmp_path,
                                                                                 capsys):
    out = tmp_path / "plan"
    try:
        code = cli.main(["plan", str(SAMPLE2), *arguments, "--out", str(out)])
    except SystemExit as stop:    # argparse's own refusals
        code = stop.code
    assert code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_the_changes_are_paired_per_draw_and_their_verdict_holds_two_standard_errors(column):
    """measure_flow with draws that return known readings: the change is two-way minus one-way per draw,
    its standard error the draws' spread over sqrt(draws); a verdict only beyond two of them."""
    times = np.array([60.0, 120.0])
    offsets = {1: 0.0, 2: 2.0, 3: 4.0}    # a draw's own sampling error: the same in both runs of it

    def draw(test, scene, folder):
        base = np.array([80.0, 60.0]) + offsets[scene.seed]
        change = np.array([1.0 + 0.1 * scene.seed, -0.2]) * (0.5 if scene.flow_cells == 12 else 1.0)
        return {"pipette": (times, base + change)}, {"pipette": (times, base)}, (2.0, 1.0)

    test = SedimentationTest(read_psd(SAMPLE2), instruments=("pipette",))
    measured = measure_flow(test, [1, 2, 3], Path("unused"), draw=draw, check_cells=12, t_end=600.0)
    # the grid check: the first draw's change at the largest reading, on 16 and on 12 cells across
    assert measured.grid_check() == (16, 12, pytest.approx(1.1), pytest.approx(0.55))
    _, change, error = measured.changes()["pipette"]
    assert change == pytest.approx([1.2, -0.2]) and error == pytest.approx([0.1 / math.sqrt(3), 0.0], abs=1e-12)
    assert measured.largest() == ("pipette", 60.0, pytest.approx(1.2), pytest.approx(0.1 / math.sqrt(3)))
    assert measured.verdict(0.5).startswith("fails") and measured.verdict(2.0).startswith("holds")
    assert measured.verdict(1.2).startswith("not resolved")
    one = FlowMeasurement(measured.scene, [1], {"pipette": times}, {"pipette": measured.two_way["pipette"][:1]},
                          {"pipette": measured.one_way["pipette"][:1]})
    assert one.verdict(5.0) == "not resolved: one draw gives no standard error (--flow-seeds 2 or more)"
    assert one.grid_check() is None


def test_a_column_whose_swirls_outgrow_its_steps_says_so(column, tmp_path, monkeypatch):
    """fix fluid/flow stops a run the flow carries across the box between solves; the measurement then
    says what that means for the column (its steps were planned from the start's flow), not LAMMPS's
    advice alone (a timestep or a grid a --measure-flow user cannot set)."""
    import sediment.planner.flow as flow

    def runaway(deck, variables, **_):
        if variables["flow"] == "yes":
            raise RuntimeError("in.sedimentation failed (exit 1): ERROR: Fix fluid/flow: the flow carries spheres "
                               "6.25 cells between solves, more than half the box across: the scene runs away")
        return type("Out", (), {"loops": [(1.0, 1)]})()

    monkeypatch.setattr(flow, "run_batch", runaway)
    with pytest.raises(RuntimeError, match=r"seed 1's column: the swirls outgrew the steps planned from the start's "
                                           r"flow \(4.3 mm/s rms\)(.|\n)*6.25 cells between solves"):
        flow.measure_draw(SedimentationTest(read_psd(SAMPLE2)), column, tmp_path)


def test_plan_measures_a_short_column_two_ways_and_its_twin(tmp_path):
    """`sediment plan --measure-flow` end to end on a short column (6 cm, 2000 parcels, the buoyancy
    sphere's readings in the first minute; the machinery, not the physics of a test): both runs of each
    draw and of the grid check finish, and flow.csv and flow.json hold the paired changes."""
    out = tmp_path / "plan"
    assert cli.main(["plan", str(SAMPLE2), "--screen-only", "--measure-flow", "--flow-seeds", "2", "--height", "0.06",
                     "--t-end", "60", "--instruments", "buoyancy", "--particles", "2000", "--jobs", "2",
                     "--out", str(out)]) == 0
    summary = json.loads((out / "flow.json").read_text())
    assert summary["seeds"] == [1, 2] and summary["grid"][:2] == [16, 16] and 1900 < summary["parcels"] < 2100
    assert summary["largest"]["instrument"] == "buoyancy" and math.isfinite(summary["largest"]["change_pp"])
    # the grid check: seed 1 again on 12 cells across, with its own twin
    check = summary["grid_check"]
    assert check["cells"] == 16 and check["check_cells"] == 12 and math.isfinite(check["check_change_pp"])
    assert "grid 12 12 " in (out / "flow" / "seed_1_cells_12" / "two" / "in.sedimentation").read_text()
    rows = (out / "flow.csv").read_text().splitlines()
    assert rows[0].startswith("instrument,time_min,one_way,two_way,change_pp") and len(rows) == 3
    for seed in (1, 2):
        for kind in ("one", "two"):
            assert (out / "flow" / f"seed_{seed}" / kind / "layers.h5").is_file()


def test_a_measurement_that_fails_puts_the_flow_into_the_plan(column, tmp_path, capsys):
    """Where two-way coupling moves a reading beyond the tolerance it is on in the plan: switch_on sets
    the decision's two_way, rewrites its deck under the flow, records the measurement, and `sediment
    sample --plan` then writes the two-way column."""
    from sediment.planner.flow import switch_on
    from sediment.planner.scenes import SampleScene, decided_options

    test = SedimentationTest(read_psd(SAMPLE2))
    scene = SampleScene(test, {"geometry": "column", "width": None, "classes": 40, "layers": 400, "t_end": 86400.0},
                        [2000], [4.0], 0.5)
    settings = {"drag": "standard", "hindrance": "richardson-zaki", "particles": 2000, "courant": 4.0}
    scene.write(settings, tmp_path / "decision", 1)
    (tmp_path / "report.json").write_text(json.dumps({"decision": {"settings": settings, "seed": 1},
                                                      "scene_options": scene.options_record()}))
    assert decided_options(tmp_path / "report.json")[0]["two_way"] is False
    times = np.array([44.5])
    failing = FlowMeasurement(dataclasses.replace(column, flow_cells=12), [1, 2], {"pipette": times}, {"pipette": np.array([[60.0], [61.0]])},
                              {"pipette": np.array([[50.0], [50.5]])})
    switch_on(tmp_path, scene, failing, 0.5)
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["two_way"]["change_pp"] == pytest.approx(10.25) and report["two_way"]["verdict"].startswith("fails")
    assert decided_options(tmp_path / "report.json")[0]["two_way"] is True
    assert decided_options(tmp_path / "report.json")[0]["flow_cells"] == 12    # the grid it was measured on
    assert "fluid/flow water grid 12 12 " in (tmp_path / "decision" / "in.sedimentation").read_text()
    assert cli.main(["sample", str(SAMPLE2), "--plan", str(tmp_path / "report.json"), "--out",
                     str(tmp_path / "sample")]) == 0
    assert "fluid/flow water grid 12 12 " in (tmp_path / "sample" / "in.sedimentation").read_text()
    # the plan decides the coupling and its grid: another wish is refused, not dropped
    for wish in (["--flow-cells", "16"], ["--two-way", "--flow-cells", "8"]):
        assert cli.main(["sample", str(SAMPLE2), "--plan", str(tmp_path / "report.json"), *wish, "--out",
                         str(tmp_path / "other")]) == 2
        assert "decided two-way coupling on 12 cells across: --flow-cells would change that" in capsys.readouterr().err
    report["decision"]["settings"]["flow_cells"] = 10**9
    (tmp_path / "report.json").write_text(json.dumps(report))
    with pytest.raises(ValueError, match="no decided flow_cells 1000000000"):
        decided_options(tmp_path / "report.json")
