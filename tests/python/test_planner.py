# SPDX-License-Identifier: GPL-2.0-or-later
"""`sediment plan`: scenes whose answer is known, the decision and its verification, a reproducible
report, bad input refused with the reason."""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from sediment import cli
from sediment.lab.psd import read_psd
from sediment.planner.contacts import ReducedScene, coarse_part, measure_contacts
from sediment.planner.plan import plan_effects
from sediment.planner.scenes import DeckScene, SampleScene
from sediment.planner.screening import INCLUDE, OMIT, SedimentationTest, screen
from sediment.sim.run import run_batch

REPO = Path(__file__).resolve().parents[2]
SUSPENSION = REPO / "examples" / "planner" / "in.suspension"
PASTE = REPO / "examples" / "paste" / "in.ball_in_paste"
SAMPLE5 = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"


def _plan(out: Path, *args: str) -> dict:
    assert cli.main(["plan", *map(str, args), "--out", str(out)]) == 0
    return json.loads((out / "report.json").read_text())


def _trial_names(report: dict) -> set[str]:
    return {t["name"] for t in report["trials"]}


def test_a_dilute_suspension_does_not_call_for_hindrance(tmp_path):
    """phi = 1e-3: Richardson & Zaki slow the suspension by 1 - 0.999^4.65 = 0.46 %, which the
    screening cannot dismiss at a 1 % tolerance (it is above a quarter of it), so it is measured,
    found within the tolerance, and left out."""
    report = _plan(tmp_path, "--deck", SUSPENSION, "--observe", "speed", "--var", "phi", "0.001")
    assert "hindered=no" in _trial_names(report)
    change = next(t for t in report["trials"] if t["name"] == "hindered=no")["error"]
    assert change == pytest.approx(1 - 0.999 ** 4.65, rel=0.05)
    assert report["decision"]["settings"]["hindered"] == "no"
    assert report["decision"]["error"] <= 0.01
    # the decided deck runs the planned one with the decision, from anywhere
    decided = run_batch(tmp_path / "decision" / "in.suspension", cwd=tmp_path).results["speed"]
    settings = {f"effect_{k}": v for k, v in report["decision"]["settings"].items()}
    assert decided == run_batch(SUSPENSION, dict(settings, phi=0.001)).results["speed"]


def test_a_suspension_at_a_tenth_calls_for_hindrance(tmp_path):
    """phi = 0.1: 39 % slower; the screening keeps the hindrance without a run."""
    report = _plan(tmp_path, "--deck", SUSPENSION, "--observe", "speed", "--var", "phi", "0.1")
    assert report["fixed"]["hindered"]["value"] == "yes"
    assert "hindered=no" not in _trial_names(report)
    assert report["decision"]["settings"]["hindered"] == "yes"


def test_a_single_grain_never_calls_for_contacts(tmp_path):
    report = _plan(tmp_path, "--deck", SUSPENSION, "--observe", "speed", "--var", "cells", "1")
    assert report["fixed"]["contacts"]["value"] == "no"
    assert "contacts=no" not in _trial_names(report)
    assert report["decision"]["settings"]["contacts"] == "no"


def test_a_newtonian_fluid_never_calls_for_the_yield_machinery(tmp_path):
    for k in range(1, 6):
        yield_screen = next(s for s in screen(SedimentationTest(read_psd(SAMPLE5.with_name(f"sample{k}.csv"))))
                            if s.effect == "yield")
        assert yield_screen.verdict == OMIT
    newtonian = _plan(tmp_path / "newtonian", "--deck", PASTE, "--observe", "depth", "--var", "tau_y", "0",
                      "--var", "t_max", "0.3", "--var", "hold", "0.01")
    assert newtonian["fixed"]["yield"]["value"] == "no"
    assert newtonian["decision"]["settings"]["yield"] == "no"
    paste = _plan(tmp_path / "paste", "--deck", PASTE, "--observe", "depth", "--var", "hold", "0.01")
    assert paste["fixed"]["yield"]["value"] == "yes"
    assert paste["fixed"]["submergence"]["value"] == "yes"    # the ball crosses the surface


