// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid/flow
   A solve at the end of a step (each step, every N, or once the spheres have
   drifted): every rank spreads its spheres' forces onto its brick of the grid
   (the nodes their kernels touch, and its subdomain's), the bricks' planes are
   sent to the ranks holding them in the FFT's slabs of planes (in = out) and
   summed there (with the column's mirror image), the slabs are transformed
   (four FFTs: separate_xy), the Stokes operator applied mode by mode
   (sediment/flow.hpp), transformed back, and each brick's velocity is sent
   back to the rank that reads it at its spheres. Memory and communication per
   rank are those of its brick and its slab: O(grid / ranks) where the ranks
   split the box along z, as LAMMPS does a tall column.
------------------------------------------------------------------------- */

#include "fix_fluid_flow.h"

#include "fft3d_wrap.h"    // KSPACE: LAMMPS's distributed 3d FFT (FFTW3 or KISS)

#include "sediment_args.h"

#include "fix_fluid.h"
#include "fix_fluid_drag.h"
#include "fix_nve_sphere_fluid.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "math_const.h"
#include "memory.h"
#include "modify.h"
#include "output.h"
#include "pair.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mpi.h>

using namespace LAMMPS_NS;
using namespace FixConst;
using MathConst::MY_PI;

static inline int wrap(int i, int n)
{
  if (i >= 0 && i < n) return i;    // the common case, without a division
  i %= n;
  return i < 0 ? i + n : i;
}

FixFluidFlow::FixFluidFlow(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), fluid_id(nullptr), fluid(nullptr), nzt(0), column(false), column_lo(0.0), column_hi(0.0),
    relax(1.0), weight_index(-1), stratify(false), excess(nullptr), gravity(nullptr), displaced_time(0.0), solve_interval(0.0), lowest_class(0), excess_in_file(false), drift_limit(0.0), drift(0.0), cfl(0.0), longest_dt(0.0), applied_dt(0.0), told_shortened(false), solved_speed(0.0), unsettled(false), solved_viscosity(0.0), velocity(nullptr), stepped_voidage(nullptr), hindered(false), solved(false), fft(nullptr),
    plane_lo(0), plane_hi(-1), last_solve(-1), warned_carry(false), carries(0), carry_start(0.0), reversals(0), reversal_growth(1.0)
{
  if (narg < 8 || strcmp(arg[4], "grid") != 0)
    error->all(FLERR, "Fix fluid/flow: expected 'fix ID group fluid/flow FLUID-ID grid NX NY NZ keyword value ...'");
  fluid_id = utils::strdup(arg[3]);
  StyleArgs args(lmp, FLERR, "Fix fluid/flow", narg, arg, 4);
  bool every_given = false, drift_given = false;
  int across = -1;    // across: 0 vessel, 1 periodic; -1 not given (a column's default is vessel)
  while (args.more()) {
    int nvalues = 1;
    if (args.is("grid")) {
      args.need(3, "3 cell counts (x, y, z)");
      for (int d = 0; d < 3; ++d) {
        grid[d] = args.count(1 + d, 4096);
        if (!sediment::fft_friendly(grid[d]))
          args.fail("grid size {} in {} is not a product of 2, 3 and 5 (the sizes LAMMPS's FFTs take)", grid[d],
                    "xyz"[d]);
      }
      nvalues = 3;
    } else if (args.is("column")) {
      args.need(2, "the bottom and the top of the column (z)");
      column_lo = args.number(1);
      column_hi = args.number(2);
      if (!(column_hi > column_lo)) args.fail("column top {} must lie above its bottom {}", column_hi, column_lo);
      column = true;
      nvalues = 2;
    } else if (args.is("brinkman")) {
      args.need(1, "a value");
      stokes.brinkman = args.number(1);
      if (stokes.brinkman < 0.0) args.fail("brinkman resistance must be >= 0, not {}", stokes.brinkman);
    } else if (args.is("width")) {
      args.need(1, "a value");
      kernel.width = args.number(1);
      if (!(kernel.width >= 1.0 && kernel.width <= 2.0))
        args.fail("width {} must be from 1 to 2 grid cells (from 1 on, a Gaussian in Fourier space makes up what "
                  "the grid's B-spline lacks)", kernel.width);
    } else if (args.is("relax")) {
      args.need(1, "a value");
      relax = args.number(1);
      if (!(relax > 0.0 && relax <= 1.0)) args.fail("relax must be in (0, 1], not {}", relax);
    } else if (args.is("every")) {
      args.need(1, "a step count");
      nevery = args.count(1, 1000000);
      every_given = true;
    } else if (args.is("drift")) {
      args.need(1, "a distance in cells");
      drift_limit = args.positive(1, "drift");
      if (!(drift_limit < 1.0))
        args.fail("drift {} must be below 1: it is both the cells the spheres may move and the fraction their "
                  "largest speed may change between solves, and a speed that drops to zero must count", drift_limit);
      drift_given = true;
    } else if (args.is("cfl")) {
      args.need(1, "a distance in cells");
      cfl = args.positive(1, "cfl");
      if (!(cfl <= 1.0))
        args.fail("cfl {} must be at most 1: a sphere that moves more than a cell in a step has left the flow the "
                  "lagged solve gave it", cfl);
    } else if (args.is("weight")) {
      weight_name = args.weight(1);
    } else if (args.is("across")) {
      args.need(1, "vessel or periodic");
      across = args.choice(1, {"vessel", "periodic"});
    } else if (args.is("stratification")) {
      args.need(1, "grains or parcels");
      stratify = args.choice(1, {"parcels", "grains"}) == 1;
    } else {
      args.unknown("grid, column, across, brinkman, width, relax, weight, stratification, every, drift or cfl");
    }
    args.next(nvalues);
  }
  stokes.vessel_across = across < 0 ? column : across == 0;
  if (drift_given && every_given)
    error->all(FLERR, "Fix fluid/flow: give 'every N' or 'drift D', not both (drift chooses the steps between solves)");
  // By default the fix chooses the steps between solves: the flow is then never more than a fifth of a
  // cell (of the kernel's width) behind the spheres, which changed four scenes' answers by 5e-4 or
  // less, a twelfth or less of their scatter between random draws (benchmarks/flow_drift.py)
  if (!every_given && !drift_given) drift_limit = DEFAULT_DRIFT;
  if (domain->dimension != 3) error->all(FLERR, "Fix fluid/flow requires a 3d simulation");
  if (!domain->xperiodic || !domain->yperiodic)
    error->all(FLERR, "Fix fluid/flow requires a box periodic in x and y (boundary p p ...)");
  if (column && domain->zperiodic)
    error->all(FLERR, "Fix fluid/flow: keyword 'column' closes the fluid at its bottom and top, in a box not periodic "
               "in z (boundary p p f); this box is periodic in z");
  if (!column && !domain->zperiodic)
    error->all(FLERR, "Fix fluid/flow: a box not periodic in z needs keyword 'column ZLO ZHI' (the closed column)");
  if (stratify && (!column || weight_name.empty()))
    error->all(FLERR, "Fix fluid/flow: 'stratification grains' is for parcels (keyword weight) in a closed column "
               "(keyword column), whose mean density varies along z");
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "Fix fluid/flow requires atom attributes radius and rmass (atom_style sphere)");
  for (int d = 0; d < 3; ++d)
    if (grid[d] < kernel.max_count())
      error->all(FLERR, "Fix fluid/flow: grid size {} in {} is smaller than the kernel's {} nodes", grid[d], "xyz"[d],
                 kernel.max_count());
  nzt = column ? 2 * grid[2] : grid[2];

  restart_global = 1;
  restart_peratom = 1;
  peratom_flag = 1;
  size_peratom_cols = 3;
  peratom_freq = 1;
  vector_flag = 1;
  size_vector = NDIAG;
  global_freq = 1;
  extvector = 0;
  maxexchange = 5;
  create_attribute = 1;
  std::fill(diag, diag + NDIAG, 0.0);
  std::fill(self_flow, self_flow + 3, 0.0);
  std::fill(solved_uniform, solved_uniform + 3, 0.0);

  grow_arrays(atom->nmax);
  atom->add_callback(Atom::GROW);
  atom->add_callback(Atom::RESTART);
}

FixFluidFlow::~FixFluidFlow()
{
  atom->delete_callback(id, Atom::GROW);
  atom->delete_callback(id, Atom::RESTART);
  memory->destroy(velocity);
  memory->destroy(excess);
  memory->destroy(stepped_voidage);
  delete fft;
  delete[] fluid_id;
}

int FixFluidFlow::setmask()
{
  return POST_INTEGRATE | END_OF_STEP;
}

// The voidage each sphere's drag read in this step, kept for the solve at its end: the integrator
// stepped the sphere's velocity with the local fraction of the step's start, refreshed only at this
// step's post_force. Recomputed from the fraction at the step's end, the drag of a sphere that enters
// a deposit's dense top at speed is many times any force it felt (18-fold in one step in sample 5 at
// 100 g/L), and the solve spread onto the fluid a force the sphere never lost.
void FixFluidFlow::post_integrate()
{
  if (!hindered || (drift_limit <= 0.0 && update->ntimestep % nevery != 0)) return;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  for (int i = 0; i < nlocal; ++i)
    if (mask[i] & groupbit) stepped_voidage[i] = -1.0;
  for (FixFluidDrag *drag : drags) {    // the first drag of a sphere's, as sphere_force() takes it
    const FixFluidDrag::Immersed immersed = drag->immersed();
    const int bit = drag->groupbit;
    for (int i = 0; i < nlocal; ++i)
      if ((mask[i] & bit) && (mask[i] & groupbit) && stepped_voidage[i] < 0.0)
        stepped_voidage[i] = immersed.drag(i).scale.voidage;
  }
}

void FixFluidFlow::init()
{
  fluid = FixFluid::find(lmp, fluid_id, "Fix fluid/flow");
  if (fluid->is_bingham())
    error->all(FLERR, "Fix fluid/flow: fluid '{}' is a Bingham fluid; the flow is solved for a Newtonian one",
               fluid_id);
  stokes.viscosity = fluid->properties().viscosity;
  if (cfl > 0.0) {    // one style sets the step, or the last to act would undo the others' limits
    for (Fix *fix : sediment_fixes_of_style(lmp, "dt/reset"))
      error->all(FLERR, "Fix fluid/flow: keyword cfl sets the time step, as fix {} dt/reset does: give one of them",
                 fix->id);
    for (Fix *fix : sediment_fixes_of_style(lmp, "fluid/flow"))
      if (fix != this && static_cast<FixFluidFlow *>(fix)->cfl > 0.0)
        error->all(FLERR, "Fix fluid/flow: keyword cfl of fix {} and of fix {} both set the time step: give it to one",
                   fix->id, id);
  }
  if (!weight_name.empty()) weight_index = sediment_find_weights(lmp, weight_name, groupbit, "Fix fluid/flow");
  if (stratify)
    gravity = sediment_find_gravity(lmp, nullptr, "Fix fluid/flow with 'stratification grains'",
                                    "it weighs the grains with the deck's only one");

  // The grid: cubic cells over the periodic box in x and y and the box or the column in z.
  for (int d = 0; d < 3; ++d) {
    origin[d] = domain->boxlo[d];
    length[d] = domain->prd[d];
  }
  if (column) {
    origin[2] = column_lo;
    length[2] = column_hi - column_lo;
  }
  for (int d = 0; d < 3; ++d) spacing[d] = length[d] / grid[d];
  for (int d = 1; d < 3; ++d)
    if (std::abs(spacing[d] - spacing[0]) > 1e-6 * spacing[0])
      error->all(FLERR, "Fix fluid/flow: the grid's cells must be cubes, not {} x {} x {} (grid counts in proportion "
                 "to the box{})", spacing[0], spacing[1], spacing[2], column ? " and the column" : "");
  stokes.smoothing = kernel.fourier_variance() * spacing[0] * spacing[0];

  if (!fft) {
    const int nprocs = comm->nprocs, me = comm->me;
    if (nzt < nprocs)
      error->all(FLERR, "Fix fluid/flow: {} planes of the transform cannot be split over {} ranks", nzt, nprocs);
    first_plane.resize(nprocs + 1);
    for (int r = 0; r <= nprocs; ++r) first_plane[r] = static_cast<int>(static_cast<long>(r) * nzt / nprocs);
    plane_lo = first_plane[me];
    plane_hi = first_plane[me + 1] - 1;
    plan_mirror_exchange();
    const long mine = static_cast<long>(grid[0]) * grid[1] * (plane_hi - plane_lo + 1);
    slab.assign(3 * mine, 0.0);
    for (auto &f : field) f.assign(2 * mine, 0.0);
    int buffer = 0;
    fft = sediment_make_fft3d(lmp, world, grid[0], grid[1], nzt, 0, grid[0] - 1, 0, grid[1] - 1, plane_lo, plane_hi,
                              &buffer);
    if (comm->me == 0) report_settings();
  }
  measure_self_flow();
  if (!solved) {    // until the first solve, the fluid's uniform velocity
    const double *u = fluid->velocity();
    for (int i = 0; i < atom->nlocal; ++i)
      for (int c = 0; c < 3; ++c) velocity[i][c] = u[c];
    std::copy_n(u, 3, solved_uniform);
  }
}

// What the keywords and their defaults made of the solve, once, as PPPM reports its grid: a user sees
// the transform's size (its cost), whether the flow uniform across is held and when the fix solves.
void FixFluidFlow::report_settings() const
{
  std::string text = fmt::format("fix {} fluid/flow: {} x {} x {} cells of {:.4g} m", id, grid[0], grid[1], grid[2],
                                 spacing[0]);
  if (column)
    text += fmt::format(" over the closed column z = {:.6g} to {:.6g} m (transformed with its mirror image: {} planes)",
                        column_lo, column_hi, nzt);
  else
    text += " over the periodic box";
  text += stokes.vessel_across ? "\n  the flow uniform across held at rest (across vessel)"
                               : "\n  the flow uniform across solved as in a periodic array (across periodic)";
  if (drift_limit > 0.0)
    text += fmt::format("; a solve once the spheres have drifted {:.3g} cells", drift_limit);
  else
    text += fmt::format("; a solve every {} steps", nevery);
  if (stokes.brinkman > 0.0) text += fmt::format("; Brinkman resistance {:.6g}", stokes.brinkman);
  if (relax < 1.0) text += fmt::format("; relaxed by {:.3g}", relax);
  if (cfl > 0.0) text += fmt::format("; the step shortened to carry spheres {:.3g} cells at most", cfl);
  if (!weight_name.empty())
    text += fmt::format("\n  parcels of d_{} grains each, stratification {}", weight_name, stratify ? "grains" : "parcels");
  utils::logmesg(lmp, text + "\n");
}

void FixFluidFlow::setup(int /*vflag*/)
{
  drags.clear();
  for (Fix *fix : sediment_fixes_of_style(lmp, "fluid/drag")) {
    auto drag = static_cast<FixFluidDrag *>(fix);
    if (drag->fluid_fix() == fluid) drags.push_back(drag);
  }
  if (drags.empty())
    error->all(FLERR, "Fix fluid/flow: no fix fluid/drag takes its drag from fluid '{}' (the flow is driven by the drag)",
               fluid_id);
  hindered = std::any_of(drags.begin(), drags.end(), [](const FixFluidDrag *drag) { return drag->reads_concentration(); });
  std::fill_n(stepped_voidage, atom->nlocal, -1.0);    // a solve before the first step: the fractions as they are
  floors.clear();
  for (Fix *fix : sediment_fixes_of_style(lmp, "nve/sphere/fluid"))
    if (auto integrator = static_cast<FixNVESphereFluid *>(fix); integrator->has_floor_or_surface()) floors.push_back(integrator);
  if (last_solve < 0) last_solve = update->ntimestep;    // a new fix, or one read from a restart
  displaced_time = sediment_time_now(update);
  if (stratify) share_slopes();    // the box is known (not yet when a restart file gave the profiles)
  // A run continues the flow it has (from the last run, or a restart): a new one starts from one solve.
  // A run whose fluid was given another uniform velocity or viscosity since the last solve solves too.
  told_shortened = false;
  if (!solved || fluid_changed()) {
    const double keep = relax;
    if (!solved) relax = 1.0;
    solve();
    relax = keep;
    if (drift_limit > 0.0) solved_speed = largest_speed(atom->v);
  }
  if (cfl > 0.0) limit_step();
}

// Whether the fluid's uniform velocity or viscosity differs from the last solve's (fix fluid given
// again between runs: another velocity, or water at another temperature).
bool FixFluidFlow::fluid_changed() const
{
  const double *u = fluid->velocity();
  return u[0] != solved_uniform[0] || u[1] != solved_uniform[1] || u[2] != solved_uniform[2] ||
      stokes.viscosity != solved_viscosity;
}

// stratification grains: each sphere's excess, how much denser its class is where it is than the
// class's mean there, relative to that mean. Where the flow moves it by d zeta along z across its
// class's profile Q_c(z), the excess grows by -(Q_c' / Q_c) d zeta: the grains of its class around it
// came from there. Each class carries its own: a sphere left behind by a faster class's front (the sand
// passing the silt) keeps none of the front's displacement, and one stirred about within a uniform
// layer gains none, whatever it meets later. The slopes are held to the share the lagged flow can
// follow: the classes' sum as the box-wide mode (share_slopes()), and each sphere's own, whose force
// the flow it drives at the sphere follows within the interval between solves, to half of that
// interval's (where its class is sparse, a front's edge, one sphere stands for much of the profile).
// The class's density is kept within its profile's range and above none (the flow only moves grains).
// Between solves a sphere keeps the fluid velocity of the last one, so the sum is exact for any every N.
void FixFluidFlow::displace()
{
  const double t = sediment_time_now(update), elapsed = t - displaced_time;
  displaced_time = t;
  const int nz = grid[2], classes = static_cast<int>(profiles.size()) / nz;
  if (classes == 0) return;    // no solve has made the profiles yet
  const int *mask = atom->mask;
  double **x = atom->x;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    const int key = settling_class(i);
    // as dense as the fluid, or of a class new since the last solve
    if (key == std::numeric_limits<int>::min() || key < lowest_class || key - lowest_class >= classes) continue;
    const int c = key - lowest_class;
    const auto [below, above] = profile_place(x[i][2]);
    // the sphere's own force, m_c |Q'/Q| per displacement, drives s (self-flow) per force: gain 0.5 at most
    const double own = std::abs(class_force[c]) * self_flow[2] * solve_interval;
    excess[i] = sediment::carried_excess(excess[i], &profiles[static_cast<size_t>(c) * nz], nz, spacing[2], below + above,
                                         slope_share[below], own > 0.0 ? 0.5 / own : HUGE_VAL,
                                         (velocity[i][2] - solved_uniform[2]) * elapsed);
  }
}

