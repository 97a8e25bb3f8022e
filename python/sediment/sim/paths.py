# SPDX-License-Identifier: GPL-2.0-or-later
"""Where the built programs and the repository's decks are."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parents[1]    # python/sediment
REPO_DIR = PACKAGE_DIR.parents[1]


def lmp_executable() -> str:
    """lmp_sediment: $SEDIMENT_LMP, the repository's build, or the PATH."""
    candidates = [os.environ.get("SEDIMENT_LMP"), str(REPO_DIR / "build" / "lmp_sediment"),
                  shutil.which("lmp_sediment")]
    for candidate in candidates:
        if candidate and Path(candidate).is_file():
            return str(Path(candidate).resolve())
    raise FileNotFoundError("lmp_sediment not found: build it with `make build` or set SEDIMENT_LMP")


def styles_library() -> str:
    """libsediment_lammps.so, the styles for a Python LAMMPS: $SEDIMENT_STYLES_LIBRARY, beside the
    lmp_sediment in use, the repository's build, or the linker's search path."""
    import ctypes.util

    beside = None
    try:
        beside = str(Path(lmp_executable()).parent / "libsediment_lammps.so")
    except FileNotFoundError:
        pass
    candidates = [os.environ.get("SEDIMENT_STYLES_LIBRARY"), beside, str(REPO_DIR / "build" / "libsediment_lammps.so")]
    for candidate in candidates:
        if candidate and Path(candidate).is_file():
            return str(Path(candidate).resolve())
    found = ctypes.util.find_library("sediment_lammps")
    if found:
        return found
    raise FileNotFoundError("libsediment_lammps.so not found: build it with `make build` or set "
                            "SEDIMENT_STYLES_LIBRARY")


def mpirun_prefix(ranks: int) -> list[str]:
    """The launcher for `ranks` MPI ranks (none for one); allowed as root and on fewer cores."""
    if ranks <= 1:
        return []
    return ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)]