def test_screening_of_a_test_bounds_what_the_runs_measure():
    """Sample 5 at c0 = 60 g/L: every effect screened, the bounds of the drag steps within a factor
    of two of the changes the planner measured for docs/effects.md (hindrance 2.12 pp, Stokes' law
    instead of the standard curve 0.589 pp)."""
    screens = {s.effect: s for s in screen(SedimentationTest(read_psd(SAMPLE5)))}
    assert set(screens) >= {"law", "hindered", "contacts", "lubrication", "inertia", "brownian", "wall", "yield", "surface"}
    assert screens["hindered"].value == pytest.approx(0.060 / (27.8e-4 * 0.36) / 2650)
    assert 1.0 < screens["hindered"].change < 4.0
    assert 0.3 < screens["law"].change < 1.2
    assert screens["inertia"].verdict == INCLUDE
    assert screens["surface"].verdict == OMIT
    dilute = {s.effect: s for s in screen(SedimentationTest(read_psd(SAMPLE5), mass=0.060 / 100))}
    assert dilute["hindered"].change < 0.25 * 0.5 and dilute["hindered"].verdict == OMIT


def _small_test(seed: int, out: Path, models: bool = False) -> dict:
    test = SedimentationTest(read_psd(SAMPLE5))
    scene = SampleScene(test, {"t_end": 1800.0, "classes": 20, "layers": 100}, [2000, 1000], [1.0, 4.0], 0.5,
                        replicas=3, models=models)
    plan_effects(scene, out, 0.5, jobs=2, seed=seed, measure_all=True, progress=False, name="sample5")
    return json.loads((out / "report.json").read_text())


def test_the_errors_are_against_the_converged_answer_with_its_sampling_error(tmp_path):
    """The reference runs three times with independent seeds; every run takes a seed of its own (so that a
    trial at the reference's parcel count carries its own sampling error), and every error is the distance
    from the replicas' mean plus twice that mean's standard error."""
    report = _small_test(5, tmp_path, models=True)
    runs = report["replicas"] + report["trials"] + report["verified"] + report["models"]
    seeds = [t["seed"] for t in runs]
    assert len(seeds) == len(set(seeds)) and [t["seed"] for t in report["replicas"]] == [5, 6, 7]
    standard_error = report["reference_standard_error"]
    assert set(standard_error) == {"hydrometer", "buoyancy", "pipette"}
    margin = {name: 2 * max(values) for name, values in standard_error.items()}
    assert all(m > 0 for m in margin.values())
    # no run, not even one of the reference, is closer to the converged estimate than the margin allows
    for t in runs:
        for name, error in t["errors"].items():
            assert error >= 2 * min(standard_error[name]) - 1e-12
    # a trial that changes only the drag law keeps the reference's parcels but not its placement
    stokes = next(t for t in report["trials"] if t["name"] == "drag=stokes")
    assert stokes["settings"]["particles"] == report["reference"]["settings"]["particles"]
    assert stokes["seed"] not in [t["seed"] for t in report["replicas"]]
    # the literature's other models, Bravo et al.'s first, each measured against the reference
    models = {(t["settings"]["drag"], t["settings"]["hindrance"]): t["error"] for t in report["models"]}
    assert list(models)[0] == ("difelice", "difelice") and len(models) == 5
    assert all(e is not None and e > 0 for e in models.values())
    assert (tmp_path / "models.csv").read_text().startswith("model,")
    # each model's change of every reading, and each run's sampling error at its parcel count
    bravo = report["models"][0]["changes"]
    assert set(bravo) == {"hydrometer", "buoyancy", "pipette"} and all(len(v) >= 3 for v in bravo.values())
    assert max(abs(c) for v in bravo.values() for _, c in v) <= models[("difelice", "difelice")]
    fewer = next(t for t in report["trials"] if t["name"] == "particles=1000")
    assert fewer["sampling_error"] == pytest.approx(report["replicas"][0]["sampling_error"] * 2 ** 0.5)


def test_the_report_of_a_test_is_reproducible_with_a_seed(tmp_path):
    first, again, other = (_small_test(s, tmp_path / n) for s, n in ((3, "a"), (3, "b"), (4, "c")))
    errors = [{t["name"]: t["errors"] for t in r["trials"]} for r in (first, again, other)]
    assert set(errors[0]) == {"hindrance=none", "drag=stokes", "particles=1000", "courant=4.0"}
    assert errors[0] == errors[1]
    assert first["decision"]["settings"] == again["decision"]["settings"]
    assert errors[0] != errors[2]
    assert all(math.isfinite(e) for trial in errors[0].values() for e in trial.values())
    for name in ("effects.csv", "trials.csv", "plan.png"):
        assert (tmp_path / "a" / name).stat().st_size > 0
    assert (tmp_path / "a" / "decision" / "in.sedimentation").is_file()


