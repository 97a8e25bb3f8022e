# SPDX-License-Identifier: GPL-2.0-or-later
"""Hostile round 3's cases of faults from outside: SIGINT, SIGTERM and SIGKILL at every phase, and a
full disk."""
from __future__ import annotations

import shutil
import signal
import subprocess
import time
from dataclasses import replace
from typing import Callable

from sediment.folders import JOURNAL, settle

from case_folders import RERUNS, SLOW, prepare, quick_command
from cases import Ctx, add
from harness import LONG, PSD, FullDisk, can_mount, crashed, csvs, diff, finish, has, must, refusal, sed, start, tree


# ==== signals at every phase ===============================================================================
PHASES = {
    # command: (a phase name -> seconds after start, or a file whose appearance starts the phase)
    "sample": {"start": 0.05, "import": 0.25, "writing": 0.4},
    "readout": {"start": 0.1, "reading": 0.6, "figure": 1.0},
    "calibrate": {"start": 0.1, "writing": 0.35},
    "plan": {"screening": 0.5, "trials": "runs"},
    "invert": {"reading": 0.5, "fit": 6.0},
    "spheres": {"runs": 1.5},
    "paste-energy": {"run": 1.5},
    "case-a": {"runs": 4.0},
    "sweep": {"runs": 1.5},
}


def signalled(writer: str, sig: int, phase: str, at) -> Callable:
    """A signal to a command rerun over its earlier result (another option, so another set): exit 130 with
    a message (SIGINT, SIGTERM), and the folder holds the earlier set whole or the new one whole."""
    def fn(ctx: Ctx):
        prepare(ctx, {writer})
        out = ctx.tmp / "out"
        args = quick_command(writer, out, ctx)
        change = RERUNS.get(writer) or []
        if writer not in SLOW:
            first = sed(*args, timeout=300)
            if first.rc != 0:
                return "crash" if crashed(first) else "wrong", f"the first run failed: {first.last}"
        old = csvs(out)
        t0 = time.monotonic()
        proc = start(args + change)
        if isinstance(at, str):
            while time.monotonic() - t0 < 60 and proc.poll() is None and not any(out.parent.rglob(at)):
                time.sleep(0.01)
        else:
            while time.monotonic() - t0 < at and proc.poll() is None:
                time.sleep(0.005)
        finished = proc.poll() is not None
        if not finished:
            proc.send_signal(sig)
        done = as_the_shell_sees(finish(proc, 60, t0), sig)
        time.sleep(0.3 if sig != signal.SIGKILL else 6.0)
        journaled = sig == signal.SIGKILL and (out / JOURNAL).exists()
        if journaled:    # killed while moving its files: the next command to lock the folder completes it first
            settle(out)
        got = csvs(out)
        clean = ctx.tmp / "clean"
        sed(*[clean if x == out else x for x in args + change], timeout=300)
        new = csvs(clean)
        leftovers = [p.name for p in out.parent.iterdir() if p.name not in ("out", "clean", "_run", "_one.csv")
                     and not p.name.endswith(".lock")]   # plan's lock files stay beside --out, as a run's do
        early = sig != signal.SIGKILL and before_our_code(done, sig)
        if sig == signal.SIGKILL:
            if done.rc not in (-9, 0):
                bad = crashed(done)
                if bad:
                    return "crash", bad
        else:
            bad = crashed(done)
            if bad and not (done.rc == -sig and finished) and not early:
                return "crash", bad
            if not finished and done.rc not in (130, 0) and not early:
                return "crash", f"exit {done.rc} after {signal.Signals(sig).name}: {done.last}"
        if got != old and got != new:
            return "wrong", f"neither the earlier set nor the new one: {diff(old, got) or 'same names'} " \
                            f"(new: {diff(new, got)})"
        if sig != signal.SIGKILL and leftovers:
            return "wrong", f"leftovers beside --out: {leftovers[:3]}"
        if sig != signal.SIGKILL and done.rc == 130 and not done.message:
            return "vague", "exit 130 with no message"
        if writer in SLOW:
            return "ok", f"{'finished first' if finished else f'exit {done.rc}'}; the folder whole"
        again = sed(*(args + change), timeout=300)
        bad = crashed(again)
        if bad or again.rc != 0:
            return ("crash", bad) if bad else ("wrong", f"the command again after the signal fails: {again.last}")
        if csvs(out) != new:
            return "wrong", "the command again after the signal gives another result: " + diff(new, csvs(out))
        state = "finished first" if finished else f"exit {done.rc}" + (
            " (killed while it moved its files: the journal completed the new set)" if journaled else "") + (
            " (the signal came in the interpreter's start-up, before sediment's first line: Python's default)"
            if early else "")
        return "ok", f"{state}; the folder {'the earlier set' if got == old and old != new else 'whole'}"
    return fn


