#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Lists the SEDIMENT styles in a LAMMPS tree's command tables (doc/src/Commands_*.rst, fix.rst,
compute.rst, pair_style.rst), in alphabetical place, so that doc/utils/check-styles.py finds them:
    lammps-pkg/doc-tables.py LAMMPS/doc/src
The styles and their one-line descriptions are read from lammps-pkg/SEDIMENT/sediment_styles.cpp,
the doc page of each from its name (fix_fluid_drag.rst for fix fluid/drag). Idempotent."""
from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
KINDS = {"fix": ("Commands_fix.rst", "fix.rst"), "compute": ("Commands_compute.rst", "compute.rst"),
         "pair": ("Commands_pair.rst", "pair_style.rst")}
ENTRY = re.compile(r"^(\s*\*\s*):doc:`([^ <`]+)[^<]*<(\w+)>`")


def styles() -> list[tuple[str, str, str, str]]:
    """(kind, name, doc page, description) of every style registered in sediment_styles.cpp."""
    source = (HERE / "SEDIMENT" / "sediment_styles.cpp").read_text()
    found = []
    for kind in KINDS:
        block = re.search(rf"{kind}_styles\[\] = \{{(.*?)\n\}};", source, re.S)
        if block is None:
            sys.exit(f"doc-tables.py: no {kind}_styles table in sediment_styles.cpp")
        for name, info in re.findall(r'\{"([^"]+)", "([^"]+)"', block.group(1)):
            page = f"{kind}_{name.replace('/', '_').replace('-', '_')}"
            if not (HERE / "SEDIMENT" / "doc" / f"{page}.rst").is_file():
                sys.exit(f"doc-tables.py: {kind} {name} has no doc page {page}.rst")
            found.append((kind, name, page, info))
    return found


def insert(path: Path, name: str, page: str, suffix: str) -> None:
    """Adds ':doc:`name <page>`' + suffix to the alphabetical list of `path`, unless it is there."""
    lines = path.read_text().splitlines(keepends=True)
    if any(f":doc:`{name} <{page}>`" in line for line in lines):
        return
    entries = [(k, m) for k, m in ((k, ENTRY.match(line)) for k, line in enumerate(lines)) if m]
    if not entries:
        sys.exit(f"doc-tables.py: {path} has no :doc: list")
    # The list the style belongs to: the longest run of consecutive entries (the tables also hold
    # short lists of general commands before the styles).
    runs: list[list] = []
    for k, m in entries:
        if runs and runs[-1][-1][0] == k - 1:
            runs[-1].append((k, m))
        else:
            runs.append([(k, m)])
    run = max(runs, key=len)
    after = next((k for k, m in run if m.group(2) > name), run[-1][0] + 1)
    indent = run[0][1].group(1)
    lines.insert(after, f"{indent}:doc:`{name} <{page}>`{suffix}\n")
    path.write_text("".join(lines))


def main() -> None:
    if len(sys.argv) != 2 or not Path(sys.argv[1]).is_dir():
        sys.exit("usage: doc-tables.py LAMMPS/doc/src")
    doc = Path(sys.argv[1])
    for kind, name, page, info in styles():
        table, listing = KINDS[kind]
        insert(doc / table, name, page, "")
        insert(doc / listing, name, page, f" - {info}")


if __name__ == "__main__":
    main()
