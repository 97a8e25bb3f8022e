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

namespace {

struct BlockSphere {
  SphereDrag drag;
  double inverse_mass, a[3], v[3];
};

// The fluid's velocity, shared by the spheres of a block: across and along the drive.
const double block_flow[3] = {2e-5, 0.0, 1e-5};

// Spheres of three sizes at three voidages, with slips across, along and against the drive, at rest
// (the direction is the drive's; block_flow is among the velocities) and with no drive at all.
std::vector<BlockSphere> block_spheres(const DragModel &model)
{
  std::vector<BlockSphere> spheres;
  int k = 0;
  for (double d : {3e-6, 3e-5, 3e-4})
    for (double voidage : {1.0, 0.9, 0.6})
      for (const auto &v : {std::array<double, 3>{1e-4, 0.0, -3e-4}, std::array<double, 3>{0.0, 0.0, -2e-3},
                            std::array<double, 3>{0.0, 0.0, 5e-3},
                            std::array<double, 3>{block_flow[0], block_flow[1], block_flow[2]},
                            std::array<double, 3>{-1e-3, 2e-3, 0.5}}) {
        BlockSphere sp{{&model, d, {1.0, 1.0, voidage}}, 1.0 / (2650.0 * sphere_volume(d)), {0.0, 0.3, -6.0},
                       {v[0], v[1], v[2]}};
        if (k++ % 7 == 3) sp.a[0] = sp.a[1] = sp.a[2] = 0.0;    // no drive: at rest it stays
        spheres.push_back(sp);
      }
  return spheres;
}

struct BlockResult {
  std::array<double, 3> v, dx;
  StepCorrection corr;
};

// The spheres stepped in blocks of DragBlock::capacity, the first block starting one sphere in (so
// every place of a block is taken), or each in a block of its own.
std::vector<BlockResult> step_in_blocks(const DragModel &model, const std::vector<BlockSphere> &spheres, double dt,
                                        BatchMath kind, bool alone)
{
  const int n = static_cast<int>(spheres.size()), size = alone ? 1 : DragBlock::capacity;
  std::vector<BlockResult> out(spheres.size());
  DragBlock block;
  block.set_law(model, block_flow);
  for (int start = alone ? 0 : 1; start < n + (alone ? 0 : 1); start += size) {
    std::vector<int> members;
    for (int j = start; j < std::min(n + (alone ? 0 : 1), start + size); ++j) members.push_back(j % n);
    for (int j : members) block.add(spheres[j].drag, spheres[j].inverse_mass, spheres[j].a, spheres[j].v);
    block.step(dt, kind);
    for (size_t m = 0; m < members.size(); ++m) {
      BlockResult &r = out[members[m]];
      block.velocity(static_cast<int>(m), r.v.data());
      block.displacement(static_cast<int>(m), r.dx.data());
      r.corr = block.correction(static_cast<int>(m));
    }
    block.clear();
  }
  return out;
}

void expect_same_bits(const BlockResult &a, const BlockResult &b)
{
  EXPECT_EQ(a.corr.along, b.corr.along);
  EXPECT_EQ(a.corr.across, b.corr.across);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(a.v[c], b.v[c]);
    EXPECT_EQ(a.dx[c], b.dx[c]);
    EXPECT_EQ(a.corr.dir[c], b.corr.dir[c]);
  }
  EXPECT_EQ(a.corr.state, b.corr.state);
}

// On every kind of this processor, the spheres stepped in blocks end bit for bit as each in a block of
// its own (wherever it sits, whoever its neighbours are); check(kind, sphere, result) then checks each
// sphere's result in blocks.
template <class Check>
void expect_blocks_step_as_alone(const DragModel &model, const std::vector<BlockSphere> &spheres, double dt, Check check)
{
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    const std::vector<BlockResult> blocks = step_in_blocks(model, spheres, dt, kind, false);
    const std::vector<BlockResult> alone = step_in_blocks(model, spheres, dt, kind, true);
    for (size_t j = 0; j < spheres.size(); ++j) {
      SCOPED_TRACE(testing::Message() << batch_math_name(kind) << " sphere " << j);
      expect_same_bits(blocks[j], alone[j]);
      check(kind, spheres[j], blocks[j]);
    }
  }
}

}    // namespace

