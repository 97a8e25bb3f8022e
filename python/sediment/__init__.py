"""SEDIMENT: fluid forces for DEM spheres in LAMMPS, and the readouts of sedimentation tests.

The physics lives in one C++ core (sediment._core), shared with the LAMMPS styles.
"""
from __future__ import annotations

__version__ = "0.1.0"

try:
    from ._core import (DragModel, critical_yield_number, drag_coefficient, drag_law_names,
                        rayleigh_time, relaxation_time, submergence, terminal_velocity,
                        time_to_fraction)
except ImportError as exc:  # pragma: no cover - only without a build
    raise ImportError("sediment._core is not built: run `make build` (or `make test`) in the "
                      "repository first") from exc

from .styles import lammps_with_styles, register_styles

__all__ = ["DragModel", "critical_yield_number", "drag_coefficient", "drag_law_names",
           "lammps_with_styles", "rayleigh_time", "register_styles", "relaxation_time",
           "submergence", "terminal_velocity", "time_to_fraction"]
