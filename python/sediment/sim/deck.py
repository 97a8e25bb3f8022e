# SPDX-License-Identifier: GPL-2.0-or-later
"""What a LAMMPS deck declares, read from its text: the files it includes, its index variables."""
from __future__ import annotations

import re
from pathlib import Path


def deck_text(deck: Path, depth: int = 0) -> str:
    """A deck's text with the files it includes (by a literal name, from its folder) in place."""
    if depth > 8:
        raise ValueError(f"{deck}: includes nest more than 8 deep")
    lines = []
    for line in Path(deck).read_text().splitlines():
        words = line.split()
        if len(words) >= 2 and words[0] == "include" and "$" not in words[1]:
            included = Path(deck).parent / words[1]
            if included.is_file():
                lines.append(deck_text(included, depth + 1))
                continue
        lines.append(line)
    return "\n".join(lines)


def index_variables(deck: Path) -> dict[str, str]:
    """The deck's `variable NAME index VALUE` lines (those a run can set with -var), includes too: each
    name with the value it has when not set (the first line of a name wins, as in LAMMPS)."""
    found: dict[str, str] = {}
    for name, value in re.findall(r"^\s*variable\s+(\w+)\s+index\s+(\S+)", deck_text(deck), re.MULTILINE):
        found.setdefault(name, value)
    return found


def unread_variables(deck: Path, names: list[str]) -> list[str]:
    """Those of `names` that `deck` (with the files it includes) never declares or reads: LAMMPS would
    ignore them without a word. None is judged where the deck includes a file named by a variable."""
    try:
        text = deck_text(deck)
    except (OSError, UnicodeDecodeError, ValueError):
        return []    # run_deck names what is wrong with the deck
    if re.search(r"^\s*include\s+\S*\$", text, re.MULTILINE):
        return []
    return [name for name in names
            if not re.search(rf"^\s*variable\s+{re.escape(name)}\s|\$\{{{re.escape(name)}\}}|\bv_{re.escape(name)}\b"
                             + (rf"|\${re.escape(name)}" if len(name) == 1 else ""), text, re.MULTILINE)]


def refuse_unread(deck: Path, names: list[str], option: str = "--var") -> None:
    """Stops, naming the first of `names` (given by `option`) that `deck` never reads (unread_variables)."""
    unread = unread_variables(deck, names)
    if unread:
        raise ValueError(f"{option} {unread[0]}: {deck} never reads a variable '{unread[0]}', so LAMMPS would run it "
                         "as if not given")
