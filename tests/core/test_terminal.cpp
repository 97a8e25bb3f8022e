// SPDX-License-Identifier: GPL-2.0-or-later
// Terminal velocities: validation cases A, B and the Bingham rest criterion.
#include "sediment/geometry.hpp"
#include "sediment/terminal.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace sediment;

TEST(Terminal, CaseASingleSphere)
{
  const DragModel model(DragLaw::Stokes, Fluid{1000.0, 1.0e-3, 0.0});
  const TerminalState state = terminal_velocity(model, 0.1e-3, 2700.0, 9.81);
  EXPECT_EQ(state.regime, TerminalRegime::Moving);
  EXPECT_NEAR(state.speed, 9.265e-3, 0.0005e-3);
  EXPECT_NEAR(state.speed, 1700.0 * 9.81 * 1e-8 / 18e-3, 1e-13);
  EXPECT_NEAR(relaxation_time(model, 0.1e-3, 2700.0), 1.5e-3, 1e-15);
}

TEST(Terminal, CaseBFineGrains)
{
  // Bravo et al. (2015) Table 1: d [um], "t99" [1e-5 s], v_t [1e-5 m/s]; within 0.1 %.
  // The table's time column is tau ln 100 (99 %) for 70 um but tau ln 20 (95 %) for the five
  // finer rows (its values scale as d^2 from 50 um down, not from 70 um); each row is checked
  // against the fraction it actually follows.
  struct Row { double d_um, t99, vt, fraction; };
  const Row rows[] = {{70, 313.4, 400.5, 0.99}, {50, 104.0, 204.3, 0.95}, {25, 26.0, 51.09, 0.95},
                      {10, 4.16, 8.17, 0.95},   {5, 1.04, 2.04, 0.95},    {2.5, 0.26, 0.51, 0.95}};
  const DragModel model(DragLaw::Stokes, Fluid{1000.0, 1.0e-3, 0.0});
  for (const Row &row : rows) {
    const double d = row.d_um * 1e-6;
    const double vt = terminal_velocity(model, d, 2500.0, 9.81).speed;
    const double t99 = time_to_fraction(model, d, 2500.0, 9.81, row.fraction);
    // The table rounds to 3-4 digits: compare within 0.1 % plus half a unit of its last digit.
    EXPECT_NEAR(vt / 1e-5, row.vt, 1e-3 * row.vt + 0.005) << row.d_um;
    EXPECT_NEAR(t99 / 1e-5, row.t99, 1e-3 * row.t99 + 0.005) << row.d_um;
    // And the quadrature reproduces -tau ln(1 - fraction) exactly for Stokes.
    EXPECT_NEAR(t99, -relaxation_time(model, d, 2500.0) * std::log1p(-row.fraction), 1e-10 * t99);
  }
}

TEST(Terminal, BinghamRestCriterion)
{
  const DragModel model(DragLaw::ZhangLi, Fluid{1280.0, 0.0131, 30.5});
  EXPECT_NEAR(critical_yield_number(model), 0.0440, 0.00005);
  const double d = 0.02, g = 9.81;
  const double yc = critical_yield_number(model);
  // Y = tau_y / ((rho_p - rho_f) g d): choose rho_p for Y just above and just below.
  const double rho_stuck = 1280.0 + 30.5 / (yc * 1.001 * g * d);
  const double rho_moving = 1280.0 + 30.5 / (yc * 0.999 * g * d);
  EXPECT_EQ(terminal_velocity(model, d, rho_stuck, g).regime, TerminalRegime::AtRest);
  const TerminalState moving = terminal_velocity(model, d, rho_moving, g);
  EXPECT_EQ(moving.regime, TerminalRegime::Moving);
  EXPECT_GT(moving.speed, 0.0);
  EXPECT_NEAR(model.force(d, moving.speed), net_weight(model.fluid(), d, rho_moving, g), 1e-9 * model.force(d, moving.speed));
}

TEST(Terminal, RootSatisfiesForceBalanceForEveryLaw)
{
  for (auto law : {DragLaw::Stokes, DragLaw::SchillerNaumann, DragLaw::Dallavalle, DragLaw::ZhangLiSmooth}) {
    const DragModel model(law, Fluid{1000.0, 1e-3, 0.0});
    for (double d : {1e-5, 1e-3, 2e-2}) {
      const TerminalState state = terminal_velocity(model, d, 2650.0, 9.81);
      const double weight = net_weight(model.fluid(), d, 2650.0, 9.81);
      EXPECT_NEAR(model.force(d, state.speed), weight, 1e-10 * weight) << drag_law_name(law) << d;
    }
  }
}

TEST(Terminal, BalanceInsideTheJumpSitsAtTheJump)
{
  const DragModel model(DragLaw::ZhangLi, Fluid{1226.0, 0.0081, 17.5});
  const double d = 0.019, g = 9.81;
  std::array<ForceJump, DragModel::max_jumps> jumps;
  ASSERT_EQ(model.jumps(d, jumps), 2);
  const double target = 0.5 * (jumps[0].force_below + jumps[0].force_above);
  const double rho_p = 1226.0 + target / (g * sphere_volume(d));
  const TerminalState state = terminal_velocity(model, d, rho_p, g);
  EXPECT_EQ(state.regime, TerminalRegime::AtJump);
  EXPECT_DOUBLE_EQ(state.speed, jumps[0].speed);
}

TEST(Terminal, RisingSphereUsesTheMagnitude)
{
  const DragModel model(DragLaw::Stokes, Fluid{1000.0, 1e-3, 0.0});
  EXPECT_NEAR(terminal_velocity(model, 1e-4, 500.0, 9.81).speed, 500.0 * 9.81 * 1e-8 / 18e-3, 1e-14);
}

TEST(Terminal, StokesLawIsTheStokesDragBalance)
{
  const DragModel model(DragLaw::Stokes, Fluid{998.2, 1.002e-3, 0.0});
  for (double d : {2.5e-6, 2e-5, 7e-5}) {
    const double v = stokes_velocity(2650.0, 998.2, 1.002e-3, 9.81, d);
    EXPECT_NEAR(terminal_velocity(model, d, 2650.0, 9.81).speed, v, 1e-12 * v);
  }
  EXPECT_LT(stokes_velocity(700.0, 1000.0, 1e-3, 9.81, 1e-4), 0.0);
}