def test_a_rerun_replaces_its_own_files_and_spares_everyone_elses(tmp_path):
    out = tmp_path / "plan"
    args = ("--deck", SUSPENSION, "--observe", "speed", "--var", "cells", "1")
    first = _plan(out, *args)
    (out / "notes.txt").write_text("mine")
    assert _plan(out, *args)["decision"]["settings"] == first["decision"]["settings"]
    assert (out / "notes.txt").read_text() == "mine"
    # a file put into the plan's own decision folder: the rerun would delete it, so it is refused
    (out / "decision" / "results.csv").write_text("precious")
    assert cli.main(["plan", *map(str, args), "--out", str(out)]) == 2
    assert (out / "decision" / "results.csv").read_text() == "precious"
    # a folder the plan never wrote into is no concern of it
    mine = tmp_path / "mine"
    (mine / "runs").mkdir(parents=True)
    (mine / "runs" / "results.csv").write_text("precious")
    _plan(mine, *args)
    assert (mine / "runs" / "results.csv").read_text() == "precious"


@pytest.mark.parametrize("args, message", [
    (["--set", "foo=1"], "unknown effect or resolution 'foo'"),
    (["--set", "hindered=maybe"], "hindered takes yes, no, not 'maybe'"),
    (["--ladder", "nothing=1,2"], "no 'variable nothing index"),
    (["--var", "nothing", "1"], "never reads a variable 'nothing'"),
])
def test_bad_deck_plans_are_refused_with_the_reason(tmp_path, capsys, args, message):
    code = cli.main(["plan", "--deck", str(SUSPENSION), "--observe", "speed", "--out", str(tmp_path / "o"), *args])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_bad_input_is_refused_with_the_reason(tmp_path, capsys):
    bare = tmp_path / "in.bare"
    bare.write_text("print 'RESULT x 1'\n")
    assert cli.main(["plan", "--deck", str(bare), "--observe", "x", "--out", str(tmp_path / "o")]) == 2
    assert "exposes no effects" in capsys.readouterr().err
    odd = tmp_path / "in.odd"
    odd.write_text("variable effect_drag index maybe\n")
    assert cli.main(["plan", "--deck", str(odd), "--observe", "x", "--out", str(tmp_path / "o")]) == 2
    assert "effect_drag must default to yes or no" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli.main(["plan", str(SAMPLE5), "--tolerance", "0"])
    assert "--tolerance: must be > 0" in capsys.readouterr().err
    with pytest.raises(ValueError, match="tolerance must be > 0"):
        plan_effects(DeckScene(SUSPENSION, ["speed"], {}, 0.01), tmp_path / "o", -1.0)
    assert cli.main(["plan", str(SAMPLE5), "--deck", str(SUSPENSION)]) == 2
    assert "either a PSD table" in capsys.readouterr().err
    assert cli.main(["plan", "--deck", str(SUSPENSION), "--observe", "speed", "--particles", "1000"]) == 2
    assert "--particles is an option of a sedimentation test, not of a deck" in capsys.readouterr().err
    assert cli.main(["plan", str(SAMPLE5), "--observe", "speed"]) == 2
    assert "--observe is an option of a deck" in capsys.readouterr().err
    assert cli.main(["plan", str(SAMPLE5), "--screen-only", "--mass", "0.19"]) == 2
    assert "the hydrometer cannot read this test" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM"])
