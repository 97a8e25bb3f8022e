// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix nve/sphere/fluid
   Velocity-Verlet split of the exponential (ETD2) drag step of sediment/integrator.hpp.
------------------------------------------------------------------------- */

#include "fix_nve_sphere_fluid.h"
#include "sediment_args.h"
#include "sediment_nve_sphere.h"
#include "sediment_rows.h"

#include "fix_fluid.h"
#include "fix_fluid_drag.h"

#include "sediment/batch_math.hpp"
#include "sediment/geometry.hpp"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "update.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

using namespace LAMMPS_NS;
using namespace FixConst;

using sediment::HalfKick;
using sediment::state_sum;

// The per-atom arrays both halves of the step read, taken anew in each half (exchanges move them).
// Rows of 3 (sediment_rows.h): found from the atom's index, not a row pointer.
using Rows3 = double (*)[3];

struct SphereArrays {
  Rows3 x, v, f, omega, torque;
  const double *radius, *rmass;
  const int *mask;
  int nlocal;
};

static inline SphereArrays sphere_arrays(const Atom *atom)
{
  return {flat_rows<3>(atom->x),     flat_rows<3>(atom->v),      flat_rows<3>(atom->f),
          flat_rows<3>(atom->omega), flat_rows<3>(atom->torque), atom->radius,
          atom->rmass,               atom->mask,                 atom->nlocal};
}

// The exponentials of a linear drag F = c d w for a sphere of diameter d and 1 / m, z = c d dt / m
// (the same product in both halves of the step), remembered for the last z of a loop over the atoms:
// every sphere of a monodisperse group shares it, so only a polydisperse group touches the atoms'
// own memos.
class LinearDecay {
 public:
  LinearDecay(double per_diameter, double dt) : per_diameter_(per_diameter), dt_(dt) {}
  const sediment::Phi &phis(double diameter, double per_mass, double memo[sediment::PHI_MEMO_SIZE])
  {
    const double z = per_diameter_ * diameter * per_mass * dt_;
    if (z != z_) {
      phis_ = sediment::phis(z, memo);
      z_ = z;
    }
    return phis_;
  }

 private:
  double per_diameter_, dt_;
  double z_ = std::numeric_limits<double>::quiet_NaN();
  sediment::Phi phis_{};
};

// Runs loop(std::true_type{}) with a floor and loop(std::false_type{}) without, so that a loop over
// the atoms is compiled both ways and tests for the floor only where there is one.
template <class Loop> static inline void with_floor_or_not(int floor_axis, Loop loop)
{
  if (floor_axis >= 0)
    loop(std::true_type{});
  else
    loop(std::false_type{});
}

FixNVESphereFluid::FixNVESphereFluid(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), weights(nullptr), general(nullptr), drag_memos(nullptr), spin_memos(nullptr), nmax_rows(0), uniform(nullptr),
    half_step(HalfStep::General), linear_per_diameter(0.0), floor_axis(-1), floor_level(-HUGE_VAL), surface_level(HUGE_VAL)
{
  StyleArgs args(lmp, FLERR, "Fix nve/sphere/fluid", narg, arg, 3);
  bool floor_given = false, surface_given = false;
  while (args.more()) {
    const bool floor = args.is("floor");
    if (!floor && !args.is("surface")) args.unknown("floor or surface");
    const char *what = floor ? "floor" : "surface";
    args.need(2, "an axis and a coordinate");
    if (floor ? floor_given : surface_given)
      args.fail("one {} per fix: a second {} would replace the first, not add to it", what, what);
    const int axis = args.axis(1, fmt::format("{} axis", what).c_str());
    if (axis == 2 && domain->dimension == 2) args.fail("a {} along z in a 2d simulation", what);
    if (floor_axis >= 0 && axis != floor_axis)
      args.fail("the floor and the surface lie across one axis, not {} and {}", "xyz"[floor_axis], "xyz"[axis]);
    floor_axis = axis;
    (floor ? floor_level : surface_level) = args.number(2);
    (floor ? floor_given : surface_given) = true;
    if (!(surface_level > floor_level))
      args.fail("the surface {} must lie above the floor {}", surface_level, floor_level);
    args.next(2);
  }
  // The per-atom arrays of atom_style sphere (newer LAMMPS has no sphere_flag; fix nve/sphere checks the same).
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR, "Fix nve/sphere/fluid requires atom_style sphere (per-atom radius, rmass, omega, torque)");

  time_integrate = 1;
  dynamic_group_allow = 1;
  vector_flag = 1;
  size_vector = NCOUNTS;
  global_freq = 1;
  extvector = 1;
  maxexchange = doubles_per_atom();

  grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
}

