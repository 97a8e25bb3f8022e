// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace sediment {

Submergence submergence(double radius, double centre_height)
{
  const double d = 2.0 * radius;
  const double h = std::clamp(radius - centre_height, 0.0, d);    // submerged cap height
  if (h >= d) return {1.0, 1.0, 1.0};
  const double volume = h * h * (3.0 * radius - h) / (4.0 * radius * radius * radius);
  const double area = h < radius ? h * (d - h) / (radius * radius) : 1.0;
  return {volume, area, h / d};
}

double rayleigh_time(double radius, double density, double youngs_modulus, double poisson_ratio)
{
  const double shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
  return pi * radius * std::sqrt(density / shear_modulus) / (0.1631 * poisson_ratio + 0.8766);
}

}    // namespace sediment
