# SPDX-License-Identifier: GPL-2.0-or-later
"""SEDIMENT: fluid forces for DEM spheres in LAMMPS, and the readouts of sedimentation tests.

The physics lives in one C++ core (sediment._core), shared with the LAMMPS styles. The package is
grouped by role: `sediment.lab` (PSDs, instruments, readouts, calibrations), `sediment.sim` (running
LAMMPS, scenes, layer files), `sediment.studies` (validation and accuracy studies) and
`sediment.cli` (the `sediment` command); `sediment.constants` and `sediment.results` serve them all.
"""
from __future__ import annotations

__version__ = "0.1.0"

try:
    from ._core import (DragModel, critical_yield_number, drag_coefficient, drag_law_names,
                        explicit_step_limit, mixture_density, rayleigh_time, relaxation_time,
                        rotation_drag_rate, sphere_inertia, stokes_velocity, submergence,
                        terminal_velocity, time_to_fraction)
except ImportError as exc:  # pragma: no cover - only without a build
    raise ImportError("sediment._core is not built: run `make build` (or `make test`) in the "
                      "repository first") from exc

from .sim.styles import lammps_with_styles, register_styles

__all__ = ["DragModel", "critical_yield_number", "drag_coefficient", "drag_law_names", "explicit_step_limit",
           "lammps_with_styles", "mixture_density", "rayleigh_time", "register_styles", "relaxation_time",
           "rotation_drag_rate", "sphere_inertia", "stokes_velocity", "submergence", "terminal_velocity",
           "time_to_fraction"]
