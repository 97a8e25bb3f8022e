// SPDX-License-Identifier: GPL-2.0-or-later
// Submergence below a free surface and the Rayleigh time (docs/physics.md sections 1 and 6).
#include "sediment/geometry.hpp"

#include <array>
#include <cmath>
#include <vector>
#include <tuple>

#include <gtest/gtest.h>

using namespace sediment;

TEST(Submergence, LimitsAndHalf)
{
  const double r = 0.5e-3;
  EXPECT_EQ(submergence(r, 2 * r).volume, 0.0);
  EXPECT_EQ(submergence(r, -2 * r).volume, 1.0);
  const Submergence half = submergence(r, 0.0);
  EXPECT_DOUBLE_EQ(half.volume, 0.5);
  EXPECT_DOUBLE_EQ(half.area, 1.0);
  EXPECT_DOUBLE_EQ(half.wetted, 0.5);
}

TEST(Submergence, CapVolumeFormula)
{
  const double r = 2.0;
  for (double h : {0.1, 0.9, 1.7, 3.2}) {
    const double cap = pi * h * h * (3 * r - h) / 3.0;
    EXPECT_NEAR(submergence(r, r - h).volume * 4.0 / 3.0 * pi * r * r * r, cap, 1e-12 * cap);
    EXPECT_NEAR(submergence(r, r - h).wetted, h / (2 * r), 1e-15);
  }
}

TEST(Submergence, ContinuousAcrossTheSurface)
{
  const double r = 1.0;
  for (double edge : {r, -r}) {
    for (double eps : {1e-6, 1e-9}) {
      const Submergence above = submergence(r, edge + eps), below = submergence(r, edge - eps);
      EXPECT_NEAR(above.volume, below.volume, 10 * eps);
      EXPECT_NEAR(above.wetted, below.wetted, 10 * eps);
      EXPECT_NEAR(above.area, below.area, 10 * eps);
    }
  }
  // Monotone in depth.
  double last = 0.0;
  for (int k = 0; k <= 1000; ++k) {
    const double vol = submergence(r, r - 2.0 * r * k / 1000).volume;
    EXPECT_GE(vol, last);
    last = vol;
  }
}

TEST(RayleighTime, ZhangLiExample)
{
  // d = 0.1 mm, rho = 2700, E = 30 GPa, nu = 0.25 -> 8.12e-8 s
  EXPECT_NEAR(rayleigh_time(0.05e-3, 2700.0, 30e9, 0.25), 8.12e-8, 0.005e-8);
}

TEST(Sphere, InertiaIsTwoFifthsMassRadiusSquared)
{
  // I = 2/5 m r^2 = m d^2 / 10: the two spellings the styles once used agree.
  const double m = 3.1e-9, d = 1.3e-4;
  EXPECT_DOUBLE_EQ(sphere_inertia(m, 0.5 * d), 0.1 * m * d * d);
}

TEST(Buoyancy, MixtureDensityAndDisplacedMass)
{
  EXPECT_DOUBLE_EQ(mixture_density(1000.0, 2650.0, 0.0), 1000.0);
  EXPECT_DOUBLE_EQ(mixture_density(1000.0, 2650.0, 1.0), 2650.0);
  EXPECT_DOUBLE_EQ(mixture_density(1000.0, 2650.0, 0.2), 1330.0);
  const double r = 2e-5;
  EXPECT_DOUBLE_EQ(displaced_mass(998.2, r, submergence(r, -3 * r)), 998.2 * sphere_volume(2 * r));
  EXPECT_DOUBLE_EQ(displaced_mass(998.2, r, submergence(r, 0.0)), 0.5 * 998.2 * sphere_volume(2 * r));
  EXPECT_EQ(displaced_mass(998.2, r, submergence(r, 3 * r)), 0.0);
}

