# SPDX-License-Identifier: GPL-2.0-or-later
"""A run's identity covers what it reads, and nothing splices, shrinks or pairs stale frames: one test
per case of issue 43 (a resume from another run's restart files, --resume --force, lost frames, stale
frames beside new tables, the planner's folder, cut inputs, orphans, and the messages)."""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from test_faults import HANG_GUARD, PSD, REPO, SEDIMENT, digest, processes_in, sample, sediment, wait_for

from sediment.sim.layers import read_layers

SAMPLE1 = REPO / "examples" / "granulometry" / "psd" / "sample1.csv"
# 43 400 steps (24 h at Courant 0.1), restart files every 2170 steps: a kill finds the run going.
LONG = ("--particles", 2000, "--t-end", 86400, "--courant", 0.1)


def restart_stamps(folder: Path) -> dict[str, int]:
    return {p.name: p.stat().st_mtime_ns for p in folder.glob("restart.*.bin")}


def kill_when(folder: Path, condition, *options) -> subprocess.Popen:
    """Starts `sediment run --force` in `folder` and SIGKILLs it and its LAMMPS at the first look where
    `condition()` holds and no restart file is being written. Each look is taken with LAMMPS stopped
    (SIGSTOP), so the files it sees are those the kill leaves, however busy the machine: a restart
    file half-written at the kill (a damaged one, which the tests of damaged files make on purpose)
    cannot come from a look that came late."""
    run = subprocess.Popen(SEDIMENT + ["run", str(folder / "in.sedimentation"), "--quiet", "--force", *options],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def signal_all(pids: list[int], sig: int) -> None:
        for pid in pids:
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass

    def writing_restart(pids: list[int]) -> bool:
        for pid in pids:
            try:
                if any(os.readlink(fd.path).startswith(str(folder / "restart.")) for fd in os.scandir(f"/proc/{pid}/fd")):
                    return True
            except OSError:
                continue
        return False

    while True:
        lammps = processes_in(folder)
        signal_all(lammps, signal.SIGSTOP)
        if lammps and condition() and not writing_restart(lammps):
            break
        signal_all(lammps, signal.SIGCONT)
        assert run.poll() is None, f"the run ended (exit {run.returncode}) before the event"
        time.sleep(0.01)
    run.send_signal(signal.SIGKILL)
    run.wait()
    signal_all(lammps, signal.SIGKILL)    # as a crash: nothing written after the look
    wait_for(lambda: not processes_in(folder))
    return run


def test_1_resume_refuses_the_restart_files_of_an_earlier_run(tmp_path):
    deck = sample(tmp_path / "x", *LONG)
    assert sediment("run", deck, "--quiet").returncode == 0
    finished, stamps = digest(deck.parent / "layers.h5"), restart_stamps(deck.parent)
    # a rerun killed before it wrote its first restart file (tried until a kill lands in that window)
    for _ in range(5):
        kill_when(deck.parent, lambda: (deck.parent / "layers.h5.partial").is_file())
        if restart_stamps(deck.parent) == stamps:
            break
    else:
        pytest.skip("the rerun wrote a restart file before every kill")
    resumed = sediment("run", deck, "--quiet", "--resume")
    assert resumed.returncode == 2
    # the earlier run's restart files refused, or before them the rerun's frames, if the kill came before
    # its first frame was whole
    assert ("restart files" in resumed.stderr and "are of another run" in resumed.stderr
            or "the interrupted run's frames are damaged" in resumed.stderr)
    assert "--force" in resumed.stderr
    assert digest(deck.parent / "layers.h5") == finished    # the good result kept


def test_1_resume_refuses_inputs_changed_since(tmp_path):
    deck = sample(tmp_path / "x", *LONG)
    kill_when(deck.parent, lambda: (deck.parent / "restart.a.bin").is_file())
    # the same PSD sampled with another seed (the same deck text, another data file): refused over the
    # interrupted run, or its files deleted with --force
    other = sediment("sample", PSD, "--out", deck.parent, *LONG, "--seed", 7)
    assert other.returncode == 2 and "holds a run of another scene" in other.stderr
    assert sediment("sample", PSD, "--out", deck.parent, *LONG, "--seed", 7, "--force").returncode == 0
    assert not (deck.parent / "restart.a.bin").exists() and not (deck.parent / "layers.h5.partial").exists()
    kill_when(deck.parent, lambda: (deck.parent / "restart.a.bin").is_file())
    data = deck.parent / "sample.data"
    data.write_text(data.read_text() + "\n")    # a data file edited since
    resumed = sediment("run", deck, "--quiet", "--resume")
    assert resumed.returncode == 2 and "changed since the interrupted run" in resumed.stderr


def test_2_resume_with_force_and_resume_of_a_finished_run_are_refused(tmp_path):
    deck = sample(tmp_path / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    finished = digest(deck.parent / "layers.h5")
    both = sediment("run", deck, "--quiet", "--resume", "--force")
    assert both.returncode == 2 and "give one of them" in both.stderr
    shutil.copy(deck.parent / "layers.h5", deck.parent / "restart.a.bin")    # any restart file: nothing to resume
    again = sediment("run", deck, "--quiet", "--resume")
    assert again.returncode == 2 and "finished: nothing to resume" in again.stderr
    assert digest(deck.parent / "layers.h5") == finished


def test_3_lost_frames_are_never_taken_for_a_result(tmp_path):
    deck = sample(tmp_path / "x", *LONG)
    assert sediment("run", deck, "--quiet").returncode == 0
    finished = digest(deck.parent / "layers.h5")
    kill_when(deck.parent, lambda: (deck.parent / "restart.b.bin").stat().st_mtime_ns
              > (deck.parent / "layers.h5").stat().st_mtime_ns)
    (deck.parent / "layers.h5.partial").unlink()    # lost after the kill
    resumed = sediment("run", deck, "--quiet", "--resume")
    assert resumed.returncode == 2 and "are gone" in resumed.stderr
    assert digest(deck.parent / "layers.h5") == finished
    # deleted while the run writes it: the run does not end in a complete file
    for name in ("restart.a.bin", "restart.b.bin"):
        (deck.parent / name).unlink()
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--quiet", "--force"], stderr=subprocess.PIPE, text=True)
    wait_for(lambda: (deck.parent / "restart.a.bin").is_file(), process=run)    # the run is past its first stages
    (deck.parent / "layers.h5.partial").unlink()
    _, err = run.communicate(timeout=HANG_GUARD)
    assert run.returncode == 2 and "vanished" in err
    assert digest(deck.parent / "layers.h5") == finished


def test_4_stale_frames_are_not_paired_with_new_tables(tmp_path):
    deck = sample(tmp_path / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    def files() -> dict[str, str]:
        return {p.name: digest(p) for p in deck.parent.iterdir() if p.is_file() and p.suffix != ".lock"}

    tables = files()
    other = sediment("sample", SAMPLE1, "--out", deck.parent, "--particles", 2000)
    assert other.returncode == 2 and "holds a run of another scene" in other.stderr
    assert files() == tables
    # the same sample again changes nothing and is allowed
    assert sediment("sample", PSD, "--out", deck.parent, "--t-end", 7200, "--courant", 1, "--particles", 2000).returncode == 0
    assert sediment("readout", deck.parent / "layers.h5", "--out", tmp_path / "r").returncode == 0
    # another test's deck and data put there by hand: readout refuses the frames
    elsewhere = sample(tmp_path / "y", "--particles", 2000, "--seed", 5)
    for name in ("sample.data", "in.sedimentation", "input_psd.csv"):
        shutil.copy(elsewhere.parent / name, deck.parent / name)
    stale = sediment("readout", deck.parent / "layers.h5", "--out", tmp_path / "r")
    assert stale.returncode == 2 and "written by a run of other inputs" in stale.stderr


def test_4_sample_waits_for_no_run_but_refuses_a_busy_folder(tmp_path):
    deck = sample(tmp_path / "x", *LONG)
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--quiet"], stderr=subprocess.PIPE, text=True)
    wait_for(lambda: (deck.parent / "layers.h5.partial").is_file(), process=run)
    busy = sediment("sample", SAMPLE1, "--out", deck.parent, "--force")
    assert busy.returncode == 2 and "another sediment command" in busy.stderr
    run.send_signal(signal.SIGINT)
    run.communicate(timeout=HANG_GUARD)


def _small_plan(out: Path, psd: Path = PSD) -> subprocess.CompletedProcess:
    return sediment("plan", psd, "--out", out, "--particles", "2000,1000", "--courant", "4", "--t-end", 7200,
                    "--replicas", 1, "--no-models")


def test_5_the_planner_replaces_its_own_files_whole_or_not_at_all(tmp_path):
    out = tmp_path / "plan"
    done = _small_plan(out)
    assert done.returncode == 0, done.stderr
    (out / "notes.txt").write_text("mine")    # a file of the user's: every plan leaves it
    before = {p.relative_to(out): digest(p) for p in out.rglob("*") if p.is_file() and p.name != ".sediment.lock"}
    # a rerun for another PSD, interrupted: the earlier plan as it was, nothing left beside it
    plan = subprocess.Popen(SEDIMENT + ["plan", str(SAMPLE1), "--out", str(out), "--particles", "2000,1000",
                                        "--courant", "4", "--t-end", "7200", "--replicas", "1", "--no-models"],
                            stderr=subprocess.PIPE, text=True)
    # as soon as its first run has a folder (a run's layers.h5.partial lives a fraction of a second,
    # between two looks when the machine is busy; the folder stays until the plan is swapped in)
    wait_for(lambda: [run for run in out.glob(".sediment-stage-*/runs/*") if run.is_dir()], process=plan)
    plan.send_signal(signal.SIGINT)
    _, err = plan.communicate(timeout=HANG_GUARD)
    assert plan.returncode == 130
    assert {p.relative_to(out): digest(p) for p in out.rglob("*") if p.is_file() and p.name != ".sediment.lock"} == before
    assert not list(out.glob(".sediment-stage-*")) and f"{out} is as it was" in err
    # sample --plan of another PSD's report: refused, naming it
    other = sediment("sample", SAMPLE1, "--plan", out / "report.json", "--out", tmp_path / "s")
    assert other.returncode == 2 and "was made for another test: the PSD" in other.stderr
    # a refused rerun deletes nothing: a run's result in decision/
    (out / "decision" / "layers.h5").write_bytes(b"a result")
    refused = _small_plan(out)
    assert refused.returncode == 2 and f"{out / 'decision' / 'layers.h5'} (not written by sediment plan)" in refused.stderr
    assert (out / "runs").is_dir() and (out / "decision" / "layers.h5").read_bytes() == b"a result"
    # that result moved away, the rerun replaces the plan's own files and keeps the user's
    (out / "decision" / "layers.h5").unlink()
    again = _small_plan(out)
    assert again.returncode == 0, again.stderr
    assert (out / "notes.txt").read_text() == "mine" and (out / "report.json").is_file()
    # a folder it did not write
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "report.json").write_text("my own")
    refused = _small_plan(mine)
    assert refused.returncode == 2 and "report.json (not written by sediment plan)" in refused.stderr
    assert (mine / "report.json").read_text() == "my own"


def test_6_cut_inputs_are_refused(tmp_path):
    deck = sample(tmp_path / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    finished = digest(deck.parent / "layers.h5")
    # a deck cut after 3 of its stages
    text = deck.read_text()
    lines = text.split("\n")
    stages = [k for k, line in enumerate(lines) if line.startswith('if "$(step)')]
    deck.write_text("\n".join(lines[:stages[2] + 1]) + "\n")
    short = sediment("run", deck, "--quiet", "--force")
    assert short.returncode == 2 and "before end_time" in short.stderr
    assert digest(deck.parent / "layers.h5") == finished
    # a data file cut before its weights
    deck.write_text(text)
    data = deck.parent / "sample.data"
    data.write_text(data.read_text().split("\nWeights")[0] + "\n")
    no_weights = sediment("run", deck, "--quiet", "--force")
    assert no_weights.returncode == 2 and "sample.data changed since sediment sample wrote it" in no_weights.stderr
    # without the folder's record of what sample wrote, the deck's own check of the weights stops it
    (deck.parent / ".sediment-files.json").unlink()
    no_weights = sediment("run", deck, "--quiet", "--force")
    assert no_weights.returncode == 2 and "did the data file lose its weights section" in no_weights.stderr
    assert digest(deck.parent / "layers.h5") == finished


def test_6_a_readout_folder_holds_one_readout(tmp_path):
    deck = sample(tmp_path / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    out = tmp_path / "r"
    assert sediment("readout", deck.parent / "layers.h5", "--out", out).returncode == 0
    assert (out / "pipette.csv").is_file()
    assert sediment("readout", deck.parent / "layers.h5", "--out", out, "--instrument", "hydrometer").returncode == 0
    assert (out / "hydrometer.csv").is_file() and not (out / "pipette.csv").exists()
    assert not (out / "buoyancy.csv").exists()


def test_6_frames_too_far_apart_are_no_reading(tmp_path):
    deck = tmp_path / "coarse" / "in.sedimentation"
    assert sediment("sample", PSD, "--out", deck.parent).returncode == 0
    assert sediment("run", deck, "--quiet", "--var", "dt_scale", 100).returncode == 0    # steps of minutes
    far = sediment("readout", deck.parent / "layers.h5", "--out", tmp_path / "r")
    assert far.returncode == 2 and "min apart, longer than the reading's own time" in far.stderr


@pytest.mark.parametrize("options, message", [
    (("--courant", 1e-300), "--courant 1e-300 is far too small"),
    (("--real-grains", "--contacts"), "contacts set a step of"),
])
def test_6_sample_refuses_decks_lammps_cannot_run(tmp_path, options, message):
    done = sediment("sample", PSD, "--out", tmp_path / "s", *options)
    assert done.returncode == 2 and "beyond LAMMPS's 2147483647" in done.stderr and message in done.stderr
    assert not (tmp_path / "s").exists()


def test_7_no_mpirun_outlives_a_killed_sediment(tmp_path):
    deck = sample(tmp_path / "x", *LONG)
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--quiet", "--np", "16", "--oversubscribe"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wait_for(lambda: len(processes_in(deck.parent)) >= 2, process=run)    # mpirun started (its ranks may still start)
    run.send_signal(signal.SIGKILL)
    run.wait()
    wait_for(lambda: not processes_in(deck.parent))


def test_8_a_damaged_partial_says_to_remove_it_and_force_replaces_it(tmp_path):
    deck = sample(tmp_path / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    partial = deck.parent / "layers.h5.partial"
    partial.write_bytes((deck.parent / "layers.h5").read_bytes()[:5000])
    again = sediment("run", deck, "--quiet")
    assert again.returncode == 2 and "is damaged" in again.stderr and "remove it" in again.stderr
    assert sediment("run", deck, "--quiet", "--force").returncode == 0
    assert read_layers(deck.parent / "layers.h5").complete and not partial.exists()


def test_8_a_damaged_newest_restart_file_falls_back_to_the_older(tmp_path):
    deck = sample(tmp_path / "x", *LONG)
    whole = sample(tmp_path / "whole", *LONG)
    assert sediment("run", whole, "--quiet").returncode == 0
    folder = deck.parent
    kill_when(folder, lambda: len(restart_stamps(folder)) == 2 and (folder / "restart.a.bin").stat().st_size > 0
              and (folder / "restart.b.bin").stat().st_size > 0)
    newest = max(folder.glob("restart.*.bin"), key=lambda p: p.stat().st_mtime_ns)
    newest.write_bytes(newest.read_bytes()[:len(newest.read_bytes()) // 2])
    resumed = sediment("run", deck, "--quiet", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert f"passing over {newest.name}" in resumed.stderr    # it no longer matches its checksum
    a, b = read_layers(whole.parent / "layers.h5"), read_layers(folder / "layers.h5")
    assert np.array_equal(a.step, b.step) and np.max(np.abs(a.fraction - b.fraction)) < 1e-12


def test_8_messages_name_the_problem(tmp_path):
    deck = sample(tmp_path / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    broken = tmp_path / "broken.h5"
    shutil.copy(deck.parent / "layers.h5", broken)
    with h5py.File(broken, "r+") as f:
        del f.attrs["units"]
    done = sediment("readout", broken, "--out", tmp_path / "r")
    assert done.returncode == 2 and "lacks the attribute units" in done.stderr and "Traceback" not in done.stderr
    # PSD rows in micrometres, as the table has them
    bad = tmp_path / "bad.csv"
    bad.write_text("diameter_um,percent_finer\n2,0\n20,40\n20,60\n70,100\n")
    done = sediment("sample", bad, "--out", tmp_path / "s")
    assert done.returncode == 2 and "row 3 (20 um) after row 2 (20 um)" in done.stderr
    # the PSD table `sample` writes reads back as it was, however close its diameters
    close = tmp_path / "close.csv"
    close.write_text("diameter_um,percent_finer\n20,0\n20.0000000001,40\n70,100\n")
    assert sediment("sample", close, "--out", tmp_path / "c", "--particles", 2000).returncode == 0
    from sediment.lab.psd import read_psd
    assert np.array_equal(read_psd(tmp_path / "c" / "input_psd.csv").diameter, read_psd(close).diameter)


def test_8_the_layer_file_a_deck_writes_and_whether_a_run_finished(tmp_path):
    from sediment.sim.provenance import finished, input_files, layer_file_of

    deck = sample(tmp_path / "x", "--particles", 2000)
    assert layer_file_of(deck, {}) == deck.parent / "layers.h5"
    assert layer_file_of(deck, {"layers_file": "other.h5"}) == deck.parent / "other.h5"
    assert input_files(deck) == [deck.parent / "sample.data"]
    assert sediment("run", deck, "--quiet").returncode == 0
    record = json.loads((deck.parent / ".sediment-run.json").read_text())
    assert record["state"] == "finished" and record["deck"] == "in.sedimentation"
    identity = read_layers(deck.parent / "layers.h5").identity
    assert identity["run_id"] == record["run_id"]
    from sediment import _core    # the writer states the release the package does (core/include/sediment/version.hpp)
    assert identity["code_version"].startswith(f"SEDIMENT {_core.VERSION}, LAMMPS ")
    # a stop that came as LAMMPS finished: the file is this run's and complete
    assert finished(deck.parent / "layers.h5", record["run_id"])
    assert not finished(deck.parent / "layers.h5", record["run_id"][:-1] + "x")
    shutil.copy(deck.parent / "layers.h5", deck.parent / "layers.h5.partial")
    assert not finished(deck.parent / "layers.h5", record["run_id"])


FLOATING = """units si
atom_style sphere
boundary p p f
region box block -0.05 0.05 -0.05 0.05 -0.1 0.1
create_box 1 box
create_atoms 1 single 0 0 0.03
set atom 1 diameter 0.02 density 500
fix grav all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3 surface z 0.0
fix buoy all fluid/buoyancy water
fix drag all fluid/drag water law standard
fix step all nve/sphere/fluid
timestep ${dt}
run 20
"""


def test_6_a_floating_sphere_with_too_long_a_step_is_warned_of(tmp_path):
    # a 2 cm ball of 500 kg/m3 bobs at the surface with a period of 0.164 s (omega^2 = 3 rho_f g / (4 rho_p r))
    (tmp_path / "in.float").write_text(FLOATING)
    for dt, warned in ((0.01, False), (0.05, True)):
        done = subprocess.run([os.environ["SEDIMENT_LMP"], "-in", "in.float", "-var", "dt", str(dt), "-log", "none"],
                              cwd=tmp_path, capture_output=True, text=True)
        assert done.returncode == 0
        assert ("bobs with period 0.1638" in done.stdout) == warned
        assert ("use a time step up to 0.013" in done.stdout) == warned


def test_8_ctrl_c_during_a_resume_stops_it(tmp_path):
    """A stop asked for is not a restart file that failed: no second attempt from the older one."""
    deck = sample(tmp_path / "x", *LONG)
    kill_when(deck.parent, lambda: len(restart_stamps(deck.parent)) == 2)
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--resume", "--quiet"], stderr=subprocess.PIPE, text=True)
    stamps = restart_stamps(deck.parent)
    wait_for(lambda: restart_stamps(deck.parent) != stamps, process=run)    # the resumed run under way
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=HANG_GUARD)
    assert run.returncode == 130 and "stopped by SIGINT" in err and "trying restart" not in err
    assert "layers.h5.partial" in err and not (deck.parent / "layers.h5").exists()