// Where height z lies on the classes' profiles (nodes at cell centres): the node below it and how far
// up to the next, clamped to the column's first and last nodes.
std::pair<int, double> FixFluidFlow::profile_place(double z) const
{
  const int nz = grid[2];
  const double at = std::clamp((z - origin[2]) / spacing[2] - 0.5, 0.0, nz - 1.0);
  const int below = std::min(static_cast<int>(at), nz - 2);
  return {below, at - below};
}

// A sphere's settling class for stratification grains: its Stokes speed's scale d^2 (rho_p - rho_f) to a
// factor sqrt(2), sinking and rising apart (even and odd); INT_MIN for one as dense as the fluid.
int FixFluidFlow::settling_class(int i) const
{
  const double r = atom->radius[i];
  const double scale = 4.0 * r * r * (atom->rmass[i] / (4.0 / 3.0 * MY_PI * r * r * r) - fluid->properties().density);
  if (!(scale != 0.0) || !std::isfinite(scale)) return std::numeric_limits<int>::min();
  return 2 * static_cast<int>(std::floor(2.0 * std::log2(std::abs(scale)))) + (scale < 0.0 ? 1 : 0);
}

void FixFluidFlow::end_of_step()
{
  if (stratify) displace();
  if (drift_limit <= 0.0) {
    solve();
  } else {
    const double speed = largest_speed(atom->v);
    drift += speed * update->dt / spacing[0];
    if (stale(speed)) {
      solved_speed = speed;
      solve();
    }
  }
  if (cfl > 0.0) limit_step();    // from the flow the next step takes
}

