// SPDX-License-Identifier: GPL-2.0-or-later
// Drag laws against their closed forms (docs/physics.md sections 2 and 4).
#include "sediment/drag.hpp"
#include "sediment/geometry.hpp"
#include "sediment/terminal.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace sediment;

namespace {
const Fluid water{1000.0, 1.0e-3, 0.0};
const Fluid clay{1280.0, 0.0131, 30.5};    // Valentik & Whitmore suspension 1

double newtonian_force(double cd, double d, double v) { return 0.5 * water.density * sphere_area(d) * cd * v * v; }
}    // namespace

TEST(DragLaw, NamesRoundTrip)
{
  for (auto law : {DragLaw::Stokes, DragLaw::SchillerNaumann, DragLaw::Dallavalle, DragLaw::ZhangLi,
                   DragLaw::ZhangLiSmooth, DragLaw::DiFelice})
    EXPECT_EQ(drag_law_from_name(drag_law_name(law)), law);
  EXPECT_FALSE(drag_law_from_name("stokes2").has_value());
  EXPECT_NE(drag_law_names().find("schiller-naumann"), std::string::npos);
}

TEST(DragLaw, StokesIsExactlyLinear)
{
  const DragModel model(DragLaw::Stokes, water);
  for (double v : {1e-9, 1e-4, 0.3, 20.0}) {
    EXPECT_NEAR(model.force(1e-4, v), 3.0 * pi * 1e-3 * 1e-4 * v, 1e-14 * 3 * pi * 1e-7 * v);
    EXPECT_DOUBLE_EQ(model.tangent(1e-4, v), 3.0 * pi * 1e-3 * 1e-4);
  }
  EXPECT_EQ(model.static_force(1e-4), 0.0);
}

TEST(DragLaw, NewtonianLawsMatchTheirCd)
{
  const double d = 2e-3;
  for (double re : {0.01, 0.5, 1.0, 37.0, 999.0, 1500.0, 1e5}) {
    const double v = re * water.viscosity / (water.density * d);
    const double sn = re <= 1000.0 ? 24.0 / re * (1.0 + 0.15 * std::pow(re, 0.687)) : 0.44;
    const double dv = std::pow(0.63 + 4.8 / std::sqrt(re), 2.0);
    EXPECT_NEAR(DragModel(DragLaw::SchillerNaumann, water).force(d, v), newtonian_force(sn, d, v),
                1e-12 * newtonian_force(sn, d, v)) << re;
    EXPECT_NEAR(DragModel(DragLaw::Dallavalle, water).force(d, v), newtonian_force(dv, d, v),
                1e-12 * newtonian_force(dv, d, v)) << re;
    EXPECT_NEAR(DragModel(DragLaw::Stokes, water).reynolds(d, v), re, 1e-12 * re);
  }
}

TEST(DragLaw, LowReynoldsLimitIsStokes)
{
  const double d = 1e-5, v = 1e-9;    // Re = 1e-11
  const double stokes = 3.0 * pi * water.viscosity * d * v;
  EXPECT_NEAR(DragModel(DragLaw::SchillerNaumann, water).force(d, v), stokes, 1e-6 * stokes);
  EXPECT_NEAR(DragModel(DragLaw::ZhangLi, water).force(d, v), stokes, 1e-12 * stokes);
  // Dallavalle tends to 4.8^2 / 24 = 0.96 of Stokes.
  EXPECT_NEAR(DragModel(DragLaw::Dallavalle, water).force(d, v), 0.96 * stokes, 1e-4 * stokes);
}

