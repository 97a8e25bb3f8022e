// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid/drag
------------------------------------------------------------------------- */

#include "fix_fluid_drag.h"
#include "sediment_args.h"

#include "compute_concentration_grid.h"
#include "fix_fluid.h"

#include "atom.h"
#include "compute.h"
#include "comm.h"
#include "error.h"
#include "modify.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mpi.h>

using namespace LAMMPS_NS;
using namespace FixConst;

static inline double norm(const double *w)
{
  return sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
}

FixFluidDrag::FixFluidDrag(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), fluid_id(nullptr), fluid(nullptr), law(sediment::DragLaw::Stokes),
    hindrance_buoyancy(sediment::HindranceBuoyancy::Plain), hindrance(sediment::Hindrance::None),
    concentration_id(nullptr),
    concentration(nullptr), max_fraction(0.64), rotation(0), implicit_groupbit(0), all_implicit(false)
{
  if (narg < 6)
    error->all(FLERR, "Fix fluid/drag: expected 'fix ID group fluid/drag FLUID-ID law NAME'");
  fluid_id = utils::strdup(arg[3]);
  bool has_law = false, has_hindrance = false;
  StyleArgs args(lmp, FLERR, "Fix fluid/drag", narg, arg, 4);
  while (args.more()) {
    if (args.is("law")) {
      args.need(1, "a name");
      const auto parsed = sediment::drag_law_from_name(args.text(1));
      if (!parsed) args.fail("unknown law '{}' (expected one of {})", args.text(1), sediment::drag_law_names());
      law = *parsed;
      has_law = true;
    } else if (args.is("hindrance")) {
      args.need(1, "a name");
      const auto parsed = sediment::hindrance_from_name(args.text(1));
      if (!parsed)
        args.fail("unknown hindrance '{}' (expected one of {})", args.text(1), sediment::hindrance_names());
      hindrance = *parsed;
      has_hindrance = true;
    } else if (args.is("rotation")) {
      args.need(1, "yes or no");
      rotation = args.yes_no(1);
    } else if (args.is("concentration")) {
      args.need(1, "a compute ID");
      delete[] concentration_id;
      concentration_id = utils::strdup(args.text(1));
    } else if (args.is("buoyancy")) {
      const std::string names = sediment::hindrance_buoyancy_names();
      args.need(1, names.c_str());
      const auto parsed = sediment::hindrance_buoyancy_from_name(args.text(1));
      if (!parsed) args.fail("buoyancy must be {}, not '{}'", names, args.text(1));
      hindrance_buoyancy = *parsed;
    } else if (args.is("max_fraction")) {
      args.need(1, "a value");
      max_fraction = args.number(1);
      if (!(max_fraction > 0.0 && max_fraction < 1.0)) args.fail("max_fraction must be in (0, 1)");
    } else {
      args.unknown("law, hindrance, rotation, concentration, buoyancy or max_fraction");
    }
    args.next(1);
  }
  if (!has_law) error->all(FLERR, "Fix fluid/drag: keyword 'law' is required");
  // The messages below name laws and hindrances from the core's list (sediment/drag.hpp).
  const sediment::DragLawTraits &traits = sediment::drag_law_traits(law);
  if (traits.own_hindrance != sediment::Hindrance::None) {
    if (has_hindrance)
      error->all(FLERR, "Fix fluid/drag: law {} is law {}'s drag with hindrance {}; for another hindrance name "
                 "law {} and 'hindrance NAME'", sediment::drag_law_name(law), sediment::drag_law_name(traits.curve),
                 sediment::hindrance_name(traits.own_hindrance), sediment::drag_law_name(traits.curve));
    hindrance = traits.own_hindrance;
  }
  if (!sediment::law_takes_hindrance(law, hindrance))
    error->all(FLERR, "Fix fluid/drag: law {} takes no hindrance {} ({})", sediment::drag_law_name(law),
               sediment::hindrance_name(hindrance), sediment::hindrance_refusal(law, hindrance));
  if (hindrance != sediment::Hindrance::None && !concentration_id)
    error->all(FLERR, "Fix fluid/drag: {} needs keyword 'concentration c_ID' (a compute concentration/grid)",
               traits.own_hindrance != sediment::Hindrance::None
                   ? fmt::format("law {}", sediment::drag_law_name(law))
                   : fmt::format("hindrance {}", sediment::hindrance_name(hindrance)));
  if (hindrance == sediment::Hindrance::None && concentration_id)
    error->all(FLERR, "Fix fluid/drag: keyword 'concentration' goes with a hindrance (hindrance NAME, or law {})",
               sediment::drag_law_names([](const sediment::DragLawTraits &other) {
                 return other.own_hindrance != sediment::Hindrance::None;
               }));
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "Fix fluid/drag requires atom attributes radius and rmass (atom_style sphere)");
  if (rotation && (!atom->omega_flag || !atom->torque_flag))
    error->all(FLERR, "Fix fluid/drag: rotation yes requires atom attributes omega and torque");

  vector_flag = 1;
  size_vector = 6;
  global_freq = 1;
  extvector = 1;
}