// With drift, whether the flow is due a solve, the spheres' largest speed now `speed`: the flow
// follows their positions and their forces, so it is stale once they may have moved drift cells, or
// once their speeds (their drag) have changed by that fraction, as when they start from rest or reach
// a floor, or while the last solve changed their fluid velocities (and so their drags) by more than
// that fraction (unsettled).
bool FixFluidFlow::stale(double speed) const
{
  return unsettled || !(drift < drift_limit && std::abs(speed - solved_speed) <= drift_limit * solved_speed);
}

// cfl: the lagged flow follows a density that it carries less than a cell between solves. Where it
// carries spheres faster than the input's timestep allows (sample 5 at 100 g/L with stratification
// grains: parcels above the deposit at 0.35-0.47 mm/s, 1.7-2.2 cells a step of 1.52 s, and the column
// ran away within 21 steps), the step is shortened to cfl cells at the largest fluid velocity at a
// sphere (the fluid's uniform velocity included), and lengthened back to the input's as the flow slows
// (by a fifth or more at a time, or to the input's). The spheres' own settling is not counted: a
// test's schedule is sized for it, and drift solves again as they move.
void FixFluidFlow::limit_step()
{
  // A timestep command since the step this fix last set gives the longest step anew (a deck's new
  // stage, also in a run with pre no, whose setup this fix does not see); one that gives the same
  // longest again (a resumed deck's stage) continues at the step this fix had set, as the run that was
  // not stopped did.
  if (update->dt != applied_dt) {
    if (applied_dt > 0.0 && update->dt == longest_dt) {
      set_step(applied_dt);
    } else {
      longest_dt = update->dt;
      told_shortened = false;    // a new stage's first shortening is news (a run with pre no has no setup)
    }
  }
  const double speed = largest_speed(velocity);
  const double between = drift_limit > 0.0 ? 1.0 : static_cast<double>(nevery);
  const double allowed = speed > 0.0 ? cfl * spacing[0] / (speed * between) : longest_dt;
  const double wanted = std::min(longest_dt, allowed);
  const double dt = update->dt;
  if (!(wanted < dt || wanted > 1.2 * dt || (wanted == longest_dt && dt != longest_dt))) return;
  if (wanted < longest_dt && !told_shortened && comm->me == 0) {
    told_shortened = true;
    utils::logmesg(lmp, "fix {} fluid/flow: step {} shortened from {:.4g} to {:.4g} (the flow at a sphere up to {:.4g}, "
                   "cfl {:.3g} cells of {:.4g}) (reported once a run and a timestep given; thermo keyword dt follows it)\n", id,
                   update->ntimestep, longest_dt, wanted, speed, cfl, spacing[0]);
  }
  set_step(wanted);
}

// The time step from now on: as fix dt/reset, the time is summed up to this step at the old step, and
// every style hears of the new one.
void FixFluidFlow::set_step(double dt)
{
  update->update_time();
  update->dt = dt;
  update->dt_default = 0;
  applied_dt = dt;
  if (force->pair) force->pair->reset_dt();
  sediment_for_each_fix(modify, [](Fix *fix) { fix->reset_dt(); });
  sediment_reset_output_dt(output);
}

