/* ----------------------------------------------------------------------
   SEDIMENT package: fix fluid/drag
------------------------------------------------------------------------- */

#include "fix_fluid_drag.h"

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

FixFluidDrag::FixFluidDrag(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), fluid_id(nullptr), fluid(nullptr), law(sediment::DragLaw::Stokes),
    hindrance_buoyancy(sediment::HindranceBuoyancy::Plain), concentration_id(nullptr),
    concentration(nullptr), max_fraction(0.64), rotation(0), implicit_groupbit(0)
{
  if (narg < 6)
    error->all(FLERR, "Fix fluid/drag: expected 'fix ID group fluid/drag FLUID-ID law NAME'");
  fluid_id = utils::strdup(arg[3]);
  bool has_law = false;
  int iarg = 4;
  while (iarg < narg) {
    if (strcmp(arg[iarg], "law") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Fix fluid/drag: keyword 'law' needs a name");
      const auto parsed = sediment::drag_law_from_name(arg[iarg + 1]);
      if (!parsed)
        error->all(FLERR, "Fix fluid/drag: unknown law '{}' (expected one of {})", arg[iarg + 1],
                   sediment::drag_law_names());
      law = *parsed;
      has_law = true;
      iarg += 2;
    } else if (strcmp(arg[iarg], "rotation") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Fix fluid/drag: keyword 'rotation' needs yes or no");
      if (strcmp(arg[iarg + 1], "yes") == 0)
        rotation = 1;
      else if (strcmp(arg[iarg + 1], "no") == 0)
        rotation = 0;
      else
        error->all(FLERR, "Fix fluid/drag: rotation must be yes or no, not '{}'", arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(arg[iarg], "concentration") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Fix fluid/drag: keyword 'concentration' needs a compute ID");
      delete[] concentration_id;
      concentration_id = utils::strdup(arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(arg[iarg], "buoyancy") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Fix fluid/drag: keyword 'buoyancy' needs plain or mixture");
      if (strcmp(arg[iarg + 1], "plain") == 0)
        hindrance_buoyancy = sediment::HindranceBuoyancy::Plain;
      else if (strcmp(arg[iarg + 1], "mixture") == 0)
        hindrance_buoyancy = sediment::HindranceBuoyancy::Mixture;
      else
        error->all(FLERR, "Fix fluid/drag: buoyancy must be plain or mixture, not '{}'", arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(arg[iarg], "max_fraction") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Fix fluid/drag: keyword 'max_fraction' needs a value");
      max_fraction = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(max_fraction > 0.0 && max_fraction < 1.0))
        error->all(FLERR, "Fix fluid/drag: max_fraction must be in (0, 1)");
      iarg += 2;
    } else {
      error->all(FLERR, "Fix fluid/drag: unknown keyword '{}' (expected law, rotation, concentration, "
                        "buoyancy or max_fraction)", arg[iarg]);
    }
  }
  if (!has_law) error->all(FLERR, "Fix fluid/drag: keyword 'law' is required");
  if (law == sediment::DragLaw::DiFelice && !concentration_id)
    error->all(FLERR, "Fix fluid/drag: law difelice needs keyword 'concentration c_ID' (a compute "
                      "concentration/grid)");
  if (law != sediment::DragLaw::DiFelice && concentration_id)
    error->all(FLERR, "Fix fluid/drag: keyword 'concentration' applies to law difelice only");
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
  model = std::make_unique<sediment::DragModel>(law, fluid->properties(), hindrance_buoyancy);
  concentration =
      concentration_id ? ComputeConcentrationGrid::find_fraction(lmp, concentration_id, "fluid/drag") : nullptr;
  implicit_groupbit = 0;
  for (int i = 0; i < modify->nfix; ++i)
    if (strcmp(modify->fix[i]->style, "nve/sphere/fluid") == 0)
      implicit_groupbit |= modify->fix[i]->groupbit;
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

sediment::SphereDrag FixFluidDrag::sphere_drag(int i) const
{
  sediment::SphereDrag drag;
  if (!(atom->mask[i] & groupbit)) return drag;
  const double radius = atom->radius[i];
  const sediment::Submergence sub = fluid->immersion(atom->x[i], radius);
  if (!sub.any()) return drag;
  drag.model = model.get();
  drag.diameter = 2.0 * radius;
  drag.scale = sub.drag_scale();
  if (concentration) drag.scale.voidage = 1.0 - std::clamp(concentration->vector_atom[i], 0.0, max_fraction);
  return drag;
}

bool FixFluidDrag::fraction_capped(int i) const
{
  return concentration && concentration->vector_atom[i] > max_fraction;
}

double FixFluidDrag::rotation_rate(int i, const sediment::SphereDrag &drag) const
{
  if (!rotation || !drag.model) return 0.0;
  // Stokes rotlet: torque = -pi mu d^3 omega, inertia I = m d^2 / 10 (solid sphere).
  const double d = drag.diameter;
  const double inertia = 0.1 * atom->rmass[i] * d * d;
  return drag.scale.wetted * sediment::pi * fluid->properties().viscosity * d * d * d / inertia;
}

void FixFluidDrag::post_force(int /*vflag*/)
{
  double **v = atom->v;
  double **f = atom->f;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const double *u = fluid->velocity();

  prepare_step();
  refresh_concentration();
  totals.clear();
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit) || (mask[i] & implicit_groupbit)) continue;
    const sediment::SphereDrag drag = sphere_drag(i);
    if (!drag.model) {
      totals[OUTSIDE] += 1.0;
      continue;
    }
    if (fraction_capped(i)) totals[CAPPED] += 1.0;
    const double w[3] = {v[i][0] - u[0], v[i][1] - u[1], v[i][2] - u[2]};
    const double speed = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (speed > 0.0) {
      // Explicit: the yield part acts only while moving, so a yield-stress fluid chatters here.
      const double coeff = model->force(drag.diameter, speed, drag.scale) / speed;
      for (int k = 0; k < 3; ++k) {
        f[i][k] -= coeff * w[k];
        totals[k] -= coeff * w[k];
      }
    }
    const double rate = rotation_rate(i, drag);
    if (rate > 0.0) {
      const double inertia = 0.1 * atom->rmass[i] * drag.diameter * drag.diameter;
      for (int k = 0; k < 3; ++k) atom->torque[i][k] -= rate * inertia * atom->omega[i][k];
    }
  }
}

int FixFluidDrag::count_unstable_explicit()
{
  // Explicit drag is stable only for dt < 2 tau, tau = m / F'(s) at the current slip.
  double **v = atom->v;
  int *mask = atom->mask;
  const double *u = fluid->velocity();
  prepare_step();
  int count = 0;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit) || (mask[i] & implicit_groupbit)) continue;
    const sediment::SphereDrag drag = sphere_drag(i);
    if (!drag.model) continue;
    const double w[3] = {v[i][0] - u[0], v[i][1] - u[1], v[i][2] - u[2]};
    const double speed = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double slope = std::max(model->tangent(drag.diameter, speed, drag.scale),
                                  model->tangent(drag.diameter, 0.0, drag.scale));
    if (update->dt > 2.0 * atom->rmass[i] / slope) ++count;
  }
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
