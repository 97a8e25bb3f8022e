#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""A hostile user against the paths of issue 43 (--resume, the folder locks, the planner's folder,
readout's checks): each case does something a user should not, and says whether SEDIMENT answered
well (an error that names the problem and leaves every result as it was, or the right result) or
not. Not part of `make test` (it takes minutes and kills processes); run it as
    PYTHONPATH=python SEDIMENT_LMP=build/lmp_sediment tests/hostile/round2.py
and it prints one line per case and the counts."""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SEDIMENT = [str(REPO / "bin" / "sediment")]
PSD = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"
PSD1 = REPO / "examples" / "granulometry" / "psd" / "sample1.csv"
LONG = ["--particles", "15000", "--courant", "0.1"]
SHORT = ["--particles", "2000", "--t-end", "7200"]
results: list[tuple[str, bool, str]] = []


def sediment(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(SEDIMENT + [str(a) for a in args], capture_output=True, text=True, timeout=timeout)


def tree(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and ".lock" not in p.name}


def case(name: str, good: bool, detail: str) -> None:
    results.append((name, good, detail))
    print(f"{'ok ' if good else 'BAD'} {name}: {detail.strip().splitlines()[-1][:160] if detail.strip() else ''}",
          flush=True)


def refused(done: subprocess.CompletedProcess, *words: str) -> bool:
    """Exit 2 with one line naming the problem, no traceback."""
    return done.returncode == 2 and "Traceback" not in done.stderr and all(w in done.stderr for w in words)


def sample(out: Path, psd: Path = PSD, *options: str) -> Path:
    done = sediment("sample", psd, "--out", out, *options)
    assert done.returncode == 0, done.stderr
    return out / "in.sedimentation"


def killed(folder: Path, when, *options: str) -> None:
    """`run --force` in `folder`, SIGKILLed once when() holds."""
    run = subprocess.Popen(SEDIMENT + ["run", str(folder / "in.sedimentation"), "--quiet", "--force", *options],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    end = time.monotonic() + 120
    while not when() and time.monotonic() < end and run.poll() is None:
        time.sleep(0.01)
    run.send_signal(signal.SIGKILL)
    run.wait()
    time.sleep(1.0)


def with_restarts(folder: Path) -> bool:
    return all((folder / n).is_file() and (folder / n).stat().st_size > 0 for n in ("restart.a.bin", "restart.b.bin"))


def interrupted(root: Path, name: str) -> Path:
    """A folder with an interrupted run that has both restart files and its partial frames."""
    deck = sample(root / name, PSD, *LONG)
    for _ in range(3):
        killed(deck.parent, lambda: with_restarts(deck.parent))
        if with_restarts(deck.parent) and (deck.parent / "layers.h5.partial").is_file():
            return deck
    raise RuntimeError(f"{deck.parent}: the run wrote no restart files before it ended")


def main() -> int:
    root = Path(tempfile.mkdtemp(prefix="hostile2-"))
    # ---- --resume ----------------------------------------------------------------------------
    deck = interrupted(root, "norecord")
    (deck.parent / ".sediment-run.json").unlink()
    case("resume without the run record", refused(sediment("run", deck, "--resume", "--quiet"), "nothing to resume"),
         sediment("run", deck, "--resume", "--quiet").stderr)
    deck = interrupted(root, "badrecord")
    (deck.parent / ".sediment-run.json").write_text("{not json")
    done = sediment("run", deck, "--resume", "--quiet")
    case("resume with a damaged run record", refused(done, "damaged", "--force"), done.stderr)
    deck = interrupted(root, "otherdeck")
    shutil.copy(deck, deck.parent / "in.copy")
    done = sediment("run", deck.parent / "in.copy", "--resume", "--quiet")
    case("resume of another deck name in the folder", refused(done, "nothing to resume"), done.stderr)
    deck = interrupted(root, "comment")
    deck.write_text(deck.read_text() + "# a note of mine\n")
    done = sediment("run", deck, "--resume", "--quiet")
    case("resume after a comment added to the deck (allowed)", done.returncode == 0, done.stderr)
    deck = interrupted(root, "edited")
    deck.write_text(deck.read_text() + 'print "edited"\n')
    done = sediment("run", deck, "--resume", "--quiet")
    case("resume after the deck was edited", refused(done, "changed since"), done.stderr)
    deck = interrupted(root, "vars")
    done = sediment("run", deck, "--resume", "--quiet", "--var", "dt_scale", "2")
    case("resume with other --var values", refused(done, "same --var"), done.stderr)
    deck = interrupted(root, "bothcut")
    for name in ("restart.a.bin", "restart.b.bin"):
        path = deck.parent / name
        path.write_bytes(path.read_bytes()[:1000])
    before = tree(deck.parent)
    done = sediment("run", deck, "--resume", "--quiet")
    case("resume with both restart files truncated", done.returncode == 2 and "Traceback" not in done.stderr
         and not (deck.parent / "layers.h5").exists(), done.stderr)
    deck = interrupted(root, "foreign")
    other = interrupted(root, "foreign-src")
    for name in ("restart.a.bin", "restart.b.bin"):
        shutil.copy(other.parent / name, deck.parent / name)
    done = sediment("run", deck, "--resume", "--quiet")
    case("resume from another folder's restart files (same deck)", refused(done, "of another run"), done.stderr)
    deck = interrupted(root, "damagedpartial")
    partial = deck.parent / "layers.h5.partial"
    partial.write_bytes(partial.read_bytes()[:3000])
    done = sediment("run", deck, "--resume", "--quiet")
    case("resume with a damaged layers.h5.partial", refused(done, "damaged", "--force"), done.stderr)
    deck = interrupted(root, "np")
    done = sediment("run", deck, "--resume", "--quiet", "--np", "2")
    whole = sample(root / "np-whole", PSD, *LONG)
    sediment("run", whole, "--quiet")
    import numpy as np
    sys.path.insert(0, str(REPO / "python"))
    from sediment.sim.layers import read_layers
    ok = done.returncode == 0
    if ok:
        a, b = read_layers(whole.parent / "layers.h5"), read_layers(deck.parent / "layers.h5")
        ok = np.array_equal(a.step, b.step) and float(np.max(np.abs(a.fraction - b.fraction))) < 1e-10
    case("resume on 2 ranks of a run begun on 1 (the same frames)", ok, done.stderr)
    deck = interrupted(root, "twice")
    first = subprocess.Popen(SEDIMENT + ["run", str(deck), "--resume", "--quiet"], stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    second = sediment("run", deck, "--resume", "--quiet")
    first.communicate()
    case("two resumes at once", refused(second, "another sediment command") and first.returncode == 0, second.stderr)
    deck = interrupted(root, "killresume")
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--resume", "--quiet"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    time.sleep(2.0)
    run.send_signal(signal.SIGKILL)
    run.wait()
    time.sleep(1.0)
    done = sediment("run", deck, "--resume", "--quiet")
    case("a resume killed, resumed again", done.returncode == 0 and read_layers(deck.parent / "layers.h5").complete,
         done.stderr)
    deck = interrupted(root, "intresume")
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--resume", "--quiet"], stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)
    run.send_signal(signal.SIGINT)
    _, err = run.communicate()
    case("Ctrl-C during a resume says where the frames are", run.returncode == 130 and "layers.h5.partial" in err
         and "--resume" in err, err)
    # ---- locks -------------------------------------------------------------------------------
    deck = sample(root / "lock", PSD, *LONG)
    run = subprocess.Popen(SEDIMENT + ["run", str(deck), "--quiet"], stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)
    done = sediment("sample", PSD, "--out", deck.parent, *LONG)
    case("sample into a folder while a run works there", refused(done, "another sediment command"), done.stderr)
    done = sediment("readout", deck.parent / "layers.h5", "--out", root / "lock-r")
    case("readout while the run works (no complete file yet)", refused(done, "no such layer file")
         or refused(done, "partial"), done.stderr)
    run.send_signal(signal.SIGINT)
    run.communicate()
    deck = sample(root / "stalelock", PSD, *SHORT)
    (deck.parent / ".sediment.lock").write_text("99999")
    done = sediment("run", deck, "--quiet")
    case("a lock file left by a dead process does not block", done.returncode == 0, done.stderr)
    ro = root / "readonly"
    deck = sample(ro, PSD, *SHORT)
    sediment("run", deck, "--quiet")
    os.chmod(ro, 0o555)
    done = subprocess.run(["setpriv", "--reuid", "65534", "--regid", "65534", "--clear-groups", "--",
                           *SEDIMENT, "run", str(deck), "--quiet", "--force"], capture_output=True, text=True,
                          env=dict(os.environ, HOME="/tmp"))
    os.chmod(ro, 0o755)
    case("a run in a folder it cannot write", done.returncode == 2 and "Traceback" not in done.stderr, done.stderr)
    # ---- the planner's folder ---------------------------------------------------------------
    plan_args = ["--particles", "2000,1000", "--courant", "4", "--t-end", "7200", "--replicas", "1", "--no-models"]
    file_out = root / "afile"
    file_out.write_text("mine")
    done = sediment("plan", PSD, "--out", file_out, *plan_args)
    case("plan --out naming a file", refused(done, "not a folder") and file_out.read_text() == "mine", done.stderr)
    out = root / "plan"
    first = sediment("plan", PSD, "--out", out, *plan_args)
    before = tree(out)
    run = subprocess.Popen(SEDIMENT + ["plan", str(PSD1), "--out", str(out), *plan_args], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    while not list(root.glob(".plan.new-*/runs/*/layers.h5.partial")) and run.poll() is None:
        time.sleep(0.01)
    run.send_signal(signal.SIGKILL)
    run.wait()
    time.sleep(6.0)    # the guards stop the trials
    left, kept = list(root.glob(".plan.new-*")), tree(out) == before
    again = sediment("plan", PSD, "--out", out, *plan_args)
    case("a plan killed outright: the earlier plan kept, its leftovers cleared by the next",
         first.returncode == 0 and kept and left and again.returncode == 0
         and not list(root.glob(".plan.new-*")), again.stderr)
    legacy = root / "legacy"
    (legacy / "runs").mkdir(parents=True)
    (legacy / "runs" / ".sediment-plan").write_text("old")
    (legacy / "report.json").write_text("{}")
    done = sediment("plan", PSD, "--out", legacy, *plan_args)
    case("a plan folder of the earlier version is replaced", done.returncode == 0 and
         "decision" in json.loads((legacy / "report.json").read_text()), done.stderr)
    first = subprocess.Popen(SEDIMENT + ["plan", str(PSD), "--out", str(out), *plan_args], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
    while not list(root.glob(".plan.new-*/runs")) and first.poll() is None:
        time.sleep(0.01)
    second = sediment("plan", PSD, "--out", out, *plan_args)
    first.communicate()
    case("two plans into one --out at once", refused(second, "another sediment command") and first.returncode == 0,
         second.stderr)
    rodir = root / "roparent"
    rodir.mkdir()
    os.chmod(rodir, 0o555)
    done = subprocess.run(["setpriv", "--reuid", "65534", "--regid", "65534", "--clear-groups", "--",
                           *SEDIMENT, "plan", str(PSD), "--out", str(rodir / "p"), *plan_args], capture_output=True,
                          text=True, env=dict(os.environ, HOME="/tmp"))
    os.chmod(rodir, 0o755)
    case("plan into a folder it cannot write", done.returncode == 2 and "Traceback" not in done.stderr, done.stderr)
    report = json.loads((out / "report.json").read_text())
    report["scene_options"].pop("psd")
    old_report = root / "old_report.json"
    old_report.write_text(json.dumps(report))
    done = sediment("sample", PSD, "--plan", old_report, "--out", root / "s-old", "--t-end", "7200")
    case("sample --plan of a report without its PSD (earlier version): a warning", done.returncode == 0 and
         "does not record the PSD" in done.stdout, done.stderr + done.stdout)
    (root / "junk.json").write_text("{\"decision\": 3}")
    done = sediment("sample", PSD, "--plan", root / "junk.json", "--out", root / "s-junk")
    case("sample --plan of a JSON that is no plan", refused(done, "not the plan"), done.stderr)
    done = sediment("sample", PSD, "--plan", out / "report.json", "--out", root / "s-mass", "--t-end", "7200",
                    "--mass", "0.05")
    case("sample --plan with another mass", refused(done, "mass"), done.stderr)
    # ---- readout -------------------------------------------------------------------------------
    deck = sample(root / "copied", PSD, *SHORT)
    sediment("run", deck, "--quiet")
    alone = root / "alone"
    alone.mkdir()
    shutil.copy(deck.parent / "layers.h5", alone / "layers.h5")
    done = sediment("readout", alone / "layers.h5", "--out", alone / "r")
    case("readout of a layer file copied away from its deck", done.returncode == 0, done.stderr)
    mine = root / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    done = sediment("readout", deck.parent / "layers.h5", "--out", mine, "--instrument", "pipette")
    sediment("readout", deck.parent / "layers.h5", "--out", mine, "--instrument", "hydrometer")
    case("readout into a folder with the user's files keeps them", (mine / "notes.txt").read_text() == "mine"
         and not (mine / "pipette.csv").exists(), done.stderr)
    (mine / ".sediment-files.json").write_text('{"format": 1, "sets": {"readout": {"files": '
                                               '{"../copied/layers.h5": [1, "ab"], "notes.txt": [1, "ab"]}}}}')
    sediment("readout", deck.parent / "layers.h5", "--out", mine, "--instrument", "hydrometer")
    case("a forged list of saved files deletes nothing outside the folder", (deck.parent / "layers.h5").is_file(), "")
    bad = sum(1 for _, good, _ in results if not good)
    print(f"{len(results)} cases: {len(results) - bad} handled well, {bad} not")
    shutil.rmtree(root, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
