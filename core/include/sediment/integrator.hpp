// SPDX-License-Identifier: GPL-2.0-or-later
// Drag-implicit time step for one sphere, split like velocity Verlet so that LAMMPS can compute
// the non-drag forces between the two halves.
//
// The slip w = v - u obeys m dw/dt = f(t) - F(|w|) w/|w|. Over a step the drag is linearised
// around the slip at the start (Newton: tangent rate F'(s)/m along the slip, secant rate
// F(s)/(s m) across it) and the resulting linear ODE is integrated exactly with the force
// interpolated linearly in time (exponential time differencing, ETD2):
//   v(dt) = u + w e^{-z} + dt [(phi1 - phi2) a_n + phi2 a_{n+1}],  z = k dt,
//   x(dt) = x + u dt + dt phi1 w + dt^2 phi2 a_n,
// with phi1 = (1 - e^{-z}) / z and phi2 = (z - 1 + e^{-z}) / z^2. This is exact for a constant
// force with linear drag at any dt, second order otherwise, and velocity Verlet when k = 0.
// Along the slip the step is advanced piecewise through the points where the force curve is
// set-valued: at rest under a yield stress (a sphere sticks while |f| <= F(0+)) and at Cd jumps
// (the speed is held at the jump while the drive lies inside the jump). A held sphere does not
// take the Verlet correction, so it stays exactly still instead of chattering.
#pragma once

#include "sediment/batch_math.hpp"
#include "sediment/drag.hpp"
#include "sediment/geometry.hpp"

#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace sediment {

double phi1(double z);
double phi2(double z);

// e^{-z}, phi1(z) and phi2(z) from one exponential.
struct Phi {
  double decay;
  double phi1;
  double phi2;
};
Phi phis(double z);
// phis of n rates at once, as three arrays, their exponentials taken together (exp_many of this
// kind): within a few ulp of phis.
void phis_many(const double *z, double *decay, double *phi1, double *phi2, int n,
               BatchMath kind = batch_math_kind());

// phis(z) remembered for the last z a sphere saw, in memo = {z, decay, phi1, phi2} (z NaN: empty).
// With a fixed step and a linear drag z does not change, so the exponential is taken once.
constexpr int PHI_MEMO_SIZE = 4;
inline Phi phis(double z, double memo[PHI_MEMO_SIZE])
{
  if (z != memo[0]) {
    const Phi p = phis(z);
    memo[0] = z;
    memo[1] = p.decay;
    memo[2] = p.phi1;
    memo[3] = p.phi2;
  }
  return {memo[1], memo[2], memo[3]};
}

// The drag seen by one sphere during a step.
struct SphereDrag {
  const DragModel *model = nullptr;    // nullptr: no drag (plain velocity Verlet)
  double diameter = 0.0;
  DragScale scale;
};

enum class SlipState { Free, Stuck, HeldAtJump };

// What the first half of the step leaves for the second: the weights of a_{n+1} along and
// across the slip direction. Zero weights mean the sphere is held (stuck or at a jump).
struct StepCorrection {
  double along = 0.0;
  double across = 0.0;
  double dir[3] = {0.0, 0.0, 1.0};
  SlipState state = SlipState::Free;
};

inline double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The factors of a half step as LAMMPS's fix nve/sphere takes them: dtf = dt ftm2v / 2 weighs f / m,
// dtf / I* weighs the torque over m r^2 (I* = 2/5, a solid sphere's inertia over m r^2). Taken once
// per half step: the compiler may not hoist a division out of a loop over the atoms.
struct HalfKick {
  double ftm2v;    // force over mass to acceleration (LAMMPS's force->ftm2v; 1 in coherent units)
  double dtf;
  double dtfrotate;
};
inline HalfKick half_kick(double dt, double ftm2v)
{
  const double dtf = 0.5 * dt * ftm2v;
  return {ftm2v, dtf, dtf / solid_sphere_inertia};
}
// fix nve/sphere's weight of the torque in a half step's kick of a sphere's rotation.
inline double spin_weight(const HalfKick &kick, double radius, double mass)
{
  return kick.dtfrotate / (radius * radius * mass);
}
// The sum of a sphere's position and velocity: NaN or inf when any of them is (or when it overflows).
inline double state_sum(const double x[3], const double v[3]) { return (x[0] + x[1] + x[2]) + (v[0] + v[1] + v[2]); }