// The largest of a velocity over the spheres of the group (all ranks): theirs (atom->v), how far they may
// have moved in a step, or their fluid's (velocity), how far the flow carries them.
double FixFluidFlow::largest_speed(double *const *v) const
{
  const int *mask = atom->mask;
  double local = 0.0;
  for (int i = 0; i < atom->nlocal; ++i)
    if (mask[i] & groupbit) local = std::max(local, v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
  double largest;
  MPI_Allreduce(&local, &largest, 1, MPI_DOUBLE, MPI_MAX, world);
  return sqrt(largest);
}

// The force sphere i puts on the fluid: minus its drag, against the fluid velocity it saw this step.
// Returns the local solid fraction its drag's hindrance reads (0 without one).
double FixFluidFlow::sphere_force(int i, double *force) const
{
  force[0] = force[1] = force[2] = 0.0;
  for (FixFluidDrag *drag : drags) {
    sediment::SphereDrag sphere = drag->sphere_drag(i);
    if (!sphere.model) continue;
    sphere.scale.voidage = stepped(i, sphere.scale.voidage);
    const double *v = atom->v[i], *u = velocity[i];
    const double w[3] = {v[0] - u[0], v[1] - u[1], v[2] - u[2]};
    double coeff = sphere.model->linear_coefficient(sphere.diameter, sphere.scale);
    if (!(coeff > 0.0)) {
      const double speed = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      coeff = speed > 0.0 ? sphere.model->force(sphere.diameter, speed, sphere.scale) / speed : 0.0;
    }
    for (int c = 0; c < 3; ++c) force[c] = coeff * w[c];
    return 1.0 - sphere.scale.voidage;
  }
  return 0.0;
}

// The forces on the fluid of the solve's spheres and their local fractions (sphere_force). Where one
// fluid/drag holds every sphere of its group wholly immersed without a rotational drag (what fix
// nve/sphere/fluid's block step takes too), its law gives the drags of the spheres in chunks, its
// exponentials and logarithms in vectors (DragModel::drags_per_speed).
void FixFluidFlow::sphere_forces()
{
  const size_t count = spheres.size();
  forces.assign(3 * count, 0.0);
  fractions.assign(count, 0.0);
  FixFluidDrag *drag = drags.size() == 1 && drags.front()->immersed_everywhere() ? drags.front() : nullptr;
  if (!drag) {
    for (size_t s = 0; s < count; ++s) fractions[s] = sphere_force(spheres[s], &forces[3 * s]);
    weigh_forces();
    return;
  }
  const FixFluidDrag::Immersed immersed = drag->immersed();
  const int drag_bit = drag->groupbit;
  const int *mask = atom->mask;
  double **v = atom->v;
  for (auto *column : {&diameter, &speed, &voidage, &per_speed}) column->resize(count);
  for (size_t s = 0; s < count; ++s) {
    const int i = spheres[s];
    if (!(mask[i] & drag_bit)) {    // no drag, no force: a diameter, slip and speed of 0, whatever its velocity
      diameter[s] = speed[s] = 0.0;
      voidage[s] = 1.0;
      continue;
    }
    const double *u = velocity[i];
    double *w = &forces[3 * s];    // the slip, until it is multiplied by the drag per speed below
    for (int c = 0; c < 3; ++c) w[c] = v[i][c] - u[c];
    speed[s] = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const sediment::SphereDrag sphere = immersed.drag(i);
    diameter[s] = sphere.diameter;
    voidage[s] = stepped(i, sphere.scale.voidage);
    fractions[s] = 1.0 - voidage[s];
  }
  if (const double linear = immersed.model->linear_coefficient(1.0); linear > 0.0)
    for (size_t s = 0; s < count; ++s) per_speed[s] = linear * diameter[s];
  else
    immersed.model->drags_per_speed(diameter.data(), speed.data(), voidage.data(), per_speed.data(),
                                    static_cast<int>(count));
  for (size_t s = 0; s < count; ++s)
    for (int c = 0; c < 3; ++c) forces[3 * s + c] *= per_speed[s];
  weigh_forces();
}

// A parcel of w grains placed independently of the other parcels (weight d_NAME) puts sqrt(w S(0))
// times its grain's drag on the fluid: the parcels' force density then fluctuates as the real
// grains' does (w grains' force per parcel, and w times fewer parcels, give a variance w times too
// large), the real grains' fluctuation being S(0) times a random placement's, with S(0) of hard
// spheres at the local fraction (docs/physics.md section 8, "Parcels").
void FixFluidFlow::weigh_forces()
{
  if (weight_index < 0) return;
  const double *weight = atom->dvector[weight_index];
  scales.resize(spheres.size());
  for (size_t s = 0; s < spheres.size(); ++s) {
    scales[s] = sqrt(weight[spheres[s]] * sediment::hard_sphere_structure_factor(fractions[s]));
    for (int c = 0; c < 3; ++c) forces[3 * s + c] *= scales[s];
  }
}

// stratification grains (docs/physics.md section 8, Parcels). The parcels' own forces, sqrt(w S(0))
// grains' each, give the force density's fluctuation its real size; but where the flow displaces the
// column's mean density profile, that displaced profile pushes back with only sqrt(S(0) / w) of the
// real grains' force. The rest, (w - sqrt(w S(0))) grains' force per parcel, its missing force, is
// added here: per settling class its mean along z, Q_c(z), made stable (a profile uniform across, which
// moves nothing, and is not added), and each sphere adds its class's mean missing force times its
// excess (displace()) to the force it spreads, into `restoring`. Undisplaced that is nothing; displaced
// by zeta, the spheres' sum is the real grains' -zeta dQ/dz less the parcels' share.
void FixFluidFlow::stratification_force()
{
  constexpr int nodes = sediment::FlowKernel::max_nodes;
  const int nz = grid[2];
  const double *weight = atom->dvector[weight_index];
  double **x = atom->x;
  std::vector<int> classes(spheres.size());
  int range[2] = {std::numeric_limits<int>::max(), std::numeric_limits<int>::max()}, span[2];    // lowest, -highest
  for (size_t s = 0; s < spheres.size(); ++s) {
    classes[s] = settling_class(spheres[s]);
    if (classes[s] == std::numeric_limits<int>::min()) continue;
    range[0] = std::min(range[0], classes[s]);
    range[1] = std::min(range[1], -classes[s]);
  }
  MPI_Allreduce(range, span, 2, MPI_INT, MPI_MIN, world);
  lowest_class = span[0];
  const int count = span[0] <= -span[1] ? -span[1] - span[0] + 1 : 0;
  class_force.assign(count, 0.0);
  // Each class's mean missing force per sphere. A grain settling at its terminal slip puts its weight
  // less its buoyancy on the fluid, which that sets, not its drag at the step: at each solve the fluid's
  // velocity at a sphere jumps, and a sphere entering a denser layer (the bed's top) has a drag many
  // times its weight until its speed has followed its hindrance. A force that followed the drags would
  // follow the flow it drives within the step, or jump with one sphere of a sparse class.
  const double density = fluid->properties().density;
  std::vector<double> local(2 * static_cast<size_t>(count), 0.0), mean(local.size());
  std::vector<double> missing_force(spheres.size(), 0.0);
  for (size_t s = 0; s < spheres.size(); ++s) {
    if (classes[s] == std::numeric_limits<int>::min()) continue;
    const int i = spheres[s];
    const double r = atom->radius[i], buoyant_mass = atom->rmass[i] - density * 4.0 / 3.0 * MY_PI * r * r * r;
    missing_force[s] = (weight[i] - scales[s]) * buoyant_mass * gravity[2];    // scales: sqrt(w S(0)) grains' own
    local[2 * (classes[s] - lowest_class)] += missing_force[s];
    local[2 * (classes[s] - lowest_class) + 1] += 1.0;
  }
  MPI_Allreduce(local.data(), mean.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, world);
  const double per_node = 1.0 / (spacing[0] * spacing[1] * spacing[2] * grid[0] * grid[1]);
  std::vector<double> missing(static_cast<size_t>(count) * nz, 0.0);
  std::vector<double> own(spheres.size(), 0.0);    // each sphere's own share of its class's profile where it is
  for (size_t s = 0; s < spheres.size(); ++s) {
    if (classes[s] == std::numeric_limits<int>::min() || missing_force[s] == 0.0) continue;
    const int c = classes[s] - lowest_class;
    const double force = class_force[c] = mean[2 * c] / mean[2 * c + 1];
    int first;
    double w[nodes];
    kernel.weights((x[spheres[s]][2] - origin[2]) / spacing[2] - 0.5, first, w);
    const auto [below, above] = profile_place(x[spheres[s]][2]);
    double *q = &missing[static_cast<size_t>(c) * nz];
    for (int a = 0; a < nodes; ++a) {
      int m = first + a;    // reflected at the bottom and the top, as the column's mirror image is
      if (m < 0)
        m = -m - 1;
      else if (m >= nz)
        m = 2 * nz - 1 - m;
      q[m] += w[a] * force * per_node;
      if (m == below || m == below + 1) own[s] += w[a] * force * per_node * (m == below ? 1.0 - above : above);
    }
  }
  profiles.resize(missing.size());
  MPI_Allreduce(missing.data(), profiles.data(), static_cast<int>(missing.size()), MPI_DOUBLE, MPI_SUM, world);
  for (int c = 0; c < count; ++c) sediment::stable_profile(&profiles[static_cast<size_t>(c) * nz], nz);
  // A sphere's excess is its class's density around it over the class's mean at its height; what it
  // displaces is the others' share of that mean. A sphere alone at its height (a straggler its class's
  // front has left) displaces none: with its own share counted, such a parcel hovered on the flow its
  // own excess drove, 2 mm under the surface of sample 2's column for over an hour (0.9 mm/s).
  restoring.assign(spheres.size(), 0.0);
  for (size_t s = 0; s < spheres.size(); ++s) {
    if (own[s] == 0.0) continue;
    const int c = classes[s] - lowest_class;
    const auto [below, above] = profile_place(x[spheres[s]][2]);
    const double *q = &profiles[static_cast<size_t>(c) * nz];
    const double here = q[below] + above * (q[below + 1] - q[below]);
    const double others = here != 0.0 ? std::clamp(1.0 - own[s] / here, 0.0, 1.0) : 0.0;
    restoring[s] = class_force[c] * excess[spheres[s]] * others;
  }
  // The lagged flow carries the spheres for the time between solves before the profile they displace
  // pushes back; where it pushes back faster than that (a front or a bed, whose real grains restore it
  // within milliseconds), the force would overshoot and grow from solve to solve. The profiles' slopes
  // are held to the stiffness (force per displacement) that the most mobile mode on the grid, the
  // box-wide one, relaxes in one such time: the stiff limit, in which the displaced profile is restored
  // as fast as the step can follow (docs/physics.md section 8).
  solve_interval = update->dt * static_cast<double>(std::max<bigint>(1, update->ntimestep - last_solve));
  share_slopes();
}

// Per cell along z, the share of the classes' slopes the lagged flow can follow: all of them up to the
// stiffest slope, at which the box-wide mode relaxes in solve_interval, their sum held there above it.
void FixFluidFlow::share_slopes()
{
  const double k = sediment::grid_wavenumber(1, grid[0], std::max(length[0], length[1]));    // 2 pi / width
  const double mobility = 1.0 / (stokes.viscosity * k * k + stokes.brinkman);
  const double stiffest = 1.0 / (mobility * solve_interval);
  const int nz = grid[2], classes = static_cast<int>(profiles.size()) / nz;
  slope_share.assign(std::max(nz - 1, 0), 0.0);
  for (int m = 0; m + 1 < nz; ++m) {
    double sum = 0.0;
    for (int c = 0; c < classes; ++c) sum += std::abs(profiles[static_cast<size_t>(c) * nz + m + 1] - profiles[static_cast<size_t>(c) * nz + m]);
    sum /= spacing[2];
    slope_share[m] = sum > stiffest ? stiffest / sum : 1.0;
  }
}

// The kernel's nodes around x on each axis, wrapped onto the periodic transform grid (their global
// indices, until place() makes them offsets into a brick), and their weights.
FixFluidFlow::Stencil FixFluidFlow::stencil_at(const double *x) const
{
  constexpr int nodes = sediment::FlowKernel::max_nodes;
  const int n[3] = {grid[0], grid[1], nzt};
  Stencil at;
  for (int d = 0; d < 3; ++d) {
    int first;
    double position = (x[d] - origin[d]) / spacing[d] - 0.5;
    // A sphere far outside the box (flung away, before LAMMPS finds it lost) is read on the periodic
    // grid, and one at a non-finite place (not stepped by this package's integrator, which stops the
    // run) at its first node: its nodes' indices stay ints within the grid.
    if (!(position >= -n[d] && position < 2.0 * n[d]))
      position = std::isfinite(position) ? position - n[d] * std::floor(position / n[d]) : 0.0;
    kernel.weights(position, first, at.w[d]);
    int m = wrap(first, n[d]);
    for (int a = 0; a < nodes; ++a) {
      at.node[d][a] = m;
      if (++m == n[d]) m = 0;
    }
  }
  return at;
}

// A rank's brick: per axis the nodes of the kernels `at` (global indices) and, with `subdomain`, those
// of every point of its subdomain (where a sphere created between solves reads the last one's flow).
void FixFluidFlow::build_brick(Brick &b, const std::vector<Stencil> &at, bool subdomain) const
{
  const int n[3] = {grid[0], grid[1], nzt};
  std::vector<char> held[3];
  for (int d = 0; d < 3; ++d) held[d].assign(n[d], 0);
  for (const Stencil &s : at)
    for (int d = 0; d < 3; ++d)
      for (long node : s.node[d]) held[d][node] = 1;
  for (int d = 0; subdomain && d < 3; ++d) {
    double lo = domain->sublo[d], hi = domain->subhi[d];
    if (d == 2 && column) {
      lo = std::max(lo, column_lo);
      hi = std::min(hi, column_hi);
    }
    if (!(hi >= lo)) continue;    // no part of the column here
    const double first = std::floor((lo - origin[d]) / spacing[d] - 0.5) - 1.0;
    const double last = std::floor((hi - origin[d]) / spacing[d] - 0.5) + sediment::FlowKernel::max_nodes - 2.0;
    if (last - first + 1.0 >= n[d])
      std::fill(held[d].begin(), held[d].end(), 1);
    else
      for (double m = first; m <= last; m += 1.0) held[d][wrap(static_cast<int>(m), n[d])] = 1;
  }
  for (int d = 0; d < 3; ++d) {
    b.nodes[d].clear();
    b.local[d].assign(n[d], -1);
    for (int m = 0; m < n[d]; ++m)
      if (held[d][m]) {
        b.local[d][m] = static_cast<int>(b.nodes[d].size());
        b.nodes[d].push_back(m);
      }
  }
}

// Whether b holds every node of the kernel at (global indices).
bool FixFluidFlow::holds(const Stencil &at, const Brick &b)
{
  for (int d = 0; d < 3; ++d)
    for (long node : at.node[d])
      if (b.local[d].empty() || b.local[d][node] < 0) return false;
  return true;
}

// The kernel's global indices made offsets into the values of b ([k][j][i][c]), which holds them.
void FixFluidFlow::place(Stencil &at, const Brick &b)
{
  const long stride[3] = {3, 3L * static_cast<long>(b.nodes[0].size()),
                          3L * static_cast<long>(b.nodes[0].size() * b.nodes[1].size())};
  for (int d = 0; d < 3; ++d)
    for (long &node : at.node[d]) node = stride[d] * b.local[d][node];
}

// The rank holding plane q of the transform.
int FixFluidFlow::owner(int q) const
{
  return static_cast<int>(std::upper_bound(first_plane.begin(), first_plane.end(), q) - first_plane.begin()) - 1;
}

// Every rank's node lists (bricks), for routing the planes both ways.
void FixFluidFlow::gather_bricks(const Brick &b)
{
  const int nprocs = comm->nprocs;
  const int mine[3] = {static_cast<int>(b.nodes[0].size()), static_cast<int>(b.nodes[1].size()),
                       static_cast<int>(b.nodes[2].size())};
  bricks.size.resize(3 * nprocs);
  bricks.offset.resize(3 * nprocs);
  MPI_Allgather(mine, 3, MPI_INT, bricks.size.data(), 3, MPI_INT, world);
  std::vector<int> counts(nprocs), starts(nprocs);
  int total = 0;
  for (int r = 0; r < nprocs; ++r) {
    starts[r] = total;
    for (int d = 0; d < 3; ++d) {
      bricks.offset[3 * r + d] = total;
      total += bricks.size[3 * r + d];
    }
    counts[r] = total - starts[r];
  }
  std::vector<int> flat;
  flat.reserve(mine[0] + mine[1] + mine[2]);
  for (const auto &nodes : b.nodes) flat.insert(flat.end(), nodes.begin(), nodes.end());
  bricks.nodes.resize(total);
  MPI_Allgatherv(flat.data(), static_cast<int>(flat.size()), MPI_INT, bricks.nodes.data(), counts.data(), starts.data(),
                 MPI_INT, world);
}

// Plane k of rank r's brick, z index q: whether it goes to this rank's slab as itself, and as the
// column's mirror image (plane nzt - 1 - q, vertical force reversed).
void FixFluidFlow::routes(int q, int to, bool mirror, bool &direct, bool &mirrored) const
{
  direct = owner(q) == to;
  mirrored = mirror && column && owner(nzt - 1 - q) == to;
}

// The force density on every rank's brick (this rank's: `force` on b) summed into the slabs, with the
// column's mirror image where `mirror`. Each plane of a brick goes once to each other rank that takes
// it (this rank's own are read where they are), and ranks and planes are summed in order, so that
// any number of ranks sums as one grid would.
void FixFluidFlow::sum_into_slabs(const Brick &b, const std::vector<double> &force, bool mirror)
{
  const int nprocs = comm->nprocs, me = comm->me;
  const long plane = 3L * static_cast<long>(b.nodes[0].size() * b.nodes[1].size());
  const std::vector<int> &zs = b.nodes[2];
  bool direct, mirrored;
  for (auto *counts : {&send_counts, &send_offsets, &recv_counts, &recv_offsets}) counts->assign(nprocs, 0);
  for (int pass = 0; pass < 2; ++pass) {    // the counts, then the planes
    long at = 0;
    for (int r = 0; r < nprocs; ++r) {
      send_offsets[r] = static_cast<int>(at);
      for (size_t k = 0; r != me && k < zs.size(); ++k) {
        routes(zs[k], r, mirror, direct, mirrored);
        if (!direct && !mirrored) continue;
        if (pass == 1) std::copy_n(&force[plane * k], plane, &sent[at]);
        at += plane;
      }
      send_counts[r] = static_cast<int>(at) - send_offsets[r];
    }
    if (pass == 0) sent.resize(at);
  }
  long total = 0;
  for (int s = 0; s < nprocs; ++s) {
    recv_offsets[s] = static_cast<int>(total);
    const int *qs = &bricks.nodes[bricks.offset[3 * s + 2]];
    for (int k = 0; s != me && k < bricks.size[3 * s + 2]; ++k) {
      routes(qs[k], me, mirror, direct, mirrored);
      if (direct || mirrored) total += 3L * bricks.size[3 * s] * bricks.size[3 * s + 1];
    }
    recv_counts[s] = static_cast<int>(total) - recv_offsets[s];
  }
  received.resize(total);
  MPI_Alltoallv(sent.data(), send_counts.data(), send_offsets.data(), MPI_DOUBLE, received.data(),
                recv_counts.data(), recv_offsets.data(), MPI_DOUBLE, world);
  std::fill(slab.begin(), slab.end(), 0.0);
  const long full = 3L * grid[0] * grid[1];
  for (int s = 0; s < nprocs; ++s) {
    const int nx = bricks.size[3 * s], ny = bricks.size[3 * s + 1];
    const int *xs = &bricks.nodes[bricks.offset[3 * s]], *ys = &bricks.nodes[bricks.offset[3 * s + 1]];
    const int *qs = &bricks.nodes[bricks.offset[3 * s + 2]];
    const double *block = received.data() + recv_offsets[s];
    for (int k = 0; k < bricks.size[3 * s + 2]; ++k) {
      routes(qs[k], me, mirror, direct, mirrored);
      if (!direct && !mirrored) continue;
      const double *values = s == me ? &force[plane * k] : block;
      for (int pass = 0; pass < 2; ++pass) {
        if (!(pass == 0 ? direct : mirrored)) continue;
        const double sign = pass == 0 ? 1.0 : -1.0;
        double *to = &slab[full * ((pass == 0 ? qs[k] : nzt - 1 - qs[k]) - plane_lo)];
        const double *from = values;
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i, from += 3) {
            double *node = to + 3L * (static_cast<long>(ys[j]) * grid[0] + xs[i]);
            node[0] += from[0];
            node[1] += from[1];
            node[2] += sign * from[2];
          }
      }
      if (s != me) block += 3L * nx * ny;
    }
  }
}

