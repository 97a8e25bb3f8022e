# SPDX-License-Identifier: GPL-2.0-or-later
"""`pip install .` in a virtual environment: the package, its console script and a `_core` that
links no LAMMPS (Debian's build backend; no network, so no build isolation)."""
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_pip_install_gives_the_package_and_the_command(tmp_path):
    source = tmp_path / "src"
    source.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy(REPO / name, source / name)
    shutil.copytree(REPO / "core", source / "core")
    shutil.copytree(REPO / "python", source / "python", ignore=shutil.ignore_patterns("_core*.so", "__pycache__"))
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    subprocess.run([venv / "bin" / "pip", "install", "--no-build-isolation", "--no-deps", "-q", str(source)],
                   check=True, cwd=tmp_path)
    out = subprocess.run([venv / "bin" / "sediment", "terminal", "--diameter", "1e-4", "--particle-density", "2700",
                          "--fluid-density", "1000", "--viscosity", "1e-3"], capture_output=True, text=True,
                         check=True, cwd=tmp_path).stdout
    assert "terminal velocity: 0.009265 m/s (moving)" in out
    where = subprocess.run([venv / "bin" / "python", "-c", "import sediment._core as c; print(c.__file__)"],
                           capture_output=True, text=True, check=True, cwd=tmp_path).stdout.strip()
    assert where.startswith(str(venv))
    linked = subprocess.run(["ldd", where], capture_output=True, text=True, check=True).stdout
    assert "lammps" not in linked and "sediment_lammps" not in linked
