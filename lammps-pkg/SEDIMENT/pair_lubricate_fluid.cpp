// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: pair lubricate/fluid
------------------------------------------------------------------------- */

#include "pair_lubricate_fluid.h"
#include "sediment_args.h"

#include "fix_fluid.h"

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mpi.h>

using namespace LAMMPS_NS;

PairLubricateFluid::PairLubricateFluid(LAMMPS *lmp) :
    Pair(lmp), fluid_id(nullptr), fluid(nullptr), repulsion_scale(0.0), limit(1), maxrad(0.0),
    damping_sum(nullptr), nmax(0)
{
  single_enable = 0;
  restartinfo = 0;    // holds a fix ID: the input deck restates it after read_restart
  comm_forward = 1;
  comm_reverse = 1;
}

PairLubricateFluid::~PairLubricateFluid()
{
  delete[] fluid_id;
  memory->destroy(damping_sum);
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
  }
}

void PairLubricateFluid::allocate()
{
  allocated = 1;
  const int n = atom->ntypes;
  memory->create(setflag, n + 1, n + 1, "pair:setflag");
  for (int i = 1; i <= n; ++i)
    for (int j = i; j <= n; ++j) setflag[i][j] = 0;
  memory->create(cutsq, n + 1, n + 1, "pair:cutsq");
}

void PairLubricateFluid::settings(int narg, char **arg)
{
  if (narg < 1) error->all(FLERR, "Pair lubricate/fluid: needs the ID of a fix fluid");
  delete[] fluid_id;
  fluid_id = utils::strdup(arg[0]);
  range = sediment::LubricationRange{};
  repulsion_scale = 0.0;
  limit = 1;
  StyleArgs args(lmp, FLERR, "Pair lubricate/fluid", narg, arg, 1);
  while (args.more()) {
    args.need(1, "a value");
    if (args.is("inner")) {
      range.inner = args.number(1);
    } else if (args.is("outer")) {
      range.outer = args.number(1);
    } else if (args.is("repulsion")) {
      repulsion_scale = args.positive(1, "repulsion force scale");
    } else if (args.is("limit")) {
      limit = args.yes_no(1);
    } else {
      args.unknown("inner, outer, repulsion or limit");
    }
    args.next(1);
  }
  if (!(range.inner > 0.0) || !(range.outer > range.inner))
    error->all(FLERR, "Pair lubricate/fluid: need 0 < inner < outer (gaps in units of the effective radius)");
}

void PairLubricateFluid::coeff(int narg, char **arg)
{
  if (narg != 2) error->all(FLERR, "Pair lubricate/fluid: pair_coeff takes the two types only");
  if (!allocated) allocate();
  int ilo, ihi, jlo, jhi;
  utils::bounds(FLERR, arg[0], 1, atom->ntypes, ilo, ihi, error);
  utils::bounds(FLERR, arg[1], 1, atom->ntypes, jlo, jhi, error);
  int count = 0;
  for (int i = ilo; i <= ihi; ++i)
    for (int j = std::max(jlo, i); j <= jhi; ++j) {
      setflag[i][j] = 1;
      ++count;
    }
  if (count == 0) error->all(FLERR, "Pair lubricate/fluid: pair_coeff sets no type pairs");
}

void PairLubricateFluid::init_style()
{
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "Pair lubricate/fluid requires atom attributes radius and rmass (atom_style sphere)");
  if (!comm->ghost_velocity)
    error->all(FLERR, "Pair lubricate/fluid needs the velocities of ghost atoms: use 'comm_modify vel yes'");
  fluid = FixFluid::find(lmp, fluid_id, "Pair lubricate/fluid");
  if (!(fluid->properties().viscosity > 0.0))
    error->all(FLERR, "Pair lubricate/fluid: fix {} has no viscosity", fluid_id);
  sediment_request_half_list(neighbor, this, instance_me);

  double local_max = 0.0;
  for (int i = 0; i < atom->nlocal; ++i) local_max = std::max(local_max, atom->radius[i]);
  MPI_Allreduce(&local_max, &maxrad, 1, MPI_DOUBLE, MPI_MAX, world);
}

double PairLubricateFluid::init_one(int i, int j)
{
  if (!setflag[i][j]) error->all(FLERR, "Pair lubricate/fluid: pair_coeff not set for types {} {}", i, j);
  // The largest gap that matters between any two spheres present: a <= r_max / 2.
  double reach = range.outer * 0.5 * maxrad;
  if (repulsion_scale > 0.0) reach = std::max(reach, sediment::bravo_reach(2.0 * maxrad, 0.0));
  return 2.0 * maxrad + reach;
}

