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

namespace {
// Atom i's buoyancy, -m_f g with m_f the mass of fluid it displaces whole, added to its force; returns m_f.
[[gnu::always_inline]] inline double push_up(double (*__restrict force)[3], const double *__restrict radius, int i,
                                             double density, double g0, double g1, double g2)
{
  const double displaced = displaced_mass(density, radius[i], Submergence{1.0, 1.0, 1.0});
  force[i][0] += -displaced * g0;
  force[i][1] += -displaced * g1;
  force[i][2] += -displaced * g2;
  return displaced;
}

// add_immersed_buoyancy's loop, the rows as restricted parameters (else GCC leaves it scalar). The
// displaced mass summed per lane of 8 (a single running sum would keep the loop scalar).
[[gnu::always_inline]] inline double add_buoyancy(double (*__restrict force)[3], const double *__restrict radius,
                                                   int first, int count, double density, double g0, double g1,
                                                   double g2)
{
  constexpr int lanes = 8;
  double sums[lanes] = {};
  const int end = first + count;
  int i = first;
  for (; i + lanes <= end; i += lanes)
    for (int l = 0; l < lanes; ++l) sums[l] += push_up(force, radius, i + l, density, g0, g1, g2);
  for (; i < end; ++i) sums[0] += push_up(force, radius, i, density, g0, g1, g2);
  double sum = 0.0;
  for (double lane : sums) sum += lane;
  return sum;
}

SEDIMENT_TARGET_AVX2 double add_buoyancy_avx2(double (*force)[3], const double *radius, int first, int count,
                                              double density, const double g[3])
{
  return add_buoyancy(force, radius, first, count, density, g[0], g[1], g[2]);
}
SEDIMENT_TARGET_AVX512 double add_buoyancy_avx512(double (*force)[3], const double *radius, int first, int count,
                                                  double density, const double g[3])
{
  return add_buoyancy(force, radius, first, count, density, g[0], g[1], g[2]);
}
}    // namespace

double add_immersed_buoyancy(double (*force)[3], const double *radius, int first, int count, double density,
                             const double g[3], BatchMath kind)
{
  if (kind == BatchMath::AVX512 && batch_math_available(kind))
    return add_buoyancy_avx512(force, radius, first, count, density, g);
  if (kind == BatchMath::AVX2 && batch_math_available(kind))
    return add_buoyancy_avx2(force, radius, first, count, density, g);
  return add_buoyancy(force, radius, first, count, density, g[0], g[1], g[2]);
}

double rayleigh_time(double radius, double density, double youngs_modulus, double poisson_ratio)
{
  const double shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
  return pi * radius * std::sqrt(density / shear_modulus) / (0.1631 * poisson_ratio + 0.8766);
}

namespace {
// E / E* of two spheres of one material (or a sphere and a wall of it): 2 (1 - nu^2).
double youngs_per_reduced(double poisson_ratio) { return 2.0 * (1.0 - poisson_ratio * poisson_ratio); }

// (delta/d)^(5/2) E* / (rho v^2) of the impact.
double impact_factor(Impact impact)
{
  return 15.0 * pi / 96.0 * (impact == Impact::Wall ? std::sqrt(2.0) : 1.0);
}
}    // namespace

double hertz_impact_overlap(Impact impact, double density, double speed, double youngs_modulus,
                            double poisson_ratio)
{
  const double reduced_modulus = youngs_modulus / youngs_per_reduced(poisson_ratio);
  return std::pow(impact_factor(impact) * density * speed * speed / reduced_modulus, 0.4);
}

double hertz_modulus_for_overlap(Impact impact, double density, double speed, double overlap,
                                 double poisson_ratio)
{
  const double reduced_modulus = impact_factor(impact) * density * speed * speed / std::pow(overlap, 2.5);
  return youngs_per_reduced(poisson_ratio) * reduced_modulus;
}

double hertz_modulus_for_load(double pressure, double overlap, double poisson_ratio)
{
  const double reduced_modulus = 3.0 * std::sqrt(2.0) * pressure / (4.0 * std::pow(overlap, 1.5));
  return youngs_per_reduced(poisson_ratio) * reduced_modulus;
}

double hertz_contact_frequency(Impact impact, double d, double density, double youngs_modulus, double poisson_ratio,
                               double overlap)
{
  const double reduced_modulus = youngs_modulus / youngs_per_reduced(poisson_ratio);
  const bool wall = impact == Impact::Wall;
  const double stiffness = 2.0 * reduced_modulus * std::sqrt((wall ? 0.5 : 0.25) * d * overlap * d);
  const double mass = density * sphere_volume(d) * (wall ? 1.0 : 0.5);
  return std::sqrt(stiffness / mass);
}

}    // namespace sediment
