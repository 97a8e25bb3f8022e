# SPDX-License-Identifier: GPL-2.0-or-later
"""Damaged files never become results (issue 58): a damaged `.partial` or restart file is refused on
--resume (the older restart file tried), no layer file is marked complete before it reads back
whole, and `readout` checks a layer file before HDF5 reads it and names what is damaged, never
crashing. What a result depends on (the PSD tables beside it, the temperature record of a plan) is
checked when it is used."""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
from pathlib import Path

import h5py
import numpy as np
import pytest

from test_faults import PSD, REPO, sample, sediment
from test_identity import SAMPLE1, kill_when

from sediment.sim import layers as layers_module
from sediment.sim.layers import LayerFileError, check_layer_file, read_layers, read_layers_guarded


def flip(path: Path, offset: int, count: int = 3) -> None:
    """Inverts `count` bytes of a file at `offset`, behind HDF5's back."""
    with open(path, "r+b") as f:
        f.seek(offset)
        data = f.read(count)
        f.seek(offset)
        f.write(bytes(b ^ 0xFF for b in data))


def chunk_offset(path: Path, frame: int) -> int:
    with h5py.File(path, "r", locking=False) as f:
        return f["fraction"].id.get_chunk_info(frame).byte_offset


# 8680 steps (24 h at Courant 0.5), some 3 s: restart files at steps 2000, 4000, 6000 and 8000.
SHORT = ("--particles", 2000, "--t-end", 86400, "--courant", 0.5)


def interrupted(folder: Path) -> None:
    """Kills a run of the deck in `folder` once both restart files and their checksums are written."""
    kill_when(folder, lambda: all((folder / f"restart.{k}.bin.crc32").is_file() for k in "ab"))
    # the killed run's processes may close the file a moment after they are gone from the folder: the
    # damage below is done as a user would, without waiting on HDF5's file lock
    assert (folder / "layers.h5.partial").is_file() and not (folder / "layers.h5").exists(), "the run finished"