// The velocity in the slabs sent to every rank's brick (this rank's into `velocity` on b; its own
// planes copied where they are).
void FixFluidFlow::read_from_slabs(const Brick &b, std::vector<double> &velocity)
{
  const int nprocs = comm->nprocs, me = comm->me;
  const long full = 3L * grid[0] * grid[1];
  // Brick r's nodes of the slab's plane q, in its order ([j][i][c]), into `into`.
  auto copy_plane = [&](int r, int q, double *into) {
    const int nx = bricks.size[3 * r], ny = bricks.size[3 * r + 1];
    const int *xs = &bricks.nodes[bricks.offset[3 * r]], *ys = &bricks.nodes[bricks.offset[3 * r + 1]];
    const double *from = &slab[full * (q - plane_lo)];
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, into += 3) std::copy_n(from + 3L * (static_cast<long>(ys[j]) * grid[0] + xs[i]), 3, into);
  };
  long at = 0;
  for (int r = 0; r < nprocs; ++r) {
    send_offsets[r] = static_cast<int>(at);
    for (int k = 0; r != me && k < bricks.size[3 * r + 2]; ++k)
      if (owner(bricks.nodes[bricks.offset[3 * r + 2] + k]) == me) at += 3L * bricks.size[3 * r] * bricks.size[3 * r + 1];
    send_counts[r] = static_cast<int>(at) - send_offsets[r];
  }
  sent.resize(at);
  for (int r = 0; r < nprocs; ++r) {
    double *into = sent.data() + send_offsets[r];
    const int *qs = &bricks.nodes[bricks.offset[3 * r + 2]];
    for (int k = 0; r != me && k < bricks.size[3 * r + 2]; ++k)
      if (owner(qs[k]) == me) {
        copy_plane(r, qs[k], into);
        into += 3L * bricks.size[3 * r] * bricks.size[3 * r + 1];
      }
  }
  const long plane = 3L * static_cast<long>(b.nodes[0].size() * b.nodes[1].size());
  long total = 0;
  for (int s = 0; s < nprocs; ++s) {
    recv_offsets[s] = static_cast<int>(total);
    for (int q : b.nodes[2])
      if (s != me && owner(q) == s) total += plane;
    recv_counts[s] = static_cast<int>(total) - recv_offsets[s];
  }
  received.resize(total);
  MPI_Alltoallv(sent.data(), send_counts.data(), send_offsets.data(), MPI_DOUBLE, received.data(),
                recv_counts.data(), recv_offsets.data(), MPI_DOUBLE, world);
  velocity.resize(3 * b.size());
  for (int s = 0; s < nprocs; ++s) {
    const double *block = received.data() + recv_offsets[s];
    for (size_t k = 0; k < b.nodes[2].size(); ++k) {
      if (owner(b.nodes[2][k]) != s) continue;
      if (s == me) {
        copy_plane(me, b.nodes[2][k], &velocity[plane * k]);
      } else {
        std::copy_n(block, plane, &velocity[plane * k]);
        block += plane;
      }
    }
  }
}

void FixFluidFlow::spread_point(const Stencil &at, const double *force, std::vector<double> &density) const
{
  constexpr int nodes = sediment::FlowKernel::max_nodes;
  const double per_volume = 1.0 / (spacing[0] * spacing[1] * spacing[2]);
  const double fx = force[0] * per_volume, fy = force[1] * per_volume, fz = force[2] * per_volume;
  for (int c = 0; c < nodes; ++c) {
    for (int b = 0; b < nodes; ++b) {
      double *row = &density[at.node[2][c] + at.node[1][b]];
      const double wzy = at.w[2][c] * at.w[1][b];
      for (int a = 0; a < nodes; ++a) {
        double *node = row + at.node[0][a];
        const double weight = wzy * at.w[0][a];
        node[0] += weight * fx;
        node[1] += weight * fy;
        node[2] += weight * fz;
      }
    }
  }
}

void FixFluidFlow::read_point(const Stencil &at, const std::vector<double> &velocity, double *u) const
{
  constexpr int nodes = sediment::FlowKernel::max_nodes;
  double ux = 0.0, uy = 0.0, uz = 0.0;
  for (int c = 0; c < nodes; ++c) {
    for (int b = 0; b < nodes; ++b) {
      const double *row = &velocity[at.node[2][c] + at.node[1][b]];
      const double wzy = at.w[2][c] * at.w[1][b];
      for (int a = 0; a < nodes; ++a) {
        const double *node = row + at.node[0][a];
        const double weight = wzy * at.w[0][a];
        ux += weight * node[0];
        uy += weight * node[1];
        uz += weight * node[2];
      }
    }
  }
  u[0] = ux;
  u[1] = uy;
  u[2] = uz;
}

