// SPDX-License-Identifier: GPL-2.0-or-later
// The drag-implicit step (docs/physics.md section 7): exactness, order, Verlet limit, yield, jumps.
#include "sediment/geometry.hpp"
#include "sediment/integrator.hpp"
#include "sediment/terminal.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <array>
#include <utility>
#include <vector>

using namespace sediment;

namespace {

const double zero[3] = {0.0, 0.0, 0.0};

struct State {
  double x[3] = {0, 0, 0};
  double v[3] = {0, 0, 0};
};

// Integrates with a_n = accel(x_n) as LAMMPS would: first half, new force, second half.
void run(const SphereDrag &drag, double mass, const std::function<void(const double *, double *)> &accel,
         double dt, int steps, State &s, const double *flow = zero)
{
  double a[3];
  accel(s.x, a);
  for (int n = 0; n < steps; ++n) {
    double dx[3];
    const StepCorrection corr = drag_step_initial(drag, 1.0 / mass, a, flow, dt, s.v, dx);
    for (int k = 0; k < 3; ++k) s.x[k] += dx[k];
    accel(s.x, a);
    drag_step_final(corr, a, s.v);
  }
}

// Case A: d = 0.1 mm quartz-like sphere in water, Stokes drag.
const Fluid water{1000.0, 1.0e-3, 0.0};
const double d_a = 1e-4, rho_a = 2700.0, g = 9.81;
const double mass_a = rho_a * sphere_volume(d_a);
const double tau_a = rho_a * d_a * d_a / (18.0 * 1e-3);
const double vt_a = (rho_a - 1000.0) * g * d_a * d_a / (18.0 * 1e-3);
void net_gravity(const double *, double *a) { a[0] = a[1] = 0.0; a[2] = -(rho_a - 1000.0) / rho_a * g; }

}    // namespace

TEST(Integrator, ExactForConstantForceAndLinearDragAtAnyStep)
{
  const DragModel stokes(DragLaw::Stokes, water);
  const SphereDrag drag{&stokes, d_a, {}};
  for (double dt : {1e-6, 1e-3, 0.1, 100 * tau_a}) {
    State s;
    const int steps = 7;
    run(drag, mass_a, net_gravity, dt, steps, s);
    const double t = dt * steps;
    const double v_exact = -vt_a * (1.0 - std::exp(-t / tau_a));
    const double z_exact = -vt_a * (t - tau_a * (1.0 - std::exp(-t / tau_a)));
    EXPECT_NEAR(s.v[2], v_exact, 1e-12 * vt_a) << dt;
    EXPECT_NEAR(s.x[2], z_exact, 1e-12 * std::abs(z_exact) + 1e-18) << dt;
    EXPECT_EQ(s.v[0], 0.0);
  }
}

TEST(Integrator, ExactWithUniformFlow)
{
  const DragModel stokes(DragLaw::Stokes, water);
  const SphereDrag drag{&stokes, d_a, {}};
  const double flow[3] = {0.01, 0.0, 0.0};
  State s;
  run(drag, mass_a, net_gravity, 0.05, 4, s, flow);
  EXPECT_NEAR(s.v[0], 0.01 * (1 - std::exp(-0.2 / tau_a)), 1e-14);
  EXPECT_NEAR(s.x[0], 0.01 * (0.2 - tau_a * (1 - std::exp(-0.2 / tau_a))), 1e-14);
}

TEST(Integrator, VelocityVerletWithoutDrag)
{
  auto spring = [](const double *x, double *a) { for (int k = 0; k < 3; ++k) a[k] = -4.0 * x[k]; };
  State s, ref;
  s.x[0] = ref.x[0] = 1.0;
  s.v[1] = ref.v[1] = 0.5;
  const double dt = 0.01;
  run(SphereDrag{}, 1.0, spring, dt, 1000, s);
  double a[3];
  spring(ref.x, a);
  for (int n = 0; n < 1000; ++n) {
    for (int k = 0; k < 3; ++k) {
      ref.v[k] += 0.5 * dt * a[k];
      ref.x[k] += dt * ref.v[k];
    }
    spring(ref.x, a);
    for (int k = 0; k < 3; ++k) ref.v[k] += 0.5 * dt * a[k];
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(s.x[k], ref.x[k], 1e-13);
    EXPECT_NEAR(s.v[k], ref.v[k], 1e-13);
  }
}

