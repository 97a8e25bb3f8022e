# SPDX-License-Identifier: GPL-2.0-or-later
"""Malformed-input sweep: every SEDIMENT style's command, broken in every way we can generate.

Each style has one valid command (a list of (token, kind) pairs) and the token counts at which it is
complete. From it come: every truncation, an unknown trailing keyword, every keyword and name
replaced by 'bogus', every number replaced by nan, inf, -inf, 1e400, abc, and by -1 or 0 where the
kind of the value forbids them, references to fixes, computes and regions that do not exist, and the
whole scene in 2d. Every deck must end with a LAMMPS ERROR line: never a crash (a signal or an exit
without an error message), a hang (timeout) or a silent run. Mutations that are still valid input
(a truncation at a complete point, 0 where 0 is allowed) are run too and must finish cleanly.
"""
from __future__ import annotations

from dataclasses import dataclass

# Kinds of tokens: 'kw' keyword, 'name' an ID that must exist, 'word' an enumerated value,
# 'pos' a number > 0, 'nonneg' >= 0, 'real' any finite number, 'count' an integer >= 1.
SCENE = """units si
atom_style sphere
atom_modify map array
dimension 3
boundary p p f
region box block -0.01 0.01 -0.01 0.01 -0.05 0.05
create_box 1 box
create_atoms 1 single 0 0 -0.01
create_atoms 1 single 0.002 0 -0.02
set atom * diameter 1e-3 density 2500
comm_modify cutoff 0.002 vel yes
region pool block INF INF INF INF INF 0
fix grav all gravity 9.81 vector 0 0 -1
"""


@dataclass(frozen=True)
class Style:
    name: str
    before: str                           # commands the style needs (fluid, compute, ...)
    head: str                             # 'fix f all fluid', ...
    tokens: tuple[tuple[str, str], ...]
    complete: frozenset[int]              # numbers of tokens after which the command is complete
    after: str = ""                       # commands that use it, then the run


WATER = "fix water all fluid density 1000 viscosity 1e-3 surface z 0\n"
GRID = "compute conc all concentration/grid layers z 10 bounds -0.05 0.05\n"
STEP = "fix step all nve/sphere/fluid\n"
RUN = "timestep 1e-4\nthermo_style custom step atoms\nrun 2\n"

STYLES = [
    Style("fluid", "", "fix f all fluid",
          (("density", "kw"), ("1000", "pos"), ("viscosity", "kw"), ("1e-3", "pos"), ("surface", "kw"), ("z", "word"),
           ("0", "real"), ("velocity", "kw"), ("0", "real"), ("0", "real"), ("0", "real"), ("region", "kw"),
           ("pool", "name")),
          frozenset({4, 7, 11, 13}), "fix d all fluid/drag f law stokes\n" + STEP + RUN),
    Style("fluid bingham", "", "fix f all fluid",
          (("density", "kw"), ("1843", "pos"), ("bingham", "kw"), ("136", "pos"), ("0.7", "pos"), ("surface", "kw"),
           ("plane", "word"), ("0", "real"), ("0", "real"), ("0", "real"), ("0", "real"), ("0", "real"), ("1", "real")),
          frozenset({5, 13}), "fix d all fluid/drag f law zhang-li\n" + STEP + RUN),
    Style("fluid/buoyancy", WATER + GRID, "fix b all fluid/buoyancy",
          (("water", "name"), ("gravity", "kw"), ("grav", "name"), ("mixture", "kw"), ("c_conc", "name"),
           ("2650", "pos")),
          frozenset({1, 3, 6}), STEP + RUN),
    Style("fluid/drag", WATER, "fix d all fluid/drag",
          (("water", "name"), ("law", "kw"), ("dallavalle", "word"), ("rotation", "kw"), ("yes", "word")),
          frozenset({3, 5}), STEP + RUN),
    Style("fluid/drag difelice", WATER + GRID, "fix d all fluid/drag",
          (("water", "name"), ("law", "kw"), ("difelice", "word"), ("concentration", "kw"), ("c_conc", "name"),
           ("buoyancy", "kw"), ("mixture", "word"), ("max_fraction", "kw"), ("0.6", "pos")),
          frozenset({5, 7, 9}), STEP + RUN),
    Style("fluid/drag hindrance", WATER + GRID, "fix d all fluid/drag",
          (("water", "name"), ("law", "kw"), ("standard", "word"), ("hindrance", "kw"), ("richardson-zaki", "word"),
           ("concentration", "kw"), ("c_conc", "name"), ("buoyancy", "kw"), ("mixture", "word")),
          frozenset({3, 7, 9}), STEP + RUN),
    Style("nve/sphere/fluid", WATER + "fix d all fluid/drag water law stokes\n", "fix step all nve/sphere/fluid",
          (("floor", "kw"), ("z", "word"), ("-0.04", "real"), ("surface", "kw"), ("z", "word"), ("0.04", "real")),
          frozenset({0, 3, 6}), RUN),
    Style("concentration/grid", WATER, "compute conc all concentration/grid",
          (("layers", "kw"), ("z", "word"), ("10", "count"), ("bounds", "kw"), ("-0.05", "real"), ("0.05", "real"),
           ("classes", "kw"), ("1e-4", "pos"), ("smooth", "kw"), ("1e-3", "pos"), ("types", "kw"), ("yes", "word")),
          frozenset({3, 6, 8, 10, 12}),
          "fix d all fluid/drag water law difelice concentration c_conc\n" + STEP + RUN),
    Style("concentration/grid cells", WATER, "compute conc all concentration/grid",
          (("cells", "kw"), ("2", "count"), ("2", "count"), ("4", "count")),
          frozenset({4}), "fix d all fluid/drag water law difelice concentration c_conc\n" + STEP + RUN),
    Style("lubricate/fluid", WATER + "fix d all fluid/drag water law stokes\n", "pair_style lubricate/fluid",
          (("water", "name"), ("inner", "kw"), ("0.01", "pos"), ("outer", "kw"), ("0.5", "pos"), ("repulsion", "kw"),
           ("1.0", "pos"), ("limit", "kw"), ("no", "word")),
          frozenset({1, 3, 5, 7, 9}), "pair_coeff * *\n" + STEP + RUN),
    Style("fluid/flow", WATER, "fix u all fluid/flow",
          (("water", "name"), ("grid", "kw"), ("8", "count"), ("8", "count"), ("40", "count"), ("column", "kw"),
           ("-0.05", "real"), ("0.05", "real"), ("brinkman", "kw"), ("0", "nonneg"), ("width", "kw"), ("1", "pos"),
           ("relax", "kw"), ("1", "pos"), ("every", "kw"), ("2", "count"), ("cfl", "kw"), ("0.5", "pos")),
          frozenset({8, 10, 12, 14, 16, 18}), "fix d all fluid/drag water law stokes\n" + STEP + RUN),
    Style("layers/hdf5", WATER + GRID, "fix layers all layers/hdf5",
          (("1", "count"), ("fuzz.h5", "file"), ("c_conc", "name"), ("fluid", "kw"), ("water", "name"),
           ("particle_density", "kw"), ("2650", "pos")),
          frozenset({3, 5, 7}), STEP + RUN),
]