FixNVESphereFluid::~FixNVESphereFluid()
{
  atom->delete_callback(id, Atom::GROW);
  for (const PerAtomArray &row : per_atom_arrays) memory->destroy(this->*row.array);
}

int FixNVESphereFluid::setmask()
{
  return INITIAL_INTEGRATE | FINAL_INTEGRATE;
}

void FixNVESphereFluid::init()
{
  if (!(update->dt > 0.0))
    error->all(FLERR, "Fix nve/sphere/fluid: the timestep must be > 0, not {} (a drag step runs forward in time)",
               update->dt);
  drags.clear();
  for (Fix *drag : sediment_fixes_of_style(lmp, "fluid/drag")) drags.push_back(static_cast<FixFluidDrag *>(drag));
  uniform = nullptr;    // decided in setup(), once every fix is initialised

  double *radius = atom->radius;
  int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; ++i)
    if ((mask[i] & groupbit) && radius[i] == 0.0)
      error->one(FLERR, "Fix nve/sphere/fluid requires extended particles (radius > 0)");
}

void FixNVESphereFluid::setup(int /*vflag*/)
{
  if (floor_axis >= 0) check_column();
  // After every fix's init(): the drag fixes know their fluid only then.
  uniform = drags.size() == 1 && drags.front()->immersed_everywhere() ? drags.front() : nullptr;
  bool nonlinear = false, set_valued = false;
  atom_flow = false;
  for (FixFluidDrag *drag : drags) {
    nonlinear |= drag->nonlinear();
    set_valued |= !drag->drag_model()->smooth();
    atom_flow |= drag->fluid_fix()->has_atom_flow();
  }
  // Linear only with a uniform drag in a fluid of one velocity: its spheres are wholly immersed, so
  // F = c d w, and the second half may take the weights anew from the diameter.
  linear_per_diameter = uniform && !atom_flow ? uniform->linear_per_diameter() : 0.0;
  if (linear_per_diameter > 0.0)
    half_step = floor_axis < 0 ? HalfStep::Linear : HalfStep::LinearOnFloor;
  else
    half_step = HalfStep::General;
  // A block steps its spheres in one flow; with a fix fluid/flow each sphere has its own, and joins
  // the block in its fluid's frame (the drag sees only the slip: first_half).
  if (nonlinear) half_step = set_valued ? HalfStep::Blocked : HalfStep::Smooth;
  // Which vector copy of the block step runs here (benchmarks/cost.py records it with its figures).
  if (comm->me == 0 && nonlinear && !reported_vectors)
    utils::logmesg(lmp, "fix nve/sphere/fluid: nonlinear drag stepped in blocks, {} vectors\n",
                   sediment::batch_math_name(sediment::batch_math_kind()));
  reported_vectors |= nonlinear;
}

// A sphere whose centre lies below the floor is lifted onto it at its first step, through the grains
// above it (and a shrink-wrapped box grown to it). A floor above every sphere of the group (or above
// the box) is a mistake in the deck, refused naming the lowest sphere; below some of them it is a
// warning with their count (a scene may drop its grains onto a floor inside them on purpose). A
// sphere reaching above the surface is set under it at its first step, with a warning.
void FixNVESphereFluid::check_column()
{
  if (std::isfinite(surface_level)) {
    bigint above = 0, all_above;
    for (int i = 0; i < atom->nlocal; ++i)
      if ((atom->mask[i] & groupbit) && atom->x[i][floor_axis] + atom->radius[i] > surface_level) ++above;
    MPI_Allreduce(&above, &all_above, 1, MPI_LMP_BIGINT, MPI_SUM, world);
    if (all_above > 0 && comm->me == 0)
      error->warning(FLERR, "Fix nve/sphere/fluid: {} spheres reach above surface {} {}: they are set under it at their "
                     "first step", all_above, "xyz"[floor_axis], surface_level);
  }
  if (!std::isfinite(floor_level)) return;
  double **x = atom->x;
  int *mask = atom->mask;
  const double none = std::numeric_limits<double>::max();
  double lowest[2] = {none, 0.0};    // the lowest centre below the floor, and its atom's ID
  bigint counts[2] = {0, 0};         // spheres of the group, and those below the floor
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    ++counts[0];
    if (x[i][floor_axis] >= floor_level) continue;
    ++counts[1];
    if (x[i][floor_axis] < lowest[0]) {
      lowest[0] = x[i][floor_axis];
      lowest[1] = static_cast<double>(atom->tag[i]);
    }
  }
  double all[2];
  bigint total[2];
  MPI_Allreduce(lowest, all, 1, MPI_2DOUBLE_PRECISION, MPI_MINLOC, world);
  MPI_Allreduce(counts, total, 2, MPI_LMP_BIGINT, MPI_SUM, world);
  const char axis = "xyz"[floor_axis];
  if (total[1] > 0 && (total[1] == total[0] || floor_level > domain->boxhi[floor_axis]))
    error->all(FLERR, "Fix nve/sphere/fluid: floor {} {} lies above every sphere (atom {}, the lowest, at {} {}; box {} "
               "to {}): give a floor at or below the grains (the bottom of the column)",
               axis, floor_level, static_cast<tagint>(all[1]), axis, all[0], domain->boxlo[floor_axis],
               domain->boxhi[floor_axis]);
  if (total[1] > 0 && comm->me == 0)
    error->warning(FLERR, "Fix nve/sphere/fluid: {} of {} spheres lie below floor {} {}: they are set on it at their "
                   "first step", total[1], total[0], axis, floor_level);
}