// Observed order of convergence for a smoothly varying force: spring + nonlinear drag in 3D.
TEST(Integrator, SecondOrderForSmoothForces)
{
  const Fluid oil{900.0, 0.05, 0.0};
  for (auto law : {DragLaw::Stokes, DragLaw::SchillerNaumann, DragLaw::Dallavalle}) {
    const DragModel model(law, oil);
    const double d = 5e-3, mass = 2500.0 * sphere_volume(d);
    const SphereDrag drag{&model, d, {}};
    auto force = [](const double *x, double *a) {
      a[0] = -40.0 * x[0];
      a[1] = -25.0 * x[1];
      a[2] = -9.81 - 30.0 * x[2];
    };
    const double t_end = 1.0;
    auto solve = [&](int steps) {
      State s;
      s.x[0] = 0.02;
      s.v[1] = 0.3;
      run(drag, mass, force, t_end / steps, steps, s);
      return s;
    };
    const State ref = solve(64000);
    double err_prev = 0.0;
    for (int steps : {250, 500, 1000}) {
      const State s = solve(steps);
      double err = 0.0;
      for (int k = 0; k < 3; ++k) err = std::max({err, std::abs(s.x[k] - ref.x[k]), 1e-2 * std::abs(s.v[k] - ref.v[k])});
      if (err_prev > 0.0) {
        const double order = std::log2(err_prev / err);
        EXPECT_GT(order, 1.9) << drag_law_name(law) << " steps " << steps;
        EXPECT_LT(order, 2.2) << drag_law_name(law) << " steps " << steps;
      }
      err_prev = err;
    }
  }
}

TEST(Integrator, NonlinearTerminalVelocityIsExactAtHugeSteps)
{
  for (auto law : {DragLaw::SchillerNaumann, DragLaw::Dallavalle}) {
    const DragModel model(law, water);
    const double d = 1e-3, rho = 2650.0, mass = rho * sphere_volume(d);
    const double vt = terminal_velocity(model, d, rho, g).speed;
    const double tau = relaxation_time(model, d, rho);
    const SphereDrag drag{&model, d, {}};
    State s;
    auto accel = [&](const double *, double *a) { a[0] = a[1] = 0; a[2] = -(rho - 1000.0) / rho * g; };
    run(drag, mass, accel, 100 * tau, 30, s);
    EXPECT_NEAR(-s.v[2], vt, 1e-10 * vt) << drag_law_name(law);
  }
}

class Bingham : public ::testing::Test {
 protected:
  const Fluid clay{1280.0, 0.0131, 30.5};
  const DragModel model{DragLaw::ZhangLi, clay};
  const double d = 0.02;
  double density_for_yield_number(double y) const { return clay.density + clay.yield_stress / (y * g * d); }
};

TEST_F(Bingham, JustAboveTheCriterionStaysExactlyStill)
{
  for (auto law : {DragLaw::ZhangLi, DragLaw::Bingham}) {
    const DragModel law_model(law, clay);
    const double rho = density_for_yield_number(critical_yield_number(law_model) * 1.0001);
    const double mass = rho * sphere_volume(d);
    const SphereDrag drag{&law_model, d, {}};
    auto accel = [&](const double *, double *a) { a[0] = a[1] = 0; a[2] = -(rho - clay.density) / rho * g; };
    State s;
    for (double dt : {1e-6, 1e-3, 0.1}) {
      run(drag, mass, accel, dt, 100000, s);
      EXPECT_EQ(s.v[2], 0.0) << drag_law_name(law);
      EXPECT_EQ(s.x[2], 0.0) << drag_law_name(law);
    }
  }
}

// Just below the criterion the Zhang-Li balance falls inside the Cd jump at Re' = 1 (the low
// branch adds only 3 pi eta d v to the static force), so the law's terminal state is the jump
// speed; the smooth variant has a true root there. Both must be reached at any step.
TEST_F(Bingham, JustBelowTheCriterionSettlesAtTheLawsTerminalVelocity)
{
  for (auto law : {DragLaw::ZhangLi, DragLaw::ZhangLiSmooth, DragLaw::Bingham}) {
    const DragModel law_model(law, clay);
    const double rho = density_for_yield_number(critical_yield_number(law_model) * 0.99);
    const double mass = rho * sphere_volume(d);
    auto accel = [&](const double *, double *a) { a[0] = a[1] = 0; a[2] = -(rho - clay.density) / rho * g; };
    const TerminalState terminal = terminal_velocity(law_model, d, rho, g);
    EXPECT_EQ(terminal.regime, law == DragLaw::ZhangLi ? TerminalRegime::AtJump : TerminalRegime::Moving);
    const SphereDrag drag{&law_model, d, {}};
    // The relaxation time m / (3 pi eta d) is about 8 s here: run 300 s.
    for (double dt : {1e-3, 0.1, 1.0}) {
      State s;
      run(drag, mass, accel, dt, static_cast<int>(300.0 / dt), s);
      EXPECT_NEAR(-s.v[2], terminal.speed, 1e-9 * terminal.speed) << drag_law_name(law) << " dt " << dt;
    }
  }
}

