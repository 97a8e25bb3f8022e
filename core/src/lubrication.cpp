// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/lubrication.hpp"

#include "sediment/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace sediment {

double squeeze_coefficient(double viscosity, double ri, double rj, double gap, const LubricationRange &range)
{
  const double a = effective_radius(ri, rj);
  if (gap >= range.outer * a) return 0.0;
  return 6.0 * pi * viscosity * a * a / std::max(gap, range.inner * a);
}

double bravo_reach(double di, double dj)
{
  return std::log(1000.0) / 10.0 * 2.0 * di / (di + dj) * di;
}

double bravo_repulsion(double di, double dj, double gap)
{
  if (gap >= bravo_reach(di, dj)) return 0.0;
  const double q = 2.0 * di / (di + dj);
  return 10.0 * q * q * q * std::exp(-10.0 * (std::max(gap, 0.0) / di) / q);
}

double damping_share(double dt, double mi, double si, double mj, double sj)
{
  double share = 1.0;
  if (2.0 * dt * si > mi) share = mi / (2.0 * dt * si);
  if (2.0 * dt * sj > mj) share = std::min(share, mj / (2.0 * dt * sj));
  return share;
}

}    // namespace sediment
