// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid/buoyancy
   F = -rho_f V_sub g, with V_sub the volume below the fluid's free surface.
------------------------------------------------------------------------- */

#include "fix_fluid_buoyancy.h"
#include "sediment_args.h"
#include "sediment_rows.h"

#include "compute_concentration_grid.h"
#include "fix_fluid.h"

#include "atom.h"
#include "comm.h"
#include "compute.h"
#include "error.h"
#include "group.h"
#include "modify.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mpi.h>
#include <type_traits>

using namespace LAMMPS_NS;
using namespace FixConst;

FixFluidBuoyancy::FixFluidBuoyancy(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), fluid_id(nullptr), gravity_id(nullptr), mixture_id(nullptr), mixture(nullptr),
    solid_density(0.0), max_fraction(0.64), fluid(nullptr), gravity(nullptr)
{
  if (narg < 4) error->all(FLERR, "Fix fluid/buoyancy: expected 'fix ID group fluid/buoyancy FLUID-ID'");
  fluid_id = utils::strdup(arg[3]);
  StyleArgs args(lmp, FLERR, "Fix fluid/buoyancy", narg, arg, 4);
  while (args.more()) {
    int nvalues = 1;
    if (args.is("gravity")) {
      args.need(1, "a fix ID");
      delete[] gravity_id;
      gravity_id = utils::strdup(args.text(1));
    } else if (args.is("mixture")) {
      args.need(2, "c_ID and the solid density");
      delete[] mixture_id;
      mixture_id = utils::strdup(args.text(1));
      solid_density = args.positive(2, "mixture solid density");
      nvalues = 2;
    } else if (args.is("max_fraction")) {
      args.need(1, "a value");
      max_fraction = args.number(1);
      if (!(max_fraction > 0.0 && max_fraction < 1.0)) args.fail("max_fraction must be in (0, 1)");
    } else {
      args.unknown("gravity, mixture or max_fraction");
    }
    args.next(nvalues);
  }
  if (!atom->radius_flag)
    error->all(FLERR, "Fix fluid/buoyancy requires atom attribute radius (atom_style sphere)");

  vector_flag = 1;
  size_vector = 4;
  global_freq = 1;
  extvector = 1;
}

FixFluidBuoyancy::~FixFluidBuoyancy()
{
  delete[] fluid_id;
  delete[] gravity_id;
  delete[] mixture_id;
}

int FixFluidBuoyancy::setmask()
{
  return POST_FORCE;
}

void FixFluidBuoyancy::init()
{
  fluid = FixFluid::find(lmp, fluid_id, "Fix fluid/buoyancy");

  const std::string caller = "Fix fluid/buoyancy";
  gravity = sediment_find_gravity(lmp, gravity_id, caller, "choose one with keyword 'gravity'");
  mixture = mixture_id ? ComputeConcentrationGrid::find_fraction(lmp, mixture_id, caller) : nullptr;
  // Two fixes of one fluid on the same atom would add its buoyancy twice.
  for (Fix *other : sediment_fixes_of_style(lmp, "fluid/buoyancy")) {
    if (other == this || FixFluid::find(lmp, static_cast<FixFluidBuoyancy *>(other)->fluid_id, caller) != fluid) continue;
    int both = 0;
    for (int i = 0; i < atom->nlocal; ++i) both += (atom->mask[i] & groupbit) && (atom->mask[i] & other->groupbit);
    int both_all = 0;
    MPI_Allreduce(&both, &both_all, 1, MPI_INT, MPI_SUM, world);
    if (both_all > 0)
      error->all(FLERR, "Fix fluid/buoyancy: fixes {} and {} both give the buoyancy of fluid {} to {} atom(s) (groups "
                 "{} and {}): it would count twice; give each atom one", id, other->id, fluid_id, both_all,
                 group->names[igroup], group->names[other->igroup]);
  }
  if (!fluid->fills_space()) warn_of_bobbing();
}