TEST(DragBlock, EachSphereStepsAsAloneAndAsTheNewtonStep)
{
  // Under Dallavalle's law and under Di Felice's, on every kind of this processor: in a block each
  // sphere steps bit for bit as in a block of one (nonlinear_step_initial, on the default kind),
  // wherever it sits and whoever its neighbours are, and as the piecewise Newton step of a law with
  // set-valued points (set_valued_step_initial: its own arithmetic, scalar exponentials; for a
  // smooth law one piece).
  const Fluid fluid{998.2, 1.002e-3, 0.0};
  const double dt = 1e-4;
  for (const DragLaw law : {DragLaw::Dallavalle, DragLaw::DiFelice}) {
    SCOPED_TRACE(drag_law_name(law));
    const DragModel model(law, fluid);
    expect_blocks_step_as_alone(model, block_spheres(model), dt, [&](BatchMath kind, const BlockSphere &sp,
                                                                     const BlockResult &block) {
      if (kind == batch_math_kind()) {
        BlockResult initial{{sp.v[0], sp.v[1], sp.v[2]}, {}, {}};
        initial.corr = nonlinear_step_initial(sp.drag, sp.inverse_mass, sp.a, block_flow, dt, initial.v.data(), initial.dx.data());
        expect_same_bits(block, initial);
      }
      double v_newton[3] = {sp.v[0], sp.v[1], sp.v[2]}, dx_newton[3];
      const StepCorrection newton =
          set_valued_step_initial(sp.drag, 1.0 / sp.inverse_mass, sp.a, block_flow, dt, v_newton, dx_newton);
      EXPECT_NEAR(block.corr.along, newton.along, 1e-12 * newton.along);
      EXPECT_NEAR(block.corr.across, newton.across, 1e-12 * newton.across);
      const double scale = std::abs(sp.v[0]) + std::abs(sp.v[1]) + std::abs(sp.v[2]) + dt * 6.0;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(block.v[c], v_newton[c], 1e-12 * scale);
        EXPECT_NEAR(block.dx[c], dx_newton[c], 1e-12 * scale * dt);
        EXPECT_NEAR(block.corr.dir[c], newton.dir[c], 1e-15);
      }
    });
  }
}

namespace {

// Spheres placed where a law's step meets its set-valued points: slips just below, on and just above
// each jump speed (along and against a drive that carries them across it, or with none), and, under a
// yield stress, spheres at rest held by it or breaking free, and spheres moving slowly against the
// drive, which stop within the step.
std::vector<BlockSphere> set_valued_spheres(const DragModel &model)
{
  std::vector<BlockSphere> spheres = block_spheres(model);
  for (double d : {3e-5, 3e-4}) {
    const double inverse_mass = 1.0 / (2650.0 * sphere_volume(d));
    std::array<ForceJump, DragModel::max_jumps> jumps;
    const int count = model.jumps(d, jumps);
    for (int j = 0; j < count; ++j)
      for (double factor : {0.999, 1.0 - 1e-13, 1.0, 1.0 + 1e-13, 1.001})
        for (double drive : {-60.0, 0.0, 60.0}) {
          // Slip along -z: a drive of -60 m/s^2 speeds it up, one of +60 slows it down.
          BlockSphere sp{{&model, d, {1.0, 1.0, 1.0}}, inverse_mass, {0.0, 0.0, drive}, {}};
          const double speed = jumps[j].speed * factor;
          for (int k = 0; k < 3; ++k) sp.v[k] = block_flow[k] - (k == 2 ? speed : 0.0);
          spheres.push_back(sp);
          // A drive inside the jump: the speed is held there.
          sp.a[2] = -0.5 * (jumps[j].force_below + jumps[j].force_above) * inverse_mass;
          spheres.push_back(sp);
        }
    const double holds = model.static_force(d) * inverse_mass;    // the largest drive the yield stress holds
    if (holds > 0.0)
      for (double factor : {0.5, 0.999, 1.001, 3.0}) {
        BlockSphere at_rest{{&model, d, {1.0, 1.0, 1.0}}, inverse_mass, {0.0, 0.6 * holds * factor, -0.8 * holds * factor},
                            {block_flow[0], block_flow[1], block_flow[2]}};
        spheres.push_back(at_rest);
        BlockSphere slow = at_rest;    // moving up against a drive down: stops within 1e-4 s, or not
        slow.v[2] += 1e-4 * holds * factor;
        spheres.push_back(slow);
      }
  }
  return spheres;
}

}    // namespace

