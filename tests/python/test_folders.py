# SPDX-License-Identifier: GPL-2.0-or-later
"""Result sets: each command's files published together, replacing only what that command wrote
(sediment.folders), and the commands that go through it."""
from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from sediment import cli
from sediment.folders import JOURNAL, MANIFEST, OutputSet, read_manifest, settle

REPO = Path(__file__).resolve().parents[2]
SAMPLE5 = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"


def publish(folder: Path, name: str, files: dict[str, str], inputs=()) -> list[Path]:
    with OutputSet(folder, name, inputs) as outputs:
        for rel, text in files.items():
            (outputs.stage / rel).parent.mkdir(parents=True, exist_ok=True)
            (outputs.stage / rel).write_text(text)
        return outputs.publish()


def contents(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): p.read_text() for p in sorted(folder.rglob("*"))
            if p.is_file() and not any(part.startswith(".sediment") for part in p.relative_to(folder).parts)}


def test_a_set_replaces_its_own_files_and_keeps_everyone_elses(tmp_path):
    publish(tmp_path, "readout", {"hydrometer.csv": "h1", "pipette.csv": "p1", "runs/a/x": "r1"})
    publish(tmp_path, "invert", {"fit.csv": "f1"})
    (tmp_path / "notes.txt").write_text("mine")
    written = publish(tmp_path, "readout", {"hydrometer.csv": "h2", "runs/b/y": "r2"})
    assert sorted(p.name for p in written) == ["hydrometer.csv", "runs"]
    # pipette.csv and runs/a were the previous readout's: gone with it; the rest untouched
    assert contents(tmp_path) == {"fit.csv": "f1", "hydrometer.csv": "h2", "notes.txt": "mine", "runs/b/y": "r2"}
    assert set(read_manifest(tmp_path)["sets"]) == {"readout", "invert"}
    assert not list(tmp_path.glob(".sediment-stage-*")) and not (tmp_path / JOURNAL).exists()
    with OutputSet(tmp_path, "readout") as outputs:    # what it removes of its previous files, it says
        (outputs.stage / "hydrometer.csv").write_text("h3")
        outputs.publish()
        assert outputs.dropped == ["runs"]


def test_a_design_never_replaces_an_inversion_in_its_folder(tmp_path, capsys):
    """`invert --design` and an inversion are different sets: a design into a finished inversion's folder is
    refused, naming the inversion's files, which stay as they were (it removed them before)."""
    out = tmp_path / "out"
    publish(out, "invert", {"psd.csv": "psd", "runs/round1/x": "r"})
    code = cli.main(["invert", "--design", str(SAMPLE5), "--masses", "0.05", "--particles", "2000", "--out", str(out)])
    assert code == 2 and "written by sediment invert" in capsys.readouterr().err
    assert contents(out) == {"psd.csv": "psd", "runs/round1/x": "r"}


@pytest.mark.parametrize("meddle, why", [
    (lambda d: (d / "fit.csv").write_text("edited"), "changed since sediment invert wrote it"),
    (lambda d: (d / "plot.png").write_text("mine"), "not written by sediment invert"),
    (lambda d: (d / "runs" / "extra").write_text("mine"), "not written by sediment invert"),
    (lambda d: (d / "table.csv").write_text("mine"), "written by sediment readout"),
])
def test_a_set_refuses_to_replace_what_it_did_not_write(tmp_path, meddle, why):
    publish(tmp_path, "readout", {"table.csv": "t"})
    publish(tmp_path, "invert", {"fit.csv": "f1", "runs/x": "r"})
    if "written by sediment readout" in why:
        (tmp_path / "table.csv").unlink()
        publish(tmp_path, "readout", {"table.csv": "t2"})
    meddle(tmp_path)
    before = contents(tmp_path)
    with pytest.raises(ValueError, match=why):
        publish(tmp_path, "invert", {"fit.csv": "f2", "plot.png": "p", "table.csv": "t3", "runs/y": "r"})
    assert contents(tmp_path) == before and not list(tmp_path.glob(".sediment-stage-*"))


def test_a_copied_folder_stays_the_commands(tmp_path):
    import shutil

    publish(tmp_path / "a", "readout", {"table.csv": "t1", "runs/x": "r"})
    shutil.copytree(tmp_path / "a", tmp_path / "b")
    publish(tmp_path / "b", "readout", {"table.csv": "t2"})
    assert contents(tmp_path / "b") == {"table.csv": "t2"}