def test_an_interrupted_plan_stops_every_run_and_says_so(tmp_path, stop):
    """Ctrl-C (or SIGTERM) while trials run in parallel: the plan stops its runs rather than waiting for
    them, exits 130 with one line, leaves no LAMMPS running and the previous plan in --out as it was.
    The plan starts with SIGINT ignored, as a background job of a script does (and as make test's own
    processes may): it is stopped all the same. Every wait is on an event, none on the clock."""
    import signal
    import subprocess

    from test_faults import lammps_in, processes_in, wait_for

    out = tmp_path / "plan"
    out.mkdir()    # earlier results there: every one of them stays as it was
    (out / "report.json").write_text('{"earlier": "plan"}\n')
    (out / "decision").mkdir()
    (out / "decision" / "in.sedimentation").write_text("# the earlier decision\n")
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    with open(tmp_path / "stderr.txt", "w") as stderr:    # a file: nothing blocks on a full pipe
        plan = subprocess.Popen([str(REPO / "bin" / "sediment"), "plan", str(SAMPLE5), "--out", str(out), "--particles",
                                 "40000,20000", "--courant", "1,2", "--t-end", "7200"], stderr=stderr, text=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))

    def trials() -> list[Path]:    # the plan works in a new folder beside --out until it is done
        return [f for f in out.glob(".sediment-stage-*/runs/*") if f.is_dir()]

    def finished() -> list[Path]:    # a trial run to its end leaves its layer file
        return [f for f in trials() if (f / "layers.h5").is_file()]

    # Stopped, not waited for: the runs' LAMMPS are paused before the signal, so that none can end by
    # itself (a trial takes some 6 s here, less than a loaded machine may take to deliver the signal).
    # A plan that waited for them would never end: the hang guard would fail the test. Only LAMMPS:
    # Open MPI's daemon shares its folder and ends when its LAMMPS does, which it must be free to do.
    wait_for(lambda: len([f for f in trials() if lammps_in(f)]) == 2, process=plan)    # two at once (--jobs 2)
    paused = [pid for f in trials() for pid in lammps_in(f)]
    lammps = paused + [pid for f in trials() for pid in processes_in(f) if pid not in paused]    # and MPI's daemons
    try:
        for pid in paused:
            os.kill(pid, signal.SIGSTOP)
        assert not finished()
        plan.send_signal(getattr(signal, stop))
        wait_for(lambda: plan.poll() is not None)
        assert not finished(), "a trial ran to its end after the signal"
    except BaseException:
        for pid in lammps:    # the test failed: its paused runs go with it
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
        raise
    err = (tmp_path / "stderr.txt").read_text()
    assert plan.returncode == 130 and "Traceback" not in err and f"interrupted by {stop}" in err
    wait_for(lambda: not [pid for pid in lammps if _alive(pid)])
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != ".sediment.lock"} \
        == before
    assert not list(out.glob(".sediment-stage-*"))


