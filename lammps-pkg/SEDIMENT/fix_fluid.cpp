/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid
------------------------------------------------------------------------- */

#include "fix_fluid.h"
#include "sediment_args.h"

#include "domain.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "region.h"
#include "update.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixFluid::FixFluid(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), has_surface(0), surface_offset(0.0), region_id(nullptr), region(nullptr)
{
  flow[0] = flow[1] = flow[2] = 0.0;
  surface_normal[0] = surface_normal[1] = 0.0;
  surface_normal[2] = 1.0;

  bool has_density = false, has_viscosity = false, has_bingham = false;
  int iarg = 3;
  auto need = [&](int n, const char *keyword) {
    if (iarg + n >= narg)
      error->all(FLERR, "Fix fluid: keyword '{}' needs {} value(s)", keyword, n);
  };
  while (iarg < narg) {
    const char *keyword = arg[iarg];
    if (strcmp(keyword, "density") == 0) {
      need(1, keyword);
      fluid.density = sediment_positive(lmp, arg[iarg + 1], "Fix fluid: density");
      has_density = true;
      iarg += 2;
    } else if (strcmp(keyword, "viscosity") == 0) {
      need(1, keyword);
      fluid.viscosity = sediment_positive(lmp, arg[iarg + 1], "Fix fluid: viscosity");
      has_viscosity = true;
      iarg += 2;
    } else if (strcmp(keyword, "bingham") == 0) {
      need(2, keyword);
      fluid.yield_stress = sediment_positive(lmp, arg[iarg + 1], "Fix fluid: bingham yield stress",
                                             " (use viscosity for a Newtonian fluid)");
      fluid.viscosity = sediment_positive(lmp, arg[iarg + 2], "Fix fluid: bingham plastic viscosity");
      has_bingham = true;
      iarg += 3;
    } else if (strcmp(keyword, "surface") == 0) {
      need(2, keyword);
      const char *axis = arg[iarg + 1];
      double normal[3] = {0.0, 0.0, 0.0};
      if (strcmp(axis, "plane") == 0) {
        need(7, "surface plane");
        double point[3];
        for (int k = 0; k < 3; ++k) point[k] = utils::numeric(FLERR, arg[iarg + 2 + k], false, lmp);
        for (int k = 0; k < 3; ++k) normal[k] = utils::numeric(FLERR, arg[iarg + 5 + k], false, lmp);
        const double len = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
        if (!(len > 0.0) || !std::isfinite(len))
          error->all(FLERR, "Fix fluid: surface plane normal must be finite and non-zero");
        surface_offset = 0.0;
        for (int k = 0; k < 3; ++k) {
          normal[k] /= len;
          surface_offset += point[k] * normal[k];
        }
        iarg += 8;
      } else {
        const int dim = sediment_axis(axis);
        if (dim < 0)
          error->all(FLERR, "Fix fluid: surface axis must be x, y, z or plane, not '{}'", axis);
        normal[dim] = 1.0;
        surface_offset = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
        iarg += 3;
      }
      for (int k = 0; k < 3; ++k) surface_normal[k] = normal[k];
      has_surface = 1;
    } else if (strcmp(keyword, "region") == 0) {
      need(1, keyword);
      delete[] region_id;
      region_id = utils::strdup(arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(keyword, "velocity") == 0) {
      need(3, keyword);
      for (int k = 0; k < 3; ++k) flow[k] = utils::numeric(FLERR, arg[iarg + 1 + k], false, lmp);
      iarg += 4;
    } else {
      error->all(FLERR, "Fix fluid: unknown keyword '{}' (expected density, viscosity, bingham, "
                        "surface, region or velocity)", keyword);
    }
  }
  if (!has_density) error->all(FLERR, "Fix fluid: keyword 'density' is required");
  if (has_viscosity == has_bingham)
    error->all(FLERR, "Fix fluid: give exactly one of 'viscosity MU' or 'bingham TAU_Y ETA_B'");
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(flow[k])) error->all(FLERR, "Fix fluid: velocity must be finite");
  if (has_surface && !std::isfinite(surface_offset))
    error->all(FLERR, "Fix fluid: surface position must be finite");
  if (domain->dimension == 2 && has_surface && surface_normal[2] != 0.0)
    error->all(FLERR, "Fix fluid: a 2d simulation needs a surface normal in the xy plane");
}

FixFluid::~FixFluid()
{
  delete[] region_id;
}

int FixFluid::setmask()
{
  return 0;
}

void FixFluid::init()
{
  // The force laws are written for a coherent unit system (force = mass * length / time^2).
  if (force->ftm2v != 1.0 || force->mv2d != 1.0)
    error->all(FLERR, "Fix fluid requires coherent units (si, cgs, micro, nano or lj), not '{}'",
               update->unit_style);
  region = nullptr;
  if (region_id) {
    const int iregion = domain->find_region(region_id);
    if (iregion < 0) error->all(FLERR, "Fix fluid: region '{}' does not exist", region_id);
    region = domain->regions[iregion];
  }
}

void FixFluid::prepare()
{
  if (region) region->prematch();
}

sediment::Submergence FixFluid::immersion(const double *x, double radius) const
{
  if (region && !region->match(x[0], x[1], x[2])) return {0.0, 0.0, 0.0};
  if (!has_surface) return {1.0, 1.0, 1.0};
  const double height = x[0] * surface_normal[0] + x[1] * surface_normal[1] +
      x[2] * surface_normal[2] - surface_offset;
  return sediment::submergence(radius, height);
}

FixFluid *FixFluid::find(LAMMPS *lmp, const char *fluid_id, const char *caller)
{
  const int ifix = lmp->modify->find_fix(fluid_id);
  if (ifix < 0) lmp->error->all(FLERR, "{}: fluid fix '{}' does not exist", caller, fluid_id);
  auto fluid = dynamic_cast<FixFluid *>(lmp->modify->fix[ifix]);
  if (!fluid)
    lmp->error->all(FLERR, "{}: fix '{}' is a fix {}, not a fix fluid", caller, fluid_id,
                    lmp->modify->fix[ifix]->style);
  return fluid;
}