// What a unit force gives back on the grid at the point where it is spread, per axis: the kernel's
// own mobility with that of its periodic images (and none of its mirror: the column's wall acts on
// a sphere as on its neighbours). Measured, not taken from Hasimoto's series, which the kernel's
// width outgrows on coarse grids.
void FixFluidFlow::measure_self_flow()
{
  // A unit force at a node, alone on the transform grid (no mirror image): read where it is, its own
  // flow with its periodic images; read along z from it, in a closed column, the flow its mirror image
  // gives a sphere at each distance from the bottom or top (the image of a sphere at height z lies
  // 2 (z - zlo) below it, and modulo the transform's height, 2 (zhi - z) above: one image).
  const double at[3] = {origin[0] + 0.5 * spacing[0], origin[1] + 0.5 * spacing[1], origin[2] + 0.5 * spacing[2]};
  const int reads = column ? IMAGE_STEPS * grid[2] + 1 : 1;
  std::vector<Stencil> unit, read;
  if (comm->me == 0) {    // spread and read on rank 0
    unit.push_back(stencil_at(at));
    for (int j = 0; j < reads; ++j) {
      const double point[3] = {at[0], at[1], at[2] + spacing[2] * j / IMAGE_STEPS};
      read.push_back(stencil_at(point));
    }
  }
  std::vector<Stencil> both(unit);
  both.insert(both.end(), read.begin(), read.end());
  Brick b;
  build_brick(b, both, false);
  gather_bricks(b);
  for (Stencil &s : unit) place(s, b);
  for (Stencil &s : read) place(s, b);
  image_flow.assign(3 * reads, 0.0);
  std::vector<double> force, velocity;
  for (int c = 0; c < 3; ++c) {
    force.assign(3 * b.size(), 0.0);
    double u[3] = {0.0, 0.0, 0.0};
    u[c] = 1.0;
    for (const Stencil &s : unit) spread_point(s, u, force);
    sum_into_slabs(b, force, false);
    transform_solve();
    read_from_slabs(b, velocity);
    for (size_t j = 0; j < read.size(); ++j) {
      read_point(read[j], velocity, u);
      // the image's force: the same along x and y, reversed along z (free slip)
      image_flow[3 * j + c] = (c == 2 ? -1.0 : 1.0) * u[c];
    }
    if (comm->me == 0) self_flow[c] = image_flow[c] * (c == 2 ? -1.0 : 1.0);
  }
  MPI_Bcast(self_flow, 3, MPI_DOUBLE, 0, world);
  MPI_Bcast(image_flow.data(), 3 * reads, MPI_DOUBLE, 0, world);
}

// The flow per unit force that the mirror image of a sphere at height z gives it back, per axis (a
// closed column only): interpolated in the table of measure_self_flow by the separation of the two.
void FixFluidFlow::image_flow_at(double z, double *u) const
{
  const double steps = 2.0 * (z - origin[2]) / spacing[2], period = nzt;
  double s = steps - period * std::floor(steps / period);
  s = IMAGE_STEPS * std::min(s, period - s);
  const int last = IMAGE_STEPS * grid[2];
  const int j = std::min(static_cast<int>(s), last - 1);
  const double t = std::min(s - j, 1.0);
  for (int c = 0; c < 3; ++c) u[c] = (1.0 - t) * image_flow[3 * j + c] + t * image_flow[3 * (j + 1) + c];
}

// Which planes go where for separate_xy: plane q of the transform lies on the rank r with
// first_plane[r] <= q < first_plane[r + 1]. Each rank sends its planes p, in increasing order, to
// the rank that holds nzt - p (mod nzt); a receiver lists the same planes of each sender in the
// same order, and so knows which of its own planes each one serves.
void FixFluidFlow::plan_mirror_exchange()
{
  const int nprocs = comm->nprocs, me = comm->me;
  const int plane = 2 * grid[0] * grid[1];    // complex values
  auto mirror_of = [&](int q) { return (nzt - q) % nzt; };
  mirror_sent.clear();
  mirror_serves.clear();
  mirror_send_counts.assign(nprocs, 0);
  mirror_send_offsets.assign(nprocs, 0);
  mirror_recv_counts.assign(nprocs, 0);
  mirror_recv_offsets.assign(nprocs, 0);
  for (int r = 0; r < nprocs; ++r) {
    mirror_send_offsets[r] = plane * static_cast<int>(mirror_sent.size());
    for (int p = plane_lo; p <= plane_hi; ++p)
      if (owner(mirror_of(p)) == r) mirror_sent.push_back(p);
    mirror_send_counts[r] = plane * static_cast<int>(mirror_sent.size()) - mirror_send_offsets[r];
    mirror_recv_offsets[r] = plane * static_cast<int>(mirror_serves.size());
    for (int p = first_plane[r]; p < first_plane[r + 1]; ++p)
      if (owner(mirror_of(p)) == me) mirror_serves.push_back(mirror_of(p));
    mirror_recv_counts[r] = plane * static_cast<int>(mirror_serves.size()) - mirror_recv_offsets[r];
  }
  mirror_out.assign(static_cast<size_t>(plane) * mirror_sent.size(), 0.0);
  mirror_in.assign(static_cast<size_t>(plane) * mirror_serves.size(), 0.0);
}

// field[0] holds Z = F_x + i F_y, the transform of f_x + i f_y (both real). Since F(-k) is the
// conjugate of F(k) for a real f, F_x = (Z(k) + conj Z(-k)) / 2 and F_y = (Z(k) - conj Z(-k)) / 2i:
// written into field[0] and field[1], with Z(-k) from the planes nzt - k (mod nzt), which may lie on
// other ranks (plan_mirror_exchange).
void FixFluidFlow::separate_xy()
{
  const int n0 = grid[0], n1 = grid[1];
  const size_t plane = 2L * n0 * n1;
  for (size_t s = 0; s < mirror_sent.size(); ++s)
    std::copy_n(&field[0][plane * (mirror_sent[s] - plane_lo)], plane, &mirror_out[plane * s]);
  MPI_Alltoallv(mirror_out.data(), mirror_send_counts.data(), mirror_send_offsets.data(), MPI_DOUBLE,
                mirror_in.data(), mirror_recv_counts.data(), mirror_recv_offsets.data(), MPI_DOUBLE, world);
  for (size_t s = 0; s < mirror_serves.size(); ++s) {
    const double *zm = &mirror_in[plane * s];
    double *zx = &field[0][plane * (mirror_serves[s] - plane_lo)];
    double *zy = &field[1][plane * (mirror_serves[s] - plane_lo)];
    for (int j = 0; j < n1; ++j)
      for (int i = 0; i < n0; ++i) {
        const size_t m = 2 * (static_cast<size_t>(j) * n0 + i);
        const size_t mm = 2 * (static_cast<size_t>((n1 - j) % n1) * n0 + (n0 - i) % n0);
        const double a = zx[m], b = zx[m + 1], c = zm[mm], d = zm[mm + 1];
        zx[m] = 0.5 * (a + c);
        zx[m + 1] = 0.5 * (b - d);
        zy[m] = 0.5 * (b + d);
        zy[m + 1] = 0.5 * (c - a);
      }
  }
}

// The flow of the force density in this rank's slab, into the slab.
void FixFluidFlow::transform_solve()
{
  // f_x + i f_y in one transform and f_z in another, told apart in Fourier space (separate_xy)
  const size_t mine = slab.size() / 3;
  double *xy = field[0].data(), *z = field[2].data();
  for (size_t m = 0; m < mine; ++m) {
    xy[2 * m] = slab[3 * m];
    xy[2 * m + 1] = slab[3 * m + 1];
    z[2 * m] = slab[3 * m + 2];
    z[2 * m + 1] = 0.0;
  }
  fft->compute(xy, xy, FFT3d::FORWARD);
  fft->compute(z, z, FFT3d::FORWARD);
  separate_xy();
  const int n[3] = {grid[0], grid[1], nzt};
  const double transform_length[3] = {length[0], length[1], column ? 2.0 * length[2] : length[2]};
  const int lo[3] = {0, 0, plane_lo}, hi[3] = {grid[0] - 1, grid[1] - 1, plane_hi};
  sediment::stokes_apply_brick(stokes, n, transform_length, lo, hi, field[0].data(), field[1].data(), field[2].data(),
                               1.0 / (static_cast<double>(n[0]) * n[1] * n[2]));
  // The velocity is real: u_x + i u_y is the inverse transform of U_x + i U_y, so one transform
  // brings back both (its real and imaginary parts), and u_z takes another.
  const double *uy = field[1].data();
  for (size_t m = 0; m < mine; ++m) {
    xy[2 * m] -= uy[2 * m + 1];
    xy[2 * m + 1] += uy[2 * m];
  }
  fft->compute(xy, xy, FFT3d::BACKWARD);
  fft->compute(z, z, FFT3d::BACKWARD);
  for (size_t m = 0; m < mine; ++m) {
    slab[3 * m] = xy[2 * m];
    slab[3 * m + 1] = xy[2 * m + 1];
    slab[3 * m + 2] = z[2 * m];
  }
}

bool FixFluidFlow::outside_column(const double *x) const
{
  return column && !(x[2] >= column_lo && x[2] < column_hi);
}