FixFluidDrag::~FixFluidDrag()
{
  delete[] fluid_id;
  delete[] concentration_id;
}

int FixFluidDrag::setmask()
{
  return POST_FORCE;
}

void FixFluidDrag::init()
{
  fluid = FixFluid::find(lmp, fluid_id, "Fix fluid/drag");
  model = std::make_unique<sediment::DragModel>(law, fluid->properties(), hindrance_buoyancy, hindrance);
  concentration =
      concentration_id ? ComputeConcentrationGrid::find_fraction(lmp, concentration_id, "Fix fluid/drag") : nullptr;
  implicit_groupbit = 0;
  for (Fix *integrator : sediment_fixes_of_style(lmp, "nve/sphere/fluid")) implicit_groupbit |= integrator->groupbit;
  // Group 'all' (bit 1) or this fix's own group: no atom of the group is dragged here.
  all_implicit = (implicit_groupbit & 1) || (implicit_groupbit & groupbit);
}

void FixFluidDrag::setup(int vflag)
{
  post_force(vflag);
  const int unstable = count_unstable_explicit();
  if (unstable > 0 && comm->me == 0)
    error->warning(FLERR, "Fix fluid/drag: {} sphere(s) have dt > 2 tau under explicit drag and "
                   "will oscillate or diverge; use fix nve/sphere/fluid or a smaller timestep",
                   unstable);
}

void FixFluidDrag::prepare_step()
{
  fluid->prepare();
}

void FixFluidDrag::refresh_concentration()
{
  // Evaluated once positions are final for this step (post_force), never in initial_integrate:
  // the implicit integrator of the next step reads these values, for the positions it starts
  // from, and atoms are not reordered in between.
  if (concentration && concentration->invoked_peratom != update->ntimestep) concentration->compute_peratom();
}

FixFluidDrag::Immersed FixFluidDrag::immersed() const
{
  return {model.get(), atom->radius, concentration ? concentration->vector_atom : nullptr, max_fraction};
}

sediment::SphereDrag FixFluidDrag::sphere_drag(int i) const
{
  if (!(atom->mask[i] & groupbit)) return {};
  const sediment::Submergence sub = fluid->immersion(atom->x[i], atom->radius[i]);
  if (!sub.any()) return {};
  sediment::SphereDrag drag = immersed_drag(i);
  drag.scale.area = sub.area;
  drag.scale.wetted = sub.wetted;
  return drag;
}

double FixFluidDrag::rotation_rate(int i, const sediment::SphereDrag &drag) const
{
  if (!rotation || !drag.model) return 0.0;
  return sediment::rotation_drag_rate(fluid->properties().viscosity, drag.diameter, atom->rmass[i],
                                      drag.scale.wetted);
}

bool FixFluidDrag::immersed_everywhere() const
{
  return fluid->fills_space() && !rotation;
}

bool FixFluidDrag::uniform() const
{
  return immersed_everywhere() && !fluid->has_atom_flow();
}

