# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment terminal: terminal velocity and time scales of one sphere under a drag law."""
from __future__ import annotations

import argparse

from .. import _core
from ..constants import GRAVITY, WATER_20C_DENSITY, WATER_20C_VISCOSITY
from .types import finite, nonnegative, positive


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("terminal", help="terminal velocity of a sphere under a drag law")
    parser.add_argument("--law", default="stokes", choices=_core.drag_law_names())
    parser.add_argument("--diameter", type=positive, required=True, help="sphere diameter [m]")
    parser.add_argument("--particle-density", type=positive, required=True, help="[kg/m3]")
    parser.add_argument("--fluid-density", type=positive, default=WATER_20C_DENSITY, help="[kg/m3] (water at 20 C)")
    parser.add_argument("--viscosity", type=positive, default=WATER_20C_VISCOSITY,
                        help="viscosity, or plastic viscosity of a Bingham fluid [Pa s]")
    parser.add_argument("--yield-stress", type=nonnegative, default=0.0, help="Bingham yield stress [Pa]")
    parser.add_argument("--gravity", type=positive, default=GRAVITY, help="[m/s2]")
    parser.add_argument("--youngs-modulus", type=positive, help="[Pa]: also print the Rayleigh time")
    parser.add_argument("--poisson-ratio", type=finite, default=0.3, help="for the Rayleigh time")
    return parser


def run(args: argparse.Namespace) -> int:
    """Prints the terminal velocity, the relaxation time and explicit limit, t99 and the Rayleigh time."""
    fluid = (args.fluid_density, args.viscosity, args.yield_stress)
    speed, regime = _core.terminal_velocity(args.law, *fluid, args.diameter, args.particle_density, args.gravity)
    print(f"terminal velocity: {speed:.6g} m/s ({regime})")
    if args.yield_stress == 0:
        tau = _core.relaxation_time(args.law, args.fluid_density, args.viscosity, args.diameter, args.particle_density)
        limit = _core.explicit_step_limit(args.law, *fluid, args.diameter, args.particle_density)
        print(f"relaxation time tau = m / F'(0): {tau:.6g} s; explicit drag needs dt < {limit:.3g} s")
    if speed > 0:
        t99 = _core.time_to_fraction(args.law, *fluid, args.diameter, args.particle_density, args.gravity, 0.99)
        print(f"time to 99 % of it from rest: {t99:.6g} s")
    if args.youngs_modulus:
        rayleigh = _core.rayleigh_time(0.5 * args.diameter, args.particle_density, args.youngs_modulus,
                                       args.poisson_ratio)
        print(f"Rayleigh time: {rayleigh:.6g} s (the 20 % rule: dt = {0.2 * rayleigh:.3g} s)")
    return 0