// Spheres the flow leaves out: outside the column, those stopped on a floor of fix nve/sphere/fluid
// (the deposit, whose weight the floor carries), and those whose local fraction is past their
// hindrance's cap (max_fraction, random close packing by default): a bed, which grains without
// contacts only reach piled on the floor. Held there whatever the fluid does, such a sphere's drag
// against the flow would only resist it, and a deposit's many resist it so stiffly that the lagged
// flow diverges within a few solves of the first landings; a bed's, capped, hold its spheres to the
// fluid, which they then stir as a suspension far denser than the bed (docs/physics.md section 8).
bool FixFluidFlow::left_out(int i) const
{
  if (outside_column(atom->x[i])) return true;
  for (const FixNVESphereFluid *floor : floors)
    if (floor->at_rest_on_floor(i)) return true;
  for (const FixFluidDrag *drag : drags)
    if (drag->fraction_capped(i)) return true;
  return false;
}

// A sphere held under the surface of a fix nve/sphere/fluid (solve() spreads none of its force).
bool FixFluidFlow::held_at_surface(int i) const
{
  for (const FixNVESphereFluid *integrator : floors)
    if (integrator->held_at_surface(i)) return true;
  return false;
}

void FixFluidFlow::solve()
{
  const int nlocal = atom->nlocal;
  const int *mask = atom->mask;
  double **x = atom->x;
  double local[4] = {0.0, 0.0, 0.0, 0.0};    // force on the fluid, spheres left out
  spheres.clear();
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    if (left_out(i))
      local[3] += 1.0;
    else
      spheres.push_back(i);
  }
  sphere_forces();
  // A sphere held at a surface of fix nve/sphere/fluid pushes the surface, which takes the force; it
  // reads the flow where it is, which keeps it there while the flow presses it up.
  held.assign(spheres.size(), 0);
  for (size_t s = 0; s < spheres.size(); ++s)
    if (held_at_surface(spheres[s])) {
      held[s] = 1;
      local[3] += 1.0;
      for (int c = 0; c < 3; ++c) forces[3 * s + c] = 0.0;
    }
  stencils.resize(spheres.size());
  for (size_t s = 0; s < spheres.size(); ++s) stencils[s] = stencil_at(x[spheres[s]]);
  build_brick(brick, stencils, true);
  gather_bricks(brick);
  if (stratify) stratification_force();
  spread.assign(3 * brick.size(), 0.0);
  for (size_t s = 0; s < spheres.size(); ++s) {
    place(stencils[s], brick);
    const double *force = &forces[3 * s];
    // the displaced stratification's force is not one the spheres lose (docs/physics.md section 8)
    const double spreads[3] = {force[0], force[1], force[2] + (stratify && !held[s] ? restoring[s] : 0.0)};
    if (spreads[0] == 0.0 && spreads[1] == 0.0 && spreads[2] == 0.0) continue;
    for (int c = 0; c < 3; ++c) local[c] += force[c];
    spread_point(stencils[s], spreads, spread);
  }
  double total[4];
  MPI_Allreduce(local, total, 4, MPI_DOUBLE, MPI_SUM, world);

  sum_into_slabs(brick, spread, true);
  transform_solve();

  // Diagnostics: the largest mean vertical velocity over a plane of nodes in the fluid (zero: no
  // net flux) and the largest speed component on the grid.
  double largest[2] = {0.0, 0.0}, overall[2];    // flux, peak
  const long plane = static_cast<long>(grid[0]) * grid[1];
  for (int q = plane_lo; q <= std::min(plane_hi, grid[2] - 1); ++q) {
    const double *u = &slab[3 * plane * (q - plane_lo)];
    double sum = 0.0;
    for (long m = 0; m < plane; ++m) {
      sum += u[3 * m + 2];
      for (int c = 0; c < 3; ++c) largest[1] = std::max(largest[1], std::abs(u[3 * m + c]));
    }
    largest[0] = std::max(largest[0], std::abs(sum / plane));
  }
  MPI_Allreduce(largest, overall, 2, MPI_DOUBLE, MPI_MAX, world);
  read_from_slabs(brick, flow);
  for (int c = 0; c < 3; ++c) diag[FX + c] = total[c];
  diag[FLUX] = overall[0];
  const double carried_by = diag[PEAK];    // the flow the spheres moved in since the last solve
  diag[PEAK] = overall[1];
  diag[LEFT_OUT] = total[3];
  check_carry(overall[1], carried_by);

  // Each sphere's fluid velocity: the uniform flow of fix fluid plus what the grid gives it, less what
  // its own force and its periodic images give it, S(0) times over in a suspension (the neighbours
  // kept clear of it: what the hindrance law already holds; docs/physics.md section 8), once for
  // parcels (placed independently, no neighbour is kept clear of one). relax acts on the grid's
  // part; the uniform velocity is the fluid's, whatever it was at the last solve.
  const double *uniform = fluid->velocity();
  // sums over the spheres: new . old, new . new, old . old, and the solve's residual, (target - old)^2
  double change[4] = {0.0, 0.0, 0.0, 0.0};
  size_t s = 0;                          // the next of `spheres` (in the order of the atoms)
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    double u[3] = {0.0, 0.0, 0.0};
    const bool inside = s < spheres.size() && spheres[s] == i;    // else left out: the uniform flow
    if (inside) {
      read_point(stencils[s], flow, u);
      const double own = weight_index >= 0 ? 1.0 : sediment::hard_sphere_structure_factor(fractions[s]);
      for (int c = 0; c < 3; ++c) u[c] -= own * self_flow[c] * forces[3 * s + c];
      // A parcel's mirror image, like the parcel, stirs the fluid with sqrt(w S(0)) grains' force; the
      // parcel moves as one grain and meets one grain's image (docs/physics.md section 8, Parcels).
      if (column && weight_index >= 0 && scales[s] > 1.0) {
        double image[3];
        image_flow_at(x[i][2], image);
        for (int c = 0; c < 3; ++c) u[c] -= (1.0 - 1.0 / scales[s]) * image[c] * forces[3 * s + c];
      }
      ++s;
    }
    for (int c = 0; c < 3; ++c) {
      const double old = velocity[i][c] - solved_uniform[c];
      const double now = relax < 1.0 && inside ? old + relax * (u[c] - old) : u[c];
      velocity[i][c] = uniform[c] + now;
      change[0] += now * old;
      change[1] += now * now;
      change[2] += old * old;
      change[3] += (u[c] - old) * (u[c] - old);
    }
  }
  double changes[4];
  MPI_Allreduce(change, changes, 4, MPI_DOUBLE, MPI_SUM, world);
  if (solved) check_stable(changes);
  // Settled once a solve finds the spheres' fluid velocities within half the drift fraction of what
  // they were (before any relax); until then their drags, and so the flow, are stale though the
  // spheres may not move (held in a stream), and drift solves again at the next step. Spheres that
  // moved drift cells since the last solve leave less behind: 0.002 to 0.08 at drift 0.2 in the
  // scenes of benchmarks/flow_drift.py and flow_cost.py.
  const double settled = 0.5 * drift_limit;
  unsettled = changes[3] > settled * settled * std::max(changes[1], changes[2]);
  std::copy_n(uniform, 3, solved_uniform);
  solved_viscosity = stokes.viscosity;
  solved = true;
  drift = 0.0;
  diag[SOLVES] += 1.0;
}

// The flow carries the spheres: across a cell or more between solves, the density it is solved from
// jumps, and a dense scene can run away (doc page, Stability). Warned once, with the numbers; a run
// in which it has done so at four solves in a row while the grid's largest velocity grew tenfold
// stops, before its results go wrong (and before the spheres jump across the box, which LAMMPS
// reports as lost atoms). How far: with drift, the path of the fastest sphere since the last solve,
// which the fix has measured; with every N, the grid's largest velocity over the steps (the last
// solve's, which moved them: the new one's would count a flow that has only just started, and cfl
// shortens the steps it will carry them), which bounds it where the spheres go with their fluid (not a sphere held where the flow pushes it into the free
// surface, whose flow carries nothing: late in sample 2's column the grid's 88 um/s over 128 steps of
// a solve made 297 cells, where the fastest sphere had moved the fifth of one that drift allows).
void FixFluidFlow::check_carry(double peak, double carried_by)
{
  const bigint steps = std::max<bigint>(1, update->ntimestep - last_solve);
  last_solve = update->ntimestep;
  const double cells = drift_limit > 0.0 ? drift : carried_by * update->dt * static_cast<double>(steps) / spacing[0];
  if (!(cells > 1.0)) {
    carries = 0;
    return;
  }
  // Across half the periodic box or more in one solve, the flow has lost every sphere's place: the next
  // steps would carry spheres past their ranks' subdomains, which LAMMPS reports as lost atoms. Where
  // the fluid velocities reverse from solve to solve, check_stable names the lag's instability instead.
  const int across = std::min(grid[0], grid[1]);
  if (cells > 0.5 * across && reversals == 0)
    error->all(FLERR, "Fix fluid/flow: the flow carries spheres {:.3g} cells between solves, more than half the box "
               "across ({} cells; largest velocity on the grid {:.3g}, step {}): the scene runs away; take a smaller "
               "timestep, a coarser grid, or solve more often (see the doc page)", cells, across, peak,
               update->ntimestep);
  if (carries++ == 0) carry_start = peak;
  if (carries >= 4 && peak > 10.0 * carry_start)
    error->all(FLERR, "Fix fluid/flow: the flow has carried spheres a cell or more between each of the last {} solves "
               "and its largest velocity grew from {:.3g} to {:.3g} (step {}): the scene runs away; take a smaller "
               "timestep, a coarser grid, or solve more often (see the doc page)", carries, carry_start, peak,
               update->ntimestep);
  if (warned_carry) return;
  warned_carry = true;
  if (comm->me == 0)
    error->warning(FLERR, "Fix fluid/flow: the flow carries spheres {:.3g} cells between solves ({} steps of {:.3g} "
                   "/ cell {:.3g}, {}; step {}); above one cell it cannot follow the density it is solved from, and a "
                   "dense scene can run away: {}", cells, steps, update->dt, spacing[0],
                   drift_limit > 0.0 ? "the fastest sphere's path"
                                     : fmt::format("largest velocity on the grid {:.3g}", carried_by),
                   update->ntimestep,
                   cfl > 0.0 ? "cfl shortens the steps by the flow from now on (the spheres' own settling is not limited)"
                             : "take a smaller timestep, a coarser grid, solve more often, or give cfl");
}

