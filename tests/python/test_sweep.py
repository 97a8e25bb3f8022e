# SPDX-License-Identifier: GPL-2.0-or-later
"""`sediment sweep`: runs, references, errors, failed runs, the table and figure, bad input."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from sediment import cli
from sediment.studies import sweep
from sediment.lab.psd import read_psd
from sediment.sim.layers import read_layers
from sediment.sim.scene import plan
from sediment.sim.scenefiles import write

PSDS = Path(__file__).resolve().parents[2] / "examples" / "granulometry" / "psd"

# A deck without atoms whose observables are known functions of dt and whose cost is 1000/dt empty
# steps; it fails for dt > 0.5.
TOY = """variable dt index 0.1
variable integrator index nve/sphere/fluid
if "${dt} > 0.5" then "no_such_command"
region box block 0 1 0 1 0 1
create_box 1 box
mass 1 1.0
timestep ${dt}
run $(round(1000/v_dt))
print "RESULT y $(1+v_dt*v_dt:%.17g)"
print "SERIES s 0 $(v_dt:%.17g)"
print "SERIES s 1 $(1+v_dt:%.17g)"
"""


@pytest.fixture
def toy(tmp_path: Path) -> Path:
    deck = tmp_path / "in.toy"
    deck.write_text(TOY)
    return deck


def test_errors_against_the_finest_run_and_failed_runs_are_kept(toy, tmp_path):
    result = sweep.run_sweep(toy, [0.2, 0.01, 1.0, 0.1], ["y", "s"], work_dir=tmp_path / "w", progress=False)
    assert [r.value for r in result.runs] == [0.01, 0.1, 0.2, 1.0]
    assert result.reference == "dt = 0.01"
    finest, coarse, coarser, failed = result.runs
    assert finest.error == 0.0
    assert coarse.errors["y"] == pytest.approx((0.1**2 - 0.01**2) / (1 + 0.01**2), rel=1e-12)
    assert coarse.errors["s"] == pytest.approx((0.1 - 0.01) / 1.01, rel=1e-12)
    assert coarser.error > coarse.error
    assert "no_such_command" in failed.failure and math.isinf(failed.error)
    assert all(r.loop_seconds > 0 for r in (finest, coarse, coarser))
    # the cheapest run within a tolerance, by loop time: here the loop times set to the step counts
    # (1000/dt), as a loaded machine cannot reorder them
    for r in (finest, coarse, coarser):
        r.loop_seconds = 1000 / r.value
    assert result.cheapest(0.05) is finest and result.cheapest(0.1) is coarse and result.cheapest(1.0) is coarser
    rows = result.table().csv().splitlines()
    assert rows[0].startswith("integrator,dt,loop_s,wall_s,status,y_value,s_value,y_error,s_error,max_error")
    assert len(rows) == 5 and "failed: ERROR" in rows[4] and rows[1].split(",")[4] == "ok"
    paths = result.save(tmp_path / "out", tolerance=0.01)
    assert all(p.stat().st_size > 0 for p in paths)


def test_analytic_references_for_a_scalar_and_a_series(toy, tmp_path):
    result = sweep.run_sweep(toy, [0.1, 0.3], ["y", "s"], references={"y": "1", "s": "x"},
                             work_dir=tmp_path, progress=False)
    assert result.reference == "analytic"
    for run in result.runs:
        assert run.errors["y"] == pytest.approx(run.value**2, rel=1e-12)
        assert run.errors["s"] == pytest.approx(run.value, rel=1e-12)
    assert result.summary(0.15)[1].startswith("runs: cheapest within 15 %: dt = 0.1 ")
    assert result.summary(0.05)[1] == "runs: no run within 5 %"
    assert result.table(0.05).text().rstrip().endswith("runs: no run within 5 %")


def test_bad_input_is_refused_with_the_reason(toy, tmp_path):
    with pytest.raises(ValueError, match="printed no RESULT or SERIES 'z'.*printed: s, y"):
        sweep.run_sweep(toy, [0.1], ["z"], work_dir=tmp_path, progress=False)
    with pytest.raises(ValueError, match="no 'variable courant index"):
        sweep.run_sweep(toy, [0.1], ["y"], parameter="courant", work_dir=tmp_path, progress=False)
    with pytest.raises(ValueError, match="unknown integrator 'rk4'"):
        sweep.run_sweep(toy, [0.1], ["y"], integrators=["rk4"], work_dir=tmp_path, progress=False)
    with pytest.raises(ValueError, match="a reference for 'q', which is not observed"):
        sweep.run_sweep(toy, [0.1], ["y"], references={"q": "1"}, work_dir=tmp_path, progress=False)
    with pytest.raises(ValueError, match="finite and > 0"):
        sweep.run_sweep(toy, [0.1, math.nan], ["y"], work_dir=tmp_path, progress=False)
    with pytest.raises(RuntimeError, match="every run failed"):
        sweep.run_sweep(toy, [1.0], ["y"], work_dir=tmp_path, progress=False)
    with pytest.raises(ValueError, match="NAME=VALUE"):
        sweep.parse_reference("speed")
    with pytest.raises(ValueError, match="cannot be evaluated"):
        sweep.evaluate_reference("__import__('os').getcwd()", None)
    with pytest.raises(FileNotFoundError):
        sweep.run_sweep(tmp_path / "missing", [0.1], ["y"], progress=False)


def test_cli_prints_table_and_cheapest_step(toy, tmp_path, capsys):
    out = tmp_path / "out"
    assert cli.main(["sweep", str(toy), "--dt", "0.01,0.1,0.2", "--observe", "y", "--out", str(out),
                     "--rayleigh", "0.5", "--tau", "0.1"]) == 0
    text = capsys.readouterr().out
    assert "dt_over_rayleigh_time dt_over_tau" in " ".join(text.split())
    assert (out / "sweep.csv").read_text().startswith("integrator,dt,dt_over_rayleigh_time,dt_over_tau,")
    assert "runs: cheapest within 1 %: dt = 0.1 " in text and "the 20 % Rayleigh-time step" in text
    assert (out / "sweep.png").stat().st_size > 0
    with pytest.raises(SystemExit):
        cli.main(["sweep", str(toy), "--dt", "0.1,-1", "--observe", "y"])
    assert cli.main(["sweep", str(toy), "--dt", "0.1", "--observe", "y", "--reference", "y"]) == 2
    assert "NAME=VALUE" in capsys.readouterr().err
    # a variable the deck never reads: every run the same (--parameter), or run as if not given
    plain = tmp_path / "in.plain"    # the toy without its integrator variable
    plain.write_text(TOY.replace("variable integrator index nve/sphere/fluid\n", ""))
    for deck, option, message in ((toy, ["--parameter", "dt_scale"], "--parameter dt_scale: "),
                                  (plain, ["--integrator", "implicit"], "--integrator integrator: "),
                                  (toy, ["--var", "flow", "yes"], "--var flow: ")):
        assert cli.main(["sweep", str(deck), "--dt", "0.1", "--observe", "y", "--out", str(tmp_path / "o"), *option]) == 2
        assert message in capsys.readouterr().err and not (tmp_path / "o").exists()


def test_readout_curves_of_a_scene_barely_move_with_the_step(tmp_path):
    """A small sedimentation scene at its planned steps and four times them: the readout curves are
    the observables (percent finer, as a fraction of the sample)."""
    scene = plan(read_psd(PSDS / "sample5.csv"), particles=1500, t_end=7200.0)
    deck = write(scene, tmp_path / "scene")[1]
    result = sweep.run_sweep(deck, [1, 4], ["hydrometer", "pipette"], parameter="dt_scale",
                             work_dir=tmp_path / "w", progress=False)
    planned, coarse = result.runs
    assert planned.error == 0.0 and len(planned.observations["hydrometer"].x) >= 5
    assert 0 < coarse.error < 0.02     # two percentage points
    # four times the step, a quarter of the steps (counted, not clocked; each stage rounds its count)
    steps = [read_layers(tmp_path / "w" / f"layers_run_{k}.h5").step[-1] for k in (1, 4)]
    assert steps[1] == pytest.approx(steps[0] / 4, rel=0.02)
    assert planned.loop_seconds > 0 and coarse.loop_seconds > 0


def test_whole_values_reach_the_deck_as_integers():
    # A deck variable read as an integer (compute concentration/grid every ${field_every}) must get
    # "10", not "10.0"; other values go exactly.
    assert sweep.deck_number(10.0) == "10"
    assert sweep.deck_number(1.0) == "1"
    assert sweep.deck_number(0.001) == "0.001"
    assert sweep.deck_number(2.5) == "2.5"
    assert float(sweep.deck_number(1e300)) == 1e300
