# SPDX-License-Identifier: GPL-2.0-or-later
"""The one reader of every CSV a user gives (PSD tables, laboratory sheets, sieve sheets, temperature
records, the spheres of `sediment spheres`): what a spreadsheet's export may hold is read where it is
unambiguous (a UTF-8 or UTF-16 byte-order mark, a trailing empty column, CRLF line ends) and refused
otherwise with one line naming the file, the line and what is wrong (docs/inputs.md)."""
from __future__ import annotations

import codecs
import csv
import math
import unicodedata
from dataclasses import dataclass, field
from pathlib import Path


class CsvError(ValueError):
    """A CSV that cannot be read as a table, with the file, the line and the reason."""


@dataclass(frozen=True)
class CsvFile:
    """A CSV's header and rows; each row keeps the line of the file it was on (blank lines and
    # comments left out, the comments kept apart)."""

    path: Path
    header: list[str]
    rows: list[tuple[int, list[str]]]
    comments: list[str] = field(default_factory=list)

    def where(self, line: int) -> str:
        """The file and line, as messages begin."""
        return f"{self.path}, line {line}"

    def numbers(self, name: str, blank: bool = False) -> list[float]:
        """A column's values as finite numbers (NaN for a blank cell where `blank` allows one)."""
        k = self.header.index(name)
        return [math.nan if blank and not row[k].strip() else number(row[k].strip(), name, self.where(line))
                for line, row in self.rows]


def number(text: str, name: str, where: str) -> float:
    """A cell as a finite number, or the reason it is none (a decimal comma, an invisible character)."""
    try:
        value = float(text)
    except ValueError:
        hint = ""
        if "," in text and _is_number(text.replace(",", ".")):
            hint = f": a decimal comma? write {text.replace(',', '.')} (and no thousands separator)"
        elif _invisible(text):
            hint = f": it holds {_invisible(text)}"
        raise CsvError(f"{where}: {name} '{text}' is not a number{hint}") from None
    if not math.isfinite(value):
        raise CsvError(f"{where}: {name} is {text}, not a finite number")
    return value


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_csv(path: str | Path, what: str = "CSV") -> CsvFile:
    """Reads a CSV file given by a user (`what` names it in messages: "PSD file", "sheet")."""
    path = Path(path)
    if path.is_dir():
        raise CsvError(f"{path} is a folder, not a {what}")
    if not path.is_file():
        raise CsvError(f"{path}: no such file (the {what} named)")
    text = _decode(path, path.read_bytes(), what)
    if "\x00" in text:    # csv cannot read past one, and no table holds one
        raise CsvError(f"{path}, line {text[:text.index(chr(0))].count(chr(10)) + 1}: a NUL character: not a text "
                       f"{what}; save it as CSV UTF-8")
    lines = text.splitlines()
    comments, kept = [], []
    for number_, line in enumerate(lines, start=1):
        if line.lstrip().startswith("#"):
            comments.append(line)
        elif line.strip():
            kept.append((number_, line))
    if not kept:
        raise CsvError(f"{path}: empty {what} (no header, no rows)")
    parsed = [(n, next(csv.reader([line], skipinitialspace=True))) for n, line in kept]    # "a, b": the space is no part of b
    header_line, header = parsed[0]
    _check_delimiter(path, header_line, header)
    # a spreadsheet's trailing empty column: no name in the header and nothing in any row
    while len(header) > 1 and not header[-1].strip() and all(len(r) < len(header) or not r[len(header) - 1].strip()
                                                              for _, r in parsed[1:]):
        header = header[:-1]
    header = [h.strip() for h in header]
    _check_header(path, header_line, header)
    rows = []
    for n, row in parsed[1:]:
        if not any(cell.strip() for cell in row):    # a spreadsheet's empty row (",,,"): a blank line
            continue
        if [cell.strip() for cell in row] == header:
            raise CsvError(f"{path}, line {n}: the header again (two tables in one file?): give one table per file")
        # empty cells past the header's last column (a row saved with trailing commas) say nothing
        while len(row) > len(header) and not row[-1].strip():
            row = row[:-1]
        if len(row) != len(header):
            raise CsvError(f"{path}, line {n}: {len(row)} values where the header has {len(header)} columns "
                           f"({','.join(header)})" + _split_number_hint(row, len(header)))
        rows.append((n, row))
    return CsvFile(path, header, rows, comments)


def _decode(path: Path, data: bytes, what: str) -> str:
    """The file's text: UTF-8 (with or without Excel's byte-order mark) or UTF-16 with its mark."""
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            raise CsvError(f"{path}: marked UTF-16 but not UTF-16 text: save it as CSV UTF-8") from None
    if b"\x00" in data[:4096]:
        raise CsvError(f"{path}: not a text {what} (NUL bytes: a binary file, or UTF-16 without its byte-order mark): "
                       "save it as CSV UTF-8")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        byte = data[exc.start]
        guess = (f"'{bytes([byte]).decode('latin-1')}' in Latin-1/Windows-1252" if 0xa0 <= byte else "")
        raise CsvError(f"{path}, line {line}: byte 0x{byte:02x} is not UTF-8 text" + (f" ({guess})" if guess else "")
                       + f": not a text {what} in UTF-8; save it as CSV UTF-8") from None


def _check_delimiter(path: Path, line: int, header: list[str]) -> None:
    """A header of one column holding ';' or tabs is another delimiter's export."""
    if len(header) != 1:
        return
    for mark, name in ((";", "';'"), ("\t", "tabs")):
        if mark in header[0]:
            raise CsvError(f"{path}, line {line}: the columns are separated by {name} (a spreadsheet's export with "
                           "decimal commas?): save it as CSV with ',' between columns and '.' as the decimal point")


def _check_header(path: Path, line: int, header: list[str]) -> None:
    """Column names must be visible, named and distinct: a misspelt or repeated one would be read wrong."""
    for k, name in enumerate(header, start=1):
        if not name:
            raise CsvError(f"{path}, line {line}: column {k} has no name (header: {','.join(header)})")
        hidden = _invisible(name)
        if hidden:
            raise CsvError(f"{path}, line {line}: column name {name!r} holds {hidden}: retype the header")
    seen: dict[str, int] = {}
    for k, name in enumerate(header, start=1):
        if name in seen:
            raise CsvError(f"{path}, line {line}: column {name} appears twice (columns {seen[name]} and {k}): which "
                           "one holds the values is not clear; keep one")
        seen[name] = k


def _invisible(text: str) -> str:
    """The first character of a text one cannot see or tell from a plain one (zero-width, no-break space,
    a byte-order mark, a control character), named; '' where there is none."""
    for char in text:
        if char != " " and unicodedata.category(char) in ("Cf", "Cc", "Zs", "Zl", "Zp", "Co", "Cn"):
            return f"an invisible character, U+{ord(char):04X} {unicodedata.name(char, 'control')}"
    return ""


def _split_number_hint(row: list[str], width: int) -> str:
    """Why a row may have more values than the header: a decimal comma splits a number in two."""
    if len(row) > width and any(cell.strip().isdigit() for cell in row[1:]):
        return ": a decimal comma (0,075) splits a number in two; write 0.075"
    return ""