TEST(DragLaw, ZhangLiBelowReOneIsYieldPlusStokes)
{
  const DragModel model(DragLaw::ZhangLi, clay);
  const double d = 0.019;
  const double v = 1e-3;
  ASSERT_LT(model.reynolds(d, v), 1.0);
  const double expected = pi * pi / 4.0 * d * d * clay.yield_stress + 3.0 * pi * d * d * clay.yield_stress +
      3.0 * pi * clay.viscosity * d * v;
  EXPECT_NEAR(model.force(d, v), expected, 1e-13 * expected);
  // (pi^2/4 + 3 pi) d^2 tau_y = 11.89 d^2 tau_y
  EXPECT_NEAR(model.static_force(d), (pi * pi / 4 + 3 * pi) * d * d * clay.yield_stress, 1e-14);
  EXPECT_NEAR(pi * pi / 4 + 3 * pi, 11.89, 0.005);
}

TEST(DragLaw, ZhangLiJumpsWhereTheSpecSays)
{
  const DragModel model(DragLaw::ZhangLi, clay);
  const double d = 0.0254;
  std::array<ForceJump, DragModel::max_jumps> jumps;
  ASSERT_EQ(model.jumps(d, jumps), 2);
  EXPECT_NEAR(model.reynolds(d, jumps[0].speed), 1.0, 1e-12);
  EXPECT_NEAR(model.reynolds(d, jumps[1].speed), 150.0, 1e-10);
  // Cd jumps from 24 to 29.315 at Re' = 1 and from 0.389 to 0.4 at 150.
  const double yield = pi * pi / 4.0 * d * d * clay.yield_stress;
  EXPECT_NEAR((jumps[0].force_above - yield) / (jumps[0].force_below - yield), 29.315 / 24.0, 1e-9);
  EXPECT_NEAR((jumps[1].force_above - yield) / (jumps[1].force_below - yield), 0.4 / (29.12 / 150 + 0.195), 1e-9);
  // The curve itself agrees with the one-sided limits.
  EXPECT_NEAR(model.force(d, jumps[0].speed * (1 - 1e-9)), jumps[0].force_below, 1e-6 * jumps[0].force_below);
  EXPECT_NEAR(model.force(d, jumps[0].speed * (1 + 1e-9)), jumps[0].force_above, 1e-6 * jumps[0].force_above);
}

TEST(DragLaw, SmoothVariantIsContinuousAndKeepsTheStaticForce)
{
  const DragModel smooth(DragLaw::ZhangLiSmooth, clay);
  const DragModel faithful(DragLaw::ZhangLi, clay);
  const double d = 0.0254;
  std::array<ForceJump, DragModel::max_jumps> jumps;
  EXPECT_EQ(smooth.jumps(d, jumps), 0);
  ASSERT_EQ(faithful.jumps(d, jumps), 2);
  for (const ForceJump &jump : jumps) {
    const double below = smooth.force(d, jump.speed * (1 - 1e-10));
    const double above = smooth.force(d, jump.speed * (1 + 1e-10));
    EXPECT_NEAR(below, above, 1e-8 * above);
  }
  EXPECT_DOUBLE_EQ(smooth.static_force(d), faithful.static_force(d));
  // Identical to the faithful law for 1 <= Re' <= 142.
  const double v = jumps[0].speed * 3.0;
  ASSERT_LT(faithful.reynolds(d, v), 142.0);
  EXPECT_DOUBLE_EQ(smooth.force(d, v), faithful.force(d, v));
}

TEST(DragLaw, TangentMatchesFiniteDifference)
{
  for (auto law : {DragLaw::Stokes, DragLaw::SchillerNaumann, DragLaw::Dallavalle, DragLaw::ZhangLi,
                   DragLaw::ZhangLiSmooth}) {
    for (const Fluid &fluid : {water, clay}) {
      const DragModel model(law, fluid);
      for (double v : {1e-4, 3e-2, 0.7, 2.5}) {
        const double d = 0.0127, h = 1e-4 * v;
        const double fd = (model.force(d, v + h) - model.force(d, v - h)) / (2 * h);
        std::array<ForceJump, DragModel::max_jumps> jumps;
        bool near_jump = false;
        for (int j = 0, n = model.jumps(d, jumps); j < n; ++j)
          near_jump |= std::abs(jumps[j].speed - v) < 2 * h;
        if (near_jump) continue;
        EXPECT_NEAR(model.tangent(d, v), fd, 1e-6 * std::abs(fd)) << drag_law_name(law) << " v=" << v;
      }
    }
  }
}