def as_the_shell_sees(done, sig: int):
    """A command that said it was interrupted and then died of that signal ends, for the shell, as exit 130
    does (128 + 2): Python kills itself with SIGINT at exit where the interrupt once went through C code
    run by PyRun_* (an extension's import), though the command caught it and said what it left."""
    if sig == signal.SIGINT and done.rc == -sig and "interrupted by SIGINT" in done.err:
        return replace(done, rc=130)
    return done


def before_our_code(done, sig: int) -> bool:
    """Whether the signal came while the interpreter started (site.py, before `python -m sediment` runs a
    line of the package, whose first takes SIGINT and SIGTERM): Python's default then acts, death by
    SIGTERM without a word or a KeyboardInterrupt whose traceback has only the interpreter's frames. On
    a quiet machine that window is some 30 ms; under a load of 14 on 2 cores, a start phase's signal
    lands in it. What the folder holds is checked as for any other signal."""
    if done.rc == -sig and not done.err.strip():
        return True
    frames = [line for line in done.err.splitlines() if line.lstrip().startswith('File "')]
    return (sig == signal.SIGINT and done.err.strip().endswith("KeyboardInterrupt") and bool(frames)
            and not any("sediment" in line for line in frames))


SIGS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM, "SIGKILL": signal.SIGKILL}
for _w, _phases in PHASES.items():
    for _ph, _at in _phases.items():
        for _sn, _s in SIGS.items():
            _cmd = "readout" if _w == "preview" else _w.split("-")[0] if _w != "case-a" else "case-a"
            add(f"{_cmd}/{_sn}-{_w}-{_ph}", _cmd, "signal", signalled(_w, _s, _ph, _at),
                needs=("run",) if _w == "readout" else ())


def budget_signal(sig: int, at: float) -> Callable:
    """budget's runs take minutes: a signal during them ends it (exit 130 and a message for SIGINT and
    SIGTERM), with no half budget in --out and no runs left working."""
    def fn(ctx: Ctx):
        out = ctx.tmp / "out"
        t0 = time.monotonic()
        proc = start(["budget", PSD, "--particles", "1000", "--replicas", "2", "--out", out])
        while time.monotonic() - t0 < at and proc.poll() is None:
            time.sleep(0.01)
        finished = proc.poll() is not None
        proc.send_signal(sig)
        done = as_the_shell_sees(finish(proc, 60, t0), sig)
        time.sleep(0.5 if sig != signal.SIGKILL else 6.5)
        if finished:
            return "crash" if crashed(done) else "wrong", f"ended by itself before the signal: exit {done.rc} {done.last}"
        left = [k for k in tree(out) if k.startswith("budget")]
        whole = sorted(left) == ["budget.csv", "budget.json", "budget.png"]    # a set is published whole or not at all
        if whole and (done.rc in (0, -signal.SIGKILL) or "after its results were written" in done.message):
            return "ok", "it finished as the signal came: its budget is whole"
        if sig != signal.SIGKILL:
            bad = crashed(done)
            if bad:
                return "crash", bad
            if done.rc == 0:
                return "wrong", f"exit 0 after {signal.Signals(sig).name}, with no budget written"
            if done.rc != 130:
                return "crash", f"exit {done.rc} after {signal.Signals(sig).name}"
            if not done.message:
                return "vague", "exit 130 with no message"
        if left:
            return "wrong", f"a budget written by a stopped command: {left}"
        procs = subprocess.run(["pgrep", "-f", str(out)], capture_output=True, text=True).stdout.split()
        if procs:
            return "wrong", f"{len(procs)} processes of the stopped budget still working"
        return "ok", done.last or "killed, nothing left"
    return fn


