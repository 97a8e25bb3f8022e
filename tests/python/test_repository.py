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


def test_the_version_is_one():
    """sediment.constants.VERSION is the release; every other file that states it agrees."""
    from sediment.constants import VERSION

    stated = {"pyproject.toml": r'^version = "([^"]+)"', "CITATION.cff": r"^version: (\S+)",
              "CMakeLists.txt": r"project\(sediment VERSION (\S+)"}
    for name, pattern in stated.items():
        found = re.search(pattern, (REPO / name).read_text(), re.MULTILINE)
        assert found and found.group(1) == VERSION, f"{name} states {found and found.group(1)}, not {VERSION}"
    # the version the layer files record (fix layers/hdf5), wherever the package defines it
    written = [m.group(1) for f in sorted((REPO / "lammps-pkg" / "SEDIMENT").glob("*.[ch]*"))
               for m in re.finditer(r'SEDIMENT_VERSION\s*=\s*"([^"]+)"', f.read_text())]
    assert written and set(written) == {VERSION}, f"the layer files' writer states {written}, not {VERSION}"