// A perfectly inelastic floor without a bed: a sphere reaching it stops with its lowest point on
// it, and stays while the forces press it down (only the settling is resolved, not the deposit).
// The free surface likewise: a sphere the flow carries into it stops with its highest point on it,
// and stays while the flow and its buoyancy press it up (a submerged grain cannot leave the water; a
// sphere turned back by fix wall/reflect took the reflection of its velocity into the next drag,
// and spread on the fluid a drag it never felt). Taken at the end of each atom's half step, with the
// floor and the surface (axis >= 0, -inf and +inf where not given) in locals the compiler keeps in
// registers. A NaN position or velocity is left as it is, not put at rest, for the check to find.
static inline void settle_in_column(double *x, double *v, double *omega, double radius, int axis, double floor,
                                    double surface)
{
  const double rest = floor + radius, held = surface - radius;
  if (x[axis] < rest || (x[axis] == rest && v[axis] <= 0.0))
    x[axis] = rest;
  else if (x[axis] > held || (x[axis] == held && v[axis] >= 0.0))
    x[axis] = held;
  else
    return;
  v[0] = v[1] = v[2] = 0.0;
  omega[0] = omega[1] = omega[2] = 0.0;
}

// At rest on the floor, pressed onto it or not pushed at all, with nothing that moves it along the
// floor (force or flow): under a drag law without set-valued points (linear or smooth) the step
// would take it into the floor and settle_in_column would put it back where it was, at rest, its
// rotation stopped; the second half would add a velocity into the floor that settle_in_column takes
// away again. So the step is the identity, bit for bit. Inline, on the arrays the step has loaded:
// most grains of a finished test rest, and this runs for every grain and step.
static inline bool rests_on_floor(const double *x, const double *v, const double *f, double radius,
                                  const double *flow, int axis, double level)
{
  // Written so that a NaN anywhere answers no: the atom then takes its step and the check finds it.
  if (x[axis] != level + radius || !(f[axis] <= 0.0)) return false;
  for (int k = 0; k < 3; ++k)
    if (v[k] != 0.0 || flow[k] != 0.0 || (k != axis && f[k] != 0.0)) return false;
  return true;
}

// A sphere that rests_on_floor held there: no weights for the second half (nor the torque's: a
// uniform step's second half gives it fix nve/sphere's, and settle_in_column takes the rotation away
// again, as the sphere's velocity stays 0), left where it is with its rotation stopped. Returns its
// state_sum (its position along the floor is not among what the test reads).
static inline double hold_on_floor(double *weights, double *x, double *v, double *omega, double radius, int axis,
                                   double level)
{
  std::fill(weights, weights + sediment::PACKED_WEIGHTS_SIZE, 0.0);
  const double state = state_sum(x, v);
  settle_in_column(x, v, omega, radius, axis, level, HUGE_VAL);
  return state;
}