// The weights of a_{n+1} in 4 doubles per sphere (pack_weights, below).
constexpr int PACKED_WEIGHTS_SIZE = 4;

// The per-atom arrays of the spheres a DragBlock takes through a whole first half of the step
// (DragBlock::step_spheres), as LAMMPS keeps them: indexed by atom, rows of 3 doubles one after
// the other. No two of them overlap.
struct SphereRows {
  double (*x)[3];
  double (*v)[3];
  double (*omega)[3];
  const double (*force)[3];
  const double (*torque)[3];
  const double *radius;
  const double *mass;
  const double *fraction;    // the local solid fraction of a hindrance, or nullptr (clear fluid)
  double max_fraction;       // where the fraction is capped (voidage_of)
  double (*weights)[PACKED_WEIGHTS_SIZE];    // written: each sphere's packed weights per unit mass
  // Each sphere's own fluid velocity (a fix fluid/flow's), held over the step, or nullptr: the block's
  // (set_law). With it, a sphere is stepped in its fluid's frame, where the block's velocity is zero.
  const double (*flow)[3] = nullptr;
};

// The slip's exact advance over t under ds/dt = c - k s from s0, given p = phis(k t).
struct Segment {
  double speed;
  double distance;
};
inline Segment advance(const Phi &p, double s0, double c, double t)
{
  return {s0 * p.decay + c * t * p.phi1, s0 * t * p.phi1 + c * t * t * p.phi2};
}

// drag_step_initial for a law with set-valued points (a yield stress or a Cd jump): Newton
// linearisation, advanced piecewise between the points (out of line).
StepCorrection set_valued_step_initial(const SphereDrag &drag, double mass, const double a[3],
                                       const double u[3], double dt, double v[3], double dx[3]);

// The step of a nonlinear law for a block of spheres under one law, held as a structure of arrays:
// each stage (slip and direction, the law's curve, the rates, their exponentials, the advance) is
// one loop over the block of independent spheres, which the compiler turns into vector instructions
// and the processor overlaps, instead of one long chain of square roots, divisions and exponentials
// per sphere. One evaluation of the law gives the Newton rate along the slip, F'(s) / m, and the
// secant rate across it, F(s) / (s m), from k, G and Re G' (DragModel::smooth_drag_per_speed).
// A law with set-valued points (a Cd jump, a yield stress) takes the same one-piece step, which is
// the first piece of set_valued_step_initial; a sphere whose step meets such a point (its Reynolds
// number reaches or sits on a jump, it starts at rest or would stop under the yield stress) is then
// stepped again alone, in pieces, from its state at the start. Rare in a settling scene: the
// Reynolds numbers of the grains stay on one branch of the law. So the arithmetic of each sphere
// does not depend on the block it is in, nor on where.
// The spheres of a block share their law and the fluid's velocity (one fluid/drag fix).
class DragBlock {
 public:
  static constexpr int capacity = 32;

  int size() const { return size_; }
  bool full() const { return size_ == capacity; }
  void clear() { size_ = 0; }
  // The law of every sphere of the block (a nonlinear one) and the velocity u of the fluid around
  // them; set while the block is empty. `fluid_jumps`: each sphere's fluid velocity may have jumped
  // since its last step (a fix fluid/flow's new solve), and a step whose start lies far from its end
  // is taken again, linearised at its end (relinearize_at_end).
  void set_law(const DragModel &model, const double u[3], bool fluid_jumps = false)
  {
    model_ = &model;
    keeps_for_pieces_ = !model.smooth();
    fluid_jumps_ = fluid_jumps;
    for (int k = 0; k < 3; ++k) u_[k] = u[k];
  }
  const DragModel *law() const { return model_; }
  // Adds a sphere (drag.model the block's law) with its velocity v, the non-drag acceleration a_n and
  // 1 / m; returns its place in the block.
  int add(const SphereDrag &drag, double inverse_mass, const double a[3], const double v[3])
  {
    const int n = add_for_one_piece(drag, inverse_mass, a, v);
    if (keeps_for_pieces_) keep_for_pieces(n, drag, inverse_mass);
    return n;
  }
  // add() for a block whose law is smooth (law()->smooth()), which keeps nothing for a step in pieces:
  // a caller that knows it saves the test per sphere.
  int add_smooth(const SphereDrag &drag, double inverse_mass, const double a[3], const double v[3])
  {
    assert(!keeps_for_pieces_);
    return add_for_one_piece(drag, inverse_mass, a, v);
  }
  // Steps every sphere of the block over dt. The kind sets the exponentials and logarithms
  // (exp_many) and, with AVX2 or AVX-512, the block's arithmetic runs in 4- or 8-wide vectors: the
  // same operations without fused multiply-adds, rounded as in the default build (the vector exp and
  // log of each kind may differ in the last bit).
  void step(double dt, BatchMath kind = batch_math_kind());
  // After step(): the mid-step velocity, the displacement and the weights of a_{n+1} of sphere n.
  void velocity(int n, double v[3]) const { copy3(mid_v_, n, v); }
  void displacement(int n, double dx[3]) const { copy3(dx_, n, dx); }
  StepCorrection correction(int n) const
  {
    StepCorrection corr;
    corr.along = along_[n];
    corr.across = across_[n];
    copy3(dir_, n, corr.dir);
    if (in_pieces_ && meets_point_[n]) corr.state = state_[n];
    return corr;
  }
  // Whether some sphere of the last step was stepped in pieces: else every correction's state is Free,
  // and a caller may take it so (correction(n) tests each sphere).
  bool stepped_in_pieces() const { return in_pieces_; }