void FixFluidBuoyancy::warn_of_bobbing()
{
  // A sphere lighter than the fluid floats at the free surface, held there by the buoyancy of its
  // waterline: it bobs at omega^2 = 3 rho_f g / (4 rho_p r). With dt omega above 1 the explicit
  // buoyancy makes it bounce or rest off its level (millimetres for a 1 cm ball at dt 0.05 s).
  if (!atom->rmass) return;
  const double rho = fluid->properties().density;
  const double g = std::sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]);
  double omega = 0.0;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(atom->mask[i] & groupbit) || atom->radius[i] <= 0.0) continue;
    const double r = atom->radius[i];
    const double density = atom->rmass[i] / sediment::sphere_volume(2.0 * r);
    if (density < rho) omega = std::max(omega, std::sqrt(3.0 * rho * g / (4.0 * density * r)));
  }
  double omega_all = 0.0;
  MPI_Allreduce(&omega, &omega_all, 1, MPI_DOUBLE, MPI_MAX, world);
  if (comm->me == 0 && omega_all * update->dt > 1.0)
    error->warning(FLERR, "Fix fluid/buoyancy: a sphere lighter than fluid {} floats at its surface and bobs with "
                   "period {:.4g}; the time step {:.4g} is too long for it (it would bounce, or rest off its level): "
                   "use a time step up to {:.3g}", fluid_id, 2.0 * sediment::pi / omega_all, update->dt, 0.5 / omega_all);
}

void FixFluidBuoyancy::setup(int vflag)
{
  post_force(vflag);
}

void FixFluidBuoyancy::post_force(int /*vflag*/)
{
  const auto x = flat_rows<3>(atom->x);
  const auto f = flat_rows<3>(atom->f);
  const double *radius = atom->radius;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const double rho = fluid->properties().density;

  fluid->prepare();
  if (mixture && mixture->invoked_peratom != update->ntimestep) mixture->compute_peratom();
  const double g[3] = {gravity[0], gravity[1], gravity[2]};
  const double *fraction = mixture ? mixture->vector_atom : nullptr;
  // Local sums: a store into the fix inside the loop would alias the force array.
  double sum[3] = {0.0, 0.0, 0.0};
  int immersed = 0;
  // The loop compiled for a fluid that fills space or not and with a mixture or not: with the tests
  // inside, the common case (clear fluid everywhere) took 41 instructions per atom. That case now runs
  // in the core's vectors (below), the others here.
  auto add_buoyancy = [&](auto fills_space, auto with_mixture) {
    for (int i = 0; i < nlocal; ++i) {
      if (!(mask[i] & groupbit)) continue;
      sediment::Submergence sub{1.0, 1.0, 1.0};
      if constexpr (!decltype(fills_space)::value) {
        sub = fluid->immersion(x[i], radius[i]);
        if (!sub.any()) continue;
      }
      // The suspension around the sphere, or the clear fluid. The local fraction is capped as the drag
      // caps it: where parcels stop on a floor without contacts their grid fraction exceeds any packing
      // (even 1), and an uncapped mixture would float the deposit.
      double density = rho;
      if constexpr (decltype(with_mixture)::value)
        density = sediment::mixture_density(rho, solid_density, std::clamp(fraction[i], 0.0, max_fraction));
      const double displaced = sediment::displaced_mass(density, radius[i], sub);
      for (int k = 0; k < 3; ++k) {
        const double fb = -displaced * g[k];
        f[i][k] += fb;
        sum[k] += fb;
      }
      ++immersed;
    }
  };
  if (!fluid->fills_space()) {
    if (fraction)
      add_buoyancy(std::false_type{}, std::true_type{});
    else
      add_buoyancy(std::false_type{}, std::false_type{});
  } else if (fraction) {
    add_buoyancy(std::true_type{}, std::true_type{});
  } else {
    // Clear fluid everywhere (the common case): each run of consecutive atoms of the group in vectors.
    // The totals from the run's displaced mass: the same forces to round-off.
    for_each_run(
        nlocal, [&](int i) { return mask[i] & groupbit; },
        [&](int first, int count) {
          const double displaced = sediment::add_immersed_buoyancy(f, radius, first, count, rho, g);
          for (int k = 0; k < 3; ++k) sum[k] += -displaced * g[k];
          immersed += count;
        },
        [](int) {});
  }
  totals.clear();
  for (int k = 0; k < 3; ++k) totals[k] = sum[k];
  totals[3] = immersed;
}

double FixFluidBuoyancy::compute_vector(int n)
{
  return totals.total(n, world);
}