TEST(DragBlock, LawsWithSetValuedPointsStepAsInPieces)
{
  // A block takes the one-piece Newton step of every sphere and steps again, in pieces
  // (set_valued_step_initial), those whose step meets a jump or the yield point: each sphere then ends
  // as in set_valued_step_initial, bit for bit when stepped in pieces and to round-off otherwise (one
  // piece, the same arithmetic in another order), and as in a block of its own.
  const Fluid water{998.2, 1.002e-3, 0.0}, paste{998.2, 1.002e-3, 0.01}, clay{1280.0, 0.0131, 30.5};
  const std::pair<DragLaw, Fluid> laws[] = {
      {DragLaw::SchillerNaumann, water}, {DragLaw::ZhangLi, water},       {DragLaw::ZhangLi, paste},
      {DragLaw::ZhangLi, clay},          {DragLaw::ZhangLiSmooth, paste}, {DragLaw::Stokes, paste},
      {DragLaw::Bingham, clay},          {DragLaw::Bingham, paste}};
  const double dt = 1e-4;
  int stuck = 0, held = 0, one_piece = 0;
  for (const auto &[law, fluid] : laws) {
    SCOPED_TRACE(testing::Message() << drag_law_name(law) << " tau_y " << fluid.yield_stress);
    const DragModel model(law, fluid);
    ASSERT_FALSE(model.smooth());
    expect_blocks_step_as_alone(model, set_valued_spheres(model), dt, [&](BatchMath kind, const BlockSphere &sp,
                                                                          const BlockResult &block) {
      BlockResult pieces{{sp.v[0], sp.v[1], sp.v[2]}, {}, {}};
      pieces.corr = set_valued_step_initial(sp.drag, 1.0 / sp.inverse_mass, sp.a, block_flow, dt, pieces.v.data(),
                                            pieces.dx.data());
      EXPECT_EQ(block.corr.state, pieces.corr.state);
      const double scale = std::abs(sp.v[0]) + std::abs(sp.v[1]) + std::abs(sp.v[2]) +
                           dt * (std::abs(sp.a[0]) + std::abs(sp.a[1]) + std::abs(sp.a[2]));
      if (block.v != pieces.v || block.dx != pieces.dx) {    // one piece: the same step to round-off
        ++one_piece;
        EXPECT_EQ(pieces.corr.state, SlipState::Free);
        EXPECT_NEAR(block.corr.along, pieces.corr.along, 1e-12 * pieces.corr.along);
        EXPECT_NEAR(block.corr.across, pieces.corr.across, 1e-12 * pieces.corr.across);
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(block.v[c], pieces.v[c], 1e-12 * scale);
          EXPECT_NEAR(block.dx[c], pieces.dx[c], 1e-12 * scale * dt);
        }
      }
      if (kind == batch_math_kind()) {
        stuck += pieces.corr.state == SlipState::Stuck;
        held += pieces.corr.state == SlipState::HeldAtJump;
      }
    });
  }
  // The scenes reach every kind of step.
  EXPECT_GT(stuck, 10);
  EXPECT_GT(held, 10);
  EXPECT_GT(one_piece, 100);
}

TEST(DragBlock, TheArithmeticIsTheSameOnEveryKind)
{
  // The AVX2 and AVX-512 steps run the block's arithmetic in 4- and 8-wide vectors, the other kinds
  // in the default build's (2-wide SSE2 on x86-64), a short block's tail one by one; without fused
  // multiply-adds (AVX-512 has them: -ffp-contract=off keeps them out) each operation rounds alike
  // in all of them, so where no vector exponential enters (every rate below 0.5 takes the scalar
  // series of the phi functions; Dallavalle's law takes none) the kinds agree bit for bit. Elsewhere
  // glibc's vector exp of each kind may differ from the others by an ulp, and the steps agree to
  // round-off.
  const DragModel model(DragLaw::Dallavalle, {998.2, 1.002e-3, 0.0});
  const std::vector<BlockSphere> spheres = block_spheres(model);
  const std::vector<BlockResult> scalar_small = step_in_blocks(model, spheres, 1e-9, BatchMath::Scalar, false);
  const std::vector<BlockResult> scalar = step_in_blocks(model, spheres, 1e-4, BatchMath::Scalar, false);
  int compared = 0;
  for (const BatchMath kind : batch_math_kinds) {
    if (kind == BatchMath::Scalar || !batch_math_available(kind)) continue;
    const std::vector<BlockResult> small = step_in_blocks(model, spheres, 1e-9, kind, false);
    const std::vector<BlockResult> normal = step_in_blocks(model, spheres, 1e-4, kind, false);
    for (size_t j = 0; j < spheres.size(); ++j) {
      SCOPED_TRACE(testing::Message() << batch_math_name(kind) << " sphere " << j);
      // Every rate of the small step is below 0.5 (the largest, of the finest sphere, is about 8e-4).
      expect_same_bits(small[j], scalar_small[j]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(normal[j].v[c], scalar[j].v[c], 1e-14 * (std::abs(scalar[j].v[c]) + 1e-3));
        EXPECT_NEAR(normal[j].dx[c], scalar[j].dx[c], 1e-14 * (std::abs(scalar[j].dx[c]) + 1e-7));
      }
    }
    ++compared;
  }
  if (compared == 0) GTEST_SKIP() << "no vector kind on this processor";
}

