# SPDX-License-Identifier: GPL-2.0-or-later
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "python"))
os.environ.setdefault("SEDIMENT_LMP", str(REPO / "build" / "lmp_sediment"))

import importlib.util
import shutil
import subprocess
from types import ModuleType

import pytest


def benchmark_script(name: str) -> ModuleType:
    """benchmarks/NAME.py loaded as a module (the scripts are not a package), for their tests."""
    spec = importlib.util.spec_from_file_location(name, REPO / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def installed(tmp_path_factory) -> Path:
    """The package installed by the README's own pip command into a venv (returns the venv), with a
    Jupyter kernel of its own, 'sediment-venv', as a user would add one."""
    source = tmp_path_factory.mktemp("install") / "src"
    source.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy(REPO / name, source / name)
    shutil.copytree(REPO / "core", source / "core")
    shutil.copytree(REPO / "python", source / "python", ignore=shutil.ignore_patterns("_core*.so", "__pycache__"))
    command = next(line.strip() for line in (REPO / "README.md").read_text().splitlines()
                   if "pip install" in line and line.strip().startswith("/usr/bin/python3 -m venv"))
    subprocess.run(["bash", "-c", command], check=True, cwd=source, capture_output=True)
    venv = source / ".venv"
    subprocess.run([venv / "bin" / "python", "-m", "ipykernel", "install", "--prefix", venv, "--name", "sediment-venv"],
                   check=True, capture_output=True)
    return venv
