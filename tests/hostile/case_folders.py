# SPDX-License-Identifier: GPL-2.0-or-later
"""Hostile round 3's cases of folders: --out onto inputs and onto other commands' folders, reruns in
the same folder, and two commands in one folder at once."""
from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import Callable

from case_inputs import KINDS, text
from cases import INVERT_SMALL, PLAN_SMALL, Ctx, add
from harness import (CASE_A, INV, LONG, PSD, PSD1, TINY, crashed, csvs, diff, finish, has, must, refusal, sed, start,
                     tree)


# ==== --out onto inputs and onto other commands' folders ===============================================
def quick_command(kind: str, out: Path, ctx: Ctx) -> list:
    """The args of a fast command of each kind writing into `out`."""
    return {
        "sample": ["sample", PSD, "--out", out, *TINY],
        "readout": ["readout", ctx.tmp / "_run" / "layers.h5", "--out", out],
        "preview": ["readout", "--stokes-preview", "--psd", PSD, "--out", out],
        "calibrate": ["calibrate", "slump", "--slump", "0.102", "0.103", "--height", "0.152", "--density", "1843",
                      "--out", out],
        "calibrate-tilt": ["calibrate", "tilt", "--lift", "205", "202", "--length", "600", "--out", out],
        "plan": ["plan", PSD, "--out", out, *PLAN_SMALL],
        "invert": ["invert", INV / "soil" / "hydrometer.csv", INV / "soil" / "sieve.csv", "--mass", "0.05",
                   *INVERT_SMALL, "--out", out],
        "spheres": ["spheres", ctx.tmp / "_one.csv", "--law", "bingham", "--out", out],
        "paste-energy": ["paste", "energy", "--out", out],
        "case-a": ["case-a", "--out", out],
        "budget": ["budget", PSD, "--particles", "1000", "--out", out],
        "sweep": ["sweep", CASE_A, "--dt", "2e-3,4e-3", "--var", "t_end", "0.008", "--observe", "velocity",
                  "--out", out],
    }[kind]


SLOW = {"plan", "invert", "spheres", "case-a", "budget", "sweep", "paste-energy", "preview"}


def prepare(ctx: Ctx, kinds) -> None:
    if "readout" in kinds:
        shutil.copytree(ctx.fx("run"), ctx.tmp / "_run")
        shutil.rmtree(ctx.tmp / "_run" / "r")
    header, rows = KINDS["spheres"]
    ctx.file("_one.csv", text(header, rows))


def foreign_folder(kind: str, ctx: Ctx) -> Path:
    """A folder another command (or the user) wrote."""
    dest = ctx.tmp / "theirs"
    if kind == "user":
        dest.mkdir()
        (dest / "notes.txt").write_text("my notes")
        (dest / "fit.csv").write_text("my,own\n1,2\n")
        (dest / "calibration.csv").write_text("mine\n")
        (dest / "hydrometer.csv").write_text("time_min,reading\n1,2\n")
        (dest / "classes.csv").write_text("mine\n")
    elif kind == "run":
        shutil.copytree(ctx.fx("run"), dest)
    elif kind == "readout":
        shutil.copytree(ctx.fx("run") / "r", dest)
    elif kind == "calibrate":
        must("calibrate", "restitution", "--drop", "1", "--rebound", "0.5", "--out", dest)
    elif kind == "plan":
        shutil.copytree(ctx.fx("plan"), dest)
    elif kind == "invert":
        shutil.copytree(ctx.fx("invert") / "out", dest)
    return dest


def run_watching(folder: Path, args: list, writer: str, whose: str):
    """Runs `sediment *args` and compares `folder` before and after: the run, a verdict if it crashed
    or changed a file that was there (`whose` names them), and the two trees."""
    before = tree(folder)
    done = sed(*args, timeout=240 if writer in SLOW else 60)
    after = tree(folder)
    bad = crashed(done)
    if bad:
        return done, ("crash", bad), before, after
    lost = {k: v for k, v in before.items() if after.get(k) != v}
    if lost:
        return done, ("wrong", f"exit {done.rc}: {whose} {diff(lost, {k: after[k] for k in lost if k in after})}"), \
            before, after
    return done, None, before, after


