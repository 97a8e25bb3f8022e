# SPDX-License-Identifier: GPL-2.0-or-later
# Type stub of the compiled core: written by scripts/core-stub.py, do not edit.
"""SEDIMENT physics core: drag laws, terminal velocities, submergence, time scales."""
from __future__ import annotations

import numpy


BOLTZMANN: float

class DragModel:
    """Resisting-force curve of a sphere under one drag law."""
    def __init__(self: DragModel, law: str, density: float, viscosity: float, yield_stress: float = ..., buoyancy: str = ..., hindrance: str = ..., yield_weight: Optional[float] = ..., yield_rise: Optional[float] = ...) -> None: ...
    def force(self: DragModel, d: float, speed: float, voidage: float = ..., area: float = ..., wetted: float = ...) -> float: ...
    def jumps(self: DragModel, d: float) -> list: ...
    def reynolds(self: DragModel, d: float, speed: float) -> float: ...
    def static_force(self: DragModel, d: float) -> float: ...
    def steady_speed(self: DragModel, d: float, driving_force: float, voidage: float = ...) -> tuple: ...
    def tangent(self: DragModel, d: float, speed: float, voidage: float = ...) -> float: ...

VERSION: str

def critical_yield_number(law: str = ...) -> float:
    """Y = tau_y / ((rho_p - rho_f) g d) at which a sphere stops."""

def drag_coefficient(law: str, reynolds: float) -> float:
    """Cd(Re) of a law (Re' for the Bingham laws)."""

def drag_law_names() -> list[str]:
    """Names of the drag laws."""

def drag_laws() -> list:
    """The core's list of drag laws, in its order: each law's name, the hindrances a deck may name for it ('none' included) and whether it is a law for a sphere in a Bingham fluid (else a Newtonian law)."""

def explicit_step_limit(law: str, density: float, viscosity: float, yield_stress: float, d: float, particle_density: float, speed: float = ...) -> float:
    """Largest step [s] at which explicit drag is stable at a slip speed (2 tau for Stokes)."""

def fft_friendly(n: int) -> bool:
    """Whether n is a grid size the FFTs of fix fluid/flow take (no prime factor but 2, 3 and 5)."""

def hard_sphere_structure_factor(phi: float) -> float:
    """The long-wave structure factor S(0) of hard spheres at solid fraction phi (Carnahan & Starling)."""

def hertz_contact_frequency(impact: str, diameter: float, density: float, youngs_modulus: float, poisson_ratio: float, overlap: float) -> float:
    """Angular frequency [1/s] of a Hertz contact linearised at `overlap` ('wall' or 'pair')."""

def hertz_impact_overlap(impact: str, density: float, speed: float, youngs_modulus: float, poisson_ratio: float) -> float:
    """Largest overlap / diameter of an undamped Hertz impact at `speed` ('wall' or 'pair' of equal spheres)."""

def hertz_modulus_for_load(pressure: float, overlap: float, poisson_ratio: float) -> float:
    """Young's modulus [Pa] at which a sphere pressed on a wall by pressure * d^2 overlaps by `overlap` of d."""

def hertz_modulus_for_overlap(impact: str, density: float, speed: float, overlap: float, poisson_ratio: float) -> float:
    """Young's modulus [Pa] whose impacts at `speed` reach `overlap` (relative to the diameter)."""

def hindrance_names() -> list[str]:
    """Names of the hindrances ('none' included)."""

def mixture_density(fluid_density: numpy.ndarray, solid_density: numpy.ndarray, fraction: numpy.ndarray) -> object:
    """Suspension density rho_f + (rho_s - rho_f) phi [kg/m3] (numpy arrays too)."""

def rayleigh_time(radius: float, density: float, youngs_modulus: float, poisson_ratio: float) -> float:
    """Rayleigh time [s]."""

def relaxation_time(law: str, density: float, viscosity: float, d: float, particle_density: float) -> float:
    """Linear relaxation time m / F'(0) [s]."""

def rotation_drag_rate(viscosity: float, d: float, particle_density: float, wetted: float = ...) -> float:
    """Rate k [1/s] of the Stokes rotlet torque -pi mu d^3 omega = -k I omega of a solid sphere."""

def sphere_inertia(mass: float, radius: float) -> float:
    """Moment of inertia 2/5 m r^2 of a solid sphere [kg m2]."""

def spring_step_limit(omega: float, rate: float) -> float:
    """Largest stable time step [s] of the drag-implicit step for a linear spring of angular frequency omega (explicit) under a linear drag of rate `rate` [1/s] (exact): 2/omega without drag, 2 rate/omega^2 overdamped."""

def stokes_velocity(particle_density: numpy.ndarray, fluid_density: numpy.ndarray, viscosity: numpy.ndarray, g: numpy.ndarray, d: numpy.ndarray) -> object:
    """Stokes' terminal speed (rho_p - rho_f) g d^2 / (18 mu) [m/s] (numpy arrays too)."""

def submergence(radius: float, centre_height: float) -> dict:
    """Submerged volume, area and wetted fractions of a sphere whose centre is centre_height above the surface."""

def terminal_velocity(law: str, density: float, viscosity: float, yield_stress: float, d: float, particle_density: float, g: float = ...) -> tuple:
    """Terminal speed [m/s] and regime ('moving', 'at_rest', 'at_jump')."""

def time_to_fraction(law: str, density: float, viscosity: float, yield_stress: float, d: float, particle_density: float, g: float = ..., fraction: float = ...) -> float:
    """Time [s] for a sphere released at rest to reach a fraction of its terminal speed."""

def water_density(celsius: float) -> float:
    """Density of water [kg/m3] at 0-40 C (Tanaka et al. 2001)."""

def water_viscosity(celsius: float) -> float:
    """Viscosity of water [Pa s] at 0-40 C (Kestin et al. 1978 with IAPWS 2008's 20 C value)."""
