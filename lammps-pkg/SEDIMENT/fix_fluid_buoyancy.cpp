/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid/buoyancy
   F = -rho_f V_sub g, with V_sub the volume below the fluid's free surface.
------------------------------------------------------------------------- */

#include "fix_fluid_buoyancy.h"
#include "sediment_args.h"

#include "compute_concentration_grid.h"
#include "fix_fluid.h"

#include "atom.h"
#include "compute.h"
#include "error.h"
#include "modify.h"
#include "update.h"

#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixFluidBuoyancy::FixFluidBuoyancy(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), fluid_id(nullptr), gravity_id(nullptr), mixture_id(nullptr), mixture(nullptr),
    solid_density(0.0), fluid(nullptr), gravity(nullptr)
{
  if (narg < 4) error->all(FLERR, "Fix fluid/buoyancy: expected 'fix ID group fluid/buoyancy FLUID-ID'");
  fluid_id = utils::strdup(arg[3]);
  int iarg = 4;
  while (iarg < narg) {
    if (strcmp(arg[iarg], "gravity") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Fix fluid/buoyancy: keyword 'gravity' needs a fix ID");
      delete[] gravity_id;
      gravity_id = utils::strdup(arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(arg[iarg], "mixture") == 0) {
      if (iarg + 2 >= narg)
        error->all(FLERR, "Fix fluid/buoyancy: keyword 'mixture' needs c_ID and the solid density");
      delete[] mixture_id;
      mixture_id = utils::strdup(arg[iarg + 1]);
      solid_density = sediment_positive(lmp, arg[iarg + 2], "Fix fluid/buoyancy: mixture solid density");
      iarg += 3;
    } else {
      error->all(FLERR, "Fix fluid/buoyancy: unknown keyword '{}' (expected gravity or mixture)", arg[iarg]);
    }
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

  Fix *gravity_fix = nullptr;
  if (gravity_id) {
    const int ifix = modify->find_fix(gravity_id);
    if (ifix < 0) error->all(FLERR, "Fix fluid/buoyancy: gravity fix '{}' does not exist", gravity_id);
    gravity_fix = modify->fix[ifix];
    if (strcmp(gravity_fix->style, "gravity") != 0)
      error->all(FLERR, "Fix fluid/buoyancy: fix '{}' is a fix {}, not a fix gravity", gravity_id,
                 gravity_fix->style);
  } else {
    for (int i = 0; i < modify->nfix; ++i) {
      if (strcmp(modify->fix[i]->style, "gravity") != 0) continue;
      if (gravity_fix)
        error->all(FLERR, "Fix fluid/buoyancy: several fix gravity are defined; choose one with "
                          "keyword 'gravity'");
      gravity_fix = modify->fix[i];
    }
    if (!gravity_fix)
      error->all(FLERR, "Fix fluid/buoyancy needs a fix gravity to know the direction and "
                        "strength of gravity");
  }
  mixture = mixture_id ? ComputeConcentrationGrid::find_fraction(lmp, mixture_id, "fluid/buoyancy") : nullptr;
  int dim = 0;
  gravity = static_cast<double *>(gravity_fix->extract("gvec", dim));
  if (!gravity) error->all(FLERR, "Fix fluid/buoyancy: fix gravity does not expose its vector");
}

void FixFluidBuoyancy::setup(int vflag)
{
  post_force(vflag);
}

void FixFluidBuoyancy::post_force(int /*vflag*/)
{
  double **x = atom->x;
  double **f = atom->f;
  double *radius = atom->radius;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const double rho = fluid->properties().density;

  fluid->prepare();
  if (mixture && mixture->invoked_peratom != update->ntimestep) mixture->compute_peratom();
  totals.clear();
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    const sediment::Submergence sub = fluid->immersion(x[i], radius[i]);
    if (!sub.any()) continue;
    // Suspension density rho_f + (rho_s - rho_f) phi around the sphere, or the clear fluid's.
    const double density = mixture ? rho + (solid_density - rho) * mixture->vector_atom[i] : rho;
    const double displaced = density * sub.volume * sediment::sphere_volume(2.0 * radius[i]);
    for (int k = 0; k < 3; ++k) {
      const double fb = -displaced * gravity[k];
      f[i][k] += fb;
      totals[k] += fb;
    }
    totals[3] += 1.0;
  }
}

double FixFluidBuoyancy::compute_vector(int n)
{
  return totals.total(n, world);
}