BAD_NUMBERS = ("nan", "inf", "-inf", "1e400", "abc")


@dataclass(frozen=True)
class Case:
    style: str
    what: str
    deck: str
    valid: bool


def _deck(style: Style, tokens: list[str]) -> str:
    return SCENE + style.before + " ".join([style.head, *tokens]) + "\n" + style.after


# 2d scenes: gravity along -y, spheres in the xy plane.
SCENE_2D = SCENE.replace("dimension 3", "dimension 2").replace("boundary p p f", "boundary p f p") \
    .replace("-0.05 0.05\n", "-0.5e-3 0.5e-3\n").replace("0 0 -0.01", "0 -0.01 0").replace("0.002 0 -0.02", "0.002 -0.02 0") \
    .replace("vector 0 0 -1", "vector 0 -1 0").replace("region pool block INF INF INF INF INF 0", "region pool block INF INF INF 0 INF INF")
CASES_2D = [
    ("fluid", "free surface along z in 2d", "fix f all fluid density 1000 viscosity 1e-3 surface z 0\n"),
    ("nve/sphere/fluid", "floor along z in 2d", "fix step all nve/sphere/fluid floor z 0\n"),
    ("nve/sphere/fluid", "surface along z in 2d", "fix step all nve/sphere/fluid surface z 0\n"),
    ("concentration/grid", "three cell counts in 2d", "compute conc all concentration/grid cells 2 2 4\n"),
    ("concentration/grid", "layers along z in 2d", "compute conc all concentration/grid layers z 4\n" + RUN),
    ("concentration/grid", "six bounds in 2d", "compute conc all concentration/grid cells 2 2 bounds 0 1 0 1 0 1\n"),
    ("fluid/flow", "a flow in 2d", "fix u all fluid/flow f grid 8 8 8\n"),
]


def cases() -> list[Case]:
    out = []
    for style in STYLES:
        words = [t for t, _ in style.tokens]
        for n in range(len(words)):
            out.append(Case(style.name, f"truncated to {n} argument(s)", _deck(style, words[:n]), n in style.complete))
        out.append(Case(style.name, "unknown trailing keyword", _deck(style, words + ["bogus", "1"]), False))
        out.append(Case(style.name, "the valid command", _deck(style, words), True))
        for i, (word, kind) in enumerate(style.tokens):
            def replaced(value: str) -> str:
                return _deck(style, words[:i] + [value] + words[i + 1:])

            if kind in ("kw", "word", "name"):
                out.append(Case(style.name, f"argument {i + 1} '{word}' -> 'bogus'", replaced("bogus"), False))
            if kind == "name" and word.startswith("c_"):
                out.append(Case(style.name, f"argument {i + 1} '{word}' -> 'c_missing'", replaced("c_missing"), False))
            if kind in ("pos", "nonneg", "real", "count"):
                for bad in BAD_NUMBERS:
                    out.append(Case(style.name, f"argument {i + 1} '{word}' -> '{bad}'", replaced(bad), False))
                if kind in ("pos", "count"):
                    out.append(Case(style.name, f"argument {i + 1} '{word}' -> '0'", replaced("0"), False))
                if kind in ("pos", "nonneg", "count"):
                    out.append(Case(style.name, f"argument {i + 1} '{word}' -> '-1'", replaced("-1"), False))
                if kind == "count":
                    out.append(Case(style.name, f"argument {i + 1} '{word}' -> '2.5'", replaced("2.5"), False))
    out += [Case(name, what, SCENE_2D + body, False) for name, what, body in CASES_2D]
    out.append(Case("concentration/grid", "valid 2d cells", SCENE_2D + "compute conc all concentration/grid cells 2 2 "
                    "thickness 1e-3\n" + RUN, True))
    return out
