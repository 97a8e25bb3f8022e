# SPDX-License-Identifier: GPL-2.0-or-later
"""The one face every result shows: ``result.table()`` gives a `Table` (``.text()`` for a terminal,
``.csv()`` for a file) and ``result.save(folder)`` writes its tables and figures and returns their
paths. Files are written under a temporary name and renamed when complete, so an interrupted save
leaves the previous file or none, never a partial one.
"""
from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Protocol, Sequence


@dataclass
class Table:
    """Columns of already formatted cells, with notes printed under the text form.

    Parameters
    ----------
    columns : sequence of str
        Column names (used as the CSV header).
    rows : list of sequences of str
        One sequence of cells per row, as many as columns.
    notes : list of str
        Lines printed after the table in `text` (summaries, units); not part of the CSV.
    """

    columns: Sequence[str]
    rows: list[Sequence[str]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, *cells: object, fmt: str = ".6g") -> None:
        """Appends a row; numbers are formatted with `fmt`, anything else with str()."""
        if len(cells) != len(self.columns):
            raise ValueError(f"a row of {len(cells)} cells for {len(self.columns)} columns")
        self.rows.append([format(c, fmt) if isinstance(c, float) else str(c) for c in cells])

    def text(self) -> str:
        """Right-aligned columns and the notes, for a terminal."""
        widths = [max([len(c)] + [len(r[k]) for r in self.rows]) for k, c in enumerate(self.columns)]
        lines = [" ".join(c.rjust(w) for c, w in zip(self.columns, widths))]
        lines += [" ".join(cell.rjust(w) for cell, w in zip(row, widths)) for row in self.rows]
        return "\n".join(lines + list(self.notes)) + "\n"

    def csv(self) -> str:
        """The header and the rows as CSV (cells containing commas are quoted)."""
        def cell(text: str) -> str:
            return f'"{text}"' if "," in text or '"' in text else text
        return "\n".join(",".join(cell(c) for c in row) for row in [list(self.columns), *self.rows]) + "\n"


_UMASK = os.umask(0o022)    # read once (umask can only be read by setting it), then restored
os.umask(_UMASK)


class Result(Protocol):
    """What every study and readout returns."""

    def table(self) -> Table:
        """The result as a table of formatted cells."""

    def save(self, folder: Path) -> list[Path]:
        """Writes the result's files into `folder`; returns their paths."""


def write_atomic(path: Path, write: Callable[[Path], None]) -> Path:
    """Calls ``write(temporary_path)`` and renames the file to `path` once it is complete.

    The temporary file sits in the same folder (a rename within one file system is atomic) and is
    removed if `write` fails; the folder is created if needed.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(handle)
    try:
        write(Path(temporary))
        os.chmod(temporary, 0o666 & ~_UMASK)    # as open() would create it, not mkstemp's owner-only 0600
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def write_text(path: Path, text: str) -> Path:
    """Writes `text` to `path` atomically (see `write_atomic`)."""
    return write_atomic(path, lambda tmp: tmp.write_text(text))