  // The first half of the step of the atoms atoms[0..count) of rows (count <= capacity, increasing),
  // with the block empty and its law smooth: each wholly immersed, of diameter 2 radius, its
  // acceleration force ftm2v / mass. Its drag step as add_smooth, step and velocity, displacement
  // and correction give it, then fix nve/sphere's kick of its rotation (spin_weight), bit for bit:
  // x and v advanced, omega kicked, its weights packed per unit mass into rows.weights; with rows.flow
  // (the block's velocity then zero), in the frame of each sphere's fluid, as above. Leaves the
  // block empty; returns the sum of the spheres' new state_sums (a check of a finite state).
  // Loops over the block's spheres in vectors of the kind's width, as the stages: consecutive atoms
  // (the common case) as rows one after the other.
  double step_spheres(const SphereRows &rows, const int *atoms, int count, const HalfKick &kick, double dt,
                      BatchMath kind = batch_math_kind());

 private:
  // What the one-piece step needs of a sphere, as the next of the block or in place n.
  int add_for_one_piece(const SphereDrag &drag, double inverse_mass, const double a[3], const double v[3])
  {
    const int n = size_++;
    set_for_one_piece(n, drag, inverse_mass, a, v);
    return n;
  }
  void set_for_one_piece(int n, const SphereDrag &drag, double inverse_mass, const double a[3], const double v[3])
  {
    for (int k = 0; k < 3; ++k) {
      v_[k][n] = v[k];
      a_[k][n] = a[k];
    }
    reynolds_per_speed_[n] = drag.model->smooth_reynolds_per_speed(drag.diameter);
    rate_per_g_[n] = drag.model->smooth_drag_per_speed(drag.diameter, drag.scale) * inverse_mass;
    voidage_[n] = drag.scale.voidage;
  }
  static void copy3(const double (&from)[3][capacity], int n, double to[3])
  {
    to[0] = from[0][n];
    to[1] = from[1][n];
    to[2] = from[2][n];
  }
  // What the step in pieces and the yield terms of the rates need of a sphere under a law with
  // set-valued points, besides its start (v_, a_).
  void keep_for_pieces(int n, const SphereDrag &drag, double inverse_mass)
  {
    diameter_[n] = drag.diameter;
    area_[n] = drag.scale.area;
    wetted_[n] = drag.scale.wetted;
    inverse_mass_[n] = inverse_mass;
  }
  // step_spheres in parts: its loads and stores over atoms atom(n), and the whole for an instruction set.
  template <class Atom>
  void add_spheres(Atom atom, int count, double ftm2v, const double (*v)[3], const double (*flow)[3],
                   const double (*force)[3], const double *radius, const double *mass, const double *fraction,
                   double max_fraction);
  template <class Atom>
  double finish_spheres(Atom atom, HalfKick kick, double dt, double (*x)[3], double (*v)[3], const double (*flow)[3],
                        double (*omega)[3], const double (*torque)[3], const double *radius, const double *mass,
                        double (*weights)[PACKED_WEIGHTS_SIZE]) const;
  template <class Atom>
  double step_spheres_of(const SphereRows &rows, Atom atom, int count, const HalfKick &kick, double dt, BatchMath kind);
  struct ConsecutiveAtoms {
    int first;
    int operator()(int n) const { return first + n; }
  };
  struct ListedAtoms {
    const int *atoms;
    int operator()(int n) const { return atoms[n]; }
  };
  double step_spheres_in(const SphereRows &rows, const int *atoms, int count, const HalfKick &kick, double dt,
                         BatchMath kind);
  double step_spheres_avx2(const SphereRows &rows, const int *atoms, int count, const HalfKick &kick, double dt);
  double step_spheres_avx512(const SphereRows &rows, const int *atoms, int count, const HalfKick &kick, double dt);
  // The stages, inlined into the step of each instruction set (integrator.cpp).
  void stages(const DragModel &model, double dt, BatchMath kind);
  void stages_avx2(const DragModel &model, double dt);
  void stages_avx512(const DragModel &model, double dt);
  template <bool yield> void stages_of(const DragModel &model, double dt, BatchMath kind);
  void slip();
  template <bool yield> void rates(const DragModel &model, double dt, BatchMath kind);
  void split_rates(const DragModel &model, double dt, BatchMath kind);
  void advance_all(double dt);
  void relinearize_at_end(const DragModel &model, double dt, BatchMath kind);
  template <bool yield> void find_set_valued_points(const DragModel &model, double dt);
  void step_in_pieces(const DragModel &model, double dt);

