# SPDX-License-Identifier: GPL-2.0-or-later
"""Physical constants and laboratory defaults, in SI units, defined once for the whole package."""
from __future__ import annotations

GRAVITY = 9.81                    # m/s2
WATER_20C_DENSITY = 998.2         # kg/m3
WATER_20C_VISCOSITY = 1.002e-3    # Pa s
SOIL_PARTICLE_DENSITY = 2650.0    # kg/m3, Gs = 2.65: what the 152H hydrometer is calibrated for
D422_CYLINDER_AREA = 27.8e-4      # m2, ASTM D422 cylinder (inner diameter 5.95 cm)
D422_CYLINDER_HEIGHT = 0.36       # m, the 1000 mL mark
BRAVO_CYLINDER_WIDTH = 0.0635     # m, Bravo et al. (2015)
BRAVO_CYLINDER_HEIGHT = 0.457     # m