def test_a_damaged_partial_is_refused_on_resume_naming_it(tmp_path):
    deck = sample(tmp_path / "x", *SHORT)
    folder = deck.parent
    interrupted(folder)
    partial = folder / "layers.h5.partial"
    kept = partial.read_bytes()
    for damage in (lambda: flip(partial, chunk_offset(partial, 1) + 40),    # a frame's bytes
                   lambda: partial.write_bytes(kept[:len(kept) // 2]),     # truncated
                   lambda: partial.write_bytes(b"")):
        partial.write_bytes(kept)
        damage()
        done = sediment("run", deck, "--quiet", "--resume")
        assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
        assert "cannot resume" in done.stderr and str(partial) in done.stderr and "--force" in done.stderr
        assert not (folder / "layers.h5").exists()
    partial.write_bytes(kept)
    with h5py.File(partial, "r+", locking=False) as f:    # whole, but another run's frames
        f.attrs["run_id"] = "0123456789ab-e3b0c4-00000000"
    done = sediment("run", deck, "--quiet", "--resume")
    assert done.returncode == 2 and "holds the frames of run 0123456789ab-e3b0c4-00000000" in done.stderr
    partial.write_bytes(kept)
    assert sediment("run", deck, "--quiet", "--resume").returncode == 0
    assert read_layers(folder / "layers.h5").complete


def test_a_frame_torn_by_the_kill_is_dropped_on_resume(tmp_path):
    # Clone 60: the kill came while fix layers/hdf5 flushed a frame, which the partial then held with
    # HDF5's fill value in its time (the flush writes the datasets' chunks in no set order), and --resume
    # refused the partial. Frames past those the fix counted as written are not the file's: the run
    # resumes, and completes its frames.
    deck = sample(tmp_path / "x", *SHORT)
    folder = deck.parent
    interrupted(folder)
    partial = folder / "layers.h5.partial"
    with h5py.File(partial, "r+", locking=False) as f:
        written = int(f.attrs["frames"])
        assert all(len(f[name]) == written for name in ("time", "step", "fraction"))
        for name in ("time", "step", "fraction", "fluid"):
            if name in f:
                f[name].resize(written + 1, axis=0)    # the frame's space, and nothing written in it
        f["fraction"][written] = 0.01                  # but its fractions and its fluid
        f["fluid"][written] = f["fluid"][written - 1]
    flip(partial, chunk_offset(partial, written) + 40)    # half written: its checksum fails
    assert len(read_layers(partial).time) == written
    done = sediment("run", deck, "--quiet", "--resume")
    assert done.returncode == 0, done.stderr
    layers = read_layers(folder / "layers.h5")
    assert layers.complete and np.all(np.diff(layers.time) > 0) and layers.time[-1] >= 86400 * (1 - 1e-9)


def test_frames_that_do_not_read_back_are_never_marked_complete(tmp_path):
    # A frame damaged between two runs of one deck, behind the fix's back: the file stays .partial.
    deck = (REPO / "lammps-pkg" / "examples" / "in.settling").read_text()
    (tmp_path / "damage.py").write_text(
        "import h5py\n"
        "with h5py.File('layers.h5.partial', 'r') as f:\n"
        "    at = f['fraction'].id.get_chunk_info(1).byte_offset\n"
        "with open('layers.h5.partial', 'r+b') as f:\n"
        "    f.seek(at + 8)\n"
        "    f.write(b'\\xff\\xfe\\xfd')\n")
    first, rest = deck.split("run             1000")
    (tmp_path / "in.damaged").write_text(first + "run 300\nshell /usr/bin/python3 damage.py\nrun 300" + rest)
    done = subprocess.run([os.environ["SEDIMENT_LMP"], "-in", "in.damaged", "-log", "none"], cwd=tmp_path,
                          capture_output=True, text=True)
    assert "frame 1 of dataset fraction does not read back" in done.stderr + done.stdout
    assert not (tmp_path / "layers.h5").exists() and (tmp_path / "layers.h5.partial").exists()


def test_random_bytes_in_the_newest_restart_file_fall_back_to_the_older(tmp_path):
    whole = sample(tmp_path / "whole", *SHORT)
    assert sediment("run", whole, "--quiet").returncode == 0
    deck = sample(tmp_path / "cut", *SHORT)
    folder = deck.parent
    interrupted(folder)
    newest = max(folder.glob("restart.*.bin"), key=lambda p: p.stat().st_mtime_ns)
    with open(newest, "r+b") as f:    # the same size, other bytes in the atoms' data
        f.seek(newest.stat().st_size // 2)
        f.write(np.random.default_rng(3).bytes(64))
    resumed = sediment("run", deck, "--quiet", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert f"passing over {newest.name} (its bytes differ" in resumed.stderr
    a, b = read_layers(whole.parent / "layers.h5"), read_layers(folder / "layers.h5")
    assert np.array_equal(a.step, b.step) and np.max(np.abs(a.fraction - b.fraction)) < 1e-12


def test_restart_files_that_both_fail_their_checksums_are_refused(tmp_path):
    deck = sample(tmp_path / "x", *SHORT)
    folder = deck.parent
    interrupted(folder)
    for name in ("restart.a.bin", "restart.b.bin"):
        flip(folder / name, 5000)
    done = sediment("run", deck, "--quiet", "--resume")
    assert done.returncode == 2 and "do not match their checksums" in done.stderr
    assert "restart.a.bin" in done.stderr and "restart.b.bin" in done.stderr and "--force" in done.stderr


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    """A finished run's folder."""
    deck = sample(tmp_path_factory.mktemp("finished") / "x", "--particles", 2000)
    assert sediment("run", deck, "--quiet").returncode == 0
    return deck.parent


def test_a_layer_file_is_checked_before_hdf5_reads_it(finished, tmp_path):
    good = (finished / "layers.h5").read_bytes()
    damaged = tmp_path / "damaged.h5"
    intact = read_layers(finished / "layers.h5")
    cases = [(b"", "is empty"), (good[:100], "truncated"), (good[:len(good) - 1], "truncated"),
             (b"\0" * 8 + good[8:], "no HDF5 signature"), (good[:8] + b"\x07" + good[9:], "superblock")]
    for data, message in cases:
        damaged.write_bytes(data)
        with pytest.raises(LayerFileError, match=message):
            check_layer_file(damaged)
    # Three bytes inverted anywhere in the metadata and in some frames: refused with the reason, or read
    # as the intact file (bytes HDF5 does not use); never a crash.
    for offset in [*range(0, 6000, 61), *(chunk_offset(finished / "layers.h5", k) + 16 for k in (0, 5, 50))]:
        damaged.write_bytes(good)
        flip(damaged, offset)
        try:
            read = read_layers_guarded(damaged)
        except LayerFileError as exc:
            assert str(damaged) in str(exc)
            continue
        assert np.array_equal(read.fraction, intact.fraction) and np.array_equal(read.time, intact.time), offset


def test_a_crash_while_reading_is_reported_not_suffered(tmp_path, monkeypatch):
    path = tmp_path / "layers.h5"
    with h5py.File(path, "w") as f:
        f.attrs["schema"] = "sediment-layers"
    monkeypatch.setattr(layers_module, "read_layers", lambda p: os.kill(os.getpid(), signal.SIGSEGV))
    with pytest.raises(LayerFileError, match="crashed the HDF5 library .SIGSEGV."):
        read_layers_guarded(path)


def test_readout_refuses_damaged_files_in_one_line(finished, tmp_path):
    layers = finished / "layers.h5"
    good = layers.read_bytes()
    try:
        # in its run's folder: any changed byte differs from what the run recorded at completion
        flip(layers, 1200)
        done = sediment("readout", layers, "--out", tmp_path / "r")
        assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
        assert "is damaged or was replaced" in done.stderr and ".sediment-run.json" in done.stderr
    finally:
        layers.write_bytes(good)
    copy = tmp_path / "copy.h5"
    for data in (b"", good[:len(good) // 2], good[:40] + b"\xff\xff\xff" + good[43:]):
        copy.write_bytes(data)
        done = sediment("readout", copy, "--out", tmp_path / "r")
        assert done.returncode == 2 and done.stderr.count("\n") == 1 and str(copy) in done.stderr, done.stderr
    assert sediment("readout", layers, "--out", tmp_path / "r").returncode == 0


def test_readout_refuses_tables_replaced_since_the_run(finished, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    assert sediment("sample", SAMPLE1, "--out", elsewhere, "--particles", 2000).returncode == 0
    table = finished / "input_psd.csv"
    kept = table.read_bytes()
    try:
        shutil.copy(elsewhere / "input_psd.csv", table)
        done = sediment("readout", finished / "layers.h5", "--out", tmp_path / "r")
        assert done.returncode == 2 and "input_psd.csv beside" in done.stderr and "changed since its run" in done.stderr
    finally:
        table.write_bytes(kept)
    # the deck of a test sampled with a temperature record put there by hand: named as what changed
    record = tmp_path / "record.csv"
    record.write_text("time_min,temperature_C\n0,15\n1440,25\n")
    warm = tmp_path / "warm"
    assert sediment("sample", PSD, "--out", warm, "--particles", 2000, "--t-end", 7200, "--courant", 1,
                    "--temperature-record", record).returncode == 0
    deck = finished / "in.sedimentation"
    kept = deck.read_bytes()
    try:
        shutil.copy(warm / "in.sedimentation", deck)
        done = sediment("readout", finished / "layers.h5", "--out", tmp_path / "r")
        assert done.returncode == 2 and "in.sedimentation changed since it started" in done.stderr
    finally:
        deck.write_bytes(kept)


def test_sample_refuses_a_plan_of_another_temperature_record(tmp_path):
    from sediment.constants import D422_CYLINDER_AREA, D422_CYLINDER_HEIGHT
    from sediment.lab.psd import read_psd

    psd = read_psd(PSD)
    report = tmp_path / "report.json"
    options = dict(geometry="column", width=None, classes=40, layers=400, t_end=86400.0, mass=0.06,
                   particle_density=2650.0, cylinder_area=D422_CYLINDER_AREA,
                   height=D422_CYLINDER_HEIGHT, temperature=20.0,
                   psd={"diameter_um": (psd.diameter * 1e6).tolist(), "percent_finer": psd.percent_finer.tolist()})
    record = tmp_path / "record.csv"
    record.write_text("time_min,temperature_C\n0,15\n1440,25\n")

    def plan(rows) -> None:
        content = {"decision": {"settings": {"drag": "standard", "hindrance": "richardson-zaki", "particles": 2000,
                                             "courant": 1.0}},
                   "scene_options": dict(options, temperature_record=rows)}
        report.write_text(json.dumps(content))

    plan([])
    done = sediment("sample", PSD, "--plan", report, "--temperature-record", record, "--out", tmp_path / "a")
    assert done.returncode == 2 and "the temperature record (none in the plan, here" in done.stderr, done.stderr
    plan([[0, 19], [86400, 23]])    # seconds, as the record is read
    done = sediment("sample", PSD, "--plan", report, "--temperature-record", record, "--out", tmp_path / "b")
    assert done.returncode == 2 and "2 rows over 1440 min, 19-23 C in the plan" in done.stderr, done.stderr
    done = sediment("sample", PSD, "--plan", report, "--out", tmp_path / "c")
    assert done.returncode == 2 and "here none" in done.stderr
    plan([[0, 15], [86400, 25]])
    done = sediment("sample", PSD, "--plan", report, "--temperature-record", record, "--out", tmp_path / "d")
    assert done.returncode == 0, done.stderr
