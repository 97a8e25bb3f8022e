# SPDX-License-Identifier: GPL-2.0-or-later
"""Hostile round 3's cases of bad input: damaged, misencoded and malformed input files, and options
with unit slips and impossible values."""
from __future__ import annotations

import random
from pathlib import Path
from typing import Callable

from cases import INVERT_SMALL, Ctx, add
from harness import CASE_A, INV, PSD, REPO, SPHERES_CSV, TINY, csvs, diff, refusal, sed


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
    # one generator for the 2000 bytes (a new one per byte gave 2000 times the same letter)
    "binary-garbage": (lambda h, r: random.Random(3).randbytes(2000), "refuse",
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


def opt_case(args: list, words, needs=(), timeout: float = 8) -> Callable:
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
    # two-way coupling's options (issue 69's hostile round)
    ("sample", ["sample", PSD, "--two-way", "--flow-cells", "7", "--out", OUT], [("7",), ("2, 3 and 5",)],
     "a grid the FFTs do not take"),
    ("sample", ["sample", PSD, "--two-way", "--flow-cells", "1000", "--out", OUT], [("1000 x 1000",), ("GB",)],
     "a grid beyond memory"),
    ("sample", ["sample", PSD, "--flow-cells", "12", "--out", OUT], [("--flow-cells",), ("--two-way",)],
     "a grid without the flow"),
    ("plan", ["plan", PSD, "--screen-only", "--measure-flow", "--flow-seeds", "1000000", "--out", OUT],
     [("--flow-seeds",), ("100",)], "a million draws"),
    ("plan", ["plan", PSD, "--screen-only", "--flow-cells", "12", "--out", OUT], [("--flow-cells",),
     ("--measure-flow",)], "a grid without a measurement"),
    ("run", ["run", CASE_A, "--var", "nosuchvariable", "3"], [("nosuchvariable",), ("never reads",)],
     "a variable the deck never reads"),
    ("sweep", ["sweep", CASE_A, "--dt", "1e-3", "--observe", "velocity", "--var", "nosuchvariable", "3", "--out", OUT],
     [("nosuchvariable",), ("never reads",)], "a sweep variable the deck never reads"),
    ("sweep", ["sweep", CASE_A, "--dt", "1,2", "--parameter", "nosuchvariable", "--observe", "velocity", "--out", OUT],
     [("--parameter",), ("never reads",)], "a swept variable the deck never reads"),
    ("plan", ["plan", "--deck", CASE_A, "--observe", "velocity", "--var", "nosuchvariable", "3", "--out", OUT],
     [("nosuchvariable",), ("never reads",)], "a plan variable the deck never reads"),
]
for _i, (_cmd, _args, _words, _why) in enumerate(SMALL):
    _slow = _cmd in ("paste", "sweep") and "funnel" not in _args and "restitution" not in _args
    add(f"{_cmd}/value-{_i:02d}-{_why.replace(' ', '-')}", _cmd, "value",
        opt_case(_args, _words, timeout=30 if _slow else 8), quick=not _slow)


def stratification_typo(ctx: Ctx):
    """A two-way sample's deck run with its stratification variable misspelt: refused before any step,
    no layer file left behind."""
    out = ctx.tmp / "out"
    written = sed("sample", PSD, "--two-way", *TINY, "--out", out, timeout=60)
    if written.rc != 0:
        return "wrong", f"sample --two-way failed: {written.last}"
    done = sed("run", out / "in.sedimentation", "--var", "stratification", "grain", timeout=60)
    if any(out.glob("layers.h5*")):
        return "wrong", f"refused, but a layer file was left: {sorted(p.name for p in out.glob('layers.h5*'))}"
    return refusal(done, [("stratification",), ("grain",), ("parcels or grains",)])


add("run/value-two-way-stratification-misspelt", "run", "value", stratification_typo, quick=True)
