# SPDX-License-Identifier: GPL-2.0-or-later
"""Hostile round 3's cases of damaged files: layer files, tables, manifests, run records, restart
files and reports that a command finds damaged."""
from __future__ import annotations

import json
import shutil
from typing import Callable

from cases import Ctx, add
from harness import PSD, PSD1, crashed, csvs, damage, diff, refusal, sed, tree


# ==== damaged files ===================================================================================
LAYER_DAMAGE = ["cut10", "cut50", "cut90", "cut99", "empty", "text", "zero10", "zero50", "zero90", "bytes3",
                "bytes30", "head", "tail", "appended"]


def readout_damaged(how: str, target: str) -> Callable:
    def fn(ctx: Ctx):
        run = ctx.copy("run")
        shutil.rmtree(run / "r")
        damage(run / target, how)
        before = tree(run)
        out = ctx.tmp / "r"
        done = sed("readout", run / "layers.h5", "--out", out, timeout=60)
        after = tree(run)

        def accept():
            a, b = csvs(out), csvs(ctx.fx("run") / "r")
            return (a == b, "the same readings as the whole file's" if a == b
                    else f"readings of a damaged {target} that differ from the whole file's: {diff(b, a)}")
        words = [(target, target.replace(".csv", "")), ("damaged", "corrupt", "truncated", "checksum", "cannot read",
                                                        "not a", "empty", "invalid", "other inputs", "changed",
                                                        *(("header", "line", "row") if target.endswith(".csv")
                                                          else ()))]
        return refusal(done, words, before, after, accept=accept)
    return fn


for _how in LAYER_DAMAGE:
    add(f"readout/damaged-layers.h5/{_how}", "readout", "damaged", readout_damaged(_how, "layers.h5"), quick=True,
        needs=("run",))
for _target in ("input_psd.csv", "simulated_psd.csv", "classes.csv", "in.sedimentation", "sample.data"):
    for _how in ("empty", "cut50", "text"):
        add(f"readout/damaged-{_target}/{_how}", "readout", "damaged", readout_damaged(_how, _target), quick=True,
            needs=("run",))


def readout_foreign_psd(ctx: Ctx):
    """input_psd.csv replaced by another sample's: the readout compares with what was not simulated."""
    run = ctx.copy("run")
    shutil.copy(PSD1, run / "input_psd.csv")
    done = sed("readout", run / "layers.h5", "--out", ctx.tmp / "r", timeout=60)
    return refusal(done, [("input_psd.csv", "input PSD"), ("changed", "another", "differ", "not the", "does not match")])


add("readout/input_psd-of-another-sample", "readout", "damaged", readout_foreign_psd, quick=True, needs=("run",))


def readout_band(content: str | bytes, words) -> Callable:
    def fn(ctx: Ctx):
        run = ctx.copy("run")
        band = ctx.file("budget.json", content)
        done = sed("readout", run / "layers.h5", "--band", band, "--out", ctx.tmp / "r", timeout=60)
        return refusal(done, [("budget.json", "band", "budget")] + words)
    return fn


for _name, _content in {"empty": "", "not-json": "{nope", "a-list": "[1, 2]", "no-samples": '{"samples": {}}',
                        "nan-total": '{"samples": {"sample5": {"total": NaN}}}', "utf16": '{}'.encode("utf-16")
                        }.items():
    add(f"readout/damaged-budget.json/{_name}", "readout", "damaged",
        readout_band(_content, [("damaged", "not a", "empty", "json", "no ", "missing", "invalid", "sample")]),
        quick=True, needs=("run",))


def readout_saved(content: str) -> Callable:
    """A damaged or forged manifest (.sediment-files.json) in a readout folder: nothing outside the
    folder goes, and no mixed set."""
    def fn(ctx: Ctx):
        run = ctx.copy("run")
        (run / "r" / ".sediment-files.json").write_text(content)
        (ctx.tmp / "precious.txt").write_text("mine")
        before = tree(run)
        before = {k: v for k, v in before.items() if not k.startswith("r/")}
        done = sed("readout", run / "layers.h5", "--out", run / "r", "--instrument", "hydrometer", timeout=60)
        after = {k: v for k, v in tree(run).items() if not k.startswith("r/")}
        bad = crashed(done)
        if bad:
            return "crash", bad
        if not (ctx.tmp / "precious.txt").is_file() or before != after:
            return "wrong", "a file outside the readout folder went: " + diff(before, after)
        if done.rc == 0:
            left = sorted(p.name for p in (run / "r").iterdir() if not p.name.startswith("."))
            extra = [n for n in left if n.startswith(("buoyancy", "pipette"))]
            return ("wrong", f"a mixed set: {extra} of the earlier readout beside the new one") if extra else \
                ("ok", "one readout, nothing outside deleted")
        return refusal(done, [(".sediment-files.json",), ("damaged",)])
    return fn


