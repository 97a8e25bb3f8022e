#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Hostile round 3 (issue 58): every command of `sediment` against faults (a full disk, SIGINT, SIGTERM
and SIGKILL at each phase, damaged files of each kind, two commands in one folder, reruns, one
command's --out onto another's folder or onto an input) and bad input (unit slips, encodings,
delimiters, duplicated columns, empty, unsorted, NaN, negative and huge values).

Each case sets up its own temporary folder, runs the command(s) and says exactly one of ok, wrong,
crash or vague (tests/hostile/harness.py says what each means). Run it as

    PYTHONPATH=python SEDIMENT_LMP=build/lmp_sediment tests/hostile/round3.py [--quick] [--only PATTERN]
        [--jobs 2] [--json OUTCOMES.json] [--list]      (tests/hostile/report.py OUTCOMES.json: the doc's tables)

`--quick` runs the cases that take seconds and no LAMMPS run of their own (they share one small
finished run, built once); tests/python/test_hostile_quick.py runs those under pytest, with the cases
in KNOWN_BAD expected to fail. The exit status is 1 when a case outside KNOWN_BAD is not ok."""
from __future__ import annotations

import argparse
import fnmatch
import json
import multiprocessing
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import (CASE_A, INV, LONG, PSD, PSD1, REPO, SPHERES_CSV, TINY, FullDisk, can_mount, crashed,  # noqa: E402
                     csvs, damage, diff, finish, has, must, refusal, sed, start, tree)


@dataclass
class Case:
    name: str
    command: str
    kind: str
    fn: Callable
    quick: bool = False
    needs: tuple = ()


CASES: dict[str, Case] = {}


def add(name: str, command: str, kind: str, fn: Callable, quick: bool = False, needs: tuple = ()) -> None:
    assert name not in CASES, name
    command = {"preview": "readout", "paste-energy": "paste", "calibrate-tilt": "calibrate",
               "invert-pipette": "invert", "invert-buoyancy": "invert", "readout-preview": "readout",
               "calibrate-slump": "calibrate", "paste-balls": "paste", "invert-plain": "invert"}.get(command, command)
    CASES[name] = Case(name, command, kind, fn, quick, tuple(needs))


class Ctx:
    def __init__(self, tmp: Path, fixtures: Path):
        self.tmp, self.fixtures = tmp, fixtures

    def fx(self, name: str) -> Path:
        return self.fixtures / name

    def copy(self, name: str, dest: str | None = None) -> Path:
        target = self.tmp / (dest or name)
        shutil.copytree(self.fx(name), target, symlinks=True)
        return target

    def file(self, name: str, data: bytes | str) -> Path:
        path = self.tmp / name
        path.write_bytes(data.encode() if isinstance(data, str) else data)
        return path


# ==== fixtures: built once per round, copied by the cases that need them ============================
def fx_run(dest: Path) -> None:
    must("sample", PSD, "--out", dest, *TINY)
    must("run", dest / "in.sedimentation", "--quiet")
    must("readout", dest / "layers.h5", "--out", dest / "r")


def fx_sample(dest: Path) -> None:
    must("sample", PSD, "--out", dest, *TINY)


def with_restarts(folder: Path) -> bool:
    return all((folder / n).is_file() and (folder / n).stat().st_size > 0 for n in ("restart.a.bin", "restart.b.bin"))


def fx_interrupted(dest: Path) -> None:
    """A run of LONG killed once both restart files and its partial frames are there."""
    must("sample", PSD, "--out", dest, *LONG)
    for _ in range(4):
        proc = start(["run", dest / "in.sedimentation", "--quiet", "--force"])
        end = time.monotonic() + 120
        while not with_restarts(dest) and time.monotonic() < end and proc.poll() is None:
            time.sleep(0.005)
        proc.send_signal(signal.SIGKILL)
        proc.communicate()
        time.sleep(1.5)
        if with_restarts(dest) and (dest / "layers.h5.partial").is_file() and not (dest / "layers.h5").exists():
            return
    raise RuntimeError("no interrupted run with restart files")


def fx_longref(dest: Path) -> None:
    must("sample", PSD, "--out", dest, *LONG)
    must("run", dest / "in.sedimentation", "--quiet")


def fx_invert(dest: Path) -> None:
    must("invert", INV / "soil" / "hydrometer.csv", INV / "soil" / "sieve.csv", "--mass", "0.05", *INVERT_SMALL,
         "--out", dest / "out", timeout=600)


def fx_plan(dest: Path) -> None:
    must("plan", PSD, "--out", dest, *PLAN_SMALL, timeout=600)


FIXTURES = {"run": fx_run, "sample": fx_sample, "interrupted": fx_interrupted, "longref": fx_longref,
            "invert": fx_invert, "plan": fx_plan}
INVERT_SMALL = ["--particles", "2000", "--bins", "8"]
PLAN_SMALL = ["--particles", "1000,500", "--courant", "4", "--t-end", "7200", "--replicas", "1", "--no-models",
              "--jobs", "1"]


def build_fixtures(names: set[str], root: Path) -> None:
    for name in sorted(names):
        dest = root / name
        if not dest.exists():
            t0 = time.monotonic()
            FIXTURES[name](dest)
            print(f"fixture {name}: {time.monotonic() - t0:.1f} s", flush=True)


# ==== bad input files ==================================================================================
def read_table(path: Path) -> tuple[list[str], list[list[str]]]:
    lines = [line for line in path.read_text().splitlines() if line.strip()]
    return lines[0].split(","), [line.split(",") for line in lines[1:]]


KINDS: dict[str, tuple[list[str], list[list[str]]]] = {
    "psd": read_table(PSD),
    "temprec": (["time_min", "temperature_C"], [["0", "19.0"], ["30", "19.5"], ["60", "20.0"], ["120", "20.5"],
                                                ["240", "21.0"]]),
    "hydrometer": read_table(INV / "soil" / "hydrometer.csv"),
    "sieve": read_table(INV / "soil" / "sieve.csv"),
    "pipette": read_table(INV / "pipette.csv"),
    "buoyancy": read_table(INV / "buoyancy.csv"),
    "spheres": (lambda h, r: (h, r[:1]))(*read_table(SPHERES_CSV)),
}


def text(header, rows, sep=",", end="\n") -> str:
    return end.join(sep.join(r) for r in [header, *rows]) + end


def col(rows, j, f) -> list[list[str]]:
    return [[(f(float(v)) if i == j else v) for i, v in enumerate(r)] for r in rows]


def fmt(x: float) -> str:
    return f"{x:.6g}"


def setcell(rows, i, j, value) -> list[list[str]]:
    rows = [list(r) for r in rows]
    rows[i][j] = value
    return rows


def latin1(h, r) -> bytes:
    h2 = [c.replace("_um", "_µm").replace("_C", "_°C").replace("_g", "_g (Waage Müller)") for c in h]
    return text(h2, r).encode("latin-1")


def utf8unit(h, r) -> bytes:
    return text([c.replace("_um", "_µm").replace("_C", "_°C") for c in h], r).encode()


def comma_decimal(h, r) -> bytes:
    return text(h, [[v.replace(".", ",") for v in row] for row in r], sep=";").encode()


def comma_quoted(h, r) -> bytes:
    return text(h, [[f'"{v.replace(".", ",")}"' if "." in v else v for v in row] for row in r]).encode()


# name: (transform(header, rows) -> bytes, expectation, words)
#   expectation "same": done as with the clean file, or refused naming the cause; "refuse": refused
#   naming the cause; "any": any answer but a crash, a refusal must name the cause.
ENC = ("encoding", "utf", "latin", "decode", "byte order", "bom")
GENERIC = {
    "bom": (lambda h, r: ("\ufeff" + text(h, r)).encode(), "same", [("BOM", "byte order", "utf-8-sig", "encoding")]),
    "crlf": (lambda h, r: text(h, r, end="\r\n").encode(), "same", [("line end", "CRLF", "\\r")]),
    "utf16": (lambda h, r: text(h, r).encode("utf-16"), "same", [("UTF-16", "encoding")]),
    "utf16le-nobom": (lambda h, r: text(h, r).encode("utf-16-le"), "refuse", [ENC]),
    "latin1": (latin1, "same", [ENC]),
    "utf8-unit-in-header": (utf8unit, "same", [("header", "column", "µm", "°C")]),
    "semicolon-comma-decimal": (comma_decimal, "refuse", [(";", "semicolon", "delimiter", "separator", "decimal comma",
                                                           "comma decimal")]),
    "semicolon": (lambda h, r: text(h, r, sep=";").encode(), "refuse", [(";", "semicolon", "delimiter", "separator")]),
    "tab": (lambda h, r: text(h, r, sep="\t").encode(), "same", [("tab", "delimiter", "separator")]),
    "quoted-comma-decimal": (comma_quoted, "refuse", [("decimal", "comma", ",")]),
    "trailing-empty-column": (lambda h, r: text([*h, ""], [[*x, ""] for x in r]).encode(), "same",
                              [("empty column", "trailing", "unnamed", "column")]),
    "duplicated-column": (lambda h, r: text([*h, h[-1]], [[*x, fmt(float(x[-1]) * 0.5 + 1)] for x in r]).encode(),
                          "refuse", [("duplicate", "twice", "more than once", "repeated")]),
    "swapped-columns": (lambda h, r: text(h[::-1], [x[::-1] for x in r]).encode(), "same", [("column", "order")]),
    "no-header": (lambda h, r: text(r[0], r[1:]).encode(), "refuse", [("header", "column")]),
    "renamed-columns": (lambda h, r: text([f"col{i}" for i in range(len(h))], r).encode(), "refuse",
                        [("column", "header")]),
    "header-spaces-case": (lambda h, r: text([f" {c.title()} " for c in h], r).encode(), "same", [("column", "header")]),
    "empty-file": (lambda h, r: b"", "refuse", [("empty", "no rows", "no data", "nothing")]),
    "header-only": (lambda h, r: text(h, []).encode(), "refuse", [("empty", "no rows", "no data", "row", "reading",
                                                                     "recorded", "no spheres")]),
    "blank-lines-at-end": (lambda h, r: (text(h, r) + "\n\n\n").encode(), "same", [("blank", "empty")]),
    "comment-line": (lambda h, r: ("# measured by me\n" + text(h, r)).encode(), "same", [("#", "comment", "header")]),
    "nan-cell": (lambda h, r: text(h, setcell(r, len(r) // 2, 1, "nan")).encode(), "refuse",
                 [("nan", "not a number", "missing", "number", "finite")]),
    "empty-cell": (lambda h, r: text(h, setcell(r, len(r) // 2, 1, "")).encode(), "refuse",
                   [("empty", "missing", "blank", "''")]),
    "text-cell": (lambda h, r: text(h, setcell(r, len(r) // 2, 1, "abc")).encode(), "refuse",
                  [("abc", "row", "line", "number")]),
    "inf-cell": (lambda h, r: text(h, setcell(r, len(r) // 2, 1, "inf")).encode(), "refuse",
                 [("inf", "finite", "number")]),
    "negative-cell": (lambda h, r: text(h, setcell(r, len(r) // 2, 1, "-" + r[len(r) // 2][1].lstrip("-")
                                                     .replace("-", ""))).encode(), "refuse",
                      [("negative", "< 0", "below 0", "positive", "-")]),
    "huge-cell": (lambda h, r: text(h, setcell(r, len(r) // 2, 1, "1e30")).encode(), "refuse",
                  [("1e+30", "1e30", "large", "implausible", "range", "above", "exceeds", "within")]),
    "binary-garbage": (lambda h, r: bytes(random.Random(3).randrange(256) for _ in range(2000)), "refuse",
                       [(*ENC, "not a csv", "binary", "header")]),
    "duplicated-row": (lambda h, r: text(h, [*r[:2], r[1], *r[2:]]).encode(), "any",
                       [("duplicate", "twice", "repeated", "increas", "sorted")]),
    "unsorted": (lambda h, r: text(h, r[::-1]).encode(), "same", [("sorted", "order", "increas", "decreas")]),
    "one-row": (lambda h, r: text(h, r[-1:]).encode(), "any", [("row", "point", "reading", "at least")]),
}
UNITS = {
    "psd": {
        "diameter-in-mm": (lambda h, r: text(h, col(r, 0, lambda x: fmt(x / 1000))).encode(), "refuse",
                           [("mm", "µm", "um", "micro")]),
        "percent-as-fraction": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x / 100))).encode(), "refuse",
                                [("fraction", "percent", "0-1", "100")]),
        "percent-retained": (lambda h, r: text(h, col(r, 1, lambda x: fmt(100 - x))).encode(), "refuse",
                             [("finer", "retained", "decreas", "increas")]),
        "percent-over-100": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x * 1.3))).encode(), "refuse",
                             [("100",)]),
    },
    "temprec": {
        "kelvin": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x + 273.15))).encode(), "refuse",
                   [("temperature",), ("K", "kelvin", "292", "0-40", "40")]),
        "fahrenheit": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x * 1.8 + 32))).encode(), "refuse",
                       [("temperature",), ("F", "fahrenheit", "0-40", "40", "66")]),
        "time-in-hours": (lambda h, r: text(h, col(r, 0, lambda x: fmt(x / 60))).encode(), "refuse",
                          [("time",), ("end", "cover", "short", "before", "hour", "min")]),
    },
    "hydrometer": {
        "temperature-kelvin": (lambda h, r: text(h, col(r, 2, lambda x: fmt(x + 273.15))).encode(), "refuse",
                               [("temperature",), ("K", "kelvin", "292", "0-40", "40")]),
        "specific-gravity-151H": (lambda h, r: text(h, col(r, 1, lambda x: fmt(1 + x / 1600))).encode(), "refuse",
                                  [("reading",), ("151H", "specific gravity", "g/L")]),
        "time-in-seconds": (lambda h, r: text(h, col(r, 0, lambda x: fmt(x * 60))).encode(), "refuse",
                            [("time",), ("min", "second", "day", "long")]),
    },
    "sieve": {
        "opening-in-um": (lambda h, r: text(h, col(r, 0, lambda x: fmt(x * 1000))).encode(), "refuse",
                          [("opening", "sieve"), ("mm", "um", "µm")]),
        "percent-as-fraction": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x / 100))).encode(), "refuse",
                                [("fraction", "percent", "0-1", "100")]),
        "percent-retained": (lambda h, r: text(h, col(r, 1, lambda x: fmt(100 - x))).encode(), "refuse",
                             [("passing", "retained", "decreas", "increas")]),
    },
    "pipette": {
        "depth-in-m": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x / 100))).encode(), "refuse",
                       [("depth", "deep"), ("cm", "m")]),
        "mass-in-mg": (lambda h, r: text(h, col(r, 2, lambda x: fmt(x * 1000))).encode(), "refuse",
                       [("mass",), ("mg", "g", "more than")]),
        "mass-in-kg": (lambda h, r: text(h, col(r, 2, lambda x: fmt(x / 1000))).encode(), "refuse",
                       [("mass",), ("kg", "g")]),
    },
    "buoyancy": {
        "mass-in-kg": (lambda h, r: text(h, col(r, 1, lambda x: fmt(x / 1000))).encode(), "refuse",
                       [("mass",), ("kg", " g")]),
        "temperature-kelvin": (lambda h, r: text(h, col(r, 2, lambda x: fmt(x + 273.15))).encode(), "refuse",
                               [("temperature",), ("K", "kelvin", "292", "0-40", "40")]),
    },
    "spheres": {
        "d-in-mm": (lambda h, r: text(h, col(r, 4, lambda x: fmt(x * 1000))).encode(), "refuse",
                    [("d", "diameter"), ("mm", "19", "m")]),
        "rho-in-g-cm3": (lambda h, r: text(h, col(r, 5, lambda x: fmt(x / 1000))).encode(), "refuse",
                         [("rho", "density"), ("kg/m3", "g/cm3", "6.513", "lighter")]),
        "eta-in-mPa-s": (lambda h, r: text(h, col(r, 2, lambda x: fmt(x * 1000))).encode(), "refuse",
                         [("eta", "viscosity"), ("Pa s", "mPa", "13.1")]),
    },
}

# where each kind of file goes: (command, args with FILE, timeout, signature of the result or None)
OUT = "@OUT"


def sig_sample(out: Path) -> dict:
    t = csvs(out)
    t.pop("input_psd.csv", None)
    deck = out / "in.sedimentation"
    if deck.is_file():
        t["deck"] = "\n".join(line for line in deck.read_text().splitlines() if not line.lstrip().startswith("#"))
    return t


def sig_csvs(out: Path) -> dict:
    t = csvs(out)
    t.pop("input_psd.csv", None)
    return t


USES = {
    "psd": [("sample", ["sample", "@FILE", "--out", OUT, *TINY], 30, sig_sample, True),
            ("plan", ["plan", "@FILE", "--screen-only", "--out", OUT], 30, "stdout", True),
            ("budget", ["budget", "@FILE", "--particles", "1000", "--out", OUT], 8, None, True)],
    "temprec": [("sample", ["sample", PSD, "--temperature-record", "@FILE", "--out", OUT, *TINY], 30, sig_sample,
                 True)],
    "hydrometer": [("invert", ["invert", "@FILE", INV / "soil" / "sieve.csv", "--mass", "0.05", *INVERT_SMALL,
                               "--out", OUT], 8, None, True)],
    "sieve": [("invert", ["invert", INV / "soil" / "hydrometer.csv", "@FILE", "--mass", "0.05", *INVERT_SMALL,
                          "--out", OUT], 8, None, True)],
    "pipette": [("invert", ["invert", "@FILE", "--mass", "0.06", *INVERT_SMALL, "--out", OUT], 8, None, True)],
    "buoyancy": [("invert", ["invert", "@FILE", "--mass", "0.06", *INVERT_SMALL, "--out", OUT], 8, None, True)],
    "spheres": [("spheres", ["spheres", "@FILE", "--law", "bingham", "--out", OUT], 60, sig_csvs, False)],
}
# shapes that do not apply to a kind (a sheet's one row is a valid sheet, a PSD's second column ...)
SKIP = {("temprec", "one-row"), ("sieve", "one-row"), ("buoyancy", "one-row"), ("pipette", "one-row"),
        ("hydrometer", "one-row"), ("spheres", "one-row"), ("spheres", "unsorted"),
        ("spheres", "duplicated-row"), ("temprec", "duplicated-row")}


def expand(args: list, file: Path, out: Path) -> list:
    return [file if a == "@FILE" else out if a == OUT else a for a in args]


def input_case(kind: str, variant: str, use: tuple, transform, expectation: str, words) -> Callable:
    command, args, timeout, sig, _ = use

    def fn(ctx: Ctx):
        header, rows = KINDS[kind]
        bad = ctx.file(f"{kind}.csv", transform(header, rows))
        out = ctx.tmp / "out"
        done = sed(*expand(args, bad, out), timeout=max(timeout, PATIENCE["value"]))

        def accept():
            if expectation == "refuse":
                return False, "accepted"
            if expectation == "any" or sig is None:
                return True, "done"
            clean = ctx.file(f"clean-{kind}.csv", text(header, rows))
            out2 = ctx.tmp / "clean"
            ref = sed(*expand(args, clean, out2), timeout=timeout)
            if sig == "stdout":
                a = done.out.replace(str(bad), "F").replace(str(out), "O")
                b = ref.out.replace(str(clean), "F").replace(str(out2), "O")
                return a == b, "the same answer as the clean file's" if a == b else "another answer than the clean file's"
            a, b = sig(out), sig(out2)
            return a == b, ("the same result as the clean file's" if a == b
                            else f"another result than the clean file's: {diff(b, a)}")
        if expectation == "refuse" or sig is not None or expectation == "any":
            return refusal(done, words, accept=accept, refuse_codes=INVERT_CODES if command == "invert" else (2,))
        return refusal(done, words, accept=accept)
    return fn


# A blank temperature is a row without one, left out as documented (a sheet of readings, with the
# temperature taken at some readings only, serves as a record): read or refused, both are right.
EXPECTED = {("temprec", "empty-cell"): "any"}
for _kind, _uses in USES.items():
    for _use in _uses:
        _variants = dict(GENERIC)
        _variants.update(UNITS.get(_kind, {}))
        for _variant, (_tf, _exp, _words) in _variants.items():
            if (_kind, _variant) in SKIP:
                continue
            _exp = EXPECTED.get((_kind, _variant), _exp)
            # a command that takes long once it accepts: only what it must refuse, within its timeout
            if _use[3] is None and _exp != "refuse":
                continue
            _kindword = "unit" if _variant in UNITS.get(_kind, {}) else "input"
            add(f"{_use[0]}/{_kind}/{_variant}", _use[0], _kindword,
                input_case(_kind, _variant, _use, _tf, _exp, _words), quick=_use[4])


# ==== options: unit slips and impossible values ==========================================================
PATIENCE = {"value": 45.0}  # how long a command that must refuse may work before it counts as accepting


def opt_case(args: list, words, needs=(), timeout: float = 8, prepare: Callable | None = None) -> Callable:
    def fn(ctx: Ctx):
        timeout_ = max(timeout, PATIENCE["value"])
        out = ctx.tmp / "out"
        base = ctx.copy(needs[0]) if needs else None
        a = [(base / "layers.h5" if x == "@LAYERS" else out if x == OUT else x) for x in args]
        done = sed(*a, timeout=timeout_)
        return refusal(done, words, refuse_codes=INVERT_CODES if a[0] == "invert" else (2,))
    return fn


PREVIEW = ["readout", "--stokes-preview", "--psd", PSD, "--out", OUT]
INVERT_CODES = (2, 3)   # invert's exit 3 is its documented verdict "no PSD explains the sheets": a refusal
OPTIONS = {
    # command: (base args, [(option, value, words, why)])
    "sample": (["sample", PSD, "--out", OUT, *TINY], [
        ("--mass", "60", [("mass", "solids"), ("60", "kg")], "grams for kg"),
        ("--mass", "6", [("mass", "solids"), ("6", "kg")], "a mass ten times... a hundred"),
        ("--particle-density", "2.65", [("density", "kg/m3"), ("2.65", "g/cm3")], "g/cm3 for kg/m3"),
        ("--particle-density", "900", [("density", "kg/m3"), ("900", "float", "lighter", "water")], "lighter than water"),
        ("--temperature", "293.15", [("temperature",), ("293", "0-40", "kelvin")], "kelvin for C"),
        ("--temperature", "68", [("temperature",), ("68", "0-40", "fahrenheit")], "fahrenheit for C"),
        ("--height", "36", [("height",), ("36",)], "cm for m"),
        ("--width", "14", [("width",), ("14",)], "mm for m"),
    ]),
    "readout-preview": (PREVIEW, [
        ("--pipette-volume", "25", [("pipette", "volume"), ("25", "m3", "mL")], "mL for m3"),
        ("--pipette-volume", "0.025", [("pipette", "volume"), ("0.025", "m3", "mL")], "L for m3"),
        ("--pipette-depth", "10", [("depth", "deep"), ("10", "cm")], "cm for m"),
        ("--sphere-depth", "30", [("depth", "deep"), ("30", "cm")], "cm for m"),
        ("--particle-density", "2.65", [("density", "kg/m3"), ("2.65", "g/cm3")], "g/cm3 for kg/m3"),
        ("--concentration", "0.05", [("concentration",), ("0.05", "g/L", "kg/L")], "kg/L for g/L"),
        ("--concentration", "50000", [("concentration",), ("50000", "g/L", "mg/L")], "mg/L for g/L"),
        ("--height", "36", [("height",), ("36",)], "cm for m"),
        ("--temperature", "293.15", [("temperature",), ("293", "0-40", "kelvin")], "kelvin for C"),
        ("--viscosity", "1.002", [("viscosity",), ("1.002", "Pa s", "mPa")], "mPa s for Pa s"),
        ("--cylinder-area", "27.8", [("area",), ("27.8", "cm2", "m2")], "cm2 for m2"),
    ]),
    "readout": (["readout", "@LAYERS", "--out", OUT], [
        ("--pipette-volume", "25", [("pipette", "volume"), ("25", "m3", "mL")], "mL for m3"),
        ("--pipette-depth", "10", [("depth", "deep"), ("10", "cm")], "cm for m"),
        ("--sphere-depth", "30", [("depth", "deep"), ("30", "cm")], "cm for m"),
        ("--temperature", "293.15", [("temperature",), ("293", "0-40", "kelvin")], "kelvin for C"),
        ("--viscosity", "1.002", [("viscosity",), ("1.002", "Pa s", "mPa")], "mPa s for Pa s"),
        ("--cylinder-area", "27.8", [("area",), ("27.8", "cm2", "m2")], "cm2 for m2"),
        ("--surface", "36", [("surface",), ("36", "layers", "column")], "cm for m"),
    ]),
    "invert": (["invert", INV / "soil" / "hydrometer.csv", INV / "soil" / "sieve.csv", "--mass", "0.05",
                *INVERT_SMALL, "--out", OUT], [
        ("--mass", "50", [("mass", "solids"), ("50", "kg")], "grams for kg"),
        ("--particle-density", "2.65", [("density", "kg/m3"), ("2.65", "g/cm3")], "g/cm3 for kg/m3"),
        ("--particle-density", "1000", [("density",), ("1000", "water")], "as dense as water"),
        ("--cylinder-area", "27.8", [("area",), ("27.8", "cm2", "m2")], "cm2 for m2"),
        ("--height", "36", [("height",), ("36",)], "cm for m"),
        ("--split", "2000", [("split", "opening"), ("2000", "mm")], "um for mm"),
        ("--volume", "1000", [("volume",), ("1000", "mL")], "mL for m3"),
        ("--bulb-volume", "67", [("bulb", "volume"), ("67", "mL", "cm3")], "cm3 for m3"),
        ("--bulb-length", "14", [("bulb", "length"), ("14", "cm")], "cm for m"),
        ("--hydrometer-type", "151H", [("151H", "hydrometer-type"), ("specific gravit",)], "a 152H sheet as a 151H"),
    ]),
    "invert-plain": (["invert", INV / "hydrometer.csv", "--mass", "0.06", *INVERT_SMALL, "--out", OUT], [
        ("--zero-correction", "2500", [("correction",), ("2500", "2.45e+03")], "implausible"),
        ("--meniscus", "100", [("meniscus",), ("100",)], "implausible"),
    ]),
    "invert-pipette": (["invert", INV / "pipette.csv", "--mass", "0.06", *INVERT_SMALL, "--out", OUT], [
        ("--pipette-volume", "0.025", [("pipette", "volume"), ("0.025", "m3", "mL")], "L for m3"),
        ("--pipette-volume", "25", [("pipette", "volume"), ("25", "m3", "mL")], "mL for m3"),
    ]),
    "invert-buoyancy": (["invert", INV / "buoyancy.csv", "--mass", "0.06", *INVERT_SMALL, "--out", OUT], [
        ("--sphere-mass", "20", [("sphere", "mass"), ("20", "kg")], "grams for kg"),
        ("--sphere-diameter", "25", [("sphere", "diameter"), ("25", "mm", "m")], "mm for m"),
        ("--sphere-depth", "10.8", [("depth", "deep"), ("10.8", "cm")], "cm for m"),
        ("--sphere-mass", "0.2", [("sphere", "mass", "apparent"), ("0.2", "kg", "float", "reading")],
         "a mass ten times too large"),
    ]),
    "budget": (["budget", PSD, "--particles", "1000", "--out", OUT], [
        ("--mass", "60", [("mass", "solids"), ("60", "kg")], "grams for kg"),
        ("--temperature", "293.15", [("temperature",), ("293", "0-40", "kelvin")], "kelvin for C"),
    ]),
    "plan": (["plan", PSD, "--screen-only", "--out", OUT], [
        ("--mass", "60", [("mass", "solids"), ("60", "kg")], "grams for kg"),
        ("--particle-density", "2.65", [("density", "kg/m3"), ("2.65", "g/cm3")], "g/cm3 for kg/m3"),
        ("--temperature", "293.15", [("temperature",), ("293", "0-40", "kelvin")], "kelvin for C"),
        ("--height", "36", [("height",), ("36",)], "cm for m"),
        ("--particles", "2000;1000", [("particles",), ("2000;1000", "comma")], "semicolons"),
        ("--courant", "1,x", [("courant",), ("x",)], "not a number"),
    ]),
    "terminal": (["terminal", "--law", "standard", "--diameter", "50e-6", "--particle-density", "2650"], [
        ("--diameter", "50", [("diameter",), ("50", "um", "µm", "m")], "um for m"),
        ("--particle-density", "2.65", [("density", "kg/m3"), ("2.65", "g/cm3")], "g/cm3 for kg/m3"),
        ("--temperature", "293.15", [("temperature",), ("293", "0-40", "kelvin")], "kelvin for C"),
        ("--solid-fraction", "40", [("fraction",), ("40", "percent", "0-1")], "percent for a fraction"),
        ("--gravity", "-9.81", [("gravity",), ("-9.81", "positive")], "a sign"),
        ("--poisson-ratio", "0.7", [("poisson",), ("0.7", "0.5")], "impossible ratio"),
        ("--youngs-modulus", "200", [("young", "modulus"), ("200", "GPa", "Pa")], "GPa for Pa"),
    ]),
    "calibrate-slump": (["calibrate", "slump", "--slump", "0.102", "0.103", "--height", "0.152", "--density", "1843"],
                        []),
    "paste-energy": (["paste", "energy"], [
        ("--diameter", "12.6", [("diameter",), ("12.6", "mm", "m")], "mm for m"),
        ("--fall", "255", [("fall",), ("255", "mm", "m")], "mm for m"),
    ]),
    "paste-balls": (["paste", "balls", "--out", OUT], [
        ("--viscosity", "279", [("viscosity",), ("279", "mPa", "Pa s")], "mPa s for Pa s"),
    ]),
}
# an option replaces the one of the same name in the base args
def with_option(base: list, option: str, value: str) -> list:
    args = list(base)
    if option in args:
        args[args.index(option) + 1] = value
    else:
        args += [option, value]
    return args


for _cmd, (_base, _rows) in OPTIONS.items():
    _needs = ("run",) if "@LAYERS" in _base else ()
    for _opt, _val, _words, _why in _rows:
        add(f"{_cmd}/unit{_opt}={_val}", _base[0], "unit", opt_case(with_option(_base, _opt, _val), _words, _needs),
            quick=_base[0] not in ("paste",) and _cmd != "readout-preview", needs=_needs)

# impossible values of every numeric option: refused naming the option
IMPOSSIBLE = {
    "sample": ("sample", ["--mass", "--particle-density", "--temperature", "--height", "--width", "--t-end",
                          "--classes", "--layers", "--particles", "--courant"], ["nan", "-1", "0", "inf"]),
    "readout": ("readout", ["--pipette-volume", "--pipette-depth", "--sphere-depth", "--concentration",
                            "--viscosity", "--cylinder-area"], ["nan", "-1", "0"]),
    "invert": ("invert", ["--mass", "--particle-density", "--cylinder-area", "--height", "--hydrometer-noise",
                          "--sieve-noise", "--thermometer", "--bins", "--particles"], ["nan", "-1", "0"]),
    "terminal": ("terminal", ["--diameter", "--particle-density", "--fluid-density", "--viscosity",
                              "--solid-fraction", "--yield-stress"], ["nan", "-1", "inf"]),
    "budget": ("budget", ["--particles", "--replicas", "--courant"], ["nan", "0"]),
    "plan": ("plan", ["--tolerance", "--jobs", "--replicas", "--classes"], ["nan", "0"]),
}
_WORDLESS = {"--t-end": ("t-end", "t_end", "time"), "--hydrometer-noise": ("noise",), "--sieve-noise": ("noise",),
             "--pipette-volume": ("pipette-volume", "pipette volume", "volume")}
for _cmd, (_c, _opts, _vals) in IMPOSSIBLE.items():
    _base = OPTIONS[_cmd][0]
    for _opt in _opts:
        for _val in _vals:
            if (_opt, _val) in {("--temperature", "0")}:      # 0 C is water's own range
                continue
            _stem = _WORDLESS.get(_opt, (_opt, _opt.lstrip("-"), _opt.lstrip("-").replace("-", " ")))
            add(f"{_cmd}/value{_opt}={_val}", _c, "value", opt_case(with_option(_base, _opt, _val), [_stem],
                needs=("run",) if "@LAYERS" in _base else ()), quick=True, needs=("run",) if "@LAYERS" in _base else ())

# the small commands' own values (fast, no LAMMPS)
SMALL = [
    ("calibrate", ["calibrate", "slump", "--slump", "102", "103", "100", "--height", "0.152", "--density", "1843"],
     [("slump",), ("height", "mm", "unit", "taller")], "slumps in mm, height in m"),
    ("calibrate", ["calibrate", "slump", "--slump", "0.102", "--height", "0.152", "--density", "1.843"],
     [("density",), ("1.843", "kg/m3", "g/cm3")], "density in g/cm3"),
    ("calibrate", ["calibrate", "slump", "--slump", "0.2", "--height", "0.152", "--density", "1843"],
     [("slump",), ("height", "taller", "exceed", "more than")], "a slump taller than the cylinder"),
    ("calibrate", ["calibrate", "slump", "--slump", "nan", "--height", "0.152", "--density", "1843"],
     [("slump",)], "NaN"),
    ("calibrate", ["calibrate", "slump", "--slump", "0.1", "--height", "inf", "--density", "1843"],
     [("height",)], "inf"),
    ("calibrate", ["calibrate", "restitution", "--drop", "1", "--rebound", "2"],
     [("rebound",), ("drop", "higher", "exceed", "more than")], "a rebound higher than the drop"),
    ("calibrate", ["calibrate", "restitution", "--drop", "1", "2", "--rebound", "0.5"],
     [("rebound", "drop"), ("as many", "same number", "count", "pairs", "each", " but ")], "unpaired heights"),
    ("calibrate", ["calibrate", "restitution", "--drop", "nan", "--rebound", "0.5"], [("drop",)], "NaN"),
    ("calibrate", ["calibrate", "tilt", "--lift", "700", "--length", "600"],
     [("lift",), ("length", "longer", "exceed", "more than")], "a lift beyond the plate"),
    ("calibrate", ["calibrate", "tilt", "--lift", "205", "--length", "0.6"],
     [("lift", "length"), ("unit", "same", "mm", "m")], "lift in mm, length in m"),
    ("calibrate", ["calibrate", "tilt", "--lift", "inf", "--length", "600"], [("lift",)], "inf"),
    ("paste", ["paste", "restitution", "--target", "1.5"], [("target", "restitution"), ("1",)], "restitution > 1"),
    ("paste", ["paste", "restitution", "--target", "-0.2"], [("target", "restitution")], "negative"),
    ("paste", ["paste", "restitution", "--target", "nan"], [("target", "restitution")], "NaN"),
    ("paste", ["paste", "energy", "--dt", "-1e-5"], [("dt",)], "negative step"),
    ("paste", ["paste", "energy", "--dt", "0"], [("dt",)], "zero step"),
    ("paste", ["paste", "energy", "--diameter", "nan"], [("diameter",)], "NaN"),
    ("paste", ["paste", "funnel", "--runs", "0", "--out", OUT], [("runs",)], "no runs"),
    ("paste", ["paste", "funnel", "--runs", "-2", "--out", OUT], [("runs",)], "negative runs"),
    ("paste", ["paste", "funnel", "--jobs", "0", "--runs", "1", "--out", OUT], [("jobs",)], "no jobs"),
    ("paste", ["paste", "funnel", "--set", "nosuchvariable=3", "--runs", "1", "--out", OUT],
     [("nosuchvariable",)], "an unknown variable"),
    ("paste", ["paste", "funnel", "--set", "stem", "--runs", "1", "--out", OUT], [("stem", "NAME=VALUE", "=")],
     "--set without a value"),
    ("paste", ["paste", "balls", "--viscosity", "-1", "--out", OUT], [("viscosity",)], "negative"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3;2e-3", "--observe", "velocity", "--out", OUT],
     [("dt",), ("1e-3;2e-3", ";", "comma")], "semicolons"),
    ("sweep", ["sweep", CASE_A, "--dt", "0,001", "--observe", "velocity", "--out", OUT],
     [("dt",), ("0,001", "0", "decimal", "comma", "positive")], "a comma decimal"),
    ("sweep", ["sweep", CASE_A, "--dt", "-1e-3,1e-3", "--observe", "velocity", "--out", OUT],
     [("dt",), ("-1e-3", "-0.001", "positive", "negative")], "a negative step"),
    ("sweep", ["sweep", CASE_A, "--dt", "nan,1e-3", "--observe", "velocity", "--out", OUT],
     [("dt",), ("nan",)], "NaN"),
    ("sweep", ["sweep", CASE_A, "--dt", "", "--observe", "velocity", "--out", OUT], [("dt",)], "empty"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3,2e-3", "--observe", "velocity", "--tolerance", "1", "--out", OUT],
     [("tolerance",), ("1", "%", "fraction")], "percent for a fraction"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3,2e-3", "--observe", "velocity", "--integrator", "leapfrog",
               "--out", OUT], [("integrator",), ("leapfrog",)], "an unknown integrator"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3,2e-3", "--observe", "velocity", "--reference",
               "velocity=__import__('os').getcwd()", "--out", OUT], [("reference",)], "code as a reference"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3,2e-3", "--observe", "velocity", "--reference", "velocity",
               "--out", OUT], [("reference",), ("=", "NAME=EXPR")], "a reference with no expression"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3,2e-3", "--observe", "velocity", "--np", "0", "--out", OUT],
     [("np", "ranks")], "no ranks"),
    ("sweep", ["sweep", REPO / "no" / "deck", "--dt", "1e-3", "--observe", "velocity", "--out", OUT],
     [("no such", "not found", "does not exist")], "a missing deck"),
    ("run", ["run", REPO / "no" / "in.deck"], [("no such", "not found", "does not exist")], "a missing deck"),
    ("run", ["run", PSD, "--np", "0"], [("np", "ranks")], "no ranks"),
    ("spheres", ["spheres", REPO / "no.csv", "--out", OUT], [("no such", "not found", "does not exist")],
     "a missing file"),
    ("readout", ["readout", REPO / "no" / "layers.h5", "--out", OUT], [("no such", "not found", "does not exist")],
     "a missing layer file"),
    ("readout", ["readout", "--out", OUT], [("layer", "stokes-preview", "psd")], "no layer file and no preview"),
    ("invert", ["invert", INV / "soil" / "hydrometer.csv", "--out", OUT], [("mass",)], "sheets without --mass"),
    ("invert", ["invert", "--mass", "0.05", "--out", OUT], [("sheet", "design")], "no sheets"),
    ("invert", ["invert", INV / "soil" / "hydrometer.csv", INV / "soil" / "hydrometer.csv", "--mass", "0.05",
                *INVERT_SMALL, "--out", OUT], [("twice", "same", "duplicate", "once")], "the same sheet twice"),
    ("invert", ["invert", INV / "soil" / "hydrometer.csv", INV / "hydrometer.csv", "--mass", "0.05",
                *INVERT_SMALL, "--out", OUT], [("hydrometer",), ("two", "twice", "one", "more than", "samples")],
     "two hydrometer sheets of two samples"),
    ("invert", ["invert", INV / "soil" / "hydrometer.csv", INV / "soil" / "sieve.csv", "--mass", "0.05", "--split",
                "5", *INVERT_SMALL, "--out", OUT], [("split",), ("5", "sieve", "opening")],
     "a split on an opening the sieve sheet lacks"),
    ("invert", ["invert", "--design", PSD, "--masses", "30,45,60", "--out", OUT], [("masses", "mass", "solids"), ("kg", "30")],
     "design masses in grams"),
    ("invert", ["invert", "--design", PSD, "--masses", "0.03;0.06", "--out", OUT], [("masses",)], "semicolons"),
    ("budget", ["budget", PSD, PSD, "--particles", "1000", "--out", OUT], [("twice", "same", "duplicate", "once")],
     "the same PSD twice"),
    ("budget", ["budget", PSD, "--replicas", "1", "--out", OUT], [("replicas",), ("2", "at least")],
     "one replica (at least 2)"),
    ("plan", ["plan", "--out", OUT], [("psd", "deck")], "neither a PSD nor --deck"),
    ("plan", ["plan", PSD, "--screen-only", "--set", "hindrance", "--out", OUT], [("set",), ("=", "NAME=VALUE")],
     "--set without a value"),
    ("plan", ["plan", PSD, "--screen-only", "--set", "nosuch=3", "--out", OUT], [("nosuch",)], "an unknown effect"),
    ("plan", ["plan", PSD, "--screen-only", "--set", "particles=-5", "--out", OUT], [("particles",)],
     "negative particles"),
]
for _i, (_cmd, _args, _words, _why) in enumerate(SMALL):
    _slow = _cmd in ("paste", "sweep") and "funnel" not in _args and "restitution" not in _args
    add(f"{_cmd}/value-{_i:02d}-{_why.replace(' ', '-')}", _cmd, "value",
        opt_case(_args, _words, timeout=30 if _slow else 8), quick=not _slow)


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
        if has(refused.message, [("another sediment command", "in use", "busy", "lock")]):
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
        done = finish(proc, 60, t0)
        time.sleep(0.3 if sig != signal.SIGKILL else 6.0)
        got = csvs(out)
        clean = ctx.tmp / "clean"
        sed(*[clean if x == out else x for x in args + change], timeout=300)
        new = csvs(clean)
        leftovers = [p.name for p in out.parent.iterdir() if p.name not in ("out", "clean", "_run", "_one.csv")
                     and not p.name.endswith(".lock")]   # plan's lock files stay beside --out, as a run's do
        if sig == signal.SIGKILL:
            if done.rc not in (-9, 0):
                bad = crashed(done)
                if bad:
                    return "crash", bad
        else:
            bad = crashed(done)
            if bad and not (done.rc == -sig and finished):
                return "crash", bad
            if not finished and done.rc not in (130, 0):
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
        state = "finished first" if finished else f"exit {done.rc}"
        return "ok", f"{state}; the folder {'the earlier set' if got == old and old != new else 'whole'}"
    return fn


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
        done = finish(proc, 60, t0)
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
        done = finish(proc, 60, t0)
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


# ==== runner ================================================================================================
OUTCOME_NAMES = ("ok", "wrong", "crash", "vague")
KNOWN_BAD: set[str] = {   # not ok in the round of docs/hostile.md; take a case off when it is fixed
    "paste-balls/unit--viscosity=279",
    "run/again-after-it-finished",
    "spheres/spheres/binary-garbage",
    
    "sweep/value-25-a-negative-step",
}


def run_case(item: tuple) -> tuple[str, str, str, float]:
    name, root, fixtures = item[:3]
    if len(item) > 3 and item[3] is not None and time.monotonic() > item[3]:
        return name, "not run", "past the --deadline", 0.0
    case = CASES[name]
    tmp = Path(tempfile.mkdtemp(prefix="c-", dir=root))
    t0 = time.monotonic()
    try:
        outcome, detail = case.fn(Ctx(tmp, Path(fixtures)))
    except Exception as e:  # noqa: BLE001 - a fault of the round itself, reported as such
        outcome, detail = "crash", f"ROUND ERROR {type(e).__name__}: {str(e).strip().splitlines()[-1][:160] if str(e).strip() else ''}"
    finally:
        subprocess.run(["umount", "-l", str(tmp / "disk")], stderr=subprocess.DEVNULL, check=False)
        shutil.rmtree(tmp, ignore_errors=True)
    assert outcome in OUTCOME_NAMES, outcome
    return name, outcome, " ".join(str(detail).split())[:300], time.monotonic() - t0


def select(only: str | None, quick: bool) -> list[str]:
    names = [n for n, c in CASES.items() if (not quick or c.quick)]
    if only:
        names = [n for n in names if fnmatch.fnmatch(n, only) or only in n]
    return names


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="only the cases that take seconds (no LAMMPS run of their own)")
    ap.add_argument("--only", help="cases whose name matches this glob or contains this text")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", type=Path, help="write the outcomes as JSON here")
    ap.add_argument("--list", action="store_true", help="list the cases and stop")
    ap.add_argument("--names", type=Path, help="run the cases named in this file (one a line)")
    ap.add_argument("--deadline", type=float, help="start no case after this many seconds (the rest: not run)")
    ap.add_argument("--patience", type=float, help="seconds a command that must refuse may work before it counts as "
                    "accepting (default 45)")
    args = ap.parse_args(argv)
    PATIENCE["value"] = args.patience or 45.0
    names = select(args.only, args.quick)
    if args.names:
        chosen = set(names)
        names = [n for n in args.names.read_text().split() if n in chosen]   # in the file's order
    if args.list:
        for n in names:
            c = CASES[n]
            print(f"{n}\t{c.command}\t{c.kind}\t{'quick' if c.quick else ''}")
        print(f"{len(names)} cases", file=sys.stderr)
        return 0
    root = Path(tempfile.mkdtemp(prefix="hostile3-"))
    fixtures = root / "fixtures"
    fixtures.mkdir()
    build_fixtures({f for n in names for f in CASES[n].needs}, fixtures)
    results = []
    t0 = time.monotonic()
    items = [(n, str(root), str(fixtures), t0 + args.deadline if args.deadline else None) for n in names]
    with multiprocessing.get_context("fork").Pool(max(1, args.jobs)) as pool:
        for name, outcome, detail, secs in pool.imap_unordered(run_case, items):
            results.append((name, outcome, detail, secs))
            mark = "ok " if outcome == "ok" else outcome.upper()
            print(f"{mark:5} {name} ({secs:.1f} s): {detail[:200]}", flush=True)
    counts = Counter(o for _, o, _, _ in results)
    print(f"{len(results)} cases in {time.monotonic() - t0:.0f} s: " +
          ", ".join(f"{counts[o]} {o}" for o in ("ok", "wrong", "crash", "vague")))
    if args.json:
        args.json.write_text(json.dumps({n: [o, d, round(s, 1)] for n, o, d, s in sorted(results)}, indent=1))
    shutil.rmtree(root, ignore_errors=True)
    unexpected = [n for n, o, _, _ in results if o not in ("ok", "not run") and n not in KNOWN_BAD]
    return 1 if unexpected else 0


if __name__ == "__main__":
    sys.exit(main())
