// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/terminal.hpp"

#include "sediment/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace sediment {

double net_weight(const Fluid &fluid, double d, double particle_density, double g)
{
  return (particle_density - fluid.density) * g * sphere_volume(d);
}

TerminalState steady_speed(const DragModel &model, double d, double driving_force,
                           DragScale scale)
{
  if (driving_force <= model.static_force(d, scale)) return {0.0, TerminalRegime::AtRest};

  // Bracket: grow from the linear (low-Re) estimate until the curve exceeds the drive.
  double hi = driving_force / std::max(model.tangent(d, 0.0, scale), 1e-300);
  while (model.force(d, hi, scale) < driving_force) hi *= 2.0;
  double lo = 0.0;
  // Invariant: F(lo) < W <= F(hi). The curve is monotone, so this converges to the unique
  // speed where W lies between the one-sided limits (a jump included).
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (model.force(d, mid, scale) < driving_force)
      lo = mid;
    else
      hi = mid;
  }
  const double speed = 0.5 * (lo + hi);

  std::array<ForceJump, DragModel::max_jumps> jumps;
  const int njumps = model.jumps(d, jumps, scale);
  for (int k = 0; k < njumps; ++k) {
    const ForceJump &jump = jumps[k];
    if (std::abs(speed - jump.speed) <= 1e-12 * jump.speed && driving_force > jump.force_below &&
        driving_force < jump.force_above)
      return {jump.speed, TerminalRegime::AtJump};
  }
  return {speed, TerminalRegime::Moving};
}

TerminalState terminal_velocity(const DragModel &model, double d, double particle_density,
                                double g)
{
  const double weight = std::abs(net_weight(model.fluid(), d, particle_density, g));
  return steady_speed(model, d, weight);
}

double time_to_fraction(const DragModel &model, double d, double particle_density, double g,
                        double fraction)
{
  const TerminalState terminal = terminal_velocity(model, d, particle_density, g);
  if (terminal.speed <= 0.0) return 0.0;
  const double mass = particle_density * sphere_volume(d);
  const double weight = std::abs(net_weight(model.fluid(), d, particle_density, g));
  // Substituting v = v_t (1 - e^{-y}) makes the integrand of dt = m dv / (W - F(v)) smooth
  // near v_t; composite 5-point Gauss-Legendre over y in [0, -ln(1 - fraction)].
  static const double nodes[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                  0.5384693101056831, 0.9061798459386640};
  static const double weights[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                    0.4786286704993665, 0.2369268850561891};
  const double y_end = -std::log1p(-fraction);
  const int panels = 400;
  const double h = y_end / panels;
  double time = 0.0;
  for (int p = 0; p < panels; ++p) {
    const double centre = (p + 0.5) * h;
    for (int q = 0; q < 5; ++q) {
      const double y = centre + 0.5 * h * nodes[q];
      const double decay = std::exp(-y);
      const double v = terminal.speed * (1.0 - decay);
      time += 0.5 * h * weights[q] * mass * terminal.speed * decay / (weight - model.force(d, v));
    }
  }
  return time;
}

double critical_yield_number(const DragModel &model)
{
  // (pi/6) (rho_p - rho_f) g d^3 = F(0+), which is d^2 tau_y times a number of the law
  // (Dedegil form: pi^2/4 + pi G(0)/8; bingham: pi H(0)/8)
  return (pi / 6.0) * model.fluid().yield_stress / model.static_force(1.0);
}

}    // namespace sediment
