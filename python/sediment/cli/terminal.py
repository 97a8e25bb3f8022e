# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment terminal: terminal velocity and time scales of one sphere under a drag law."""
from __future__ import annotations

import argparse

import math

from ..constants import DRAG_LAWS, GRAVITY, WATER_20C_DENSITY, WATER_20C_VISCOSITY
from .types import quantity, temperature


EXAMPLES = [
    'sediment terminal --law standard --diameter 50e-6 --particle-density 2650 --temperature 20',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("terminal", help="terminal velocity of a sphere under a drag law",
                                 description="Example: sediment terminal --law standard --diameter 70e-6 "
                                 "--particle-density 2650 --temperature 18")
    parser.add_argument("--law", default="stokes", choices=DRAG_LAWS)
    parser.add_argument("--diameter", type=quantity("sphere_size"), required=True, help="sphere diameter [m]")
    parser.add_argument("--particle-density", type=quantity("solid_density"), required=True, help="[kg/m3]")
    parser.add_argument("--fluid-density", type=quantity("fluid_density"), help="[kg/m3] (default water at 20 C)")
    parser.add_argument("--viscosity", type=quantity("viscosity"),
                        help="viscosity, or plastic viscosity of a Bingham fluid "
                        "[Pa s] (default water at 20 C)")
    parser.add_argument("--temperature", type=temperature, help="water at this temperature [C], 0-40, instead of "
                        "--fluid-density and --viscosity")
    parser.add_argument("--hindrance", default="none", help="with --solid-fraction: the speed in a uniform "
                        "suspension under this hindrance (richardson-zaki, garside, difelice)")
    parser.add_argument("--solid-fraction", type=quantity("solid_fraction"), default=0.0,
                        help="solid volume fraction of the suspension around the sphere (default 0, clear fluid)")
    parser.add_argument("--yield-stress", type=quantity("yield_stress"), default=0.0, help="Bingham yield stress [Pa]")
    parser.add_argument("--gravity", type=quantity("gravity"), default=GRAVITY, help="[m/s2]")
    parser.add_argument("--youngs-modulus", type=quantity("youngs_modulus"), help="[Pa]: also print the Rayleigh time")
    parser.add_argument("--poisson-ratio", type=quantity("poisson_ratio"), default=0.3, help="for the Rayleigh time")
    return parser


def run(args: argparse.Namespace) -> int:
    """Prints the terminal velocity, the relaxation time and explicit limit, t99 and the Rayleigh time."""
    from .. import _core

    if args.temperature is not None:
        if args.fluid_density is not None or args.viscosity is not None:
            raise ValueError("--temperature sets the water's density and viscosity: give it or them, not both")
        args.fluid_density, args.viscosity = _core.water_density(args.temperature), _core.water_viscosity(args.temperature)
    args.fluid_density = WATER_20C_DENSITY if args.fluid_density is None else args.fluid_density
    args.viscosity = WATER_20C_VISCOSITY if args.viscosity is None else args.viscosity
    if (args.hindrance != "none") != (args.solid_fraction > 0):
        raise ValueError("--hindrance and --solid-fraction go together")
    fluid = (args.fluid_density, args.viscosity, args.yield_stress)
    speed, regime = _core.terminal_velocity(args.law, *fluid, args.diameter, args.particle_density, args.gravity)
    print(f"terminal velocity: {speed:.6g} m/s ({regime}), Re = {args.fluid_density * speed * args.diameter / args.viscosity:.3g}")
    if args.solid_fraction > 0:
        model = _core.DragModel(args.law, *fluid, hindrance=args.hindrance)
        weight = (args.particle_density - args.fluid_density) * args.gravity * math.pi / 6 * args.diameter ** 3
        hindered, _ = model.steady_speed(args.diameter, weight, 1 - args.solid_fraction)
        print(f"in a suspension at phi = {args.solid_fraction:g} ({args.hindrance}): {hindered:.6g} m/s, "
              f"{hindered / speed:.4g} of it (exponent {math.log(hindered / speed) / math.log(1 - args.solid_fraction):.3g})")
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