def test_a_set_never_replaces_its_own_input(tmp_path):
    publish(tmp_path, "invert", {"fit.csv": "f1"})
    with pytest.raises(ValueError, match="fit.csv is an input of this sediment invert"):
        publish(tmp_path, "invert", {"fit.csv": "f2"}, inputs=[tmp_path / "fit.csv"])
    assert (tmp_path / "fit.csv").read_text() == "f1"


def test_a_publish_killed_midway_is_completed_by_the_next_command(tmp_path):
    publish(tmp_path, "readout", {"a.csv": "a1", "b.csv": "b1"})
    # a publish stopped after its first move: the journal is in place, b.csv still staged
    with OutputSet(tmp_path, "readout") as outputs:
        for name in ("a.csv", "b.csv"):
            (outputs.stage / name).write_text(name[0] + "2")
        stage = outputs.stage
        journal = {"set": "readout", "stage": stage.name, "move": ["a.csv", "b.csv"], "remove": []}
        (stage / MANIFEST).write_text(json.dumps({"format": 1, "sets": {}}))
        (tmp_path / JOURNAL).write_text(json.dumps(journal))
        os.replace(stage / "a.csv", tmp_path / "a.csv")
    assert stage.is_dir() and contents(tmp_path) == {"a.csv": "a2", "b.csv": "b1"}    # the stage kept for settle()
    with OutputSet(tmp_path, "invert"):
        pass
    assert contents(tmp_path) == {"a.csv": "a2", "b.csv": "b2"} and not stage.exists()
    assert not (tmp_path / JOURNAL).exists()


def test_damaged_bookkeeping_is_named(tmp_path):
    (tmp_path / JOURNAL).write_text("{half")
    with pytest.raises(ValueError, match=f"{JOURNAL} is damaged"):
        settle(tmp_path)
    (tmp_path / JOURNAL).unlink()
    for files in ('{"a": 3}', '{"../outside": [1, "ab"]}', '{"/etc/passwd": [1, "ab"]}', '{"a/../../b": [1, "ab"]}'):
        (tmp_path / MANIFEST).write_text('{"sets": {"x": {"files": %s}}}' % files)
        with pytest.raises(ValueError, match=f"{MANIFEST} is damaged"):
            publish(tmp_path, "x", {"a": "1"})
    (tmp_path / MANIFEST).unlink()
    # a forged journal may not move or remove anything outside the folder
    (tmp_path / "keep").write_text("k")
    (tmp_path / JOURNAL).write_text('{"stage": ".sediment-stage-1", "move": [], "remove": ["../" + "%s/keep"]}'
                                    % tmp_path.name)
    with pytest.raises(ValueError, match=f"{JOURNAL} is damaged"):
        settle(tmp_path)
    assert (tmp_path / "keep").read_text() == "k"


def test_a_manifest_edited_by_hand_is_not_trusted(tmp_path):
    """A set renamed in the manifest (an inversion's files made a readout's), or an entry forged for a user's
    file, would have the next command remove them: the manifest's checksum fails, and nothing is removed."""
    publish(tmp_path, "invert", {"psd.csv": "p", "fit.csv": "f"})
    (tmp_path / "notes.txt").write_text("mine")
    manifest = json.loads((tmp_path / MANIFEST).read_text())
    assert manifest["format"] == 2 and len(manifest["checksum"]) == 64
    for edit in (lambda m: m["sets"].__setitem__("readout", m["sets"].pop("invert")),
                 lambda m: m["sets"]["invert"]["files"].__setitem__("notes.txt", [4, "0" * 64])):
        edited = json.loads(json.dumps(manifest))
        edit(edited)
        (tmp_path / MANIFEST).write_text(json.dumps(edited))
        before = contents(tmp_path)
        with pytest.raises(ValueError, match=f"{MANIFEST} was edited \\(its checksum fails\\)"):
            publish(tmp_path, "readout", {"hydrometer.csv": "h"})
        assert contents(tmp_path) == before
    # a manifest of format 1 (no checksum) is read as written, and written again with its checksum
    (tmp_path / MANIFEST).write_text(json.dumps({"format": 1, "sets": manifest["sets"]}))
    publish(tmp_path, "invert", {"psd.csv": "p2"})
    assert read_manifest(tmp_path)["format"] == 2 and not (tmp_path / "fit.csv").exists()
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_a_full_disk_while_staging_leaves_the_folder_as_it_was(tmp_path):
    publish(tmp_path, "readout", {"a.csv": "a1"})
    with pytest.raises(OSError, match="No space left on device .*a.csv.*nothing of this sediment readout was published"):
        with OutputSet(tmp_path, "readout") as outputs:
            (outputs.stage / "b.csv").write_text("b2")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(outputs.stage / "a.csv"))
    assert contents(tmp_path) == {"a.csv": "a1"} and not list(tmp_path.glob(".sediment-stage-*"))