// The lagged solve's instability (doc page, Stability): the spheres' fluid velocities reverse from
// solve to solve and grow. A flow the spheres drive does not keep reversing; once a run of reversals
// has grown the velocities a hundredfold, the run stops before its results go wrong.
void FixFluidFlow::check_stable(const double *change)
{
  if (change[0] < 0.0 && change[1] > change[2]) {
    ++reversals;
    reversal_growth *= change[1] / change[2];    // of the squared speeds
  } else {
    reversals = 0;
    reversal_growth = 1.0;
  }
  if (reversals >= 4 && reversal_growth > 1e4)
    error->all(FLERR, "Fix fluid/flow: the fluid velocity reversed at each of the last {} solves and grew {:.3g} "
               "times (step {}): the lagged flow is unstable at this time step; use relax W with W < 1/(1+K), K "
               "the collective mobility over the single sphere's (about 6/5 N a/R for a cloud), a longer step, or "
               "every N (see the doc page)", reversals, std::sqrt(reversal_growth), update->ntimestep);
}

double FixFluidFlow::compute_vector(int n)
{
  // force on the fluid (x, y, z), largest |mean u_z| over a plane of nodes, largest |u| component on
  // the grid, spheres of the group whose force was left out (outside the column, on a floor, held under a surface,
  // capped; all of the last solve); solves so far
  return diag[n];
}

void FixFluidFlow::grow_arrays(int nmax)
{
  memory->grow(velocity, nmax, 3, "fluid/flow:velocity");
  memory->grow(excess, nmax, "fluid/flow:excess");
  memory->grow(stepped_voidage, nmax, "fluid/flow:stepped_voidage");
  array_atom = velocity;
}

void FixFluidFlow::copy_arrays(int i, int j, int /*delflag*/)
{
  for (int c = 0; c < 3; ++c) velocity[j][c] = velocity[i][c];
  excess[j] = excess[i];
  stepped_voidage[j] = stepped_voidage[i];
}

// A sphere created during a run (create_atoms between runs, fix deposit or pour) takes the fluid
// velocity of the last solve where it is, until the next solve gives it its own: not the row a
// deleted sphere left behind.
void FixFluidFlow::set_arrays(int i)
{
  // The fluid is looked up by its ID: it may be defined after this fix, or replaced since the last
  // run's init (and init then sets every sphere's velocity, if nothing was solved yet).
  const auto *now = dynamic_cast<const FixFluid *>(sediment_fix_by_id(modify, fluid_id));
  static const double at_rest[3] = {0.0, 0.0, 0.0};
  const double *uniform = now ? now->velocity() : at_rest;
  double u[3] = {0.0, 0.0, 0.0};
  const double *x = atom->x[i];
  // The last solve's grid where this rank holds it (its subdomain's nodes: where spheres are created);
  // none yet after a restart
  if (Stencil at = stencil_at(x); solved && !outside_column(x) && !flow.empty() && holds(at, brick)) {
    place(at, brick);
    read_point(at, flow, u);
  }
  for (int c = 0; c < 3; ++c) velocity[i][c] = uniform[c] + u[c];
  excess[i] = 0.0;
  stepped_voidage[i] = -1.0;
}

int FixFluidFlow::pack_exchange(int i, double *buf)
{
  for (int c = 0; c < 3; ++c) buf[c] = velocity[i][c];
  buf[3] = excess[i];
  buf[4] = stepped_voidage[i];
  return 5;
}

int FixFluidFlow::unpack_exchange(int nlocal, double *buf)
{
  for (int c = 0; c < 3; ++c) velocity[nlocal][c] = buf[c];
  excess[nlocal] = buf[3];
  stepped_voidage[nlocal] = buf[4];
  return 5;
}

void FixFluidFlow::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  // A negative count first: files written before it held 4 values, the first 0 or 1. Last the profiles
  // of stratification grains, whose slopes the steps before the next solve read (their classes, then them).
  const double count = RESTART_VALUES + STEP_VALUES + profiles.size() + class_force.size();
  std::vector<double> state = {-count, (solved ? 1.0 : 0.0) + STEP_STATE, drift, solved_speed, unsettled ? 1.0 : 0.0,
                               solved_viscosity};
  state.insert(state.end(), solved_uniform, solved_uniform + 3);
  state.insert(state.end(), diag, diag + NDIAG);
  state.push_back(solve_interval);
  state.push_back(lowest_class);
  state.push_back(grid[2]);
  state.push_back(longest_dt);
  state.push_back(applied_dt);
  state.insert(state.end(), profiles.begin(), profiles.end());
  state.insert(state.end(), class_force.begin(), class_force.end());
  const int size = static_cast<int>(state.size() * sizeof(double));
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(state.data(), sizeof(double), state.size(), fp);
}

void FixFluidFlow::restart(char *buf)
{
  // Four layouts. Files written before the fix kept its diagnostics and the fluid of its last solve
  // hold 4 values: solved, drift, speed, solves (the first 0 or 1); its first run then solves again.
  // Files written before stratification grains kept its state hold UNSTRATIFIED, and the fifth value
  // per atom some of them hold was a displacement, not an excess: it is not read. Then RESTART_VALUES,
  // and since cfl (solved given as STEP_STATE more) its steps after them; then per class its profile
  // (planes values), then per class its force.
  double first, second = 0.0;
  memcpy(&first, buf, sizeof(double));
  const bool before = first >= 0.0;
  const double count = -first;
  if (!before && count >= 2.0) memcpy(&second, buf + sizeof(double), sizeof(double));
  const int fixed = RESTART_VALUES + (second >= STEP_STATE ? STEP_VALUES : 0);
  std::vector<double> state(before ? 4 : (count == UNSTRATIFIED ? UNSTRATIFIED : fixed), 0.0);
  excess_in_file = !before && count != UNSTRATIFIED;
  double planes = 0.0, classes = 0.0;
  if (excess_in_file) {
    if (count >= fixed) memcpy(state.data(), buf, fixed * sizeof(double));
    planes = state[RESTART_VALUES - 1];
    classes = planes >= 1.0 ? (count - fixed) / (planes + 1.0) : -1.0;
    if (count < fixed || !(classes >= 0.0) || classes != std::floor(classes))
      error->all(FLERR, "Fix fluid/flow: the restart file holds {} values of its state, not {} and its "
                 "profiles: written by another release", count, fixed);
  } else {
    memcpy(state.data(), buf, state.size() * sizeof(double));
  }
  if (fixed > RESTART_VALUES) {
    state[1] -= STEP_STATE;
    longest_dt = state[RESTART_VALUES];
    applied_dt = state[RESTART_VALUES + 1];
  }
  const double *kept = before ? state.data() : state.data() + 1;    // solved, drift, speed
  solved = kept[0] != 0.0;
  drift = kept[1];
  solved_speed = kept[2];
  if (before) {
    diag[SOLVES] = state[3];
    solved_viscosity = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  unsettled = state[4] != 0.0;
  solved_viscosity = state[5];
  std::copy_n(&state[6], 3, solved_uniform);
  std::copy_n(&state[9], static_cast<int>(NDIAG), diag);
  if (!excess_in_file) return;
  solve_interval = state[9 + NDIAG];
  lowest_class = static_cast<int>(state[10 + NDIAG]);
  std::vector<double> stored(static_cast<size_t>(count) - fixed);
  if (!stored.empty()) memcpy(stored.data(), buf + fixed * sizeof(double), stored.size() * sizeof(double));
  const auto profile_values = static_cast<size_t>(classes * planes);
  profiles.assign(stored.begin(), stored.begin() + profile_values);
  class_force.assign(stored.begin() + profile_values, stored.end());
  if (static_cast<int>(planes) != grid[2]) profiles.clear();    // another grid's: the next solve makes this one's
}

int FixFluidFlow::pack_restart(int i, double *buf)
{
  buf[0] = 5;
  for (int c = 0; c < 3; ++c) buf[1 + c] = velocity[i][c];
  buf[4] = excess[i];
  return 5;
}

void FixFluidFlow::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; ++k) m += static_cast<int>(extra[nlocal][m]);
  const int size = static_cast<int>(extra[nlocal][m++]);    // 4 in files written before the excess
  for (int c = 0; c < 3; ++c) velocity[nlocal][c] = extra[nlocal][m + c];
  excess[nlocal] = size > 4 && excess_in_file ? extra[nlocal][m + 3] : 0.0;    // restart() read the layout
}

int FixFluidFlow::size_restart(int /*i*/)
{
  return 5;
}

int FixFluidFlow::maxsize_restart()
{
  return 5;
}

double FixFluidFlow::memory_usage()
{
  const double grids = static_cast<double>(spread.capacity() + flow.capacity() + slab.size() + 3 * field[0].size() +
                                           mirror_out.size() + mirror_in.size() + sent.capacity() +
                                           received.capacity() + image_flow.capacity()) +
      static_cast<double>(bricks.nodes.capacity()) * sizeof(int) / sizeof(double);
  const double per_sphere = static_cast<double>(stencils.capacity()) * sizeof(Stencil) +
      static_cast<double>(forces.capacity() + fractions.capacity() + scales.capacity() + diameter.capacity() +
                          speed.capacity() + voidage.capacity() + per_speed.capacity()) * sizeof(double) +
      static_cast<double>(spheres.capacity()) * sizeof(int);
  const double stratification =
      static_cast<double>(profiles.capacity() + class_force.capacity() + slope_share.capacity() + restoring.capacity()) *
          sizeof(double);
  return (5.0 * atom->nmax + grids) * sizeof(double) + per_sphere + stratification;
}