template <FixNVESphereFluid::HalfStep path, bool is_uniform, bool on_floor, class Lookup>
void FixNVESphereFluid::first_half(Lookup lookup)
{
  const auto [x, v, f, omega, torque, radius, rmass, mask, nlocal] = sphere_arrays(atom);
  const auto weight_rows = flat_rows<NWEIGHTS>(weights);
  const auto general_rows = flat_rows<NGENERAL>(general);
  const auto drag_memo_rows = flat_rows<sediment::PHI_MEMO_SIZE>(drag_memos);
  const auto spin_memo_rows = flat_rows<sediment::PHI_MEMO_SIZE>(spin_memos);
  const int floor_dim = floor_axis;    // locals: the stores into the atom arrays cannot change them
  const double floor_at = floor_level, surface_at = surface_level;
  const double dt = update->dt;
  const double ftm2v = force->ftm2v;
  const HalfKick kick = sediment::half_kick(dt, ftm2v);
  static const double no_flow[3] = {0.0, 0.0, 0.0};
  constexpr bool linear = path == HalfStep::Linear || path == HalfStep::LinearOnFloor;
  constexpr bool keeps_weights = path != HalfStep::Linear;    // else final_integrate takes them anew
  constexpr bool keeps_all = !is_uniform;    // the atom's being in a fluid and the torque's weight too
  LinearDecay linear_decay(linear_per_diameter, dt);

  // What follows the drag step of atom i: position, rotation, the weights for the second half
  // (taken per unit mass and moment of inertia, so the second half divides by neither). Returns
  // the state_sum of the new position and velocity, for the check of a finite state. Captures by
  // value, as the look-ups do: with references to the locals, the block's out-of-line step made the
  // loop reload them from the stack for every atom.
  auto finish = [=](int i, const sediment::StepCorrection &corr, const double dx[3], double spin_rate,
                    double per_mass) {
    const double new_x[3] = {x[i][0] + dx[0], x[i][1] + dx[1], x[i][2] + dx[2]};
    x[i][0] = new_x[0];
    x[i][1] = new_x[1];
    x[i][2] = new_x[2];
    const double state = state_sum(new_x, v[i]);
    if (corr.state == sediment::SlipState::Stuck) counts[STUCK] += 1.0;
    if (corr.state == sediment::SlipState::HeldAtJump) counts[AT_JUMP] += 1.0;

    double spin;
    if (is_uniform || spin_rate == 0.0) {    // no rotational drag: fix nve/sphere's kick, in fewer operations
      spin = nve_sphere_spin(omega[i], torque[i], radius[i], rmass[i], kick);
    } else {
      const double per_inertia = ftm2v / sediment::sphere_inertia(rmass[i], radius[i]);
      const double alpha[3] = {torque[i][0] * per_inertia, torque[i][1] * per_inertia, torque[i][2] * per_inertia};
      spin = sediment::rotation_step_initial(spin_rate, alpha, dt, omega[i], spin_memo_rows[i]) * per_inertia;
    }
    if constexpr (keeps_all) general_rows[i][SPIN] = spin;
    if constexpr (keeps_weights) sediment::pack_weights(corr, per_mass, weight_rows[i]);
    if (on_floor) settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
    return state;
  };

  // Atoms under a nonlinear law wait in a block of one law (sediment::DragBlock), which steps them
  // together, each stage one vector loop over the block; then each is finished here.
  struct Waiting {
    int i;
    double spin_rate;
    double per_mass;
    const double *flow;    // a fix fluid/flow's velocity at the sphere, stepped in its frame; nullptr: none
  };
  constexpr bool blocks = path == HalfStep::Smooth || path == HalfStep::Blocked;
  sediment::DragBlock block;
  Waiting waiting[sediment::DragBlock::capacity];
  auto step_block = [&]() {
    block.step(dt);
    double state = 0.0;
    // Compiled with and without spheres stepped in pieces: without, every sphere is free, and finish
    // counts no stuck or held sphere.
    auto finish_all = [&](auto in_pieces) {
      for (int n = 0; n < block.size(); ++n) {
        const Waiting &b = waiting[n];
        double dx[3];
        block.velocity(n, v[b.i]);
        block.displacement(n, dx);
        if (b.flow)    // back from the fluid's frame
          for (int c = 0; c < 3; ++c) {
            v[b.i][c] += b.flow[c];
            dx[c] += b.flow[c] * dt;
          }
        sediment::StepCorrection corr = block.correction(n);
        if constexpr (!decltype(in_pieces)::value) corr.state = sediment::SlipState::Free;
        state += finish(b.i, corr, dx, b.spin_rate, b.per_mass);
      }
    };
    if (block.stepped_in_pieces())
      finish_all(std::true_type{});
    else
      finish_all(std::false_type{});
    block.clear();
    return state;
  };

  // The sum of the new positions and velocities of the group's atoms (NaN and inf survive a sum),
  // taken as each atom is stepped (or left at rest on the floor).
  double state = 0.0;

  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    sediment::SphereDrag sphere;
    const double *flow = no_flow;
    double spin_rate = 0.0;
    lookup(i, sphere, flow, spin_rate);

    if constexpr (keeps_all) general_rows[i][IN_FLUID] = sphere.model ? 1.0 : 0.0;
    if (!sphere.model) {
      counts[OUTSIDE] += 1.0;
      state += nve_sphere_kick_drift(x[i], v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick, dt);
      if (on_floor) settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
      continue;
    }

    // A sphere resting on the floor whose step would end where it starts (rests_on_floor) is skipped;
    // a set-valued law would count it as stuck, so it takes its step.
    if (on_floor && rests_on_floor(x[i], v[i], f[i], radius[i], flow, floor_dim, floor_at) &&
        (linear || sediment::step_kind(sphere) != sediment::StepKind::SetValued)) {
      if constexpr (keeps_all) general_rows[i][SPIN] = 0.0;
      state += hold_on_floor(weight_rows[i], x[i], v[i], omega[i], radius[i], floor_dim, floor_at);
      continue;
    }

    // Divisions dominate a cheap step: one for the forces and one for the torques, as fix nve/sphere
    // (fix fluid requires coherent units: ftm2v = 1, so per_mass is also the drag step's 1 / m).
    const double per_mass = ftm2v / rmass[i];
    const double a[3] = {f[i][0] * per_mass, f[i][1] * per_mass, f[i][2] * per_mass};
    double dx[3];
    if constexpr (linear) {    // sphere.diameter * c, as the law's linear_coefficient
      const sediment::Phi &p = linear_decay.phis(sphere.diameter, per_mass, drag_memo_rows[i]);
      state += finish(i, sediment::linear_step_initial(p, a, flow, dt, v[i], dx), dx, spin_rate, per_mass);
      continue;
    }
    if constexpr (blocks) {
      // With a fix fluid/flow each sphere steps in the frame of its own fluid velocity (held over the
      // step), where the block's flow is zero: the drag depends on the slip alone.
      double slip[3];
      const double *block_v = v[i], *block_flow = flow;
      if (atom_flow) {
        for (int c = 0; c < 3; ++c) slip[c] = v[i][c] - flow[c];
        block_v = slip;
        block_flow = no_flow;
      }
      if (path == HalfStep::Smooth ? sediment::step_kind(sphere) == sediment::StepKind::Smooth
                                   : sediment::steps_in_block(sphere, block_v, block_flow)) {
        if (sphere.model != block.law()) {    // a block per law, and so per fluid/drag fix and flow
          if (block.size() > 0) state += step_block();
          block.set_law(*sphere.model, block_flow, flow_jumped);
        }
        const int n = path == HalfStep::Smooth ? block.add_smooth(sphere, per_mass, a, block_v)
                                                : block.add(sphere, per_mass, a, block_v);
        waiting[n] = {i, spin_rate, per_mass, atom_flow ? flow : nullptr};
        if (block.full()) state += step_block();
        continue;
      }
    }
    state += finish(i,
                    sediment::drag_step_initial(sphere, per_mass, a, flow, dt, v[i], dx, drag_memo_rows[i], flow_jumped),
                    dx, spin_rate, per_mass);
  }
  if (blocks && block.size() > 0) state += step_block();
  check_finite(state);
}

