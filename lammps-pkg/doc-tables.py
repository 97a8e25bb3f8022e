#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Lists the SEDIMENT styles in a LAMMPS tree's command tables (doc/src/Commands_*.rst, fix.rst,
compute.rst, pair_style.rst) and the package in its package lists (Packages.rst or
Packages_list.rst, Packages_details.rst), in alphabetical place, so that doc/utils/check-styles.py
and check-packages.py find them; --check only checks that every place exists:
    lammps-pkg/doc-tables.py [--check] LAMMPS/doc/src
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


class Missing(Exception):
    """A LAMMPS doc file lacks what SEDIMENT's entry is placed by."""


def insert(text: str, path: Path, name: str, page: str, suffix: str) -> str:
    """`text` with ':doc:`name <page>`' + suffix in its alphabetical list, unless it is there."""
    lines = text.splitlines(keepends=True)
    if any(f":doc:`{name} <{page}>`" in line for line in lines):
        return text
    entries = [(k, m) for k, m in ((k, ENTRY.match(line)) for k, line in enumerate(lines)) if m]
    if not entries:
        raise Missing(f"{path} has no :doc: list")
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
    return "".join(lines)


# The package's entries in the package lists that LAMMPS's doc/utils/check-packages.py reads: a row of
# the table in Packages.rst (Packages_list.rst before 2023), a line of the list in Packages_details.rst
# and its section there, each in alphabetical place.
PACKAGE = "SEDIMENT"
ROW = f"""   * - :ref:`{PACKAGE} <PKG-{PACKAGE}>`
     - fluid forces for settling spheres
     - :doc:`fix fluid <fix_fluid>`
     - ``PACKAGES/sediment``
     - sys
"""
SECTION = f""".. _PKG-{PACKAGE}:

{PACKAGE} package
{"-" * (len(PACKAGE) + 8)}

**Contents:**

Fluid forces for finite-size spheres settling in a fluid, without CFD coupling: buoyancy with partial
submergence at a free surface, Newtonian and Bingham-plastic drag laws with hindered settling,
squeeze-film lubrication, a drag-implicit sphere integrator, a concentration grid and its layer
profiles written to HDF5.

**Install:**

Needs the HDF5 library, which CMake finds on the system.

**Supporting info:**

* ``src/{PACKAGE}``: filenames -> commands
* :doc:`fix fluid <fix_fluid>`
* :doc:`fix fluid/drag <fix_fluid_drag>`
* :doc:`fix nve/sphere/fluid <fix_nve_sphere_fluid>`
* :doc:`compute concentration/grid <compute_concentration_grid>`
* ``examples/PACKAGES/sediment``

----------

"""


def before_first_after(text: str, path: Path, pattern: str, entry: str) -> str:
    """`text` with `entry` inserted before the first line matching `pattern` (whose group 1 is a
    package name) that sorts after SEDIMENT, unless `entry`'s first line is there."""
    if entry.splitlines()[0] in text.splitlines():
        return text
    lines = text.splitlines(keepends=True)
    names = [(k, m.group(1)) for k, m in ((k, re.match(pattern, line)) for k, line in enumerate(lines)) if m]
    if not names:
        raise Missing(f"{path} has no entry like {pattern!r}")
    after = next((k for k, name in names if name > PACKAGE), None)
    if after is None:
        raise Missing(f"{path}: no package after {PACKAGE} to place it before")
    lines.insert(after, entry)
    return "".join(lines)


def package_lists(doc: Path) -> dict[Path, str]:
    """The package lists' new texts."""
    listing = next((doc / n for n in ("Packages.rst", "Packages_list.rst")
                    if (doc / n).is_file() and ":ref:`GRANULAR <PKG-GRANULAR>`" in (doc / n).read_text()), None)
    if listing is None:
        raise Missing(f"{doc} has no package table (Packages.rst or Packages_list.rst)")
    details = doc / "Packages_details.rst"
    if not details.is_file():
        raise Missing(f"{details} does not exist")
    text = details.read_text()
    text = before_first_after(text, details, r"^   \* :ref:`([A-Z0-9-]+) <PKG-", f"   * :ref:`{PACKAGE} <PKG-{PACKAGE}>`\n")
    text = before_first_after(text, details, r"^\.\. _PKG-([A-Z0-9-]+):", SECTION)
    return {listing: before_first_after(listing.read_text(), listing, r"^   \* - :ref:`([A-Z0-9-]+) <PKG-", ROW),
            details: text}


def main() -> None:
    check = "--check" in sys.argv[1:]
    folders = [a for a in sys.argv[1:] if a != "--check"]
    if len(folders) != 1 or not Path(folders[0]).is_dir():
        sys.exit("usage: doc-tables.py [--check] LAMMPS/doc/src")
    doc = Path(folders[0])
    # Every new text is made before any file is written: a tree whose docs lack an anchor is left as it was.
    try:
        texts = package_lists(doc)
        for kind, name, page, info in styles():
            for table, suffix in zip(KINDS[kind], ("", f" - {info}")):
                path = doc / table
                if not path.is_file():
                    raise Missing(f"{path} does not exist")
                texts[path] = insert(texts.get(path, path.read_text()), path, name, page, suffix)
    except Missing as exc:
        sys.exit(f"doc-tables.py: {exc}")
    if not check:
        for path, text in texts.items():
            if path.read_text() != text:
                path.write_text(text)


if __name__ == "__main__":
    main()