def out_onto(writer: str, owner: str) -> Callable:
    """`writer --out` a folder `owner` wrote: refused with nothing changed, or done with every file of
    the owner's as it was."""
    def fn(ctx: Ctx):
        prepare(ctx, {writer})
        theirs = foreign_folder(owner, ctx)
        done, verdict, before, after = run_watching(theirs, quick_command(writer, theirs, ctx), writer,
                                                    f"{owner}'s files")
        if verdict:
            return verdict
        if done.rc == 0:
            return "ok", "written beside the other files, none of them touched"
        return refusal(done, [("theirs", "folder", "another", "not written", "own")], before, after)
    return fn


OWNERS = ["user", "run", "readout", "calibrate", "plan", "invert"]
WRITERS = ["sample", "readout", "calibrate", "calibrate-tilt", "plan", "invert", "spheres", "paste-energy",
           "case-a", "sweep"]
for _w in WRITERS:
    for _o in OWNERS:
        if _w == _o or (_w, _o) in {("preview", "readout"), ("calibrate-tilt", "calibrate")}:
            continue
        if _w in SLOW and _o not in ("user", "run"):
            continue
        _needs = tuple(sorted({"run"} & ({_o, _w} | ({"run"} if _o == "readout" or _w == "readout" else set())) |
                              ({"plan"} if _o == "plan" else set()) | ({"invert"} if _o == "invert" else set())))
        if _o in ("run", "readout") or _w == "readout":
            _needs = tuple(sorted(set(_needs) | {"run"}))
        add(f"{_w}/out-onto-{_o}-folder", _w.split("-")[0] if _w != "case-a" else "case-a", "ownership",
            out_onto(_w, _o), quick=_w not in SLOW and _o not in ("plan", "invert") or
            (_w not in SLOW and _o in ("plan", "invert")), needs=_needs)


def out_onto_input(writer: str, which: str) -> Callable:
    """--out naming an input file of the same command, or the folder that holds it with a clashing name."""
    def fn(ctx: Ctx):
        prepare(ctx, {writer})
        args = quick_command(writer, ctx.tmp / "X", ctx)
        inputs = [a for a in args[1:] if isinstance(a, Path) and a.is_file()]
        if not inputs:
            return "ok", "no input file"
        # work on copies of the inputs, in the folder the output goes to
        home = ctx.tmp / "home"
        home.mkdir(exist_ok=True)
        copies = {}
        for a in inputs:
            name = {"sample5.csv": "input_psd.csv", "sieve.csv": "fit.csv", "hydrometer.csv": "psd.csv",
                    "_one.csv": "terminal_velocities.csv", "in.case_a": "sweep.csv"}.get(a.name, a.name)
            if writer == "readout":
                shutil.copytree(a.parent, home, dirs_exist_ok=True)
                copies[a] = home / a.name
                continue
            copies[a] = home / name
            shutil.copy(a, copies[a])
        args = [copies.get(a, a) if isinstance(a, Path) else a for a in args]
        first = next(iter(copies.values()))
        target = first if which == "file" else home
        args[args.index(ctx.tmp / "X")] = target
        done, verdict, _, _ = run_watching(home, args, writer, "inputs")
        if verdict:
            return verdict
        if done.rc == 0:
            return ("wrong", "exit 0 with --out naming an input file") if which == "file" else \
                ("ok", "written beside its inputs, none touched")
        return refusal(done, [("not a folder", "input", "is a file", "would overwrite", "own", "folder", "exists")])
    return fn


for _w in WRITERS:
    for _which in ("file", "its-folder"):
        if _w in SLOW and _which != "file" or _w in ("calibrate", "calibrate-tilt", "paste-energy", "case-a"):
            continue
        add(f"{_w}/out-onto-input-{_which}", _w.split("-")[0] if _w != "case-a" else "case-a", "ownership",
            out_onto_input(_w, _which), quick=_w not in SLOW, needs=("run",) if _w == "readout" else ())