  const DragModel *model_ = nullptr;
  bool keeps_for_pieces_ = false;    // the law has set-valued points
  bool fluid_jumps_ = false;         // set_law
  int size_ = 0;
  // The last step's law has set-valued points, and some sphere's step met one (meets_point_, state_):
  // keeps_for_pieces_ && any_meets_point_, kept as one flag because correction() reads it per sphere
  // (derived there, the finish loop ran one instruction more per sphere: cachegrind, nonlinear scene).
  bool in_pieces_ = false;
  std::int64_t any_meets_point_ = 0;
  double u_[3] = {0.0, 0.0, 0.0};    // the flow
  // Per sphere, component first: velocity at the start and at mid-step (after step()), a_n, direction
  // of the slip, displacement.
  double v_[3][capacity], mid_v_[3][capacity], a_[3][capacity], dir_[3][capacity], dx_[3][capacity];
  double reynolds_per_speed_[capacity], rate_per_g_[capacity], voidage_[capacity];    // K, k / m, eps
  double speed_[capacity], a_par_[capacity], reynolds_[capacity];
  DragCurve curve_[capacity];
  double c_[capacity];                                       // ds/dt = c - rate_along s
  double z_[2][capacity];                                    // rates x dt along and across the slip
  double decay_[2][capacity], phi1_[2][capacity], phi2_[2][capacity];
  double along_[capacity], across_[capacity];
  // Under a law with set-valued points (keep_for_pieces): the sphere's drag; under a yield stress, s_y
  // and F_y / m (see DragModel::smooth_drag_per_speed); whether its step meets a set-valued point (64
  // bits, as a lane of doubles, for the vector loop that finds it) and then the state its step in
  // pieces ends in.
  double diameter_[capacity], area_[capacity], wetted_[capacity], inverse_mass_[capacity];
  double yield_speed_[capacity], yield_accel_[capacity];
  std::int64_t meets_point_[capacity];
  SlipState state_[capacity];
};

// The step of a nonlinear law for one sphere (a block of one).
StepCorrection nonlinear_step_initial(const SphereDrag &drag, double inverse_mass, const double a[3],
                                      const double u[3], double dt, double v[3], double dx[3],
                                      bool fluid_jumps = false);

// Which step a sphere's drag takes.
enum class StepKind { Free, Linear, Smooth, SetValued };
inline bool drag_acts(const SphereDrag &drag)
{
  return drag.model != nullptr && (drag.scale.area > 0.0 || drag.scale.wetted > 0.0);
}
inline StepKind step_kind(const SphereDrag &drag)
{
  if (!drag_acts(drag)) return StepKind::Free;
  if (drag.model->linear_coefficient(drag.diameter, drag.scale) > 0.0) return StepKind::Linear;
  return drag.model->smooth() ? StepKind::Smooth : StepKind::SetValued;
}
// A sphere at rest in a fluid with a yield stress mostly stays stuck: the step in pieces decides that
// at once, where a block would first take its one-piece step and then step it again in pieces.
inline bool at_rest_under_yield(const SphereDrag &drag, const double v[3], const double u[3])
{
  return drag.model->fluid().yield_stress > 0.0 && v[0] == u[0] && v[1] == u[1] && v[2] == u[2];
}
// Whether a DragBlock steps this sphere.
inline bool steps_in_block(const SphereDrag &drag, const double v[3], const double u[3])
{
  const StepKind kind = step_kind(drag);
  return kind == StepKind::Smooth || (kind == StepKind::SetValued && !at_rest_under_yield(drag, v, u));
}