for _ph, _at in (("start", 0.3), ("runs", 3.0)):
    for _sn, _s in SIGS.items():
        add(f"budget/{_sn}-{_ph}", "budget", "signal", budget_signal(_s, _at))


def run_signal(sig: int, phase: str) -> Callable:
    """A fresh run signalled at a phase: exit 130 saying where the frames are (SIGINT, SIGTERM), no layers.h5,
    and --resume gives the uninterrupted run's frames."""
    def fn(ctx: Ctx):
        folder = ctx.tmp / "s"
        must("sample", PSD, "--out", folder, *LONG)
        deck = folder / "in.sedimentation"
        t0 = time.monotonic()
        proc = start(["run", deck, "--quiet"])
        trigger = {"start": 0.1, "lammps-start": ".log.lammps.*.partial", "first-frames": "layers.h5.partial",
                   "first-restart": "restart.a.bin", "both-restarts": "restart.b.bin"}[phase]
        while proc.poll() is None and time.monotonic() - t0 < 60:
            if isinstance(trigger, float) and time.monotonic() - t0 > trigger:
                break
            if isinstance(trigger, str) and any(p.stat().st_size for p in folder.glob(trigger)):
                break    # (LAMMPS's log is written under a partial name, log.lammps only once it finished)
            time.sleep(0.002)
        finished = proc.poll() is not None
        if not finished:
            proc.send_signal(sig)
        done = as_the_shell_sees(finish(proc, 60, t0), sig)
        time.sleep(0.3 if sig != signal.SIGKILL else 6.0)
        if sig != signal.SIGKILL:
            bad = crashed(done)
            if bad:
                return "crash", bad
            if not finished and done.rc == 0 and not (folder / "layers.h5").exists():
                return "wrong", "exit 0 after the signal, with no layers.h5"
            if not finished and done.rc not in (0, 130):
                return "crash", f"exit {done.rc} after the signal: {done.last}"
            if not finished and not has(done.message, [("--resume", "again", "start")]):
                return "vague", f"'{done.last}' (wants what to do next)"
        if (folder / "layers.h5").exists() and not finished:
            return "wrong", "a layers.h5 after a run stopped early"
        again = sed("run", deck, "--quiet", "--resume", timeout=180)
        if again.rc != 0:
            again = sed("run", deck, "--quiet", timeout=180)
            if again.rc == 2 and has(again.message, [("--force",)]):    # the way on, as the message says
                again = sed("run", deck, "--quiet", "--force", timeout=180)
            if again.rc != 0:
                return ("crash", crashed(again)) if crashed(again) else \
                    ("vague" if again.rc == 2 else "wrong", f"neither --resume nor a fresh run after it: {again.last}")
        a = sed("readout", folder / "layers.h5", "--out", ctx.tmp / "r", timeout=60)
        b = sed("readout", ctx.fx("longref") / "layers.h5", "--out", ctx.tmp / "ref", timeout=60)
        if a.rc != 0:
            return "wrong", f"the frames after the signal and a resume do not read: {a.last}"
        same = csvs(ctx.tmp / "r") == csvs(ctx.tmp / "ref")
        return ("ok", "resumed to the uninterrupted run's readings") if same else \
            ("wrong", "readings after the signal and a resume differ from the uninterrupted run's")
    return fn


for _ph in ("start", "lammps-start", "first-frames", "first-restart", "both-restarts"):
    for _sn, _s in SIGS.items():
        add(f"run/{_sn}-{_ph}", "run", "signal", run_signal(_s, _ph), needs=("longref",))