for _cmd, _args in {"budget": ["budget", PSD, "--particles", "1000"], "paste": ["paste", "drop-test"],
                    "terminal": None}.items():
    if _args is None:
        continue

    def _fn(ctx, _args=_args):
        f = ctx.file("afile", "mine")
        done = sed(*_args, "--out", f, timeout=10)
        if f.read_bytes() != b"mine":
            return "wrong", "the file named by --out was overwritten"
        return refusal(done, [("not a folder", "is a file", "afile")])
    add(f"{_cmd}/out-onto-a-file", _cmd, "ownership", _fn, quick=True)


# ==== reruns in the same folder ==========================================================================
def rerun(writer: str, change: list | None) -> Callable:
    """The same command again into its own folder (the same result), or with another option (a whole new
    set, nothing of the earlier one left but what the user put there)."""
    def fn(ctx: Ctx):
        prepare(ctx, {writer})
        out = ctx.tmp / "out"
        args = quick_command(writer, out, ctx)
        first = sed(*args, timeout=300)
        if first.rc != 0:
            return "crash" if crashed(first) else "wrong", f"the first run failed: {first.last}"
        (out / "my-notes.txt").write_text("mine")
        before = csvs(out)
        second = sed(*(args + (change or [])), timeout=300)
        bad = crashed(second)
        if bad:
            return "crash", bad
        after = csvs(out)
        if "my-notes.txt" not in after:
            return "wrong", "the user's file in the folder was deleted by the rerun"
        if change is None:
            if second.rc != 0:
                return "vague", f"the same command again refused: {second.last}"
            return ("ok", "the same result") if after == before else ("wrong", "another result: " + diff(before, after))
        if second.rc != 0:
            return refusal(second, [("force", "exists", "another", "folder")], before, after)
        clean = ctx.tmp / "clean"
        third = sed(*([a if a != out else clean for a in args] + change), timeout=300)
        ref = csvs(clean)
        ref["my-notes.txt"] = after["my-notes.txt"]
        return ("ok", "the new set, whole") if ref == after else ("wrong", "a mixed set: " + diff(ref, after))
    return fn


RERUNS = {
    "sample": ["--seed", "2"], "preview": ["--concentration", "40"], "readout": ["--temperature", "23"],
    "calibrate": ["--density", "1900"], "calibrate-tilt": ["--length", "610"],
    "readout-fewer": None, "plan": ["--courant", "8"], "invert": ["--bins", "6"], "spheres": ["--law", "zhang-li"],
    "paste-energy": ["--fall", "0.2"], "sweep": ["--dt", "2e-3,8e-3"],
}
for _w, _change in RERUNS.items():
    if _w == "readout-fewer":
        def _fewer(ctx):
            """A readout of every instrument, then of one: the others' tables must go (one readout per folder)."""
            prepare(ctx, {"readout"})
            out = ctx.tmp / "out"
            args = quick_command("readout", out, ctx)
            sed(*args, timeout=60)
            done = sed(*args, "--instrument", "hydrometer", timeout=60)
            bad = crashed(done)
            if bad:
                return "crash", bad
            left = sorted(p.name for p in out.iterdir() if p.name.startswith(("buoyancy", "pipette")))
            return ("wrong", f"tables of the earlier readout left beside the new: {left}") if left else \
                ("ok", "one readout in the folder")
        add("readout/rerun-fewer-instruments", "readout", "rerun", _fewer, quick=True, needs=("run",))
        continue
    _cmd = _w.split("-")[0] if _w != "preview" else "readout"
    if _w not in SLOW:
        add(f"{_cmd}/rerun-same{'-' + _w if _w != _cmd else ''}", _cmd, "rerun", rerun(_w, None),
            quick=True, needs=("run",) if _w == "readout" else ())
    add(f"{_cmd}/rerun-changed{'-' + _w if _w != _cmd else ''}", _cmd, "rerun", rerun(_w, _change),
        quick=_w not in SLOW, needs=("run",) if _w == "readout" else ())


