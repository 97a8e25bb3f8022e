# SPDX-License-Identifier: GPL-2.0-or-later
"""Faults a user meets: a full disk, a rerun or another run over an earlier result, a killed run and
its resumption, two runs in one folder, signals, too many ranks, implausible input. None may end
with exit status 0 and a wrong or partial result, or lose an earlier result."""
from __future__ import annotations

import hashlib
import math
import os
import shutil
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from sediment.sim.layers import read_layers
from sediment.sim.run import run_batch

REPO = Path(__file__).resolve().parents[2]
SEDIMENT = [str(REPO / "bin" / "sediment")]
PSD = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"


def sediment(*args, cwd: Path | None = None, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(SEDIMENT + [str(a) for a in args], capture_output=True, text=True, cwd=cwd, **kwargs)


def sample(out: Path, *options) -> Path:
    # Courant 1: runs long enough (about 4x the default's steps) for a signal to find them running
    done = sediment("sample", PSD, "--out", out, "--t-end", 7200, "--courant", 1, *options)
    assert done.returncode == 0, done.stderr
    return out / "in.sedimentation"


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def processes_in(folder: Path) -> list[int]:
    """PIDs of live (not zombie) processes whose working folder is `folder`."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if Path(os.readlink(entry / "cwd")) == folder and "Z" not in (entry / "stat").read_text().split()[2]:
                found.append(int(entry.name))
        except OSError:
            continue
    return found


def lammps_in(folder: Path) -> list[int]:
    """PIDs of the LAMMPS processes (SEDIMENT_LMP) working in `folder`: not mpirun, not Open MPI's daemon."""
    lmp = Path(os.environ["SEDIMENT_LMP"]).resolve()
    found = []
    for pid in processes_in(folder):
        try:
            if Path(os.readlink(f"/proc/{pid}/exe")) == lmp:
                found.append(pid)
        except OSError:
            continue
    return found


# How long a wait may last before it counts as a hang: no test's outcome depends on it (every event
# awaited comes within seconds, loaded or not); it only turns a hang of a broken build into a failure.
HANG_GUARD = 600.0


def wait_for(condition, seconds: float = HANG_GUARD, *, process: subprocess.Popen | None = None) -> None:
    """Waits for an event: `condition()` true. No clock decides a test: with `process` (the command
    that should bring the event) the wait fails as soon as that command has ended without it.
    `seconds` is only a hang guard, far beyond what any event awaited here needs on a loaded machine,
    so that a broken build fails instead of hanging the suite."""
    end = time.monotonic() + seconds
    while not condition():
        if process is not None and process.poll() is not None:
            assert condition(), f"the command ended (exit {process.returncode}) before the event came"
            return
        assert time.monotonic() < end, f"hang guard: no event after {seconds:g} s"
        time.sleep(0.05)


def test_a_full_disk_stops_the_run_and_leaves_no_result(tmp_path):
    small = tmp_path / "small"
    small.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(small)], capture_output=True).returncode:
        pytest.skip("cannot mount a small file system here (not root)")
    try:
        deck = (REPO / "lammps-pkg" / "examples" / "in.settling").read_text()
        deck = deck.replace("layers.h5", str(small / "layers.h5")).replace("layers z 50", "layers z 400")
        deck = deck.replace("layers/hdf5 100", "layers/hdf5 5")
        (tmp_path / "in.full").write_text(deck)
        done = subprocess.run([os.environ["SEDIMENT_LMP"], "-in", "in.full", "-log", "none"], cwd=tmp_path,
                              capture_output=True, text=True)
        assert done.returncode != 0
        assert "Fix layers/hdf5" in done.stdout and "disk full" in done.stdout
        assert not (small / "layers.h5").exists()    # only layers.h5.partial, which readout refuses
        assert not read_layers(small / "layers.h5.partial").complete
    finally:
        subprocess.run(["umount", str(small)], check=True)