_FORGED = '{"format": 1, "sets": {"readout": {"files": {%s}}}}'
for _name, _content in {"outside": _FORGED % '"../input_psd.csv": [1, "a"], "../../precious.txt": [1, "a"]',
                        "absolute": _FORGED % '"/etc/hostname": [1, "a"]', "binary": "\x00\x01\x02", "empty": "",
                        "not-a-set": '{"format": 1, "sets": [1, 2]}'}.items():
    add(f"readout/damaged-manifest/{_name}", "readout", "damaged", readout_saved(_content), quick=True,
        needs=("run",))


def resume_damaged(target: str, how: str) -> Callable:
    """--resume with a damaged .partial or restart file: refused, or resumed to the uninterrupted frames."""
    def fn(ctx: Ctx):
        deck = ctx.copy("interrupted") / "in.sedimentation"
        folder = deck.parent
        if target == "newest-restart" or target == "oldest-restart":
            files = sorted((folder / n for n in ("restart.a.bin", "restart.b.bin")), key=lambda p: p.stat().st_mtime)
            path = files[-1] if target == "newest-restart" else files[0]
        else:
            path = folder / target
        damage(path, how)
        done = sed("run", deck, "--resume", "--quiet", timeout=600)

        def accept():
            layers = folder / "layers.h5"
            if not layers.is_file():
                return False, "exit 0 but no layers.h5"
            check = sed("readout", layers, "--out", ctx.tmp / "r", timeout=60)
            if check.rc != 0:
                return False, f"a layers.h5 marked complete that readout refuses: {check.last[:120]}"
            ref = sed("readout", ctx.fx("longref") / "layers.h5", "--out", ctx.tmp / "ref", timeout=60)
            a, b = csvs(ctx.tmp / "r"), csvs(ctx.tmp / "ref")
            return (a == b, "resumed to the uninterrupted run's readings" if a == b
                    else f"resumed to readings that differ from the uninterrupted run's: {diff(b, a)}")
        return refusal(done, [(path.name, "restart", "partial"), ("damaged", "corrupt", "truncated", "cannot",
                                                                   "check", "invalid")], accept=accept)
    return fn


for _target in ("layers.h5.partial", "newest-restart", "oldest-restart"):
    for _how in ("cut50", "bytes3", "zero50", "head", "tail", "empty"):
        add(f"run/resume-damaged-{_target}/{_how}", "run", "damaged", resume_damaged(_target, _how),
            needs=("interrupted", "longref"))


def run_record(content: str, resume: bool) -> Callable:
    def fn(ctx: Ctx):
        folder = ctx.copy("interrupted" if resume else "run")
        (folder / ".sediment-run.json").write_text(content)
        before = tree(folder)
        if resume:
            done = sed("run", folder / "in.sedimentation", "--resume", "--quiet", timeout=120)
            return refusal(done, [(".sediment-run.json", "run record", "record"), ("damaged", "--force", "nothing")],
                           before, tree(folder))
        done = sed("readout", folder / "layers.h5", "--out", ctx.tmp / "r", timeout=60)
        if done.rc == 0:
            return "ok", "readout does not need the record"
        return refusal(done, [(".sediment-run.json", "record")])
    return fn


RECORDS = {"empty": "", "not-json": "{not json", "a-list": "[]", "no-state": '{"run_id": "x", "deck": "in.sedimentation"}',
           "other-run-id": '{"run_id": "0-0-0", "deck": "in.sedimentation", "variables": {}, "state": "interrupted"}',
           "state-finished": None, "deck-outside": '{"run_id": "x", "deck": "../../etc/passwd", "variables": {}, '
                                                   '"state": "interrupted"}'}
for _name, _content in RECORDS.items():
    if _content is None:
        continue
    add(f"run/resume-damaged-run-record/{_name}", "run", "damaged", run_record(_content, True),
        needs=("interrupted",))
    add(f"readout/damaged-run-record/{_name}", "readout", "damaged", run_record(_content, False), quick=True,
        needs=("run",))


