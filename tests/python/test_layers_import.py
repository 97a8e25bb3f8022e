# SPDX-License-Identifier: GPL-2.0-or-later
"""scripts/check-imports.py (run by make test): the package's imports point one way, and the check
refuses an import back up or round a cycle, one hidden inside a function too."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "check-imports.py"


def check(package: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), str(package)], capture_output=True, text=True)


def copy(tmp_path: Path) -> Path:
    package = tmp_path / "sediment"
    shutil.copytree(ROOT / "python" / "sediment", package, symlinks=True,
                    ignore=shutil.ignore_patterns("__pycache__", "*.so", "examples"))
    return package


def test_the_package_imports_point_one_way():
    done = check(ROOT / "python" / "sediment")
    assert done.returncode == 0, done.stdout + done.stderr


def test_an_import_back_up_inside_a_function_is_refused(tmp_path):
    package = copy(tmp_path)
    with open(package / "lab" / "psd.py", "a") as f:
        f.write("\n\ndef _planted():\n    from ..inverse.model import LabTest\n    return LabTest\n")
    done = check(package)
    assert done.returncode == 1
    assert "sediment.lab.psd (lab) imports sediment.inverse.model (inverse), a layer above it" in done.stdout


def test_a_cycle_within_a_layer_is_refused(tmp_path):
    package = copy(tmp_path)
    with open(package / "lab" / "readout.py", "a") as f:
        f.write("\n\ndef _planted():\n    from .sheet import Sheet\n    return Sheet\n")
    done = check(package)
    assert done.returncode == 1
    assert "import cycle: sediment.lab." in done.stdout and "sediment.lab.readout" in done.stdout