TEST_F(Bingham, SphereThrownUpwardStopsWithoutChattering)
{
  const double rho = density_for_yield_number(0.2);    // deeply stuck under gravity
  const double mass = rho * sphere_volume(d);
  const SphereDrag drag{&model, d, {}};
  auto accel = [&](const double *, double *a) { a[0] = a[1] = 0; a[2] = -(rho - clay.density) / rho * g; };
  State s;
  s.v[2] = 0.5;
  s.v[0] = 0.1;
  run(drag, mass, accel, 1e-3, 2000, s);
  for (double v : s.v) EXPECT_EQ(v, 0.0);
  const double x_stop = s.x[2];
  EXPECT_GT(x_stop, 0.0);
  run(drag, mass, accel, 1e-3, 2000, s);
  EXPECT_EQ(s.x[2], x_stop);
}

TEST_F(Bingham, BalanceInsideTheCdJumpStaysAtTheJumpForEveryStep)
{
  std::array<ForceJump, DragModel::max_jumps> jumps;
  ASSERT_EQ(model.jumps(d, jumps), 2);
  for (int j = 0; j < 2; ++j) {
    const double drive = 0.5 * (jumps[j].force_below + jumps[j].force_above);
    const double rho = clay.density + drive / (g * sphere_volume(d));
    const double mass = rho * sphere_volume(d);
    const SphereDrag drag{&model, d, {}};
    auto accel = [&](const double *, double *a) { a[0] = a[1] = 0; a[2] = -(rho - clay.density) / rho * g; };
    for (double dt : {1e-5, 1e-4, 1e-2, 1.0}) {
      State s;
      run(drag, mass, accel, dt, std::max(200, static_cast<int>(3.0 / dt)), s);
      double vmax = 0.0;
      for (int n = 0; n < 200; ++n) {
        run(drag, mass, accel, dt, 1, s);
        vmax = std::max(vmax, std::abs(-s.v[2] - jumps[j].speed));
      }
      EXPECT_LT(vmax, 1e-9 * jumps[j].speed) << "jump " << j << " dt " << dt;
    }
  }
}

TEST(Integrator, RotationDecaysExactly)
{
  const double alpha[3] = {0, 0, 0};
  double omega[3] = {1.0, 0.0, -2.0};
  const double rate = 50.0, dt = 0.3;
  const double weight = rotation_step_initial(rate, alpha, dt, omega);
  EXPECT_NEAR(omega[0], std::exp(-rate * dt), 1e-15);
  EXPECT_NEAR(weight, dt * phi2(rate * dt), 1e-16);
  EXPECT_DOUBLE_EQ(rotation_step_initial(0.0, alpha, dt, omega), 0.5 * dt);
}

TEST(Integrator, PhiFunctionsAreSmoothAcrossTheSeriesSwitches)
{
  // References in long double: the direct formulas where they do not cancel, else the series.
  for (double z : {0.0, 1e-12, 1e-4, 9.76e-4, 9.78e-4, 9.99e-4, 0.0624, 0.0626, 0.1, 0.4999, 0.5001, 2.0, 10.0, 1e6}) {
    const long double x = z;
    long double p1 = 0.0L, p2 = 0.0L, term1 = 1.0L, term2 = 0.5L;
    if (z > 1.0) {
      p1 = (1.0L - std::exp(-x)) / x;
      p2 = (x - 1.0L + std::exp(-x)) / (x * x);
    } else {
      for (int n = 0; n < 30; ++n) {    // phi1 = sum (-z)^n/(n+1)!, phi2 = sum (-z)^n/(n+2)!
        p1 += term1;
        p2 += term2;
        term1 *= -x / (n + 2);
        term2 *= -x / (n + 3);
      }
    }
    EXPECT_NEAR(phi1(z), static_cast<double>(p1), 1e-15) << z;
    EXPECT_NEAR(phi2(z), static_cast<double>(p2), 4e-15) << z;
  }
}