template <class Visit> void FixFluidDrag::for_each_explicit(Visit visit)
{
  double **v = atom->v;
  const int *mask = atom->mask;
  const bool everywhere = fluid->fills_space();    // tested once, not per atom
  prepare_step();
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit) || (mask[i] & implicit_groupbit)) continue;
    const sediment::SphereDrag drag = everywhere ? immersed_drag(i) : sphere_drag(i);
    const double *u = fluid->velocity_at(i);
    const double slip[3] = {v[i][0] - u[0], v[i][1] - u[1], v[i][2] - u[2]};
    visit(i, drag, slip);
  }
}

void FixFluidDrag::post_force(int /*vflag*/)
{
  double **f = atom->f;
  refresh_concentration();
  totals.clear();
  if (all_implicit) return;    // fix nve/sphere/fluid takes the drag of every atom into its step
  // Local sums: a store into the fix inside the loop would alias the force array.
  double sum[3] = {0.0, 0.0, 0.0};
  auto pull = [&](int i, double coeff, const double *slip) {
    for (int k = 0; k < 3; ++k) {
      f[i][k] -= coeff * slip[k];
      sum[k] -= coeff * slip[k];
    }
  };
  if (const double per_diameter = linear_per_diameter(); per_diameter > 0.0 && uniform()) {
    // Stokes drag on wholly immersed spheres: F = c d w with c taken once (bit for bit the law's
    // linear_coefficient), without the per-sphere look-ups of the general loop.
    prepare_step();
    double **v = atom->v;
    const double *radius = atom->radius;
    const int *mask = atom->mask;
    const double *flow = fluid->velocity();
    const double u[3] = {flow[0], flow[1], flow[2]};
    for (int i = 0; i < atom->nlocal; ++i) {
      if (!(mask[i] & groupbit) || (mask[i] & implicit_groupbit)) continue;
      const double slip[3] = {v[i][0] - u[0], v[i][1] - u[1], v[i][2] - u[2]};
      pull(i, per_diameter * (2.0 * radius[i]), slip);
    }
    for (int k = 0; k < 3; ++k) totals[k] = sum[k];
    return;
  }
  for_each_explicit([&](int i, const sediment::SphereDrag &drag, const double *slip) {
    if (!drag.model) {
      totals[OUTSIDE] += 1.0;
      return;
    }
    if (fraction_capped(i)) totals[CAPPED] += 1.0;
    const double linear = model->linear_coefficient(drag.diameter, drag.scale);
    const double speed = linear > 0.0 ? 0.0 : norm(slip);
    // Explicit: the yield part acts only while moving, so a yield-stress fluid chatters here.
    if (linear > 0.0 || speed > 0.0)
      pull(i, linear > 0.0 ? linear : model->force(drag.diameter, speed, drag.scale) / speed, slip);
    const double rate = rotation_rate(i, drag);
    if (rate > 0.0) {
      const double inertia = sediment::sphere_inertia(atom->rmass[i], atom->radius[i]);
      for (int k = 0; k < 3; ++k) atom->torque[i][k] -= rate * inertia * atom->omega[i][k];
    }
  });
  for (int k = 0; k < 3; ++k) totals[k] = sum[k];
}

int FixFluidDrag::count_unstable_explicit()
{
  int count = 0;
  for_each_explicit([&](int i, const sediment::SphereDrag &drag, const double *slip) {
    if (drag.model &&
        update->dt > sediment::explicit_step_limit(*model, drag.diameter, norm(slip), atom->rmass[i], drag.scale))
      ++count;
  });
  int count_all = 0;
  MPI_Allreduce(&count, &count_all, 1, MPI_INT, MPI_SUM, world);
  return count_all;
}

double FixFluidDrag::compute_vector(int n)
{
  // Vector: fx fy fz, spheres with dt > 2 tau, spheres outside the fluid, capped local fractions.
  if (n == 3) return count_unstable_explicit();
  return totals.total(n < 3 ? n : n - 1, world);
}
