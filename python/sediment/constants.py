# SPDX-License-Identifier: GPL-2.0-or-later
"""Physical constants and laboratory defaults, in SI units, defined once for the whole package."""
from __future__ import annotations

GRAVITY = 9.81                    # m/s2
WATER_20C_DENSITY = 998.2067      # kg/m3 (Tanaka et al. 2001; sediment._core.water_density(20))
WATER_20C_VISCOSITY = 1.0016e-3   # Pa s (IAPWS 2008; sediment._core.water_viscosity(20))
LAB_TEMPERATURE = 20.0            # deg C
SOIL_PARTICLE_DENSITY = 2650.0    # kg/m3, Gs = 2.65: what the 152H hydrometer is calibrated for
D422_CYLINDER_AREA = 27.8e-4      # m2, ASTM D422 cylinder (inner diameter 5.95 cm)
D422_CYLINDER_HEIGHT = 0.36       # m, the 1000 mL mark
SUSPENSION_VOLUME = 1e-3          # m3, the sedimentation tests' 1000 mL
SPECIMEN_MASS = 0.060             # kg, the dry sample of a test unless one is given (60 g/L)
NOMINAL_BULB_LENGTH = 0.140       # m, the 152H of D422
NOMINAL_BULB_VOLUME = 67.0e-6     # m3
BRAVO_CYLINDER_WIDTH = 0.0635     # m, Bravo et al. (2015)
BRAVO_CYLINDER_HEIGHT = 0.457     # m

# The sedimentation tests' instruments (sediment.lab.instruments holds one class each; the command line
# offers these names before the C++ core is loaded, and tests/python/test_instruments.py checks them
# against the registry), and the hydrometer's two scales (D422 3.2).
INSTRUMENTS = ("hydrometer", "buoyancy", "pipette")
HYDROMETER_TYPES = ("152H", "151H")
PIPETTE_DEPTH = 0.10              # m, the tip below the surface
PIPETTE_VOLUME = 25e-6            # m3, one sample
SPHERE_DIAMETER = 0.025           # m, Bardet & Young's Teflon sphere
SPHERE_MASS = 0.020               # kg
SPHERE_DEPTH_SHARE = 0.3          # its centre's depth, as a share of the suspension's height
# Reading errors: a 152H read to 0.5 g/L; a balance to 1 mg; a pipette sample's dry mass to 0.1 mg;
# a sieve's percent passing to 0.5 points
HYDROMETER_NOISE = 0.25           # g/L
BALANCE_NOISE = 1e-3              # g
PIPETTE_NOISE = 1e-4              # g of a sample
SIEVE_NOISE = 0.5                 # points
THERMOMETER_NOISE = 0.5           # C, of the temperature record

# Names the command line offers before the C++ core is loaded (its --help works before a build);
# tests/python/test_cli.py checks them against the core's own lists.
DRAG_LAWS = ("stokes", "schiller-naumann", "dallavalle", "zhang-li", "zhang-li/smooth", "difelice", "standard",
             "bingham")
# The laws for a sphere in a Bingham fluid: SEDIMENT's (the default), the paper's and its continuous variant.
BINGHAM_LAWS = ("bingham", "zhang-li", "zhang-li/smooth")
# The single-sphere drag of a test: the measured standard drag curve (the default), Schiller &
# Naumann's, Dallavalle's, Stokes' law; and Bravo et al.'s model, Dallavalle's curve under Di Felice's
# hindrance, named difelice as in the paper (docs/physics.md).
DRAGS = ("standard", "schiller-naumann", "dallavalle", "stokes", "difelice")
# How the local concentration hinders the drag: Richardson & Zaki's measured exponent (Rowe's smooth
# fit, the default: left out, the hindrance moves the readings of Bravo et al.'s five samples at 60 g/L
# by 2.1 to 18.9 points of percent finer, docs/effects.md), Garside & Al-Dibouni's, Di Felice's, none.
HINDRANCES = ("richardson-zaki", "garside", "difelice", "none")
SCHEDULES = {              # hydrometer reading times [min]
    "d422": [2, 5, 15, 30, 60, 250, 1440],
    "d7928": [1, 2, 4, 15, 30, 60, 240, 1440],
    "bravo": [0.5, 1, 2, 4, 15, 30, 60, 120, 240, 480],
}


def __getattr__(name: str):
    """BOLTZMANN [J/K] (core/include/sediment/water.hpp) and VERSION, the release
    (core/include/sediment/version.hpp): the core's, loaded when first asked for, so that the names above
    work before a build."""
    if name in ("BOLTZMANN", "VERSION"):
        from . import _core
        return getattr(_core, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

# The swirls settling grains drive (Segre, Herbolzheimer & Chaikin 1997, PRL 79 2574, dilute spheres,
# phi <= 0.05): vertical velocity fluctuations of SWIRL_SPEED phi^1/3 times the mean settling speed,
# correlated over 2 xi = SWIRL_LENGTH a phi^-1/3 (a the radius). The planner's screening estimates
# what they change from these; `sediment sample --two-way` makes its column some swirls wide.
SWIRL_SPEED = 2.0      # times phi^1/3, of the mean settling speed
SWIRL_LENGTH = 40.0    # times a phi^-1/3