// Within the series' range phis() takes phi2 from as many terms as round-off needs and phi1 = 1 - z phi2,
// e^-z = 1 - z phi1 from it: each within about one ulp of the exact values (a long double series) at
// every term count, for either sign of z.
TEST(Integrator, PhiFunctionsOfTheSeriesAreRoundedWithinAnUlp)
{
  double worst[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i <= 40000; ++i) {
    const double size = std::pow(10.0, -12.0 + 11.69 * i / 40000.0);    // 1e-12 to 0.49
    for (double z : {size, -size}) {
      const long double x = z;
      long double p1 = 0.0L, p2 = 0.0L, term1 = 1.0L, term2 = 0.5L;
      for (int n = 0; n < 40; ++n) {
        p1 += term1;
        p2 += term2;
        term1 *= -x / (n + 2);
        term2 *= -x / (n + 3);
      }
      const long double exact[3] = {1.0L - x * p1, p1, p2};
      const Phi p = phis(z);
      const double got[3] = {p.decay, p.phi1, p.phi2};
      for (int k = 0; k < 3; ++k) {
        const double ulp = std::nextafter(static_cast<double>(exact[k]), 2.0) - static_cast<double>(exact[k]);
        worst[k] = std::max(worst[k], static_cast<double>(std::abs(got[k] - exact[k]) / ulp));
      }
    }
  }
  EXPECT_LT(worst[0], 1.2) << "e^-z";
  EXPECT_LT(worst[1], 1.0) << "phi1";
  EXPECT_LT(worst[2], 1.0) << "phi2";
}

TEST(Integrator, PhiFunctionsPastTheUnderflowOfTheExponentialAreTheDirectForms)
{
  // Within 4 ulp of the direct forms (phis multiplies by 1 / z instead of dividing twice), also
  // where z^2 overflows (the direct form gives 0 there, phis 1 / z).
  for (double z : {745.0, 745.2, 745.3, 1e4, 2.4e5, 1e300}) {
    const double decay = std::exp(-z);
    const Phi p = phis(z);
    EXPECT_EQ(p.decay, decay) << z;
    EXPECT_DOUBLE_EQ(p.phi1, (1.0 - decay) / z) << z;
    EXPECT_DOUBLE_EQ(p.phi2, (z - 1.0 + decay) / z / z) << z;
  }
}

TEST(Integrator, PhiMemoGivesTheSameStepAndFollowsTheRate)
{
  double memo[PHI_MEMO_SIZE] = {std::nan(""), 0.0, 0.0, 0.0};
  for (double z : {0.3, 0.3, 2.0, 1e-9, 2.0}) {
    const Phi direct = phis(z);
    const Phi remembered = phis(z, memo);
    EXPECT_EQ(remembered.decay, direct.decay) << z;
    EXPECT_EQ(remembered.phi1, direct.phi1) << z;
    EXPECT_EQ(remembered.phi2, direct.phi2) << z;
    EXPECT_EQ(memo[0], z);
  }
  // A stale memo is never used for another z, even one that differs in the last bit.
  const double z = 0.7;
  phis(z, memo);
  const double next = std::nextafter(z, 1.0);
  EXPECT_EQ(phis(next, memo).decay, phis(next).decay);
  EXPECT_EQ(memo[0], next);
}

