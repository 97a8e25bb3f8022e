# SPDX-License-Identifier: GPL-2.0-or-later
"""The SEDIMENT LAMMPS styles inside a Python `lammps.lammps()` instance.

The styles live in a shared library built against one LAMMPS (`libsediment_lammps.so`, next to
`lmp_sediment`); it is loaded only here, so `sediment._core` and the rest of the package work with
any LAMMPS, or none. A LAMMPS with SEDIMENT built in (the in-tree package) needs no registration.
"""
from __future__ import annotations

import ctypes
from typing import Any, Sequence

from .paths import styles_library


def register_styles(lmp: Any) -> Any:
    """Registers the SEDIMENT fix, compute and pair styles into `lmp`.

    Parameters
    ----------
    lmp : lammps.lammps
        An open instance of the LAMMPS the styles library was built against (Debian's, for
        ``make build``).

    Returns
    -------
    lammps.lammps
        `lmp` itself.

    Raises
    ------
    ValueError
        `lmp` is not an open instance.
    FileNotFoundError
        No styles library was found (see `sediment.sim.paths.styles_library`).
    """
    handle = getattr(lmp, "lmp", None)
    value = getattr(handle, "value", handle)
    if not value:
        raise ValueError("register_styles needs an open lammps.lammps instance")
    library = ctypes.CDLL(styles_library(), mode=ctypes.RTLD_GLOBAL)
    library.sediment_register.argtypes = [ctypes.c_void_p]
    library.sediment_register.restype = None
    library.sediment_register(ctypes.c_void_p(int(value)))
    return lmp


def lammps_with_styles(cmdargs: Sequence[str] = ("-log", "none", "-screen", "none")) -> Any:
    """A new `lammps.lammps` instance with the SEDIMENT styles registered."""
    import lammps

    return register_styles(lammps.lammps(cmdargs=list(cmdargs)))
