# SPDX-License-Identifier: GPL-2.0-or-later
"""Terminal speeds from the core's drag laws, for every layer above the lab (the scene's time step and
contacts, the planner's screening, the inverse's cut diameters, the error budget): one module, so that
none of them takes physics from another's."""
from __future__ import annotations

import numpy as np

from .. import _core
from .readout import Suspension


def terminal_speed(suspension: Suspension, diameter: float, law: str) -> float:
    """Terminal speed [m/s] of a lone grain of `diameter` under `law` in the suspension's clear fluid
    (law difelice alone is Dallavalle's curve, as the core takes it)."""
    speed, _ = _core.terminal_velocity(law, suspension.fluid_density, suspension.viscosity, 0.0, float(diameter),
                                       suspension.particle_density, suspension.gravity)
    return speed


def terminal_speeds(suspension: Suspension, diameter: np.ndarray, law: str = "standard",
                    voidage: float = 1.0, hindrance: str = "none") -> np.ndarray:
    """Terminal speed [m/s] of each diameter under a drag law (hindered, or law difelice: in a suspension
    of fluid fraction `voidage`, with plain buoyancy)."""
    model = _core.DragModel(law, suspension.fluid_density, suspension.viscosity, hindrance=hindrance)
    return np.array([model.steady_speed(float(d), suspension.buoyant_weight(float(d)), voidage)[0] for d in diameter])