// The packed weights an integrator keeps per sphere between the halves add what the weights add,
// to rounding, for either sign of along - across and of the force's projection on the slip, and
// exactly for isotropic weights; a held sphere (both weights 0) gets nothing.
TEST(Integrator, PackedWeightsAddTheWeightedAcceleration)
{
  const double s = 1.0 / std::sqrt(3.0);
  const double dir[3] = {s, -s, s};
  const double scale = 7.5e12;    // 1 / m of a 30 um grain
  for (const auto [along, across] : std::vector<std::pair<double, double>>{
           {2e-5, 5e-5}, {5e-5, 2e-5}, {5e-5, 5e-5}, {0.0, 0.0}, {3e-5, 0.0}, {0.0, 3e-5}}) {
    for (const double sign : {1.0, -1.0}) {
      const double a[3] = {sign * 0.3, -sign * 2.0, sign * 9.81};    // a . dir of either sign
      StepCorrection corr;
      corr.along = along;
      corr.across = across;
      std::copy(dir, dir + 3, corr.dir);
      const double v0[3] = {1e-3, -2e-3, 4e-3};
      double direct[3], packed_v[3], packed[PACKED_WEIGHTS_SIZE];
      std::copy(v0, v0 + 3, direct);
      std::copy(v0, v0 + 3, packed_v);
      add_weighted_acceleration(along * scale, across * scale, dir, a, direct);
      pack_weights(corr, scale, packed);
      add_packed_weighted_acceleration(packed, a, packed_v);
      for (int k = 0; k < 3; ++k) {
        const double added = direct[k] - v0[k];
        if (along == across)
          EXPECT_EQ(packed_v[k], direct[k]) << along << " " << k;
        else    // a few ulp of the largest term added
          EXPECT_NEAR(packed_v[k] - v0[k], added, 1e-14 * std::max(along, across) * scale * 10.0)
              << along << " " << across << " " << sign << " " << k;
      }
    }
  }
}

TEST(Integrator, PackedIsotropicWeightsKeepTheSignOfZero)
{
  // Isotropic weights (held: both 0; linear: equal) add exactly across a, as add_weighted_acceleration
  // does, down to the sign of a zero velocity.
  for (const double weight : {0.0, 3e-5}) {
    StepCorrection corr;
    corr.along = corr.across = weight;
    double packed[PACKED_WEIGHTS_SIZE];
    pack_weights(corr, 7.5e12, packed);
    const double a[3] = {-0.0, 0.0, -9.81};
    double direct[3] = {-0.0, -0.0, 0.0}, packed_v[3] = {-0.0, -0.0, 0.0};
    add_weighted_acceleration(weight * 7.5e12, weight * 7.5e12, corr.dir, a, direct);
    add_packed_weighted_acceleration(packed, a, packed_v);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(packed_v[k], direct[k]) << weight << " " << k;
      EXPECT_EQ(std::signbit(packed_v[k]), std::signbit(direct[k])) << weight << " " << k;
    }
  }
}

// A sphere on a linear spring under Stokes drag, advanced by the drag step with the spring force
// explicit (as LAMMPS computes contact forces between the halves): largest |x| over many steps.
static double spring_amplitude(double omega, double rate, double dt, int steps)
{
  const double d = 1e-4, mass = 2650.0 * sphere_volume(d);
  const double viscosity = rate * mass / (3.0 * pi * d);
  const DragModel model(DragLaw::Stokes, Fluid{1000.0, viscosity, 0.0});
  const SphereDrag drag{&model, d, {}};
  const double u[3] = {0.0, 0.0, 0.0};
  double x = 1.0, v[3] = {0.0, 0.0, 0.0}, largest = 0.0;
  for (int n = 0; n < steps; ++n) {
    double a[3] = {-omega * omega * x, 0.0, 0.0}, dx[3];
    const StepCorrection corr = drag_step_initial(drag, 1.0 / mass, a, u, dt, v, dx);
    x += dx[0];
    a[0] = -omega * omega * x;
    drag_step_final(corr, a, v);
    largest = std::max(largest, std::abs(x));
  }
  return largest;
}

TEST(Integrator, SpringStepLimitSeparatesBoundedFromGrowingMotion)
{
  const double omega = 1e4;
  // From no drag through critical damping (rate = 2 omega) to a drag 1000 times overdamping.
  for (double rate : {0.0, 0.3 * omega, 2.0 * omega, 30.0 * omega, 1e3 * omega}) {
    const double limit = spring_step_limit(omega, rate);
    EXPECT_LT(spring_amplitude(omega, rate, 0.98 * limit, 20000), 10.0) << rate;    // Verlet: 5 at 0.98
    EXPECT_GT(spring_amplitude(omega, rate, 1.02 * limit, 20000), 1e3) << rate;
  }
  EXPECT_NEAR(spring_step_limit(omega, 0.0), 2.0 / omega, 1e-12 / omega);    // velocity Verlet
  // Overdamped: the spring relaxes at omega^2 / rate, and the step is bounded by twice its inverse.
  const double rate = 1e4 * omega;
  EXPECT_NEAR(spring_step_limit(omega, rate), 2.0 * rate / (omega * omega), 1e-3 * 2.0 * rate / (omega * omega));
  EXPECT_EQ(spring_step_limit(0.0, rate), std::numeric_limits<double>::infinity());    // no spring
}