def sample_other_psd_over_run(force: bool) -> Callable:
    def fn(ctx: Ctx):
        folder = ctx.copy("run")
        before = tree(folder)
        done = sed("sample", PSD1, "--out", folder, *TINY, *(["--force"] if force else []), timeout=30)
        after = tree(folder)
        if not force:
            return refusal(done, [("--force",), ("run", "layer")], before, after)
        bad = crashed(done)
        if bad:
            return "crash", bad
        left = [k for k in after if k.startswith(("layers.h5", "restart", "log"))]
        stale = [k for k in after if k.startswith("r/")]
        if left:
            return "wrong", f"the run's files left beside another test: {left}"
        if stale:
            return "wrong", f"the old run's readout left beside another test's deck: {stale[:3]}"
        return "ok", "the old run's files gone, the new sample whole"
    return fn


add("sample/over-a-run-of-another-psd", "sample", "rerun", sample_other_psd_over_run(False), quick=True,
    needs=("run",))
add("sample/over-a-run-of-another-psd--force", "sample", "rerun", sample_other_psd_over_run(True), quick=True,
    needs=("run",))


def run_again_finished(ctx: Ctx):
    folder = ctx.copy("run")
    before = tree(folder)
    done = sed("run", folder / "in.sedimentation", "--quiet", timeout=120)
    after = tree(folder)
    bad = crashed(done)
    if bad:
        return "crash", bad
    if done.rc == 0:
        return ("ok", "ran again to the same frames") if after.get("r/hydrometer.csv") == before.get("r/hydrometer.csv") \
            else ("wrong", "ran again and changed the readout folder")
    return refusal(done, [("--force", "finished", "already")], {k: v for k, v in before.items() if "log" not in k},
                   {k: v for k, v in after.items() if "log" not in k})


add("run/again-after-it-finished", "run", "rerun", run_again_finished, needs=("run",))


def readout_stale_after_rerun(ctx: Ctx):
    """A run redone with --force over a folder whose readout was of the earlier frames: readout r stays of
    the earlier run; reading it again must give the new run's."""
    folder = ctx.copy("run")
    must("run", folder / "in.sedimentation", "--quiet", "--force", "--var", "seed", "5")
    done = sed("readout", folder / "layers.h5", "--out", folder / "r", timeout=60)
    bad = crashed(done)
    return ("crash", bad) if bad else (("ok", "read again") if done.rc == 0 else
                                       refusal(done, [("run",)]))


add("readout/again-after-a-forced-rerun", "readout", "rerun", readout_stale_after_rerun, needs=("run",))


# ==== concurrency ==========================================================================================
def concurrent(first: str, second: str, same_out: bool = True, delay: float = 0.15) -> Callable:
    """Two commands in one folder at once: one waits or is refused naming the other; the folder ends as
    one whole result of one of them."""
    def fn(ctx: Ctx):
        prepare(ctx, {first, second})
        out = ctx.tmp / "out"
        a_args = quick_command(first, out, ctx)
        b_args = quick_command(second, out, ctx)
        if first == second and first in RERUNS and RERUNS[first]:
            b_args = b_args + RERUNS[first]
        t0 = time.monotonic()
        a = start(a_args)
        time.sleep(delay)
        b = sed(*b_args, timeout=300)
        ad = finish(a, 300, t0)
        for d in (ad, b):
            bad = crashed(d)
            if bad:
                return "crash", bad
        got = csvs(out)
        refs = []
        for i, args in enumerate((a_args, b_args)):
            clean = ctx.tmp / f"clean{i}"
            sed(*[clean if x == out else x for x in args], timeout=300)
            refs.append(csvs(clean))
        codes = (ad.rc, b.rc)
        if codes == (0, 0):
            whole = got == refs[1] or got == refs[0] or (first != second and set(got) == set(refs[0]) | set(refs[1]))
            return ("ok", "both done in turn, the folder whole") if whole else \
                ("wrong", "both exit 0, the folder mixed: " + diff(refs[1], got))
        refused = b if b.rc != 0 else ad
        winner = refs[0] if b.rc != 0 else refs[1]
        if got != winner:
            return "wrong", f"exit {codes}: the folder is not the other's whole result: {diff(winner, got)}"
        # refused while the other runs (the lock), or, started as the other published, for its files,
        # which the message says the other command wrote
        if has(refused.message, [("another sediment command", "in use", "busy", "lock", "(written by sediment ")]):
            return "ok", refused.last
        return "vague", f"'{refused.last[:150]}' (wants the other command named)"
    return fn


