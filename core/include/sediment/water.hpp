// SPDX-License-Identifier: GPL-2.0-or-later
// Water as a laboratory has it: density and viscosity at the temperature of the test (docs/physics.md 2.2).
#pragma once

namespace sediment {

// Boltzmann's constant [J/K], exact in the SI since 2019: the water's thermal agitation, which moves
// the finest grains (Stokes-Einstein diffusion; Python reads it as sediment.constants.BOLTZMANN).
constexpr double boltzmann = 1.380649e-23;

// The range of temperatures [deg C] over which both correlations hold.
constexpr double water_min_temperature = 0.0;
constexpr double water_max_temperature = 40.0;

// Density of air-free water at 101.325 kPa [kg/m3] (Tanaka et al. 2001, Metrologia 38, 301: within
// 1e-6 of the measurements from 0 to 40 deg C).
double water_density(double celsius);

// Viscosity of water at 101.325 kPa [Pa s]: Kestin, Sokolov & Wakeham's (1978) relative law
// log10(mu / mu20) = (20 - T) / (T + 96) (1.2364 - 1.37e-3 (20 - T) + 5.7e-6 (20 - T)^2) with
// mu20 = 1.0016 mPa s (IAPWS 2008), within 0.1 % of IAPWS 2008 from 0 to 40 deg C.
double water_viscosity(double celsius);

}    // namespace sediment