template <bool on_floor> void FixNVESphereFluid::first_half_immersed()
{
  const auto [x, v, f, omega, torque, radius, rmass, mask, nlocal] = sphere_arrays(atom);
  const FixFluidDrag::Immersed immersed = uniform->immersed();
  // A fix fluid/flow's velocity per sphere, or the fluid's own for all (the block's).
  double **flow_rows = uniform->fluid_fix()->atom_velocities();
  const sediment::SphereRows rows{x, v, omega, f, torque, radius, rmass, immersed.fraction,
                                  immersed.max_fraction, flat_rows<NWEIGHTS>(weights), flat_rows<3>(flow_rows)};
  const int drag_bit = uniform->groupbit;
  static const double no_flow[3] = {0.0, 0.0, 0.0};
  const double *flow = flow_rows ? no_flow : uniform->fluid_fix()->velocity();
  const int floor_dim = floor_axis;
  const double floor_at = floor_level, surface_at = surface_level;
  const double dt = update->dt;
  const HalfKick kick = sediment::half_kick(dt, force->ftm2v);

  sediment::DragBlock block;
  block.set_law(*immersed.model, flow, flow_jumped);
  int waiting[sediment::DragBlock::capacity];
  int size = 0;
  double state = 0.0;    // as in first_half; local sums: a store into the fix would alias the atom arrays
  int outside = 0, capped = 0;
  auto step_block = [&]() {
    state += block.step_spheres(rows, waiting, size, kick, dt);
    if constexpr (on_floor)
      for (int n = 0; n < size; ++n) {
        const int i = waiting[n];
        settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
      }
    size = 0;
  };
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    if (!(mask[i] & drag_bit)) {
      ++outside;
      state += nve_sphere_kick_drift(x[i], v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick, dt);
      if constexpr (on_floor) settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
      continue;
    }
    if (immersed.capped(i)) ++capped;
    if (on_floor && rests_on_floor(x[i], v[i], f[i], radius[i], flow_rows ? flow_rows[i] : flow, floor_dim, floor_at)) {
      state += hold_on_floor(weights[i], x[i], v[i], omega[i], radius[i], floor_dim, floor_at);
      continue;
    }
    waiting[size++] = i;
    if (size == sediment::DragBlock::capacity) step_block();
  }
  if (size > 0) step_block();
  counts[OUTSIDE] += outside;
  counts[CAPPED] += capped;
  check_finite(state);
}

