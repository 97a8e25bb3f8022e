// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/water.hpp"

#include <cmath>

namespace sediment {

double water_density(double celsius)
{
  constexpr double a1 = -3.983035, a2 = 301.797, a3 = 522528.9, a4 = 69.34881, a5 = 999.974950;
  const double t = celsius;
  return a5 * (1.0 - (t + a1) * (t + a1) * (t + a2) / (a3 * (t + a4)));
}

double water_viscosity(double celsius)
{
  constexpr double mu20 = 1.0016e-3;
  const double below = 20.0 - celsius;
  const double exponent = below / (celsius + 96.0) * (1.2364 - 1.37e-3 * below + 5.7e-6 * below * below);
  return mu20 * std::pow(10.0, exponent);
}

}    // namespace sediment