// Drag linear in the slip, F = c w: the step with equal rates along and across the slip and no
// set-valued points, in closed form, given p = phis(c dt / m).
inline StepCorrection linear_step_initial(const Phi &p, const double a[3], const double u[3], double dt, double v[3],
                                          double dx[3])
{
  // Copies first: the stores into v could alias u or a, which would then be read anew each time.
  const double flow[3] = {u[0], u[1], u[2]}, accel[3] = {a[0], a[1], a[2]};
  const double slip[3] = {v[0] - flow[0], v[1] - flow[1], v[2] - flow[2]};
  const double weight_now = dt * (p.phi1 - p.phi2), weight_drift = dt * p.phi2;
  for (int k = 0; k < 3; ++k) {
    v[k] = flow[k] + slip[k] * p.decay + weight_now * accel[k];
    dx[k] = dt * (flow[k] + p.phi1 * slip[k] + weight_drift * accel[k]);
  }
  StepCorrection corr;
  corr.along = corr.across = weight_drift;
  return corr;
}

// First half: advances x by dx and replaces v with the mid-step velocity, given the non-drag
// acceleration a_n = f_n / m, 1 / m and the uniform fluid velocity u. A memo (see phis) saves the
// exponential of a linear drag from step to step. Inline: the per-atom loops of the integrator
// take the linear and no-drag cases without a call, and without a division (1 / m is shared with
// the caller's a_n).
inline StepCorrection drag_step_initial(const SphereDrag &drag, double inverse_mass, const double a[3],
                                        const double u[3], double dt, double v[3], double dx[3],
                                        double *memo = nullptr, bool fluid_jumps = false)
{
  if (!drag_acts(drag)) {
    for (int k = 0; k < 3; ++k) {
      v[k] += 0.5 * dt * a[k];
      dx[k] = dt * v[k];
    }
    StepCorrection corr;
    corr.along = corr.across = 0.5 * dt;
    return corr;
  }
  // The law's linear coefficient taken once: it also tells the kind of step (step_kind).
  const double linear = drag.model->linear_coefficient(drag.diameter, drag.scale);
  if (!(linear > 0.0)) {
    if (at_rest_under_yield(drag, v, u)) return set_valued_step_initial(drag, 1.0 / inverse_mass, a, u, dt, v, dx);
    return nonlinear_step_initial(drag, inverse_mass, a, u, dt, v, dx, fluid_jumps);
  }
  const double z = linear * inverse_mass * dt;
  return linear_step_initial(memo ? phis(z, memo) : phis(z), a, u, dt, v, dx);
}

// Second half: adds the weighted acceleration a_{n+1} = f_{n+1} / m, weight `along` along the
// direction dir (read only when the weights differ) and `across` across it, written as the isotropic
// part plus the excess along dir (fewer operations than the two projections). Values copied first:
// the stores into v could alias the other arrays, which would then be read anew after each store.
inline void add_weighted_acceleration(double along, double across, const double dir[3], const double a[3],
                                      double v[3])
{
  const double accel[3] = {a[0], a[1], a[2]};
  if (along == across) {    // isotropic: linear drag, no drag, or held
    for (int k = 0; k < 3; ++k) v[k] += along * accel[k];
    return;
  }
  const double d[3] = {dir[0], dir[1], dir[2]};
  const double excess = (along - across) * dot(accel, d);
  for (int k = 0; k < 3; ++k) v[k] += across * accel[k] + excess * d[k];
}
inline void drag_step_final(const StepCorrection &corr, const double a[3], double v[3])
{
  add_weighted_acceleration(corr.along, corr.across, corr.dir, a, v);
}