template <bool is_uniform, class Lookup> void FixNVESphereFluid::step_first_half(Lookup lookup)
{
  // Linear is taken by initial_integrate with its own look-up. Each way compiled with and without the
  // floor, whose tests took 7 instructions per atom where there is none.
  with_floor_or_not(floor_axis, [&](auto with_floor) {
    constexpr bool on_floor = decltype(with_floor)::value;
    if (half_step == HalfStep::Smooth) {
      if constexpr (is_uniform)
        first_half_immersed<on_floor>();
      else
        first_half<HalfStep::Smooth, false, on_floor>(lookup);
    } else if (half_step == HalfStep::Blocked)
      first_half<HalfStep::Blocked, is_uniform, on_floor>(lookup);
    else
      first_half<HalfStep::General, is_uniform, on_floor>(lookup);
  });
}

void FixNVESphereFluid::initial_integrate(int /*vflag*/)
{
  flow_jumped = false;
  for (FixFluidDrag *drag : drags) {
    drag->prepare_step();
    flow_jumped |= drag->fluid_fix()->flow_solved_at(update->ntimestep - 1);
  }
  counts.clear();

  if (drags.empty()) {    // every fluid effect off: fix nve/sphere's step, no per-atom bookkeeping
    const auto [x, v, f, omega, torque, radius, rmass, mask, nlocal] = sphere_arrays(atom);
    const int floor_dim = floor_axis;
    const double floor_at = floor_level, surface_at = surface_level;
    const double dt = update->dt;
    const HalfKick kick = sediment::half_kick(dt, force->ftm2v);
    int outside = 0;    // local sums: a store into the fix would alias the atom arrays
    double state = 0.0;
    with_floor_or_not(floor_dim, [&](auto with_floor) {
      for (int i = 0; i < nlocal; ++i)
        if (mask[i] & groupbit) {
          state += nve_sphere_kick_drift(x[i], v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick, dt);
          if constexpr (decltype(with_floor)::value)
            settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
          ++outside;
        }
    });
    counts[OUTSIDE] = outside;
    check_finite(state);
    return;
  }

  if (FixFluidDrag *drag = uniform) {
    const int *mask = atom->mask;
    const int drag_bit = drag->groupbit;
    const double *flow = drag->fluid_fix()->velocity();
    if (half_step == HalfStep::Linear || half_step == HalfStep::LinearOnFloor) {
      // A linear law has no local fraction: the diameter is all it needs.
      const double *radius = atom->radius;
      const sediment::DragModel *model = drag->drag_model();
      auto lookup = [=](int i, sediment::SphereDrag &sphere, const double *&u, double &) {
        if (!(mask[i] & drag_bit)) return;
        sphere.model = model;
        sphere.diameter = 2.0 * radius[i];
        u = flow;
      };
      if (half_step == HalfStep::Linear)
        first_half<HalfStep::Linear, true, false>(lookup);
      else
        first_half<HalfStep::LinearOnFloor, true, true>(lookup);
      return;
    }
    const FixFluidDrag::Immersed immersed = drag->immersed();
    double **flow_rows = drag->fluid_fix()->atom_velocities();
    step_first_half<true>([=](int i, sediment::SphereDrag &sphere, const double *&u, double &) {
      if (!(mask[i] & drag_bit)) return;
      sphere = immersed.drag(i);
      u = flow_rows ? flow_rows[i] : flow;
      if (immersed.capped(i)) counts[CAPPED] += 1.0;
    });
    return;
  }
  step_first_half<false>([&](int i, sediment::SphereDrag &sphere, const double *&u, double &spin_rate) {
    for (FixFluidDrag *drag : drags) {
      const sediment::SphereDrag candidate = drag->sphere_drag(i);
      if (!candidate.model) continue;
      if (sphere.model)
        error->one(FLERR, "Fix nve/sphere/fluid: atom {} is in the fluid of two fluid/drag fixes", atom->tag[i]);
      sphere = candidate;
      u = drag->fluid_fix()->velocity_at(i);
      spin_rate = drag->rotation_rate(i, sphere);
      if (drag->fraction_capped(i)) counts[CAPPED] += 1.0;
    }
  });
}