TEST(DragLaw, PartialSubmergenceScalesAreaAndYield)
{
  const DragModel model(DragLaw::ZhangLi, clay);
  const double d = 0.016, v = 0.01;
  const DragScale half{0.5, 0.25};
  const double yield = pi * pi / 4.0 * d * d * clay.yield_stress;
  EXPECT_NEAR(model.force(d, v, half), 0.25 * yield + 0.5 * (model.force(d, v) - yield), 1e-12 * yield);
}

TEST(DiFelice, UnhinderedIsDallavalle)
{
  const DragModel felice(DragLaw::DiFelice, water), dalla(DragLaw::Dallavalle, water);
  for (double v : {1e-6, 1e-3, 0.2}) {
    EXPECT_EQ(felice.force(1e-4, v), dalla.force(1e-4, v));
    EXPECT_EQ(felice.tangent(1e-4, v), dalla.tangent(1e-4, v));
  }
}

TEST(DiFelice, ExponentAndItsSlope)
{
  EXPECT_NEAR(di_felice_exponent(std::pow(10.0, 1.5)).value, 3.05, 1e-12);    // dip at log10 Re = 1.5
  EXPECT_NEAR(di_felice_exponent(1e-8).value, 3.7, 1e-12);
  EXPECT_EQ(di_felice_exponent(0.0).value, 3.7);
  for (double re : {0.01, 1.0, 30.0, 500.0}) {
    const double h = 1e-6 * re;
    const double fd = (di_felice_exponent(re + h).value - di_felice_exponent(re - h).value) / (2 * h);
    EXPECT_NEAR(di_felice_exponent(re).re_slope, re * fd, 1e-7 * std::abs(re * fd) + 1e-14) << re;
  }
}

TEST(DiFelice, HinderedTangentMatchesFiniteDifference)
{
  for (auto buoyancy : {HindranceBuoyancy::Plain, HindranceBuoyancy::Mixture}) {
    const DragModel model(DragLaw::DiFelice, water, buoyancy);
    const DragScale dense{1.0, 1.0, 0.65};
    for (double v : {1e-4, 1e-2, 0.3}) {
      const double d = 1e-3, h = 1e-4 * v;
      const double fd = (model.force(d, v + h, dense) - model.force(d, v - h, dense)) / (2 * h);
      EXPECT_NEAR(model.tangent(d, v, dense), fd, 1e-6 * fd) << v;
    }
  }
}

// Richardson & Zaki (1954): u / u_t = eps^4.65 at low Re; Di Felice with plain buoyancy gives
// eps^(chi + 1) = eps^4.7 there, within 3 % up to phi = 0.4 (validation case G).
TEST(DiFelice, LowReynoldsHinderedSettlingFollowsRichardsonZaki)
{
  const DragModel model(DragLaw::DiFelice, water);
  const double d = 5e-6, weight = 1650.0 * 9.81 * sphere_volume(d);
  const double single = steady_speed(model, d, weight).speed;
  const double expected[] = {0.613, 0.354, 0.190, 0.093};
  const double phis[] = {0.1, 0.2, 0.3, 0.4};
  for (int k = 0; k < 4; ++k) {
    const double hindered = steady_speed(model, d, weight, DragScale{1.0, 1.0, 1.0 - phis[k]}).speed;
    EXPECT_NEAR(hindered / single, std::pow(1.0 - phis[k], 4.65), 0.03 * std::pow(1.0 - phis[k], 4.65)) << phis[k];
    EXPECT_NEAR(hindered / single, expected[k], 0.03 * expected[k]) << phis[k];
  }
}

