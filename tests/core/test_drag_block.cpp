// SPDX-License-Identifier: GPL-2.0-or-later
// The block step (DragBlock) and the per-atom rows it steps: each sphere steps as it would alone, in
// pieces where the law has set-valued points, bit for bit alike on every instruction set, and the
// rows' second half adds the packed weights and kicks the rotation.
#include "sediment/geometry.hpp"
#include "sediment/integrator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

using namespace sediment;

namespace {

const double zero[3] = {0.0, 0.0, 0.0};
const Fluid water{1000.0, 1.0e-3, 0.0};

}    // namespace

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
                                        BatchMath kind, bool alone, bool fluid_jumps = false)
{
  const int n = static_cast<int>(spheres.size()), size = alone ? 1 : DragBlock::capacity;
  std::vector<BlockResult> out(spheres.size());
  DragBlock block;
  block.set_law(model, block_flow, fluid_jumps);
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
// its own (wherever it sits, whoever its neighbours are), also when the step is taken again after a
// fluid's jump (fluid_jumps); check(kind, sphere, result) then checks each sphere's result in blocks.
template <class Check>
void expect_blocks_step_as_alone(const DragModel &model, const std::vector<BlockSphere> &spheres, double dt,
                                 Check check, bool fluid_jumps = false)
{
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    const std::vector<BlockResult> blocks = step_in_blocks(model, spheres, dt, kind, false, fluid_jumps);
    const std::vector<BlockResult> alone = step_in_blocks(model, spheres, dt, kind, true, fluid_jumps);
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

TEST(DragBlock, AfterAFluidJumpTheStepEndsAtTheTerminalSlip)
{
  // A grain at its terminal slip whose fluid velocity jumps by 19 mm/s (a fix fluid/flow's new solve) starts its step
  // with the jump as its slip. A step of 30 Stokes relaxation times ends at the terminal slip again, within 1e-3 of
  // it (1e-6 to 6e-5 here: the iteration stops once it keeps less than 1e-3), where fluid_jumps takes the step again
  // linearised at its end. Linearised at the start alone it ends a Newton step away, off by a share of the jump: 0.46
  // and 27 terminal slips for quartz of 67 and 2.6 um under the standard curve, 0.52 and 84 under Dallavalle's, which
  // the flow solved from the drag fed back until parcels of a test's column ran away. Each sphere steps bit for bit
  // as alone, after a jump too.
  const Fluid fluid{998.2, 1.002e-3, 0.0};
  for (const DragLaw law : {DragLaw::Standard, DragLaw::Dallavalle}) {
    const DragModel model(law, fluid);
    for (const double d : {6.7e-5, 2.6e-6}) {
      SCOPED_TRACE(testing::Message() << drag_law_name(law) << " d " << d);
      const double mass = 2650.0 * sphere_volume(d), inverse_mass = 1.0 / mass;
      const double tau = mass / (3.0 * M_PI * fluid.viscosity * d), dt = 30.0 * tau;
      const double a[3] = {0.0, 0.0, -(2650.0 - 998.2) * 9.81 / 2650.0};
      const SphereDrag drag{&model, d, {}};
      // the terminal slip: steps from rest in still fluid, where the slip hardly changes from one to the next
      double terminal[3] = {0.0, 0.0, 0.0}, dx[3];
      for (int step = 0; step < 200; ++step)
        drag_step_final(drag_step_initial(drag, inverse_mass, a, zero, dt, terminal, dx), a, terminal);
      const double jump[3] = {1.2e-2, 0.0, 1.5e-2};    // the first solve's swirls in a test's column
      const double speed = std::abs(terminal[2]);
      double off[2];
      for (const bool fluid_jumps : {false, true}) {
        double v[3] = {terminal[0], terminal[1], terminal[2]};    // the fluid now moves at `jump`
        drag_step_final(nonlinear_step_initial(drag, inverse_mass, a, jump, dt, v, dx, fluid_jumps), a, v);
        off[fluid_jumps] = std::hypot(v[0] - jump[0] - terminal[0], v[1] - jump[1] - terminal[1],
                                      v[2] - jump[2] - terminal[2]) / speed;
      }
      EXPECT_LT(off[1], 1e-3);
      EXPECT_GT(off[0], 0.1);    // the defect the second linearisation mends
    }
    expect_blocks_step_as_alone(
        model, block_spheres(model), 1e-4, [](BatchMath, const BlockSphere &, const BlockResult &) {}, true);
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
  std::vector<std::array<double, 3>> flow;    // each sphere's fluid velocity (a fix fluid/flow's)
  SphereRows rows(bool hindered, bool with_flow = false)
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
            reinterpret_cast<double(*)[PACKED_WEIGHTS_SIZE]>(weights.data()),
            with_flow ? reinterpret_cast<const double(*)[3]>(flow.data()) : nullptr};
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
    atoms.flow.push_back({2e-4 * std::cos(2 * t), 0.0, (i % 3 == 1) ? -1e-3 : 5e-4 * std::sin(t)});
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
  // loads and stores) and atoms with gaps between them, under three laws, on every kind; and with a
  // fluid velocity per sphere (rows.flow), each stepped in its fluid's frame as fix nve/sphere/fluid's
  // general step does: its slip added, its velocity and displacement taken back with the flow's.
  const Fluid fluid{998.2, 1.002e-3, 0.0};
  const double dt = 1e-4, ftm2v = 1.0;
  const HalfKick kick = half_kick(dt, ftm2v);
  const int n = 2 * DragBlock::capacity + 7;
  for (const DragLaw law : {DragLaw::Dallavalle, DragLaw::Standard, DragLaw::DiFelice}) {
    const DragModel model(law, fluid);
    const bool hindered = law == DragLaw::DiFelice;
    for (const BatchMath kind : batch_math_kinds) {
      if (!batch_math_available(kind)) continue;
      for (const auto [gap, with_flow] : {std::pair{1, false}, {3, false}, {1, true}, {3, true}}) {
        // every atom, or every third
        SCOPED_TRACE(testing::Message() << drag_law_name(law) << " " << batch_math_name(kind) << " gap " << gap
                                        << (with_flow ? " with flow" : ""));
        Atoms expected = some_atoms(n), stepped = some_atoms(n);
        std::vector<int> chosen;
        for (int i = 1; i < n; i += gap) chosen.push_back(i);
        double expected_state = 0.0, state = 0.0;
        DragBlock block;
        block.set_law(model, zero, with_flow);    // each sphere's fluid velocity may have jumped
        for (size_t start = 0; start < chosen.size(); start += DragBlock::capacity) {
          const int count = static_cast<int>(std::min<size_t>(DragBlock::capacity, chosen.size() - start));
          for (int m = 0; m < count; ++m) {
            const int i = chosen[start + m];
            const double per_mass = ftm2v / expected.mass[i];
            const double a[3] = {expected.force[i][0] * per_mass, expected.force[i][1] * per_mass,
                                 expected.force[i][2] * per_mass};
            DragScale scale;
            if (hindered) scale.voidage = voidage_of(expected.fraction[i], 0.55);
            double slip[3];
            for (int k = 0; k < 3; ++k) slip[k] = expected.v[i][k] - (with_flow ? expected.flow[i][k] : 0.0);
            block.add_smooth({&model, 2.0 * expected.radius[i], scale}, per_mass, a,
                             with_flow ? slip : expected.v[i].data());
          }
          block.step(dt, kind);
          for (int m = 0; m < count; ++m) {
            const int i = chosen[start + m];
            double dx[3];
            block.velocity(m, expected.v[i].data());
            block.displacement(m, dx);
            if (with_flow)
              for (int k = 0; k < 3; ++k) {
                expected.v[i][k] += expected.flow[i][k];
                dx[k] += expected.flow[i][k] * dt;
              }
            for (int k = 0; k < 3; ++k) expected.x[i][k] += dx[k];
            expected_state += state_sum(expected.x[i].data(), expected.v[i].data());
            const double spin = spin_weight(kick, expected.radius[i], expected.mass[i]);
            for (int k = 0; k < 3; ++k) expected.omega[i][k] += spin * expected.torque[i][k];
            pack_weights(block.correction(m), ftm2v / expected.mass[i], expected.weights[i].data());
          }
          block.clear();
          state += block.step_spheres(stepped.rows(hindered, with_flow), chosen.data() + start, count, kick, dt,
                                      kind);
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
