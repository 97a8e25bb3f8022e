# SPDX-License-Identifier: GPL-2.0-or-later
"""What a clone carries: a licence line on every source file, and the notes the code cites."""
import re
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SOURCE = re.compile(r"(\.(cpp|h|hpp|py|sh|lmp|cmake)|CMakeLists\.txt|Makefile|/in\.[a-z_]+|^bin/\w+|^\.ci/run)$")


def _tracked() -> list[str]:
    files = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True, check=True).stdout.split()
    return [f for f in files if SOURCE.search(f) and (REPO / f).is_file()]


def test_every_source_file_names_its_licence():
    files = _tracked()
    assert len(files) > 100
    missing = [f for f in files if "SPDX-License-Identifier: GPL-2.0-or-later" not in
               "".join((REPO / f).read_text().splitlines(keepends=True)[:3])]
    assert missing == []
    assert "GNU GENERAL PUBLIC LICENSE" in (REPO / "LICENSE").read_text()


def test_the_notes_the_code_cites_are_in_the_repository():
    cited = set()
    for f in _tracked():
        cited |= set(re.findall(r"docs/[\w-]+\.md", (REPO / f).read_text()))
    assert {"docs/physics.md", "docs/sedimentation-tests.md"} <= cited
    assert [c for c in sorted(cited) if not (REPO / c).is_file()] == []
    outside = ("../" + "shared", "shared/" + "spec", "shared/" + "data")    # spelled apart: not a hit here
    assert [f for f in _tracked() if any(word in (REPO / f).read_text() for word in outside)] == []


def test_the_version_is_stated_once():
    """core/include/sediment/version.hpp states the release; the build, the package, the layer files' writer
    and the documentation read it from there, and no other file types it in (CITATION.cff, which GitHub
    reads as written, is checked against it)."""
    from sediment import _core
    import sediment

    header = (REPO / "core" / "include" / "sediment" / "version.hpp").read_text()
    release = re.search(r'version = "([0-9.]+)"', header).group(1)
    assert _core.VERSION == sediment.__version__ == release
    assert re.search(r"^version: (\S+)$", (REPO / "CITATION.cff").read_text(), re.MULTILINE).group(1) == release
    assert 'dynamic = ["version"]' in (REPO / "pyproject.toml").read_text()
    typed = re.compile(r'(?<![\w.])' + re.escape(release) + r'(?![\w.])')
    readers = ("CMakeLists.txt", "setup.py", "pyproject.toml", "docs/site/conf.py", "python/sediment/constants.py",
               "python/sediment/cli/__init__.py", "lammps-pkg/SEDIMENT/fix_layers_hdf5.cpp")
    assert [f for f in readers if typed.search((REPO / f).read_text())] == []
    assert "sediment::version" in (REPO / "lammps-pkg" / "SEDIMENT" / "fix_layers_hdf5.cpp").read_text()