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
import sysconfig
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
    """The package installed by the README's own pip command into a venv (returns the venv), from a
    copy of what a checkout holds for it. setuptools must leave build/ (CMake's) alone."""
    source = tmp_path_factory.mktemp("install") / "src"
    source.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy(REPO / name, source / name)
    shutil.copytree(REPO / "core", source / "core")
    shutil.copytree(REPO / "examples", source / "examples")
    # python/sediment/examples stays the link it is in the checkout
    shutil.copytree(REPO / "python", source / "python", symlinks=True,
                    ignore=shutil.ignore_patterns("_core*.so", "__pycache__"))
    command = next(line.strip() for line in (REPO / "README.md").read_text().splitlines()
                   if "pip install" in line and line.strip().startswith("/usr/bin/python3 -m venv"))
    # The command as written; its compiler goes through ccache where installed (the environment's CC,
    # which setuptools honours), so that a fresh clone recompiles nothing an earlier one compiled:
    # the copy's paths are hashed relative to it
    env = dict(os.environ)
    if shutil.which("ccache"):
        env.update(CC=f"ccache {sysconfig.get_config_var('CC')}", CCACHE_BASEDIR=str(source))
    subprocess.run(["bash", "-c", command], check=True, cwd=source, capture_output=True, env=env)
    assert not (source / "build").exists() and (source / "build-pip").is_dir()
    return source / ".venv"


def pytest_configure(config):
    config.addinivalue_line("markers", "xdist_group(name): tests that run in one worker of pytest -n (pytest-xdist)")


@pytest.hookimpl(tryfirst=True)    # before xdist's own, which reads the groups
def pytest_collection_modifyitems(config, items):
    """Under pytest -n N --dist loadgroup (make test-python), the tests of the installed package run in
    one worker, so that the venv is installed once, not once per worker."""
    for item in items:
        if "installed" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.xdist_group("installed"))
