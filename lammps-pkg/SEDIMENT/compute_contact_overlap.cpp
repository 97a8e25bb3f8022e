// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: compute contact/overlap
------------------------------------------------------------------------- */

#include "compute_contact_overlap.h"
#include "sediment_args.h"
#include "sediment_lammps_api.h"

#include "atom.h"
#include "error.h"
#include "force.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <algorithm>
#include <cmath>

using namespace LAMMPS_NS;

ComputeContactOverlap::ComputeContactOverlap(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), list(nullptr), measured_step(-1)
{
  StyleArgs args(lmp, FLERR, "Compute contact/overlap", narg, arg, 3);
  if (args.more()) args.unknown("none: the compute takes no keywords");
  if (!atom->radius_flag)
    error->all(FLERR, "Compute contact/overlap requires atom attribute radius (atom_style sphere)");

  scalar_flag = vector_flag = 1;
  size_vector = 3;
  extscalar = 0;
  extvector = 0;
  vector = new double[size_vector];
  std::fill(vector, vector + size_vector, 0.0);
}

ComputeContactOverlap::~ComputeContactOverlap()
{
  delete[] vector;
}

void ComputeContactOverlap::init()
{
  if (!force->pair)
    error->all(FLERR, "Compute contact/overlap needs a pair style (its cutoff reaches the touching spheres)");
  sediment_request_compute_list(neighbor, this, instance_me);
  measured_step = -1;    // a run may start again at a step already measured (reset_timestep)
}

void ComputeContactOverlap::init_list(int /*id*/, NeighList *ptr)
{
  list = ptr;
}

double ComputeContactOverlap::compute_scalar()
{
  invoked_scalar = update->ntimestep;
  measure();
  return scalar;
}

void ComputeContactOverlap::compute_vector()
{
  invoked_vector = update->ntimestep;
  measure();
}

void ComputeContactOverlap::measure()
{
  if (measured_step == update->ntimestep) return;
  measured_step = update->ntimestep;

  double **x = atom->x;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  const tagint *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const bool newton = force->newton_pair;
  // Local: largest overlap relative to 4 a (the diameter of two equal spheres; a = r_i r_j / (r_i + r_j)),
  // largest overlap, and pairs in contact (a pair across ranks counted once).
  double local[3] = {0.0, 0.0, 0.0};
  for (int ii = 0; ii < list->inum; ++ii) {
    const int i = list->ilist[ii];
    if (!(mask[i] & groupbit)) continue;
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i]; ++jj) {
      const int j = jlist[jj] & NEIGHMASK;
      if (!(mask[j] & groupbit)) continue;
      const double dx = x[i][0] - x[j][0], dy = x[i][1] - x[j][1], dz = x[i][2] - x[j][2];
      const double reach = radius[i] + radius[j];
      const double rsq = dx * dx + dy * dy + dz * dz;
      if (rsq >= reach * reach) continue;
      const double overlap = reach - std::sqrt(rsq);
      const double a = radius[i] * radius[j] / reach;
      local[0] = std::max(local[0], overlap / (4.0 * a));
      local[1] = std::max(local[1], overlap);
      if (j < nlocal || newton || tag[i] < tag[j]) local[2] += 1.0;
    }
  }
  double largest[2];
  MPI_Allreduce(local, largest, 2, MPI_DOUBLE, MPI_MAX, world);
  MPI_Allreduce(&local[2], &vector[2], 1, MPI_DOUBLE, MPI_SUM, world);
  vector[0] = scalar = largest[0];
  vector[1] = largest[1];
}