# ==== a full disk ========================================================================================
def full_disk(writer: str, free: int, rerun_over: bool) -> Callable:
    """The command with its output on a full tmpfs: exit 2 naming the full disk, the earlier set whole (or
    no folder), no half-written files."""
    def fn(ctx: Ctx):
        if not can_mount():
            return "ok", "skipped: not root"
        prepare(ctx, {writer})
        disk = FullDisk(ctx.tmp / "disk", size=8 << 20)
        try:
            out = disk.path / "out"
            args = quick_command(writer, out, ctx)
            if rerun_over:
                first = sed(*args, timeout=300)
                if first.rc != 0:
                    return "crash" if crashed(first) else "wrong", f"the first run failed: {first.last}"
            change = (RERUNS.get(writer) or []) if rerun_over else []
            before = tree(out)
            disk.fill(free)
            done = sed(*(args + change), timeout=300)
            after = tree(out)
            bad = crashed(done)
            if bad:
                return "crash", bad
            others = [p.name for p in disk.path.iterdir() if p.name not in ("out", ".filler")]
            if done.rc == 0:
                disk.free()
                clean = ctx.tmp / "clean"
                sed(*[clean if x == out else x for x in args + change], timeout=300)
                return ("ok", "it fitted") if csvs(clean) == csvs(out) else \
                    ("wrong", "exit 0 on a full disk with another result: " + diff(csvs(clean), csvs(out)))
            if others:
                return "wrong", f"exit {done.rc}, leftovers on the full disk: {others[:3]}"
            if writer == "run" or writer.startswith("run"):
                pass
            return refusal(done, [("space", "full", "disk", "ENOSPC")], before, after)
        finally:
            disk.close()
    return fn


for _w in ("sample", "readout", "calibrate", "calibrate-tilt", "paste-energy", "spheres", "plan", "invert",
           "case-a", "sweep"):
    for _free, _label in ((0, "no-space"), (24 << 10, "24k-free"), (200 << 10, "200k-free")):
        for _over in (False, True):
            if _w in SLOW and (_label == "24k-free" or _over):
                continue
            _cmd = "readout" if _w == "preview" else _w.split("-")[0] if _w != "case-a" else "case-a"
            add(f"{_cmd}/full-disk-{_w}-{_label}{'-over-earlier' if _over else ''}", _cmd, "full-disk",
                full_disk(_w, _free, _over), needs=("run",) if _w == "readout" else ())


def run_full_disk(free: int, resume: bool) -> Callable:
    def fn(ctx: Ctx):
        if not can_mount():
            return "ok", "skipped: not root"
        disk = FullDisk(ctx.tmp / "disk", size=24 << 20)
        try:
            folder = disk.path / "s"
            if resume:
                shutil.copytree(ctx.fx("interrupted"), folder)
            else:
                must("sample", PSD, "--out", folder, *LONG)
            disk.fill(free)
            done = sed("run", folder / "in.sedimentation", "--quiet", *(["--resume"] if resume else []), timeout=180)
            bad = crashed(done)
            if bad:
                return "crash", bad
            if done.rc == 0:
                return "wrong" if not (folder / "layers.h5").is_file() else "ok", "exit 0 on a full disk"
            if (folder / "layers.h5").exists():
                return "wrong", "a layers.h5 from a run that ran out of space"
            if not has(done.message, [("space", "full", "disk", "ENOSPC")]):
                return "vague", f"'{done.last[:150]}' (wants the full disk named)"
            disk.free()
            again = sed("run", folder / "in.sedimentation", "--quiet", "--resume", timeout=180)
            if again.rc != 0:
                again = sed("run", folder / "in.sedimentation", "--quiet", "--force", timeout=180)
            if again.rc != 0:
                return "wrong", f"no way on once space is free: {again.last}"
            return "ok", done.last
        finally:
            disk.close()
    return fn


for _free, _label in ((0, "no-space"), (64 << 10, "64k-free"), (600 << 10, "600k-free"), (3 << 20, "3M-free")):
    for _resume in (False, True):
        add(f"run/full-disk-{_label}{'-resume' if _resume else ''}", "run", "full-disk", run_full_disk(_free, _resume),
            needs=("interrupted",) if _resume else ())
