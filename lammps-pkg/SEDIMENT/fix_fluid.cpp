// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid
------------------------------------------------------------------------- */

#include "fix_fluid.h"
#include "fix_fluid_flow.h"
#include "sediment_args.h"

#include "domain.h"
#include "error.h"
#include "force.h"
#include "input.h"
#include "modify.h"
#include "region.h"
#include "update.h"
#include "variable.h"

#include <cmath>
#include <cstring>

using namespace LAMMPS_NS;
using namespace FixConst;

FixFluid::FixFluid(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), atom_flow(nullptr), flow_fix(nullptr), has_surface(0), surface_offset(0.0), surface_variable(nullptr), surface_ivar(-1),
    centre_crossing(false), prepared_step(-1), region_id(nullptr), region(nullptr)
{
  flow[0] = flow[1] = flow[2] = 0.0;
  surface_normal[0] = surface_normal[1] = 0.0;
  surface_normal[2] = 1.0;

  bool has_density = false, has_viscosity = false, has_bingham = false;
  StyleArgs args(lmp, FLERR, "Fix fluid", narg, arg, 3);
  while (args.more()) {
    int nvalues = 1;
    if (args.is("density")) {
      args.need(1, "1 value");
      fluid.density = args.positive(1, "density");
      has_density = true;
    } else if (args.is("viscosity")) {
      args.need(1, "1 value");
      fluid.viscosity = args.positive(1, "viscosity");
      has_viscosity = true;
    } else if (args.is("bingham")) {
      args.need(2, "2 values");
      fluid.yield_stress = args.positive(1, "bingham yield stress", " (use viscosity for a Newtonian fluid)");
      fluid.viscosity = args.positive(2, "bingham plastic viscosity");
      has_bingham = true;
      nvalues = 2;
    } else if (args.is("surface")) {
      args.need(2, "an axis and a position, or plane and a point and a normal");
      double normal[3] = {0.0, 0.0, 0.0};
      if (strcmp(args.text(1), "plane") == 0) {
        args.need(7, "plane, a point and a normal");
        double point[3];
        for (int k = 0; k < 3; ++k) point[k] = args.number(2 + k);
        for (int k = 0; k < 3; ++k) normal[k] = args.number(5 + k);
        const double len = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
        if (!(len > 0.0)) args.fail("surface plane normal must be finite and non-zero");
        surface_offset = 0.0;
        for (int k = 0; k < 3; ++k) {
          normal[k] /= len;
          surface_offset += point[k] * normal[k];
        }
        nvalues = 7;
      } else {
        const int dim = sediment_axis(args.text(1));
        if (dim < 0) args.fail("surface axis must be x, y, z or plane, not '{}'", args.text(1));
        normal[dim] = 1.0;
        delete[] surface_variable;
        surface_variable = nullptr;
        if (strncmp(args.text(2), "v_", 2) == 0)
          surface_variable = utils::strdup(args.text(2) + 2);
        else
          surface_offset = args.number(2);
        nvalues = 2;
      }
      for (int k = 0; k < 3; ++k) surface_normal[k] = normal[k];
      has_surface = 1;
    } else if (args.is("crossing")) {
      args.need(1, "cap or centre");
      if (strcmp(args.text(1), "cap") == 0)
        centre_crossing = false;
      else if (strcmp(args.text(1), "centre") == 0)
        centre_crossing = true;
      else
        args.fail("crossing must be cap or centre, not '{}'", args.text(1));
    } else if (args.is("region")) {
      args.need(1, "a region ID");
      delete[] region_id;
      region_id = utils::strdup(args.text(1));
    } else if (args.is("velocity")) {
      args.need(3, "3 values");
      for (int k = 0; k < 3; ++k) flow[k] = args.number(1 + k);
      nvalues = 3;
    } else {
      args.unknown("density, viscosity, bingham, surface, crossing, region or velocity");
    }
    args.next(nvalues);
  }
  if (!has_density) error->all(FLERR, "Fix fluid: keyword 'density' is required");
  if (has_viscosity == has_bingham)
    error->all(FLERR, "Fix fluid: give exactly one of 'viscosity MU' or 'bingham TAU_Y ETA_B'");
  if (centre_crossing && !has_surface)
    error->all(FLERR, "Fix fluid: keyword 'crossing' needs a 'surface'");
  if (has_surface && !std::isfinite(surface_offset))
    error->all(FLERR, "Fix fluid: surface position must be finite");
  if (domain->dimension == 2 && has_surface && surface_normal[2] != 0.0)
    error->all(FLERR, "Fix fluid: a 2d simulation needs a surface normal in the xy plane");
}

FixFluid::~FixFluid()
{
  delete[] surface_variable;
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
    region = sediment_region_by_id(domain, region_id);
    if (!region) error->all(FLERR, "Fix fluid: region '{}' does not exist", region_id);
  }
  prepared_step = -1;    // a new run may start at the step of the last one, with other positions
  // The fix fluid/flow that gives this fluid its velocity, if any (looked up at every init: it may
  // have been unfixed since the last run).
  atom_flow = nullptr;
  flow_fix = nullptr;
  for (Fix *fix : sediment_fixes_of_style(lmp, "fluid/flow")) {
    auto flow = static_cast<FixFluidFlow *>(fix);
    if (strcmp(flow->fluid_name(), id) != 0) continue;
    if (atom_flow) error->all(FLERR, "Fix fluid: two fix fluid/flow give fluid '{}' its velocity", id);
    atom_flow = flow->velocity_rows();
    flow_fix = flow;
  }
  if (surface_variable) {
    surface_ivar = input->variable->find(surface_variable);
    if (surface_ivar < 0)
      error->all(FLERR, "Fix fluid: surface variable '{}' does not exist", surface_variable);
    if (!input->variable->equalstyle(surface_ivar))
      error->all(FLERR, "Fix fluid: surface variable '{}' must be equal-style", surface_variable);
  }
}

void FixFluid::prepare()
{
  // Buoyancy and drag both ask, at the same step and with the same result.
  if (prepared_step == update->ntimestep) return;
  prepared_step = update->ntimestep;
  if (region) region->prematch();
  if (surface_variable) {
    // The variable may read other fixes' results of the previous step (the volume the spheres
    // displace, for a level that rises as they sink), as fix wall does with its position.
    modify->clearstep_compute();
    surface_offset = input->variable->compute_equal(surface_ivar);
    modify->addstep_compute(update->ntimestep + 1);
    if (!std::isfinite(surface_offset))
      error->all(FLERR, "Fix fluid: surface variable '{}' gave {}", surface_variable, surface_offset);
  }
}

sediment::Submergence FixFluid::bounded_immersion(const double *x, double radius) const
{
  if (region && !region->match(x[0], x[1], x[2])) return {0.0, 0.0, 0.0};
  if (!has_surface) return {1.0, 1.0, 1.0};
  const double height = x[0] * surface_normal[0] + x[1] * surface_normal[1] +
      x[2] * surface_normal[2] - surface_offset;
  if (centre_crossing) return height <= 0.0 ? sediment::Submergence{1.0, 1.0, 1.0} : sediment::Submergence{0.0, 0.0, 0.0};
  return sediment::submergence(radius, height);
}

FixFluid *FixFluid::find(LAMMPS *lmp, const char *fluid_id, const std::string &caller)
{
  return sediment_find_fix<FixFluid>(lmp, fluid_id, "fluid", caller, "fluid");
}

bool FixFluid::flow_solved_at(bigint step) const
{
  return flow_fix && flow_fix->solved_at(step);
}