def run_damaged_input(target: str, how: str) -> Callable:
    """A fresh run of a deck whose data file is damaged: refused naming the file, no layers.h5."""
    def fn(ctx: Ctx):
        folder = ctx.copy("sample")
        damage(folder / target, how)
        done = sed("run", folder / "in.sedimentation", "--quiet", timeout=120)
        if (folder / "layers.h5").exists():
            return "wrong", f"exit {done.rc}: a layers.h5 from a damaged {target}"
        return refusal(done, [(target, "read_data", "data file", "deck", "line")])
    return fn


for _target, _hows in {"sample.data": ("cut50", "empty", "text", "bytes30"), "in.sedimentation": ("cut50", "empty")
                       }.items():
    for _how in _hows:
        add(f"run/damaged-{_target}/{_how}", "run", "damaged", run_damaged_input(_target, _how), needs=("sample",))


def plan_report(mutate: Callable[[dict], object], words) -> Callable:
    def fn(ctx: Ctx):
        report = json.loads((ctx.fx("plan") / "report.json").read_text())
        new = mutate(report)
        path = ctx.file("report.json", new if isinstance(new, (str, bytes)) else json.dumps(new))
        done = sed("sample", PSD, "--plan", path, "--out", ctx.tmp / "s", "--t-end", "7200", timeout=30)
        return refusal(done, [("report", "plan")] + words)
    return fn


def _drop(key):
    def f(r):
        r.pop(key, None)
        return r
    return f


def _setdec(key, value):
    def f(r):
        if isinstance(r.get("decision"), dict) and isinstance(r["decision"].get("settings"), dict):
            r["decision"]["settings"][key] = value
        return r
    return f


REPORTS = {
    "empty": (lambda r: "", [("empty", "not", "damaged", "json")]),
    "truncated": (lambda r: json.dumps(r)[: len(json.dumps(r)) // 2], [("damaged", "not", "json", "truncated")]),
    "utf16": (lambda r: json.dumps(r).encode("utf-16"), [("damaged", "not", "json", "encoding", "utf")]),
    "no-decision": (_drop("decision"), [("decision",)]),
    "no-scene-options": (_drop("scene_options"), [("scene", "options", "psd")]),
    "decision-particles-negative": (_setdec("particles", -5), [("particles",)]),
    "decision-particles-text": (_setdec("particles", "many"), [("particles",)]),
    "decision-drag-unknown": (_setdec("drag", "warp"), [("drag", "warp")]),
    "decision-courant-nan": (_setdec("courant", float("nan")), [("courant",)]),
    "another-temperature": (lambda r: (r.get("scene_options", {}).__setitem__("temperature", 30.0), r)[1],
                            [("temperature",)]),
    "a-list": (lambda r: [r], [("not the", "not a", "plan")]),
}
for _name, (_mutate, _words) in REPORTS.items():
    add(f"sample/damaged-plan-report/{_name}", "sample", "damaged", plan_report(_mutate, _words), quick=True,
        needs=("plan",))


def funnel_compare_damaged(content: dict) -> Callable:
    def fn(ctx: Ctx):
        folders = []
        for i, files in enumerate((content, content)):
            d = ctx.tmp / f"study{i}"
            d.mkdir()
            for name, data in files.items():
                (d / name).write_text(data)
            folders.append(d)
        done = sed("paste", "funnel-compare", *folders, "--out", ctx.tmp / "out", timeout=30)
        return refusal(done, [("study0", "study1", "saved", "funnel")])
    return fn


for _name, _content in {"empty-folders": {}, "garbage-csv": {"funnel.csv": "x;y\n\x00\x01"},
                        "empty-csv": {"funnel.csv": ""}}.items():
    add(f"paste/funnel-compare-damaged/{_name}", "paste", "damaged", funnel_compare_damaged(_content), quick=True)


def compare_missing(ctx: Ctx):
    done = sed("paste", "funnel-compare", ctx.tmp / "nothere", "--out", ctx.tmp / "out", timeout=30)
    return refusal(done, [("nothere",), ("no such", "not found", "does not exist", "not a folder")])


add("paste/funnel-compare-missing-folder", "paste", "damaged", compare_missing, quick=True)
