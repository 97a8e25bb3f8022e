# SPDX-License-Identifier: GPL-2.0-or-later
"""The common face of results (sediment.results) and the public API's documentation."""
import ast
from pathlib import Path

import pytest

from sediment.lab.calibrate import restitution_from_drops
from sediment.results import Table, write_atomic, write_text

PACKAGE = Path(__file__).resolve().parents[2] / "python" / "sediment"


def test_table_text_and_csv():
    table = Table(["name", "value"], notes=["one note"])
    table.add("a, b", 1.0 / 3.0)
    table.add("c", 2, fmt=".3g")
    assert table.csv() == 'name,value\n"a, b",0.333333\nc,2\n'
    lines = table.text().splitlines()
    assert lines == ["name    value", "a, b 0.333333", "   c        2", "one note"]
    with pytest.raises(ValueError, match="a row of 1 cells for 2 columns"):
        table.add("lonely")


def test_an_interrupted_write_keeps_the_previous_file_and_leaves_no_temporary(tmp_path):
    path = write_text(tmp_path / "sub" / "result.csv", "complete\n")

    def fail_half_way(temporary: Path) -> None:
        temporary.write_text("partial")
        raise OSError("No space left on device")

    with pytest.raises(OSError, match="No space left"):
        write_atomic(path, fail_half_way)
    assert path.read_text() == "complete\n"
    assert sorted(p.name for p in path.parent.iterdir()) == ["result.csv"]


def test_written_files_have_the_permissions_of_any_new_file(tmp_path):
    """Not mkstemp's owner-only 0600: others on a shared machine read results as they read any file."""
    import os

    umask = os.umask(0o022)
    os.umask(umask)
    path = write_text(tmp_path / "result.csv", "x\n")
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask


def test_a_result_tabulates_and_saves(tmp_path):
    result = restitution_from_drops([95, 188], [37.0, 72.0])
    assert result.table().notes[0].startswith("coefficient of restitution (drop test): mean 0.62")
    paths = result.save(tmp_path)
    assert paths == [tmp_path / "calibration.csv"]
    assert paths[0].read_text().splitlines()[0] == "test,coefficient of restitution (drop test)"


def _undocumented(path: Path) -> list[str]:
    tree = ast.parse(path.read_text())
    missing = [] if ast.get_docstring(tree) else ["module"]
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and not node.name.startswith("_"):
            if not ast.get_docstring(node):
                missing.append(node.name)
            if isinstance(node, ast.ClassDef):
                missing += [f"{node.name}.{m.name}" for m in node.body if isinstance(m, ast.FunctionDef)
                            and not m.name.startswith("_") and not ast.get_docstring(m)]
    return missing


@pytest.mark.parametrize("path", sorted(PACKAGE.rglob("*.py")), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_every_public_function_and_class_has_a_docstring(path):
    assert _undocumented(path) == []
