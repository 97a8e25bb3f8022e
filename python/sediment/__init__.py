# SPDX-License-Identifier: GPL-2.0-or-later
"""SEDIMENT: fluid forces for DEM spheres in LAMMPS, and the readouts of sedimentation tests.

The physics lives in one C++ core (sediment._core), shared with the LAMMPS styles. The package is
grouped by role: `sediment.lab` (PSDs, instruments, readouts, calibrations), `sediment.sim` (running
LAMMPS, scenes, layer files), `sediment.studies` (validation and accuracy studies) and
`sediment.cli` (the `sediment` command); `sediment.constants`, `sediment.results` and
`sediment.folders` (who may write what in a folder of results) serve them all.

The names below are loaded when first used, so that the parts that need no compiled code (running
decks, reading layer files) import before the extension is built.
"""
_CORE = ("DragModel", "critical_yield_number", "drag_coefficient", "drag_law_names", "explicit_step_limit",
         "mixture_density", "rayleigh_time", "relaxation_time", "rotation_drag_rate", "sphere_inertia",
         "stokes_velocity", "submergence", "terminal_velocity", "time_to_fraction", "water_density",
         "water_viscosity")
_STYLES = ("lammps_with_styles", "register_styles")

__all__ = sorted(_CORE + _STYLES)


def __getattr__(name: str):
    """The core's functions, the release (__version__: the core's VERSION) and the style registration,
    imported on first use."""
    if name in _CORE or name == "__version__":
        try:
            from . import _core
        except ImportError as exc:
            raise ImportError("sediment._core is not built: run `make build` (or `make test`) in the repository, "
                              "or `pip install .`") from exc
        return getattr(_core, "VERSION" if name == "__version__" else name)
    if name in _STYLES:
        from .sim import styles

        return getattr(styles, name)
    raise AttributeError(f"module 'sediment' has no attribute '{name}'")


def __dir__():
    """What a user calls (the names loaded on first use) and the version, for dir() and completion."""
    return sorted(__all__ + ["__version__"])
