# SPDX-License-Identifier: GPL-2.0-or-later
"""Builds the extension sediment._core from the physics core (pyproject.toml has the rest)."""
from glob import glob

from pybind11.setup_helpers import Pybind11Extension
from setuptools import setup

core = Pybind11Extension(
    "sediment._core",
    sorted(["python/src/core_module.cpp", *glob("core/src/*.cpp")]),
    include_dirs=["core/include"],
    cxx_std=17,
)

setup(ext_modules=[core])