def test_a_second_command_in_the_folder_is_refused(tmp_path):
    with OutputSet(tmp_path, "plan"):
        with pytest.raises(RuntimeError, match=f"another sediment command \\(pid {os.getpid()}\\) is using {tmp_path}"):
            with OutputSet(tmp_path, "readout"):
                pass


def test_stages_of_dead_commands_are_cleared(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stale = tmp_path / f".sediment-stage-{dead.stdout.strip()}"
    (stale / "runs").mkdir(parents=True)
    publish(tmp_path, "readout", {"a.csv": "a"})
    assert not stale.exists()


def test_signals_wait_for_the_publish(tmp_path):
    """SIGINT during the moves is taken after them: the set is whole. Another thread runs, as a
    progress bar's does: the signal may land in it."""
    import threading

    done = threading.Event()
    threading.Thread(target=done.wait, daemon=True).start()
    with pytest.raises(KeyboardInterrupt):
        with OutputSet(tmp_path, "readout") as outputs:
            for k in range(50):
                (outputs.stage / f"{k}.csv").write_text(str(k))
            previous = signal.signal(signal.SIGINT, signal.default_int_handler)
            try:
                real = os.replace

                def replace_then_interrupt(a, b):
                    real(a, b)
                    if Path(b).name == "0.csv":
                        os.kill(os.getpid(), signal.SIGINT)
                os.replace = replace_then_interrupt
                try:
                    outputs.publish()
                finally:
                    os.replace = real
            finally:
                signal.signal(signal.SIGINT, previous)
    done.set()
    assert len(contents(tmp_path)) == 50 and outputs.published


def test_commands_publish_their_files_as_one_set(tmp_path, capsys):
    """Two readouts into one folder with a user's file: the second replaces the first's files only."""
    out = tmp_path / "r"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    preview = ["readout", "--psd", str(SAMPLE5), "--stokes-preview", "--out", str(out)]
    assert cli.main(preview) == 0
    assert f"wrote {out}: buoyancy.csv, errors.csv" in capsys.readouterr().out
    assert (out / "pipette.csv").is_file()
    assert cli.main(preview + ["--instrument", "hydrometer"]) == 0
    assert not (out / "pipette.csv").exists() and (out / "notes.txt").read_text() == "mine"
    # a results folder given as the sheet it would overwrite
    (out / "errors.csv").write_text("my sheet")
    assert cli.main(preview) == 2
    err = capsys.readouterr().err
    assert "errors.csv (changed since sediment readout wrote it)" in err and (out / "errors.csv").read_text() == "my sheet"


def test_sample_force_removes_the_run_and_what_was_read_from_it(tmp_path, capsys):
    """A readout of a run's frames in the run's folder goes with the frames that `sample --force` deletes."""
    out = tmp_path / "s"
    small = ["--particles", "2000", "--t-end", "7200", "--out", str(out)]
    assert cli.main(["sample", str(SAMPLE5)] + small) == 0
    (out / "layers.h5").write_bytes(b"frames")    # stands in for a run: readout's inputs are only recorded
    publish(out, "readout", {"hydrometer.csv": "h"}, inputs=[out / "layers.h5"])
    publish(out / "r", "readout", {"pipette.csv": "p"}, inputs=[out / "layers.h5"])    # as run.sh reads it
    publish(out / "mine", "readout", {"pipette.csv": "p"}, inputs=[SAMPLE5])
    other = REPO / "examples" / "granulometry" / "psd" / "sample1.csv"
    assert cli.main(["sample", str(other)] + small) == 2
    assert "holds a run of another scene (layers.h5)" in capsys.readouterr().err
    assert cli.main(["sample", str(other), "--force"] + small) == 0
    printed = capsys.readouterr().out
    assert "removed the results of sediment readout" in printed and "removed 1 file(s) in" in printed
    assert "that this sample replaces: layers.h5" in printed
    assert not (out / "layers.h5").exists() and not (out / "hydrometer.csv").exists()
    assert not (out / "r" / "pipette.csv").exists() and (out / "mine" / "pipette.csv").is_file()
    assert set(read_manifest(out)["sets"]) == {"sample"} and read_manifest(out / "r")["sets"] == {}