void FixNVESphereFluid::final_integrate()
{
  const auto [x, v, f, omega, torque, radius, rmass, mask, nlocal] = sphere_arrays(atom);
  const auto weight_rows = flat_rows<NWEIGHTS>(weights);
  const auto general_rows = flat_rows<NGENERAL>(general);
  const auto drag_memo_rows = flat_rows<sediment::PHI_MEMO_SIZE>(drag_memos);
  const int floor_dim = floor_axis;
  const double floor_at = floor_level, surface_at = surface_level;
  const double ftm2v = force->ftm2v;

  const HalfKick kick = sediment::half_kick(update->dt, ftm2v);
  if (drags.empty()) {
    with_floor_or_not(floor_dim, [&](auto with_floor) {
      for (int i = 0; i < nlocal; ++i)
        if (mask[i] & groupbit) {
          nve_sphere_kick(v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick);
          if constexpr (decltype(with_floor)::value)
            settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
        }
    });
    return;
  }

  if (half_step == HalfStep::Linear) {
    // The weights as the first half took them (linear_step_initial's dt phi2 / m along and across,
    // fix nve/sphere's for the torque), bit for bit, from the atom's diameter and mass: reading them
    // from a row cost more than fix nve/sphere's two divisions (perf, drag scene of
    // benchmarks/in.cost: a row of 64 bytes written and read again per atom and step).
    const double dt = update->dt;
    const int drag_bit = uniform->groupbit;
    LinearDecay linear_decay(linear_per_diameter, dt);
    for (int i = 0; i < nlocal; ++i) {
      if (!(mask[i] & groupbit)) continue;
      if (!(mask[i] & drag_bit)) {
        nve_sphere_kick(v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick);
        continue;
      }
      const double per_mass = ftm2v / rmass[i];
      const double along = dt * linear_decay.phis(2.0 * radius[i], per_mass, drag_memo_rows[i]).phi2 * per_mass;
      sediment::add_weighted_acceleration(along, along, nullptr, f[i], v[i]);
      nve_sphere_spin(omega[i], torque[i], radius[i], rmass[i], kick);
    }
    return;
  }

  // The uniform step: each run of consecutive atoms in the drag's group (the fluid's) takes its second
  // half in vectors (sediment::drag_step_final_rows); an atom of the group outside it fix nve/sphere's.
  if (uniform) {
    const sediment::SphereRows rows{x, v, omega, f, torque, radius, rmass, nullptr, 0.0, weight_rows};
    const int both = groupbit | uniform->groupbit;
    with_floor_or_not(floor_dim, [&](auto with_floor) {
      constexpr bool on_floor = decltype(with_floor)::value;
      for_each_run(
          nlocal, [&](int i) { return (mask[i] & both) == both; },
          [&](int first, int count) {
            sediment::drag_step_final_rows(rows, first, count, kick);
            if constexpr (on_floor)
              for (int i = first; i < first + count; ++i)
                settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
          },
          [&](int i) {
            if (!(mask[i] & groupbit)) return;
            nve_sphere_kick(v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick);
            if constexpr (on_floor) settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
          });
    });
    return;
  }

  // The general step, compiled with and without the floor (its test in the loop cost 4 instructions of
  // 80 per atom).
  with_floor_or_not(floor_dim, [&](auto with_floor) {
    for (int i = 0; i < nlocal; ++i) {
      if (!(mask[i] & groupbit)) continue;
      if (general_rows[i][IN_FLUID] == 0.0) {
        nve_sphere_kick(v[i], omega[i], f[i], torque[i], radius[i], rmass[i], kick);
      } else {
        const double spin = general_rows[i][SPIN];    // read first: the stores into v could alias it
        sediment::add_packed_weighted_acceleration(weight_rows[i], f[i], v[i]);
        omega[i][0] += spin * torque[i][0];
        omega[i][1] += spin * torque[i][1];
        omega[i][2] += spin * torque[i][2];
      }
      if constexpr (decltype(with_floor)::value)
        settle_in_column(x[i], v[i], omega[i], radius[i], floor_dim, floor_at, surface_at);
    }
  });
}