def _alive(pid: int) -> bool:
    """A process that exists and is not a zombie."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _narrow_psd(tmp_path: Path) -> Path:
    """Grains of 40 to 40.4 um: speeds within 2 % of each other."""
    path = tmp_path / "narrow.csv"
    path.write_text("diameter_um,percent_finer\n40,0\n40.4,100\n")
    return path


def test_grains_of_one_size_lose_nothing_to_contacts(tmp_path):
    """Grains settling at (nearly) one speed seldom meet: each class keeps its terminal speed to within
    its sampling error, and the readings do not move."""
    test = SedimentationTest(read_psd(_narrow_psd(tmp_path)))
    progress = []
    m = measure_contacts(test, ReducedScene(40e-6, 0.3e-3, 3e-3, fall=0.5, classes=2), tmp_path / "run",
                         on_progress=lambda done, total: progress.append((done, total)))
    assert m.grains.sum() > 50
    assert abs(m.speed_ratio - 1).max() < 5e-4    # measured: 4e-5
    assert m.change < 1e-3
    # The progress bar's feed: a hundred rows over the window, never backwards, ending at the total
    # of the relaxation and the window.
    done, total = np.array(progress).T
    assert len(progress) > 100 and np.all(np.diff(done) >= 0) and np.all(total == total[0])
    assert done[-1] == total[0] and m.steps < total[0] < 1.1 * m.steps


def test_contacts_slow_the_coarse_grains_and_carry_the_fine_ones(tmp_path):
    """Sample 5 above 20 um, a small box: the coarsest class is held back by the slower grains it runs
    into and the finest carried along, by a few percent at most (what the screening's ballistic estimate
    predicts in sign, within a factor 4); the soft contacts stay within their overlap tolerance; and
    the measurement is the same for the same seed."""
    test = SedimentationTest(read_psd(SAMPLE5))
    setup = ReducedScene(20e-6, 0.3e-3, 3e-3, fall=0.2)
    m = measure_contacts(test, setup, tmp_path / "a")
    assert m.speed_ratio[-1] < 1 < m.speed_ratio[0]
    assert abs(m.speed_ratio - 1).max() < 0.05
    assert np.all(np.sign(m.speed_ratio - 1)[[0, -1]] == np.sign(m.estimated_ratio - 1)[[0, -1]])
    assert np.all(np.abs(m.estimated_ratio - 1)[[0, -1]] < 4 * np.abs(m.speed_ratio - 1)[[0, -1]])
    assert 0 < m.largest_overlap < 0.01
    assert 0 < m.change < 1
    again = measure_contacts(test, setup, tmp_path / "b")
    assert np.array_equal(again.speed_ratio, m.speed_ratio)


def test_a_reduced_scene_outside_the_psd_is_refused(tmp_path, capsys):
    with pytest.raises(ValueError, match="cut diameter 80 um must lie within the PSD's span"):
        coarse_part(read_psd(SAMPLE5), 80e-6)
    with pytest.raises(ValueError, match="must be > 0"):
        ReducedScene(20e-6, width=0.0)
    assert cli.main(["plan", str(SAMPLE5), "--screen-only", "--measure-contacts", "--contact-cut", "100",
                     "--out", str(tmp_path / "o")]) == 2
    assert "cut diameter 100 um must lie within" in capsys.readouterr().err
    assert cli.main(["plan", "--deck", str(SUSPENSION), "--observe", "speed", "--measure-contacts"]) == 2
    assert "--measure-contacts is an option of a sedimentation test" in capsys.readouterr().err
    assert cli.main(["plan", str(SAMPLE5), "--screen-only", "--contact-cut", "30"]) == 2
    assert "--contact-cut sets the reduced scene of --measure-contacts" in capsys.readouterr().err
    # A screening writes no file, and says so
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "report.json").write_text("kept")
    assert cli.main(["plan", str(SAMPLE5), "--screen-only", "--out", str(mine)]) == 0
    assert f"wrote nothing into {mine}: this plan writes no file" in capsys.readouterr().out
    assert (mine / "report.json").read_text() == "kept"


def test_the_coarse_part_of_a_psd_keeps_its_shape():
    psd = read_psd(SAMPLE5)
    coarse, share = coarse_part(psd, 20e-6)
    assert share == pytest.approx(1 - psd.at([20e-6])[0] / 100)
    assert coarse.percent_finer[0] == 0 and coarse.percent_finer[-1] == pytest.approx(100)
    d = np.array([25e-6, 40e-6])
    assert coarse.at(d) == pytest.approx((psd.at(d) - psd.at([20e-6])[0]) / share)


def test_the_swirls_of_a_narrow_sample_spread_its_fall_as_segre_et_al_say():
    """For grains of one size the swirls' dispersion is D = 80 v a (1 - exp(-W / (60 a phi^-1/3))) while
    they fall, and the spread of their arrival at depth H is sqrt(2 D H / v) / H; the fluctuation is
    2.0 phi0^1/3 (Segre, Herbolzheimer & Chaikin 1997)."""
    from sediment.lab.psd import PSD
    from sediment.lab.settling import terminal_speeds
    from sediment.planner.screening import swirl_spread

    d = 30e-6
    test = SedimentationTest(PSD(np.array([d, d * 1.0001]), np.array([0.0, 100.0])))
    diameter, spread, fluctuation = swirl_spread(test, 0.1, classes=8)
    phi = test.solid_fraction
    assert fluctuation == pytest.approx(2.0 * phi ** (1 / 3))
    v = float(terminal_speeds(test.suspension, np.array([d]))[0])
    cut = 1 - math.exp(-test.cylinder.diameter / (60 * d / 2 * phi ** (-1 / 3)))
    # its 8 classes leave within 0.02 % of one another's time: each is spread as the whole sample
    whole = math.sqrt(2 * 80 * v * d / 2 * cut * 0.1 / v) / 0.1
    assert spread == pytest.approx(np.full(8, whole), rel=1e-3)


def test_two_way_coupling_is_screened_and_never_turned_on_by_the_screen():
    """The flow the grains drive is screened with the others, but never omitted on its estimate, which
    the measured column exceeded up to 23 times (sample 5 at 30 g/L): reported at any tolerance, for
    --measure-flow to measure (the planner's sub-volume cannot hold the swirls)."""
    psd = read_psd(SAMPLE5)
    for tolerance in (0.05, 0.5, 5.0):
        two_way = {s.effect: s for s in screen(SedimentationTest(psd), tolerance=tolerance)}["two-way"]
        assert two_way.value == pytest.approx(2.0 * SedimentationTest(psd).solid_fraction ** (1 / 3))
        assert 0 < two_way.change < 0.125 and two_way.verdict == "report only"
        assert "it bounds nothing" in two_way.reason and "--measure-flow measures it" in two_way.reason


def test_the_two_way_figure_draws_the_screens_own_readings(tmp_path):
    """benchmarks/two_way_swirls.py (docs/effects.md's figure) reads the screen's readings: its panel's
    largest difference is the screen's change, which it checks before it draws."""
    import subprocess

    out = tmp_path / "two_way.png"
    done = subprocess.run(["/usr/bin/python3", REPO / "benchmarks" / "two_way_swirls.py", "--samples", "5", "--out", out],
                          capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(REPO / "python")))
    assert done.returncode == 0, done.stderr
    change = {s.effect: s for s in screen(SedimentationTest(read_psd(SAMPLE5)))}["two-way"].change
    assert f"sample 5: the screen's largest change of a reading {change:.3g} pp" in done.stdout and out.is_file()