CONCURRENT = [("sample", "sample"), ("readout", "readout"), ("calibrate", "calibrate"),
              ("calibrate", "calibrate-tilt"), ("sample", "readout"), ("readout", "sample"),
              ("plan", "plan"), ("invert", "invert"), ("plan", "sample"), ("invert", "readout"),
              ("spheres", "spheres"), ("paste-energy", "calibrate"), ("sweep", "sweep"), ("case-a", "calibrate")]
for _a, _b in CONCURRENT:
    add(f"{_a.split('-')[0] if _a != 'case-a' else _a}/concurrent-with-{_b}", _a.split("-")[0] if _a != "case-a"
        else _a, "concurrent", concurrent(_a, _b), needs=("run",) if "readout" in (_a, _b) else ())


def start_run_in(folder: Path, deck: Path):
    """`sediment run --force` of the deck, started and waited on until its LAMMPS runs under the
    folder's lock (its log is written, under a partial name), or it ended; the process and its start."""
    stale = set(folder.glob(".log.lammps.*.partial"))    # a killed run's (the fixture's): not this run's
    a = start(["run", deck, "--quiet", "--force"])
    t0 = time.monotonic()
    while not set(folder.glob(".log.lammps.*.partial")) - stale and a.poll() is None and time.monotonic() - t0 < 20:
        time.sleep(0.05)
    return a, t0


def run_concurrent(second: list) -> Callable:
    def fn(ctx: Ctx):
        deck = ctx.copy("interrupted") / "in.sedimentation"
        folder = deck.parent
        a, t0 = start_run_in(folder, deck)
        args = [folder if x == "@F" else deck if x == "@DECK" else x for x in second]
        before = {k: v for k, v in tree(folder).items() if not k.startswith(("layers", "restart", "log", ".sediment",
                                                                               ".log"))}
        b = sed(*args, timeout=120)
        ad = finish(a, 300, t0)
        for d in (ad, b):
            bad = crashed(d)
            if bad:
                return "crash", bad
        after = {k: v for k, v in tree(folder).items() if not k.startswith(("layers", "restart", "log", ".sediment",
                                                                              ".log"))}
        if b.rc == 0 and second[0] != "readout":
            return "wrong", f"{second[0]} exit 0 while a run worked in the folder"
        if ad.rc != 0:
            return "wrong", f"the run failed because of the other command: {ad.last}"
        return refusal(b, [("another sediment command", "running", "in use", "partial", "no such", "not complete")],
                       before, after)
    return fn


for _name, _second in {"run": ["run", "@DECK", "--quiet"], "run-force": ["run", "@DECK", "--quiet", "--force"],
                       "resume": ["run", "@DECK", "--quiet", "--resume"],
                       "sample-same": ["sample", PSD, "--out", "@F", *LONG],
                       "sample-force": ["sample", PSD1, "--out", "@F", *TINY, "--force"],
                       "readout": ["readout", "@F/layers.h5", "--out", "@F/r"],
                       "plan-into": ["plan", PSD, "--screen-only", "--out", "@F"]}.items():
    _second = [str(x).replace("@F/", "") if False else x for x in _second]
    if _name == "readout":
        def _rd(ctx, _f=None):
            return None
        _second = ["readout", "@LAY", "--out", "@R"]

        def _fn(ctx):
            deck = ctx.copy("interrupted") / "in.sedimentation"
            folder = deck.parent
            a, t0 = start_run_in(folder, deck)
            b = sed("readout", folder / "layers.h5", "--out", folder / "r", timeout=60)
            ad = finish(a, 300, t0)
            for d in (ad, b):
                bad = crashed(d)
                if bad:
                    return "crash", bad
            if b.rc == 0:
                return "wrong", "read a layer file while a run was replacing it"
            return refusal(b, [("partial", "no such layer file", "another sediment command", "running")])
        add("readout/while-a-run-works", "readout", "concurrent", _fn, needs=("interrupted",))
        continue
    add(f"run/concurrent-{_name}", "run" if _second[0] == "run" else _second[0], "concurrent",
        run_concurrent(_second), needs=("interrupted",))