namespace {

// Per-atom arrays laid out as LAMMPS keeps them (rows of 3 one after the other), for the steps that
// take them whole (DragBlock::step_spheres, drag_step_final_rows).
struct Atoms {
  std::vector<std::array<double, 3>> x, v, omega, force, torque;
  std::vector<double> radius, mass, fraction;
  std::vector<std::array<double, PACKED_WEIGHTS_SIZE>> weights;
  SphereRows rows(bool hindered)
  {
    return {reinterpret_cast<double(*)[3]>(x.data()),
            reinterpret_cast<double(*)[3]>(v.data()),
            reinterpret_cast<double(*)[3]>(omega.data()),
            reinterpret_cast<const double(*)[3]>(force.data()),
            reinterpret_cast<const double(*)[3]>(torque.data()),
            radius.data(),
            mass.data(),
            hindered ? fraction.data() : nullptr,
            0.55,
            reinterpret_cast<double(*)[PACKED_WEIGHTS_SIZE]>(weights.data())};
  }
};

// n grains of three sizes with slips across, along and against their forces, fractions up to past
// the cap, and some torque.
Atoms some_atoms(int n)
{
  Atoms atoms;
  for (int i = 0; i < n; ++i) {
    const double d = std::array<double, 3>{3e-6, 3e-5, 3e-4}[i % 3];
    const double t = 0.37 * i;
    atoms.x.push_back({1e-3 * std::cos(t), 2e-3 * std::sin(t), 1e-2 + 1e-4 * i});
    atoms.v.push_back({1e-4 * std::sin(3 * t), -2e-4 * std::cos(t), -3e-3 * (i % 5) + 1e-3});
    atoms.omega.push_back({std::cos(t), 0.5, -std::sin(t)});
    atoms.radius.push_back(d / 2);
    atoms.mass.push_back(2650.0 * sphere_volume(d));
    const double weight = -(2650.0 - 998.2) * 9.81 * sphere_volume(d);
    atoms.force.push_back({0.1 * weight * std::sin(t), (i % 7 == 2) ? 0.0 : 0.05 * weight, weight});
    atoms.torque.push_back({1e-3 * weight * d, -2e-3 * weight * d * std::cos(t), 0.0});
    atoms.fraction.push_back(std::array<double, 4>{0.0, 0.1, 0.3, 0.7}[i % 4]);
    atoms.weights.push_back({0.0, 0.0, 0.0, 0.0});
  }
  return atoms;
}

void expect_same_atoms(const Atoms &a, const Atoms &b)
{
  for (size_t i = 0; i < a.x.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "atom " << i);
    EXPECT_EQ(a.x[i], b.x[i]);
    EXPECT_EQ(a.v[i], b.v[i]);
    EXPECT_EQ(a.omega[i], b.omega[i]);
    EXPECT_EQ(a.weights[i], b.weights[i]);
  }
}

}    // namespace