TEST(Buoyancy, ImmersedRowsTakeEachAtomsBuoyancyOnEveryKind)
{
  // add_immersed_buoyancy adds -displaced_mass g to each force row of its run, bit for bit the atom's
  // own sum (a zero component of g adds -0.0, which changes no force), in vectors and their tail, and
  // returns the run's displaced mass to round-off.
  const int n = 29, first = 2, count = 23;
  const double g[3] = {0.0, 0.5, -9.81}, rho = 998.2;
  for (const sediment::BatchMath kind : sediment::batch_math_kinds) {
    if (!sediment::batch_math_available(kind)) continue;
    SCOPED_TRACE(sediment::batch_math_name(kind));
    std::vector<std::array<double, 3>> force(n), expected(n);
    std::vector<double> radius(n);
    for (int i = 0; i < n; ++i) {
      radius[i] = 1e-6 * (5 + 7 * (i % 5));
      force[i] = expected[i] = {i % 3 == 0 ? -0.0 : 1e-9 * i, -2e-9 * i, 3e-10};
    }
    double displaced = 0.0;
    for (int i = first; i < first + count; ++i) {
      const double mass = sediment::displaced_mass(rho, radius[i], {1.0, 1.0, 1.0});
      for (int k = 0; k < 3; ++k) expected[i][k] += -mass * g[k];
      displaced += mass;
    }
    const double sum = sediment::add_immersed_buoyancy(reinterpret_cast<double(*)[3]>(force.data()), radius.data(),
                                                       first, count, rho, g, kind);
    EXPECT_NEAR(sum, displaced, 1e-14 * displaced);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(force[i][k], expected[i][k]) << i << " " << k;
        EXPECT_EQ(std::signbit(force[i][k]), std::signbit(expected[i][k])) << i << " " << k;
      }
  }
}

TEST(HertzImpact, OverlapAndModulusAreInverse)
{
  // 75 um grains of 2650 kg/m3 at 4e-3 m/s (the largest settling speeds of the samples) with 1 % overlap.
  for (const Impact impact : {Impact::Wall, Impact::Pair}) {
    const double youngs = hertz_modulus_for_overlap(impact, 2650.0, 4e-3, 0.01, 0.3);
    EXPECT_NEAR(hertz_impact_overlap(impact, 2650.0, 4e-3, youngs, 0.3), 0.01, 1e-15);
  }
  // On a wall the overlap is 2^(1/5) that of two equal spheres at the same speed; it grows as v^(4/5).
  const double pair = hertz_impact_overlap(Impact::Pair, 8135.0, 1.7, 200e9, 0.3);
  EXPECT_NEAR(hertz_impact_overlap(Impact::Wall, 8135.0, 1.7, 200e9, 0.3) / pair, std::pow(2.0, 0.2), 1e-14);
  EXPECT_NEAR(hertz_impact_overlap(Impact::Pair, 8135.0, 3.4, 200e9, 0.3) / pair, std::pow(2.0, 0.8), 1e-14);
  // Steel balls of case E meeting at 1.7 m/s: (15 pi rho v^2 / (96 E*))^(2/5), E* = 200e9 / (2 (1 - 0.09)).
  const double pi = std::acos(-1.0);
  EXPECT_NEAR(pair, std::pow(15.0 * pi * 8135.0 * 1.7 * 1.7 / (96.0 * 200e9 / 1.82), 0.4), 1e-16);
}

TEST(HertzLoad, OverlapUnderAPressedWeight)
{
  // Back through Hertz: F = (4/3) E* sqrt(R) delta^(3/2) with R = d/2 must equal p d^2 at the given overlap.
  const double d = 75e-6, p = 170.0, overlap = 0.01, nu = 0.3;
  const double reduced = hertz_modulus_for_load(p, overlap, nu) / (2.0 * (1.0 - nu * nu));
  const double delta = overlap * d;
  EXPECT_NEAR(4.0 / 3.0 * reduced * std::sqrt(d / 2) * std::pow(delta, 1.5), p * d * d, 1e-12 * p * d * d);
}

TEST(HertzContact, FrequencyIsTheForceSlopeOverTheMass)
{
  // dF/d delta of F = (4/3) E* sqrt(R) delta^(3/2), by a central difference, over the effective mass.
  const double d = 60e-6, rho = 2650.0, E = 1.9e4, nu = 0.3, overlap = 0.01;
  const double reduced = E / (2.0 * (1.0 - nu * nu)), m = rho * sphere_volume(d);
  for (auto [impact, R, m_eff] : {std::tuple{Impact::Wall, d / 2, m}, std::tuple{Impact::Pair, d / 4, m / 2}}) {
    auto force = [&, R = R](double delta) { return 4.0 / 3.0 * reduced * std::sqrt(R) * std::pow(delta, 1.5); };
    const double delta = overlap * d, h = 1e-4 * delta;
    const double slope = (force(delta + h) - force(delta - h)) / (2 * h);
    EXPECT_NEAR(hertz_contact_frequency(impact, d, rho, E, nu, overlap), std::sqrt(slope / m_eff),
                1e-7 * std::sqrt(slope / m_eff));
  }
  EXPECT_NEAR(hertz_contact_frequency(Impact::Pair, d, rho, E, nu, overlap) /
                  hertz_contact_frequency(Impact::Wall, d, rho, E, nu, overlap), std::pow(2.0, 0.25), 1e-14);
}