def test_a_rerun_with_other_parameters_keeps_the_earlier_result(tmp_path):
    deck = sample(tmp_path / "pd", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    first = digest(deck.parent / "layers.h5")
    # (`sample` refuses a folder with a run of other inputs: test_identity.py) The deck edited by hand:
    deck.write_text(deck.read_text().replace("particle_density 2650", "particle_density 3500"))
    again = sediment("run", deck, "--quiet")
    assert again.returncode == 2 and "particle_density 2650, this run has 3500" in again.stderr
    assert digest(deck.parent / "layers.h5") == first and (deck.parent / "log.failed.lammps").is_file()
    assert sediment("run", deck, "--quiet", "--force").returncode == 0
    assert read_layers(deck.parent / "layers.h5").attributes["particle_density"] == 3500


def test_a_run_starting_anew_over_a_result_is_refused(tmp_path):
    """`sediment run` refuses a rerun of its finished deck before LAMMPS starts, naming --force; LAMMPS
    run by hand refuses it in fix layers/hdf5. The result stays as it was either way."""
    deck = sample(tmp_path / "same", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    before = digest(deck.parent / "layers.h5")
    again = sediment("run", deck, "--quiet")
    assert again.returncode == 2 and "in.sedimentation has already finished: layers.h5 holds its complete frames" \
        in again.stderr and "--force" in again.stderr
    by_hand = subprocess.run([os.environ["SEDIMENT_LMP"], "-in", deck.name, "-log", "none"], cwd=deck.parent,
                             capture_output=True, text=True)
    assert by_hand.returncode != 0 and "starts anew at step 0" in by_hand.stdout
    assert digest(deck.parent / "layers.h5") == before


def test_frames_of_another_fluid_are_not_spliced(tmp_path):
    deck = (REPO / "lammps-pkg" / "examples" / "in.settling").read_text().replace("run             1000", "run 200")
    (tmp_path / "in.first").write_text(deck)
    (tmp_path / "in.second").write_text(deck.replace("viscosity 1.002e-3", "viscosity 2e-3").replace(
        "timestep        0.01", "reset_timestep 300\ntimestep 0.01"))
    lmp = os.environ["SEDIMENT_LMP"]
    assert subprocess.run([lmp, "-in", "in.first", "-log", "none"], cwd=tmp_path, capture_output=True).returncode == 0
    before = digest(tmp_path / "layers.h5")
    second = subprocess.run([lmp, "-in", "in.second", "-log", "none"], cwd=tmp_path, capture_output=True, text=True)
    assert second.returncode != 0 and "fluid_viscosity 0.001002, this run has 0.002" in second.stdout
    assert digest(tmp_path / "layers.h5") == before


@pytest.mark.parametrize("water", ["constant", "record"])
def test_a_killed_run_keeps_the_earlier_result_and_resumes_to_the_same_frames(tmp_path, water):
    # 8600 steps (24 h at Courant 0.5): restart files at steps 2000 and 4000, and steps after them
    # for the kill to find the run going. With a temperature record the deck re-issues the fluid
    # between its runs: the resumed run starts in the water of its own part of the day.
    options = ("--particles", 5000, "--t-end", 86400, "--courant", 0.5)
    if water == "record":
        (tmp_path / "record.csv").write_text("time_min,temperature_C\n0,19\n1440,23\n")
        options += ("--temperature-record", tmp_path / "record.csv")
    whole = sample(tmp_path / "whole", *options)
    assert sediment("run", whole, "--quiet").returncode == 0
    cut = sample(tmp_path / "cut", *options)
    # An earlier complete result in the folder, which the killed rerun (--force) must not damage.
    assert sediment("run", cut, "--quiet").returncode == 0
    earlier = digest(cut.parent / "layers.h5")
    for name in ("restart.a.bin", "restart.b.bin"):
        (cut.parent / name).unlink()
    run = subprocess.Popen(SEDIMENT + ["run", str(cut), "--quiet", "--force"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    wait_for(lambda: (cut.parent / "restart.b.bin").is_file(), process=run)
    run.send_signal(signal.SIGKILL)
    run.wait()
    wait_for(lambda: not processes_in(cut.parent))    # LAMMPS dies with its wrapper
    assert digest(cut.parent / "layers.h5") == earlier
    assert not read_layers(cut.parent / "layers.h5.partial").complete
    resumed = sediment("run", "--resume", cut, "--quiet")
    assert resumed.returncode == 0, resumed.stderr
    a, b = read_layers(whole.parent / "layers.h5"), read_layers(cut.parent / "layers.h5")
    assert b.complete and not (cut.parent / "layers.h5.partial").exists()
    assert np.array_equal(a.step, b.step) and np.allclose(a.time, b.time, rtol=1e-12, atol=0)
    assert np.max(np.abs(a.fraction - b.fraction)) < 1e-12


def test_a_two_way_run_killed_past_its_stages_resumes_to_the_same_frames(tmp_path):
    """At four times its planned steps a two-way column's flow shortens them (fix fluid/flow cfl): its
    stages end short of t_end (after 834 steps) and the deck runs on until its frames reach it (2812
    steps). Killed there, after its restart file at step 2000, and resumed, it ends on the frames of
    the run that was not killed: the shortened steps come back with the restart file."""
    decks = []
    for name in ("whole", "cut"):
        done = sediment("sample", REPO / "examples" / "granulometry" / "psd" / "sample2.csv", "--two-way", "--height",
                        0.06, "--t-end", 60, "--particles", 1000, "--out", tmp_path / name)
        assert done.returncode == 0, done.stderr
        decks.append(tmp_path / name / "in.sedimentation")
    whole, cut = decks
    longer = ("--var", "dt_scale", "4")
    assert sediment("run", whole, "--quiet", *longer).returncode == 0
    log = (whole.parent / "log.lammps").read_text()
    assert "fix flow fluid/flow: step 1 shortened from" in log
    assert log.count("Loop time of") == whole.read_text().count('if "$(step) < ${stage_end}"') + 1    # and on to t_end
    run = subprocess.Popen(SEDIMENT + ["run", str(cut), "--quiet", *longer], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    wait_for(lambda: (cut.parent / "restart.a.bin").is_file(), process=run)
    run.send_signal(signal.SIGKILL)
    run.wait()
    wait_for(lambda: not processes_in(cut.parent))
    assert not (cut.parent / "layers.h5").exists()    # killed before it finished
    resumed = sediment("run", "--resume", cut, "--quiet", *longer)
    assert resumed.returncode == 0, resumed.stderr
    a, b = read_layers(whole.parent / "layers.h5"), read_layers(cut.parent / "layers.h5")
    assert a.complete and b.complete and 60 <= a.time[-1] < 60 + 2 * np.diff(a.time)[-1] and a.step[-1] > 2000
    assert np.array_equal(a.step, b.step) and np.allclose(a.time, b.time, rtol=1e-12, atol=0)
    assert np.max(np.abs(a.fraction - b.fraction)) < 1e-12


@pytest.mark.parametrize("dt_scale", ["1", "0.37", "0.3"])
def test_restart_files_come_at_multiples_of_the_atoms_sort(tmp_path, dt_scale):
    """LAMMPS sorts the atoms every 1000 steps and at each run's start. A two-way column resumed from a
    restart file at step 300 summed its flow in another order of its atoms than the run never stopped,
    and left its trajectory (a layer's fraction 1.4 apart within 3000 steps); resumed at step 1000 it
    ran to the same frames bit for bit. The decks' restart files come at multiples of the sort at any
    dt_scale (sample 2's two-way column, 28 255 steps: every 2000, 4000 and 5000 steps, where 3819
    and 4710 were at 0.37 and 0.3)."""
    done = sediment("sample", REPO / "examples" / "granulometry" / "psd" / "sample2.csv", "--two-way", "--particles",
                    1000, "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    deck = (tmp_path / "in.sedimentation").read_text()
    head = deck[:deck.index("variable        stage_end equal 0")]
    (tmp_path / "in.head").write_text("echo screen\n" + head)
    out = run_batch(tmp_path / "in.head", {"dt_scale": dt_scale})
    every = int(re.search(r"^restart +(\d+) restart\.a\.bin", out.text, re.M).group(1))
    sort = int(re.search(r"^atom_modify +sort +(\d+)", out.text, re.M).group(1))
    planned = int(re.search(r"SEDIMENT plan steps (\d+)", out.text).group(1))
    assert planned == math.ceil(28255 / float(dt_scale)) and every % sort == 0 and every >= max(2000, planned / 20)
    assert every == {"1": 2000, "0.37": 4000, "0.3": 5000}[dt_scale]


def test_a_batch_run_streams_its_lines_and_is_stopped_at_its_timeout(tmp_path):
    """run_batch hands each line to a reader as LAMMPS prints it, and a run past its timeout is
    stopped (no LAMMPS left behind) with TimeoutExpired, not taken for a result."""
    deck = tmp_path / "in.loop"
    deck.write_text("units lj\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\ncreate_atoms 1 single 0.5 0.5 0.5\n"
                    "mass 1 1\nfix step all nve\nthermo_style custom step\nthermo 2000\nthermo_modify flush yes\n"
                    "run 2000000000\n")
    # Read as printed, not at the end of the run: each thermo row reaches the reader while LAMMPS
    # still runs (this run ends only at its timeout), whatever the machine's load.
    procs, rows = set(), []

    def on_line(line: str) -> None:
        if line.split()[:1] and line.split()[0].isdigit():
            rows.append(len(procs) == 1 and next(iter(procs)).poll() is None)
    start = time.monotonic()
    with pytest.raises(subprocess.TimeoutExpired):
        run_batch(deck, timeout=5, running=procs, on_line=on_line)
    # stopped at its timeout, not before (a bound no load can break: the run never ends by itself, so
    # the TimeoutExpired above is the stop)
    assert time.monotonic() - start >= 5
    assert not processes_in(tmp_path)
    assert len(rows) > 3 and all(rows)


def test_a_rerun_over_frames_a_killed_run_left_says_how_to_go_on(tmp_path):
    deck = sample(tmp_path / "left", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    # What a run killed before its first restart file leaves: its frames under layers.h5.partial
    shutil.copy(deck.parent / "layers.h5", deck.parent / "layers.h5.partial")
    again = sediment("run", deck, "--quiet")
    assert again.returncode == 2 and "unfinished run's frames" in again.stderr
    assert "--resume" in again.stderr and "--force starts it anew" in again.stderr
    assert sediment("run", deck, "--quiet", "--force").returncode == 0
    assert read_layers(deck.parent / "layers.h5").complete and not (deck.parent / "layers.h5.partial").exists()


def test_resume_needs_a_restart_file(tmp_path):
    deck = sample(tmp_path / "fresh", "--particles", 2000)
    done = sediment("run", "--resume", deck, "--quiet")
    assert done.returncode == 2 and "nothing to resume" in done.stderr


def test_two_runs_in_one_folder_and_signals(tmp_path):
    # The second run and the signal must find the first still running: its two ranks are paused once
    # LAMMPS is under way (its log open), so that it cannot end by itself however busy the machine
    deck = sample(tmp_path / "busy", "--particles", 15000, "--courant", 0.1)
    first = subprocess.Popen(SEDIMENT + ["run", str(deck), "--quiet", "--np", "2"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    wait_for(lambda: (deck.parent / "layers.h5.partial").is_file() and len(lammps_in(deck.parent)) == 2, process=first)
    for pid in lammps_in(deck.parent):
        os.kill(pid, signal.SIGSTOP)
    try:
        second = sediment("run", deck, "--quiet")
        assert second.returncode == 2 and "another sediment command" in second.stderr
    except BaseException:
        first.kill()    # the test failed: its run's guard stops the paused ranks
        raise
    first.send_signal(signal.SIGTERM)
    _, err = first.communicate(timeout=HANG_GUARD)
    assert first.returncode == 130 and "stopped by SIGTERM" in err and "Traceback" not in err
    wait_for(lambda: not processes_in(deck.parent))    # mpirun and both ranks stopped
    assert not (deck.parent / "layers.h5").exists() and (deck.parent / "log.failed.lammps").is_file()


def test_a_signal_while_the_run_is_launched_stops_it(tmp_path, monkeypatch):
    # The signal comes after LAMMPS was spawned but before the launch returned its process: the run is
    # stopped all the same and the caller hears RunInterrupted, not a bare KeyboardInterrupt
    from sediment.sim import process

    spawned = []

    def start_then_signal(*args, **kwargs):
        spawned.append(subprocess.Popen(["sleep", "60"], start_new_session=True))
        spawned[-1].guard = None
        os.kill(os.getpid(), signal.SIGINT)
        return spawned[-1]

    monkeypatch.setattr(process, "start_process", start_then_signal)
    with pytest.raises(process.RunInterrupted, match="stopped by SIGINT"):
        with process.signals_stop() as launch:
            launch.start(["sleep"], {}, tmp_path)
            pytest.fail("the launch returned despite the signal")
    assert spawned[0].poll() is not None    # stopped, not left running


@pytest.mark.parametrize("args, message", [
    (["run", "in.sedimentation", "--np", "1000"], "more ranks than the"),
    (["sample", PSD, "--particle-density", "998.2"], "grains settle in water only if denser than it"),
    (["sample", PSD, "--mass", "1e3"], "1000 kg is not within 0.01-0.2 kg"),
    (["sample", PSD, "--height", "1e-6"], "1e-06 m is not within 0.05-2 m"),
    (["sample", PSD, "--particles", "1e12"], "at most 1e+09"),
    (["sample", REPO / "examples", "--out", "x"], "is a folder"),
])
def test_implausible_input_is_refused_with_the_reason(tmp_path, args, message):
    (tmp_path / "in.sedimentation").write_text("units si\n")
    done = sediment(*args, cwd=tmp_path)
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr


def test_unusable_outputs_and_decks_end_in_one_line(tmp_path):
    (tmp_path / "file").write_text("")
    done = sediment("sample", PSD, "--out", tmp_path / "file")
    assert done.returncode == 2 and "exists and is not a folder" in done.stderr
    binary = tmp_path / "in.binary"
    binary.write_bytes(bytes(range(256)) * 4)
    done = sediment("run", binary, "--quiet")
    assert done.returncode == 2 and "ERROR" in done.stderr and "Traceback" not in done.stderr


def test_readout_refuses_partial_and_implausible_readings(tmp_path):
    deck = sample(tmp_path / "r", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    layers = deck.parent / "layers.h5"
    cases = [(["--surface", "-1"], "leaves no layer below it"),
             (["--cylinder-area", "1e-9"], "1e-09 m2 is not within 0.0005-0.05 m2"),
             (["--pipette-volume", "1"], "1 m3 is not within 1e-05-5e-05 m3")]
    for options, message in cases:
        done = sediment("readout", layers, "--out", tmp_path / "out", *options)
        assert done.returncode == 2 and message in done.stderr, (options, done.stderr)
    partial = deck.parent / "copy.h5"
    partial.write_bytes(layers.read_bytes())
    import h5py
    with h5py.File(partial, "r+") as f:
        f.attrs["complete"] = 0.0
    done = sediment("readout", partial, "--out", tmp_path / "out")
    assert done.returncode == 2 and "is partial" in done.stderr
    assert sediment("readout", partial, "--out", tmp_path / "out", "--allow-partial").returncode == 0
    with h5py.File(partial, "r+") as f:
        f["fraction"][3, 0, 0] = np.nan
    done = sediment("readout", partial, "--out", tmp_path / "out", "--allow-partial")
    assert done.returncode == 2 and "corrupt frame data" in done.stderr


def test_damaged_files_and_interrupts_end_in_one_line(tmp_path):
    deck = sample(tmp_path / "d", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    layers = deck.parent / "layers.h5"
    import h5py

    def damaged(name: str, change) -> Path:
        copy = tmp_path / f"{name}.h5"
        copy.write_bytes(layers.read_bytes())
        with h5py.File(copy, "r+") as f:
            change(f)
        return copy

    def overwrite_frame_bytes(f):    # random bytes in a stored frame, behind HDF5's back
        offset = f["fraction"].id.get_chunk_info(2).byte_offset
        f.close()
        with open(tmp_path / "bytes.h5", "r+b") as raw:
            raw.seek(offset)
            raw.write(np.random.default_rng(1).bytes(64))

    cases = [(damaged("viscosity", lambda f: f.attrs.__setitem__("fluid_viscosity", np.nan)), "not a physical value"),
             (damaged("empty", lambda f: [f[n].resize(0, axis=0) for n in ("time", "step", "fraction")]),
              "no frames"),
             (damaged("bytes", overwrite_frame_bytes), "truncated or corrupt")]
    for path, message in cases:
        done = sediment("readout", path, "--out", tmp_path / "out")
        assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr, done.stderr
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if os.access(locked, os.W_OK):    # root writes anywhere: a file where the folder should be instead
            locked.chmod(0o700)
            (locked / "out").write_text("")
            target = locked / "out" / "readout"
        else:
            target = locked / "readout"
        done = sediment("readout", layers, "--out", target)
        assert done.returncode == 2 and "Traceback" not in done.stderr and done.stderr.count("\n") == 1
    finally:
        locked.chmod(0o700)
    running = subprocess.Popen(SEDIMENT + ["run", str(deck), "--quiet", "--force"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    wait_for(lambda: len(processes_in(deck.parent)) >= 1, process=running)
    running.send_signal(signal.SIGINT)
    _, err = running.communicate(timeout=HANG_GUARD)
    assert running.returncode == 130 and "stopped by SIGINT" in err and "Traceback" not in err


@pytest.mark.parametrize("where", ["after LAMMPS ended", "while the record was written"])
def test_a_signal_as_the_run_finishes_keeps_its_complete_result(tmp_path, monkeypatch, where):
    """A SIGINT once LAMMPS has finished (its layer file complete) but before the run's bookkeeping is done:
    the run record says finished, with the layer file's SHA-256, the log is in place, and the message says
    the results are complete (it said 'files left as *.partial ... --resume continues', the record 'failed')."""
    import json

    from sediment.sim import run as sim_run

    deck = sample(tmp_path / "s", "--particles", 1000)
    real_run, real_write = sim_run._run, sim_run.write_record

    def then_interrupted(*args, **kwargs):
        real_run(*args, **kwargs)
        raise KeyboardInterrupt("SIGINT")

    def interrupted_while_written(folder, **record):
        real_write(folder, **record)
        if record.get("state") == "finished":
            signal.raise_signal(signal.SIGINT)    # held until the record is written, then raised
    if where == "after LAMMPS ended":
        monkeypatch.setattr(sim_run, "_run", then_interrupted)
    else:
        monkeypatch.setattr(sim_run, "write_record", interrupted_while_written)
    from sediment import cli

    with pytest.raises(sim_run.RunInterrupted, match="its results are complete"):
        previous = signal.signal(signal.SIGINT, cli._interrupt)
        try:
            sim_run.run_deck(deck, progress=False)
        finally:
            signal.signal(signal.SIGINT, previous)
    record = json.loads((deck.parent / sim_run.RECORD).read_text())
    assert record["state"] == "finished" and record["layers"]["sha256"] == digest(deck.parent / "layers.h5")
    assert (deck.parent / "log.lammps").is_file() and read_layers(deck.parent / "layers.h5").complete


def test_resume_names_what_changed_since_the_interrupted_run(tmp_path):
    """--resume of a run whose inputs changed names the file: the deck edited, sample.data deleted, a file the
    deck now includes (it blamed sample.data for an edited deck, and said '(none) changed' once it was gone)."""
    import json

    from sediment.sim.provenance import RECORD

    deck = sample(tmp_path / "r", "--particles", 1000)
    assert sediment("run", deck, "--quiet").returncode == 0
    record = json.loads((deck.parent / RECORD).read_text())
    (deck.parent / RECORD).write_text(json.dumps(record | {"state": "interrupted"}))    # as a killed run leaves it
    assert (deck.parent / "restart.a.bin").is_file()
    text = deck.read_text()
    for change, words in [(lambda: deck.write_text(text + "variable edited equal 1\n"), "in.sedimentation changed"),
                          (lambda: (deck.parent / "sample.data").rename(deck.parent / "kept.data"), "sample.data deleted"),
                          (lambda: ((deck.parent / "extra.lmp").write_text("print hello\n"),
                                    deck.write_text(text + "include extra.lmp\n")), "in.sedimentation now reads extra.lmp")]:
        change()
        done = sediment("run", deck, "--resume", "--quiet")
        assert done.returncode == 2 and words in done.stderr and "since the interrupted run started" in done.stderr, \
            done.stderr
        deck.write_text(text)
        if (deck.parent / "kept.data").exists():
            (deck.parent / "kept.data").rename(deck.parent / "sample.data")


def test_a_run_that_starts_after_the_stop_is_stopped_at_once(tmp_path):
    """The planner stops its trials together on Ctrl-C; a trial whose thread had started its LAMMPS but not yet
    added it to the runs under way was missed, and the plan waited for it (for ever, were it paused). A run
    added after the stop is stopped as soon as it is known, and none starts after it."""
    from sediment.sim.process import RunInterrupted, Runs, start_process
    from sediment.sim.run import run_batch

    runs = Runs()
    runs.stop()
    proc = start_process(["sleep", "600"], dict(os.environ), tmp_path)
    runs.add(proc)
    assert proc.poll() is not None
    deck = tmp_path / "in.none"
    deck.write_text("print hello\n")
    with pytest.raises(RunInterrupted, match="stopped before this one began"):
        run_batch(deck, running=runs)


@pytest.mark.parametrize("starts_hanging", [1, 2])
def test_a_start_that_hangs_silently_is_tried_again_once(tmp_path, monkeypatch, starts_hanging):
    """Open MPI's singleton start hung twice in one make test (MPI_Init waiting on its daemon, no CPU
    time, until killed by hand). A run that prints nothing is stopped after START_WAIT and started once
    more; after two such starts it is an error that says so. The stand-in for LAMMPS hangs silently on
    its first `starts_hanging` starts, then prints like a run."""
    from sediment.sim import process
    from sediment.sim.run import run_deck

    monkeypatch.setattr(process, "START_WAIT", 1.0)
    starts = tmp_path / "starts"
    fake = tmp_path / "lmp_fake"
    fake.write_text("#!/bin/sh\n"
                    f"echo x >> {starts}\n"
                    f'[ "$(wc -l < {starts})" -le {starts_hanging} ] && exec sleep 600\n'
                    'while [ "$1" != -log ]; do shift; done\n'
                    "echo 'LAMMPS (fake)'; echo 'Loop time of 0.1 on 1 procs for 0 steps' | tee $2\n")
    fake.chmod(0o755)
    monkeypatch.setenv("SEDIMENT_LMP", str(fake))
    deck = tmp_path / "in.none"
    deck.write_text("print hello\n")
    began = time.monotonic()
    if starts_hanging == 1:
        out = run_batch(deck)
        assert "Loop time" in out.text and out.returncode == 0
        starts.unlink()
        result = run_deck(deck, progress=False)
        assert "Loop time" in result.log.read_text() and starts.read_text().count("x") == 2
    else:
        with pytest.raises(RuntimeError, match="printed nothing in 1 s after each of 2 starts"):
            run_batch(deck)
    assert time.monotonic() - began < 60    # the hung starts were stopped, not waited on
    assert not processes_in(tmp_path)    # (another test's `sleep 600` may run beside this one)


def test_the_wait_for_the_runs_takes_a_signal_another_thread_received():
    """The kernel may hand SIGINT or SIGTERM to any thread that does not block it: to a worker waiting on
    its run, Python's handler then runs in the main thread only once that thread runs again. Waiting on
    the workers without a timeout (concurrent.futures.as_completed), the main thread did not, and a plan
    whose runs were paused hung after the signal (1 time in 8 on a loaded machine). Here the signal goes
    to the worker while the main thread waits on it; the wait raises the handler's exception at once."""
    from concurrent.futures import ThreadPoolExecutor

    from sediment.sim.process import finished_in_turn

    class Stopped(Exception):
        pass

    def stop(_signum, _frame):
        raise Stopped

    started, release = threading.Event(), threading.Event()
    worker = []

    def wait_in_worker() -> None:
        worker.append(threading.get_ident())
        started.set()
        release.wait(60)    # a hang guard only: the test ends long before

    previous = signal.signal(signal.SIGUSR1, stop)
    try:
        with ThreadPoolExecutor(max_workers=1) as pool:
            future = pool.submit(wait_in_worker)
            started.wait()
            to_worker = threading.Timer(0.3, signal.pthread_kill, (worker[0], signal.SIGUSR1))
            begun = time.monotonic()
            try:
                with pytest.raises(Stopped):
                    to_worker.start()
                    for _ in finished_in_turn([future]):
                        pass
            finally:
                release.set()
            assert time.monotonic() - begun < 30
    finally:
        signal.signal(signal.SIGUSR1, previous)


def test_a_stopped_run_leaves_no_process_holding_its_output(tmp_path):
    """A one-rank run is an Open MPI singleton whose daemon (orted) sets up a session of its own and holds
    the run's stdout; stopping only the run's session left it there, and the reader of the run's output
    (an interrupted plan) waiting until the daemon chose to exit. Here the run starts a child in another
    session that holds the output as the daemon does: after the stop the output ends at once."""
    from sediment.sim.process import start_process, stop_process

    proc = start_process(["sh", "-c", "echo started; setsid sleep 600"], dict(os.environ), tmp_path,
                         stdout=subprocess.PIPE)
    assert proc.stdout.readline() == "started\n"
    time.sleep(0.2)    # setsid has made its session and become sleep
    stop_process(proc, grace=5.0)
    rest: list[str] = []
    reader = threading.Thread(target=lambda: rest.append(proc.stdout.read()), daemon=True)
    reader.start()
    reader.join(timeout=15)
    assert not reader.is_alive(), "a process the run started still holds its output"
    assert rest == [""]


def test_lammps_lines_reach_a_pipe_as_they_are_printed(tmp_path):
    """Debian's 2021 LAMMPS ends a refused deck inside error->all with MPI_Finalize() and exit(1): a fault in
    MPI's shutdown (seen once in thousands of runs, under load) took the ERROR line, still in stdout's
    block buffer, with it. lmp_sediment's stdout is line-buffered: a line is in the pipe when printed."""
    from sediment.sim.paths import lmp_executable
    from sediment.sim.process import run_environment, start_process, stop_process

    deck = tmp_path / "in.wait"
    deck.write_text("units si\nregion b block 0 1 0 1 0 1\ncreate_box 1 b\nshell sleep 60\n")
    proc = start_process([lmp_executable(), "-in", str(deck), "-log", "none"], run_environment(), tmp_path,
                         stdout=subprocess.PIPE)
    try:
        first: list[str] = []
        reader = threading.Thread(target=lambda: first.append(proc.stdout.readline()), daemon=True)
        reader.start()
        reader.join(timeout=30)
        assert first and first[0].startswith("LAMMPS ("), "LAMMPS's first line was still in its buffer"
    finally:
        stop_process(proc, grace=5.0)


@pytest.mark.parametrize("deck", ["refused", "finished"])
def test_mpi_components_stay_mapped_through_mpi_finalize(tmp_path, deck):
    """Open MPI 4.1's singleton unloads its PMIx component in MPI_Finalize before it stops the progress thread
    that may still call into it: once in thousands of runs under load, the thread jumped into unmapped code
    (SIGSEGV; a core showed it). lmp_sediment pins the components of Open MPI and PMIx first, on both ways
    out: LAMMPS's own MPI_Finalize inside error->all (Debian's 2021 build) and the driver's."""
    from sediment.sim.paths import lmp_executable
    from sediment.sim.process import run_environment

    text = "units si\nregion b block 0 1 0 1 0 1\ncreate_box 1 b\n"
    if deck == "refused":
        text += "fix f all fluid density -1 viscosity 1e-3\n"
    (tmp_path / "in.deck").write_text(text)
    proc = subprocess.Popen([lmp_executable(), "-in", "in.deck", "-log", "none"], cwd=tmp_path, text=True,
                            env=dict(run_environment(), LD_DEBUG="files"), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    out, _ = proc.communicate(timeout=120)
    assert proc.returncode == (1 if deck == "refused" else 0), out[-2000:]
    lines = out.splitlines()
    last = "ERROR: Fix fluid: density" if deck == "refused" else "Total wall time"
    end = max(k for k, line in enumerate(lines) if line.startswith(last))
    unloaded = [line.split("file=")[1].split()[0] for line in lines[end:]
                if line.strip().startswith(f"{proc.pid}:") and "destroying link map" in line]
    components = [path for path in unloaded if Path(path).name.startswith(("mca_", "pmix_mca_"))]
    assert unloaded, "LD_DEBUG's record of unloaded libraries is missing"
    assert not components, f"unloaded by MPI_Finalize: {components}"
