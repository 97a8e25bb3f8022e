# SPDX-License-Identifier: GPL-2.0-or-later
"""The SEDIMENT LAMMPS styles inside a Python `lammps.lammps()` instance."""
from __future__ import annotations

from typing import Any, Sequence

from .. import _core


def register_styles(lmp: Any) -> Any:
    """Registers fix fluid, fluid/buoyancy, fluid/drag and nve/sphere/fluid into `lmp`.

    `lmp` is a `lammps.lammps` instance; returns it. Note that Debian's LAMMPS is built without
    exceptions: a LAMMPS error in a deck ends the Python process, as it ends lmp_sediment.
    """
    handle = getattr(lmp, "lmp", None)
    value = getattr(handle, "value", handle)
    if not value:
        raise ValueError("register_styles needs an open lammps.lammps instance")
    _core.register_styles(int(value))
    return lmp


def lammps_with_styles(cmdargs: Sequence[str] = ("-log", "none", "-screen", "none")) -> Any:
    """A new `lammps.lammps` instance with the SEDIMENT styles registered."""
    import lammps

    return register_styles(lammps.lammps(cmdargs=list(cmdargs)))
