# SPDX-License-Identifier: GPL-2.0-or-later
"""Builds the extension sediment._core from the physics core (pyproject.toml has the rest).

setuptools works in build-pip/, not in build/: build/ is CMake's (make build), and pip install .
must not write into it."""
import re
from glob import glob
from pathlib import Path

from pybind11.setup_helpers import ParallelCompile, Pybind11Extension
from setuptools import setup

# The core's files compiled side by side, on every core (SEDIMENT_BUILD_JOBS=N to limit them).
ParallelCompile("SEDIMENT_BUILD_JOBS").install()

core = Pybind11Extension(
    "sediment._core",
    sorted(["python/src/core_module.cpp", *glob("core/src/*.cpp")]),
    include_dirs=["core/include"],
    cxx_std=17,
)

# The release, from the one place that states it (pyproject.toml lists the version as dynamic)
release = re.search(r'version = "([0-9.]+)"', Path("core/include/sediment/version.hpp").read_text()).group(1)
setup(version=release, ext_modules=[core], options={"build": {"build_base": "build-pip"}})