TEST(DragBlock, StepSpheresIsTheBlockStepThenTheRotationKick)
{
  // step_spheres takes LAMMPS's rows itself: bit for bit the step that add_smooth and step give each
  // sphere (1 / m, a_n and the voidage as fix nve/sphere/fluid takes them), then fix nve/sphere's kick of
  // its rotation and the weights packed per unit mass. For atoms one after the other (the vector
  // loads and stores) and atoms with gaps between them, under three laws, on every kind.
  const Fluid fluid{998.2, 1.002e-3, 0.0};
  const double dt = 1e-4, ftm2v = 1.0;
  const HalfKick kick = half_kick(dt, ftm2v);
  const int n = 2 * DragBlock::capacity + 7;
  for (const DragLaw law : {DragLaw::Dallavalle, DragLaw::Standard, DragLaw::DiFelice}) {
    const DragModel model(law, fluid);
    const bool hindered = law == DragLaw::DiFelice;
    for (const BatchMath kind : batch_math_kinds) {
      if (!batch_math_available(kind)) continue;
      for (const int gap : {1, 3}) {    // every atom, or every third
        SCOPED_TRACE(testing::Message() << drag_law_name(law) << " " << batch_math_name(kind) << " gap " << gap);
        Atoms expected = some_atoms(n), stepped = some_atoms(n);
        std::vector<int> chosen;
        for (int i = 1; i < n; i += gap) chosen.push_back(i);
        double expected_state = 0.0, state = 0.0;
        DragBlock block;
        block.set_law(model, zero);
        for (size_t start = 0; start < chosen.size(); start += DragBlock::capacity) {
          const int count = static_cast<int>(std::min<size_t>(DragBlock::capacity, chosen.size() - start));
          for (int m = 0; m < count; ++m) {
            const int i = chosen[start + m];
            const double per_mass = ftm2v / expected.mass[i];
            const double a[3] = {expected.force[i][0] * per_mass, expected.force[i][1] * per_mass,
                                 expected.force[i][2] * per_mass};
            DragScale scale;
            if (hindered) scale.voidage = voidage_of(expected.fraction[i], 0.55);
            block.add_smooth({&model, 2.0 * expected.radius[i], scale}, per_mass, a, expected.v[i].data());
          }
          block.step(dt, kind);
          for (int m = 0; m < count; ++m) {
            const int i = chosen[start + m];
            double dx[3];
            block.velocity(m, expected.v[i].data());
            block.displacement(m, dx);
            for (int k = 0; k < 3; ++k) expected.x[i][k] += dx[k];
            expected_state += state_sum(expected.x[i].data(), expected.v[i].data());
            const double spin = spin_weight(kick, expected.radius[i], expected.mass[i]);
            for (int k = 0; k < 3; ++k) expected.omega[i][k] += spin * expected.torque[i][k];
            pack_weights(block.correction(m), ftm2v / expected.mass[i], expected.weights[i].data());
          }
          block.clear();
          state += block.step_spheres(stepped.rows(hindered), chosen.data() + start, count, kick, dt, kind);
          EXPECT_EQ(block.size(), 0);
        }
        expect_same_atoms(stepped, expected);
        EXPECT_NEAR(state, expected_state, 1e-12 * std::abs(expected_state));
      }
    }
  }
}

TEST(DragBlock, StepSpheresSumsANonFiniteState)
{
  const DragModel model(DragLaw::Standard, {998.2, 1.002e-3, 0.0});
  Atoms atoms = some_atoms(DragBlock::capacity);
  atoms.v[17][1] = std::numeric_limits<double>::quiet_NaN();
  std::vector<int> all(DragBlock::capacity);
  for (int i = 0; i < DragBlock::capacity; ++i) all[i] = i;
  DragBlock block;
  block.set_law(model, zero);
  const double dt = 1e-4;
  const double state = block.step_spheres(atoms.rows(false), all.data(), DragBlock::capacity, half_kick(dt, 1.0), dt);
  EXPECT_FALSE(std::isfinite(state));
}

TEST(Integrator, FinalRowsAddThePackedWeightsAndKickTheRotation)
{
  // drag_step_final_rows: per atom add_packed_weighted_acceleration of its force and fix nve/sphere's
  // kick of its rotation, bit for bit, in vectors on every kind; a run that starts inside the arrays
  // and ends in a short tail. The weights: isotropic (held, linear), along above and below across.
  const HalfKick kick = half_kick(1e-4, 1.0);
  const int n = 45, first = 3, count = 39;
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    SCOPED_TRACE(batch_math_name(kind));
    Atoms expected = some_atoms(n);
    for (int i = 0; i < n; ++i) {
      StepCorrection corr;
      corr.along = std::array<double, 3>{2e-5, 5e-5, 0.0}[i % 3];
      corr.across = std::array<double, 4>{5e-5, 2e-5, 0.0, 3e-5}[i % 4];
      const double norm = std::sqrt(1.0 + 0.25 + i * i * 1e-2);
      corr.dir[0] = 1.0 / norm;
      corr.dir[1] = -0.5 / norm;
      corr.dir[2] = 0.1 * i / norm;
      pack_weights(corr, 1.0 / expected.mass[i], expected.weights[i].data());
    }
    // Isotropic (along == across) at i = 2, 9 and 4 among others; at 4 a velocity and force of -0.0.
    expected.v[4][0] = expected.force[4][0] = -0.0;
    Atoms stepped = expected;
    for (int i = first; i < first + count; ++i) {
      add_packed_weighted_acceleration(expected.weights[i].data(), expected.force[i].data(), expected.v[i].data());
      const double spin = spin_weight(kick, expected.radius[i], expected.mass[i]);
      for (int k = 0; k < 3; ++k) expected.omega[i][k] += spin * expected.torque[i][k];
    }
    drag_step_final_rows(stepped.rows(false), first, count, kick, kind);
    expect_same_atoms(stepped, expected);
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

