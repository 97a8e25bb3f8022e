#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The style table of the driver and the plugin (lammps-pkg/SEDIMENT/sediment_styles.cpp) against the
style headers: every FixStyle, ComputeStyle and PairStyle line of a header has its entry in the table,
under the same name and class, and its header included; the table has no entry that no header
declares. An in-tree build registers the styles from the headers alone, the driver and the plugin
from the table, so a style added to one and not the other would exist on one route only.
    tests/decks/style_table.py [PACKAGE_DIR]    (ctest: styles.table; default: lammps-pkg/SEDIMENT)
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "lammps-pkg" / "SEDIMENT"
DECLARED = re.compile(r"^\s*(Fix|Compute|Pair)Style\(\s*([^,\s]+)\s*,\s*(\w+)\s*\)", re.MULTILINE)
TABLE = re.compile(r"StyleEntry<\w+::(Fix|Compute|Pair)Creator>\s+\w+\[\]\s*=\s*\{(.*?)\n\};", re.DOTALL)
ENTRY = re.compile(r'\{\s*"([^"]+)"\s*,\s*"[^"]*"\s*,\s*&create(?:_pair)?<(?:\w+\s*,\s*)?(\w+)>\s*\}')
INCLUDE = re.compile(r'^#include "([^"]+\.h)"', re.MULTILINE)


def declared_styles(package: Path = PACKAGE) -> dict[tuple[str, str, str], str]:
    """(kind, name, class) of every style a header of the package declares -> the header's name; kind
    is Fix, Compute or Pair."""
    return {style: header.name for header in sorted(package.glob("*.h"))
            for style in DECLARED.findall(header.read_text())}


def main() -> int:
    package = Path(sys.argv[1]) if len(sys.argv) > 1 else PACKAGE
    headers = declared_styles(package)
    declared = set(headers)
    source = (package / "sediment_styles.cpp").read_text()
    listed = {(kind, name, cls) for kind, body in TABLE.findall(source) for name, cls in ENTRY.findall(body)}
    included = set(INCLUDE.findall(source))
    problems = []
    for kind, name, cls in sorted(declared - listed):
        problems.append(f"{headers[(kind, name, cls)]} declares {kind.lower()} style {name} ({cls}), which "
                        f"sediment_styles.cpp's {kind.lower()}_styles table lacks")
    for kind, name, cls in sorted(listed - declared):
        problems.append(f"sediment_styles.cpp's {kind.lower()}_styles lists {name} ({cls}), which no header's "
                        f"{kind}Style line declares")
    for style in sorted(declared):
        if headers[style] not in included:
            problems.append(f"sediment_styles.cpp does not include {headers[style]}")
    if not declared:
        problems.append(f"no style headers in {package}")
    for problem in problems:
        print("FAIL", problem)
    if problems:
        return 1
    print(f"PASS style_table: {len(declared)} styles, each in the headers and the table alike")
    return 0


if __name__ == "__main__":
    sys.exit(main())
