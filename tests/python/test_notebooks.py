# SPDX-License-Identifier: GPL-2.0-or-later
"""Every notebook in notebooks/ executes headless by the README's command, with the package installed
by the README's pip command, from a folder outside the checkout: the notebook imports the installed
sediment and finds its data through the package."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import nbformat
import pytest

REPO = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((REPO / "notebooks").glob("*.ipynb"))


def readme_command() -> str:
    """The README's command that runs the notebook."""
    return next(line.strip() for line in (REPO / "README.md").read_text().splitlines()
                if "nbconvert" in line and line.strip().startswith(".venv/bin/python"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_from_outside_the_checkout(path, installed, tmp_path):
    # The README's command run in a folder that holds the notebook and nothing else (no examples/,
    # no python/); the venv's kernel (registered by the command) runs the installed package.
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "notebooks").mkdir(parents=True)
    shutil.copy(path, elsewhere / "notebooks" / path.name)
    command = readme_command().replace(".venv/", f"{installed}/").replace("$PWD/build/", f"{REPO}/build/")
    command = command.replace("notebooks/sedimentation_test.ipynb", f"notebooks/{path.name}")
    assert str(REPO) in command and str(installed) in command
    env = dict(os.environ, PYTHONPATH="")
    env.pop("SEDIMENT_NOTEBOOK_OUT", None)
    done = subprocess.run(["bash", "-c", command], cwd=elsewhere, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr[-3000:]
    out = elsewhere / "out" / "notebook"
    notebook = nbformat.read(out / path.name, as_version=4)
    outputs = [o for cell in notebook.cells for o in cell.get("outputs", [])]
    assert outputs and not [o for o in outputs if o.get("output_type") == "error"]
    assert not [p for p in elsewhere.rglob("*") if p.is_dir() and p.name == "examples"]
    if path.stem == "sedimentation_test":    # it says which package it imported, and wrote where asked
        assert f"from {installed}" in "".join(o.get("text", "") for o in outputs)
        assert (out / "layers.h5").is_file() and (out / "soil" / "texture.png").is_file()


def test_the_installed_package_carries_the_notebooks_data(installed, tmp_path):
    """The example data the notebook reads, as package data: real files in site-packages, the same
    bytes as the checkout's examples/."""
    code = "from importlib.resources import files; print(files('sediment') / 'examples')"
    where = Path(subprocess.run([installed / "bin" / "python", "-c", code], capture_output=True, text=True,
                                check=True, cwd=tmp_path, env=dict(os.environ, PYTHONPATH="")).stdout.strip())
    assert where.is_dir() and not where.is_symlink() and str(where).startswith(str(installed))
    for name in ("granulometry/psd/sample5.csv", "inverse/hydrometer.csv", "inverse/soil/sieve.csv"):
        assert (where / name).read_bytes() == (REPO / "examples" / name).read_bytes()


def test_there_is_a_notebook():
    assert NOTEBOOKS    # an empty glob would leave the test above with nothing to run