// The weights of a_{n+1} (a StepCorrection's, times `scale`) in 4 doubles, for a caller that keeps
// them per sphere from one half of the step to the other: the weight across the slip with the sign
// of along - across (a weight is never negative: phi2 > 0 at every rate), and the slip direction
// times sqrt|along - across|. Half a 64-byte cache line per sphere, where the two weights and the
// direction took 5 doubles: the memory traffic between the halves is what a cheap step waits on.
inline void pack_weights(const StepCorrection &corr, double scale, double packed[PACKED_WEIGHTS_SIZE])
{
  const double along = corr.along * scale, across = corr.across * scale;
  const double root = std::sqrt(std::abs(along - across));
  packed[0] = std::copysign(across, along - across);
  for (int k = 0; k < 3; ++k) packed[1 + k] = corr.dir[k] * root;
}
// add_weighted_acceleration from packed weights: the same to rounding (the square root and its
// square), and exactly the same when the weights are isotropic (linear drag, no drag, or held).
inline void add_packed_weighted_acceleration(const double packed[PACKED_WEIGHTS_SIZE], const double a[3],
                                             double v[3])
{
  const double accel[3] = {a[0], a[1], a[2]};
  const double across = std::abs(packed[0]);
  const double scaled_dir[3] = {packed[1], packed[2], packed[3]};
  // Without a branch, so that loops over many spheres take it in vectors: the direction all == 0.0
  // (either sign) tested with & (&& would branch), and the excess's sign (that of along - across) by a
  // product with +-1, which is exact (std::signbit has no vector form).
  const bool isotropic = (scaled_dir[0] == 0.0) & (scaled_dir[1] == 0.0) & (scaled_dir[2] == 0.0);
  const double excess = dot(accel, scaled_dir) * std::copysign(1.0, packed[0]);    // (along - across) (a . dir)
  // Isotropic, the excess's term is replaced by -0.0, which leaves any sum as it is: so v takes
  // across a exactly. Through the bits: GCC turns a choice between -0.0 and the term into a masked
  // add, which AVX2 lacks, and leaves the loop scalar.
  const std::uint64_t keep = isotropic ? 0 : ~std::uint64_t{0}, negative_zero = std::uint64_t{1} << 63;
  for (int k = 0; k < 3; ++k) {
    std::uint64_t term_bits;
    const double term = excess * scaled_dir[k];
    std::memcpy(&term_bits, &term, sizeof term);
    term_bits = (term_bits & keep) | (negative_zero & ~keep);
    double kept_term;
    std::memcpy(&kept_term, &term_bits, sizeof term_bits);
    v[k] += across * accel[k] + kept_term;
  }
}

// The second half of the step of the atoms first..first + count - 1 of rows, each with the weights
// its first half packed per unit mass (DragBlock::step_spheres): add_packed_weighted_acceleration of
// its force (the step is linear in the force, so f takes the place of a = f / m), then fix
// nve/sphere's kick of its rotation. In vectors of the kind's width.
void drag_step_final_rows(const SphereRows &rows, int first, int count, const HalfKick &kick,
                          BatchMath kind = batch_math_kind());

// Largest time step at which this step is stable for a sphere on a linear spring of angular
// frequency omega (the spring force taken explicitly, as LAMMPS's contacts are) under a linear drag
// of rate `rate` (taken exactly). Over (x, dt v) the step is the matrix
//   [[1 - h^2 phi2, phi1], [-h^2 (phi1 - phi2) - h^2 phi2 (1 - h^2 phi2), e^-z - h^2 phi1 phi2]],
// h = omega dt, z = rate dt; it is stable while |trace| <= 1 + det and det <= 1. The limit is 2 / omega
// without drag (velocity Verlet) and tends to 2 rate / omega^2 when the drag overdamps the spring:
// then the spring's own relaxation, not its oscillation, sets the step. Infinite for omega = 0;
// omega and rate finite and >= 0.
double spring_step_limit(double omega, double rate);

// Rotation with a linear drag torque -k I omega: same ETD2 weights, isotropic.
// Returns the weight of alpha_{n+1} for the second half (dt / 2 when k = 0).
inline double rotation_step_initial(double rate, const double alpha[3], double dt, double omega[3],
                                    double *memo = nullptr)
{
  if (rate == 0.0) {    // phis(0) = {1, 1, 1/2}: the same values without the memo
    for (int k = 0; k < 3; ++k) omega[k] += dt * 0.5 * alpha[k];
    return dt * 0.5;
  }
  const Phi p = memo ? phis(rate * dt, memo) : phis(rate * dt);
  const double weight_now = dt * (p.phi1 - p.phi2);
  for (int k = 0; k < 3; ++k) omega[k] = omega[k] * p.decay + weight_now * alpha[k];
  return dt * p.phi2;
}

}    // namespace sediment
