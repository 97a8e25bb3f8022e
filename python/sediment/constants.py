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
BRAVO_CYLINDER_WIDTH = 0.0635     # m, Bravo et al. (2015)
BRAVO_CYLINDER_HEIGHT = 0.457     # m
