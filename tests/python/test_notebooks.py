# SPDX-License-Identifier: GPL-2.0-or-later
"""Every notebook in notebooks/ executes headless, in Jupyter with the package installed by the
README's pip command (a kernel of that venv; the notebook then imports the installed sediment)."""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import nbformat
import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path, installed, tmp_path):
    # nbclient in the venv's Python finds the venv's kernel; the checkout is not on its path
    runner = ("import sys, nbformat; from nbclient import NotebookClient; nb = nbformat.read(sys.argv[1], 4); "
              "NotebookClient(nb, timeout=300, kernel_name='sediment-venv', resources={'metadata': {'path': sys.argv[2]}})"
              ".execute(); nbformat.write(nb, sys.argv[3])")
    env = dict(os.environ, SEDIMENT_NOTEBOOK_OUT=str(tmp_path), PYTHONPATH="")
    done = subprocess.run([installed / "bin" / "python", "-c", runner, path, path.parent, tmp_path / "run.ipynb"],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    notebook = nbformat.read(tmp_path / "run.ipynb", as_version=4)
    outputs = [o for cell in notebook.cells for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    if path.stem == "sedimentation_test":    # it says which package it imported
        assert f"from {installed}" in "".join(o.get("text", "") for o in outputs)


def test_there_is_a_notebook():
    assert NOTEBOOKS    # an empty glob would leave the test above with nothing to run