TEST(ExplicitStep, StokesLimitIsTwoRelaxationTimes)
{
  const DragModel model(DragLaw::Stokes, Fluid{1000.0, 1e-3, 0.0});
  const double d = 1e-4, rho_p = 2700.0, mass = rho_p * sphere_volume(d);
  const double tau = rho_p * d * d / (18 * 1e-3);
  for (double speed : {0.0, 1e-3, 1.0}) EXPECT_NEAR(explicit_step_limit(model, d, speed, mass), 2 * tau, 1e-14 * tau);
}

TEST(ExplicitStep, NonlinearLimitFollowsTheSteeperTangent)
{
  // Dallavalle stiffens with speed: the limit shrinks as the slip grows, and is the at-rest one at 0.
  const DragModel model(DragLaw::Dallavalle, Fluid{1000.0, 1e-3, 0.0});
  const double d = 1e-3, mass = 2650.0 * sphere_volume(d);
  const double at_rest = explicit_step_limit(model, d, 0.0, mass);
  EXPECT_DOUBLE_EQ(at_rest, 2 * mass / model.tangent(d, 0.0));
  EXPECT_LT(explicit_step_limit(model, d, 0.1, mass), at_rest);
  EXPECT_DOUBLE_EQ(explicit_step_limit(model, d, 0.1, mass), 2 * mass / model.tangent(d, 0.1));
}

TEST(RotationDrag, RotletOverInertia)
{
  // torque = -pi mu d^3 omega = -k I omega with I = m d^2 / 10: k = 10 pi mu d / m.
  const double mu = 1.2e-3, d = 2e-4, mass = 2500.0 * sphere_volume(d);
  EXPECT_NEAR(rotation_drag_rate(mu, d, mass), 10 * pi * mu * d / mass, 1e-13 * 10 * pi * mu * d / mass);
  EXPECT_DOUBLE_EQ(rotation_drag_rate(mu, d, mass, 0.25), 0.25 * rotation_drag_rate(mu, d, mass));
}

TEST(DragLaw, ForceAndTangentInOneEvaluationAreBitwiseTheSeparateOnes)
{
  const DragScale hindered{0.7, 0.6, 0.8};
  for (auto law : {DragLaw::Stokes, DragLaw::SchillerNaumann, DragLaw::Dallavalle, DragLaw::ZhangLi,
                   DragLaw::ZhangLiSmooth, DragLaw::DiFelice})
    for (const Fluid &fluid : {water, clay})
      for (double speed : {0.0, 1e-6, 3e-3, 0.4, 7.0}) {
        const DragModel model(law, fluid);
        const DragModel::ForceSlope both = model.force_and_tangent(2e-4, speed, hindered);
        EXPECT_EQ(both.slope, model.tangent(2e-4, speed, hindered)) << drag_law_name(law) << " " << speed;
        EXPECT_EQ(both.force, model.force(2e-4, speed, hindered)) << drag_law_name(law) << " " << speed;
      }
}

TEST(DragLaw, SmoothLawsAreThoseWithoutYieldOrJumps)
{
  EXPECT_TRUE(DragModel(DragLaw::Stokes, water).smooth());
  EXPECT_TRUE(DragModel(DragLaw::Dallavalle, water).smooth());
  EXPECT_TRUE(DragModel(DragLaw::DiFelice, water).smooth());
  EXPECT_TRUE(DragModel(DragLaw::ZhangLiSmooth, water).smooth());
  EXPECT_FALSE(DragModel(DragLaw::SchillerNaumann, water).smooth());    // Cd steps at Re 1000
  EXPECT_FALSE(DragModel(DragLaw::ZhangLi, water).smooth());            // steps at Re' 1 and 150
  EXPECT_FALSE(DragModel(DragLaw::ZhangLiSmooth, clay).smooth());       // yield stress
  EXPECT_FALSE(DragModel(DragLaw::Stokes, clay).smooth());
}