template <class Visit> void PairLubricateFluid::for_each_pair(Visit visit)
{
  double **x = atom->x;
  double *radius = atom->radius;
  int *type = atom->type;
  for (int ii = 0; ii < list->inum; ++ii) {
    const int i = list->ilist[ii];
    for (int jj = 0; jj < list->numneigh[i]; ++jj) {
      const int j = list->firstneigh[i][jj] & NEIGHMASK;
      if (!setflag[std::min(type[i], type[j])][std::max(type[i], type[j])]) continue;
      const double del[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      const double r = std::sqrt(del[0] * del[0] + del[1] * del[1] + del[2] * del[2]);
      if (r > 0.0) visit(i, j, del, r, r - radius[i] - radius[j]);
    }
  }
}

void PairLubricateFluid::sum_damping()
{
  if (atom->nmax > nmax) {
    memory->destroy(damping_sum);
    nmax = atom->nmax;
    memory->create(damping_sum, nmax, "lubricate/fluid:damping_sum");
  }
  std::fill(damping_sum, damping_sum + atom->nlocal + atom->nghost, 0.0);
  double *radius = atom->radius;
  const double viscosity = fluid->properties().viscosity;
  const int nlocal = atom->nlocal;
  for_each_pair([&](int i, int j, const double *, double, double gap) {
    const double c = sediment::squeeze_coefficient(viscosity, radius[i], radius[j], gap, range);
    damping_sum[i] += c;
    if (force->newton_pair || j < nlocal) damping_sum[j] += c;
  });
  if (force->newton_pair) sediment_reverse_comm(comm, this);
  sediment_forward_comm(comm, this);
}

void PairLubricateFluid::compute(int eflag, int vflag)
{
  ev_init(eflag, vflag);
  if (limit) sum_damping();

  double **v = atom->v;
  double **f = atom->f;
  double *radius = atom->radius;
  double *rmass = atom->rmass;
  const int nlocal = atom->nlocal;
  const int newton_pair = force->newton_pair;
  const double viscosity = fluid->properties().viscosity;
  const double dt = update->dt;

  for_each_pair([&](int i, int j, const double *del, double r, double gap) {
    double c = sediment::squeeze_coefficient(viscosity, radius[i], radius[j], gap, range);
    double push_i = 0.0, push_j = 0.0;
    if (repulsion_scale > 0.0) {
      push_i = repulsion_scale * sediment::bravo_repulsion(2.0 * radius[i], 2.0 * radius[j], gap);
      push_j = repulsion_scale * sediment::bravo_repulsion(2.0 * radius[j], 2.0 * radius[i], gap);
    }
    if (c == 0.0 && push_i == 0.0 && push_j == 0.0) return;
    if (limit && c > 0.0) c *= sediment::damping_share(dt, rmass[i], damping_sum[i], rmass[j], damping_sum[j]);

    // Along the line of centres n = (x_i - x_j) / r: the film resists dh/dt = (v_i - v_j) . n.
    double approach = 0.0;
    for (int d = 0; d < 3; ++d) approach += (v[i][d] - v[j][d]) * del[d];
    const double film = -c * approach / r;
    const double on_i = (film + push_i) / r, on_j = (film + push_j) / r;
    for (int d = 0; d < 3; ++d) f[i][d] += on_i * del[d];
    if (newton_pair || j < nlocal)
      for (int d = 0; d < 3; ++d) f[j][d] -= on_j * del[d];
    // The virial takes the mean pair force (the repulsion is not symmetric for unequal spheres).
    if (evflag) ev_tally(i, j, nlocal, newton_pair, 0.0, 0.0, 0.5 * (on_i + on_j), del[0], del[1], del[2]);
  });
  if (vflag_fdotr) virial_fdotr_compute();
}

int PairLubricateFluid::pack_forward_comm(int n, int *list_, double *buf, int /*pbc_flag*/, int * /*pbc*/)
{
  for (int k = 0; k < n; ++k) buf[k] = damping_sum[list_[k]];
  return n;
}

void PairLubricateFluid::unpack_forward_comm(int n, int first, double *buf)
{
  for (int k = 0; k < n; ++k) damping_sum[first + k] = buf[k];
}

int PairLubricateFluid::pack_reverse_comm(int n, int first, double *buf)
{
  for (int k = 0; k < n; ++k) buf[k] = damping_sum[first + k];
  return n;
}

void PairLubricateFluid::unpack_reverse_comm(int n, int *list_, double *buf)
{
  for (int k = 0; k < n; ++k) damping_sum[list_[k]] += buf[k];
}

double PairLubricateFluid::memory_usage()
{
  return static_cast<double>(nmax) * sizeof(double);
}