void FixNVESphereFluid::check_finite(double state) const
{
  // The sum is taken in the step's own loops, while the atom's values are in registers: a pass of
  // its own over x and v cost 0.74 cache misses per atom-step (cachegrind, 20 000 atoms).
  if (!std::isfinite(state)) find_non_finite();
}

void FixNVESphereFluid::find_non_finite() const
{
  // Some state sum is not finite: name the first atom of the group whose own sum is not (a sum
  // of finite values can overflow, and an atom outside the group is not this fix's to name;
  // then none is named and the run goes on).
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit) || std::isfinite(state_sum(atom->x[i], atom->v[i]))) continue;
    const double *x = atom->x[i], *v = atom->v[i], *f = atom->f[i];
    error->one(FLERR, "Fix nve/sphere/fluid: atom {} has a non-finite position or velocity at step {} "
               "(x {} {} {}, v {} {} {}, f {} {} {}); check the forces acting on it and the timestep",
               atom->tag[i], update->ntimestep, x[0], x[1], x[2], v[0], v[1], v[2], f[0], f[1], f[2]);
  }
}

// Only the surface puts a sphere exactly there, and only when the step carried it into the surface: the
// second half may then have given it the new force's velocity, away from the surface (its weight).
bool FixNVESphereFluid::held_at_surface(int i) const
{
  return floor_axis >= 0 && (atom->mask[i] & groupbit) && atom->x[i][floor_axis] == surface_level - atom->radius[i];
}

bool FixNVESphereFluid::at_rest_on_floor(int i) const
{
  const double *v = atom->v[i];
  return floor_axis >= 0 && (atom->mask[i] & groupbit) && atom->x[i][floor_axis] == floor_level + atom->radius[i] &&
      v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0;
}

double FixNVESphereFluid::compute_vector(int n)
{
  return counts.total(n, world);
}

void FixNVESphereFluid::grow_arrays(int nmax)
{
  for (const PerAtomArray &row : per_atom_arrays) memory->grow(this->*row.array, nmax, row.columns, row.name);
  // Empty memos for the new rows (a memo is used only when its z matches).
  for (int i = nmax_rows; i < nmax; ++i)
    drag_memos[i][0] = spin_memos[i][0] = std::numeric_limits<double>::quiet_NaN();
  nmax_rows = nmax;
}

const std::array<FixNVESphereFluid::PerAtomArray, 4> FixNVESphereFluid::per_atom_arrays = {{
    {&FixNVESphereFluid::weights, NWEIGHTS, "nve/sphere/fluid:weights"},
    {&FixNVESphereFluid::general, NGENERAL, "nve/sphere/fluid:general"},
    {&FixNVESphereFluid::drag_memos, sediment::PHI_MEMO_SIZE, "nve/sphere/fluid:drag_memos"},
    {&FixNVESphereFluid::spin_memos, sediment::PHI_MEMO_SIZE, "nve/sphere/fluid:spin_memos"},
}};

int FixNVESphereFluid::doubles_per_atom()
{
  int n = 0;
  for (const PerAtomArray &row : per_atom_arrays) n += row.columns;
  return n;
}

void FixNVESphereFluid::copy_arrays(int i, int j, int /*delflag*/)
{
  for (const PerAtomArray &row : per_atom_arrays) {
    double **array = this->*row.array;
    std::copy(array[i], array[i] + row.columns, array[j]);
  }
}

int FixNVESphereFluid::pack_exchange(int i, double *buf)
{
  int m = 0;
  for (const PerAtomArray &row : per_atom_arrays) {
    const double *from = (this->*row.array)[i];
    std::copy(from, from + row.columns, buf + m);
    m += row.columns;
  }
  return m;
}

int FixNVESphereFluid::unpack_exchange(int nlocal, double *buf)
{
  int m = 0;
  for (const PerAtomArray &row : per_atom_arrays) {
    std::copy(buf + m, buf + m + row.columns, (this->*row.array)[nlocal]);
    m += row.columns;
  }
  return m;
}

double FixNVESphereFluid::memory_usage()
{
  return static_cast<double>(atom->nmax) * doubles_per_atom() * sizeof(double);
}
