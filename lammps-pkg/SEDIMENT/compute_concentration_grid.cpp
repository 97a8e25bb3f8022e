/* ----------------------------------------------------------------------
   SEDIMENT package: compute concentration/grid
------------------------------------------------------------------------- */

#include "compute_concentration_grid.h"

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "modify.h"
#include "update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mpi.h>

using namespace LAMMPS_NS;

ComputeConcentrationGrid::ComputeConcentrationGrid(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), axis(-1), nlayers(0), has_bounds(0), bound_lo(0.0), bound_hi(0.0),
    by_type(0), thickness(0.0), smooth_width(0.0), ncols(1), layers{0.0, 1.0, 1}, profiled_step(-1),
    nmax(0)
{
  int iarg = 3;
  while (iarg < narg) {
    const char *keyword = arg[iarg];
    if (strcmp(keyword, "layers") == 0) {
      if (iarg + 2 >= narg) error->all(FLERR, "Compute concentration/grid: 'layers' needs an axis and a count");
      const char *dim = arg[iarg + 1];
      axis = strcmp(dim, "x") == 0 ? 0 : strcmp(dim, "y") == 0 ? 1 : strcmp(dim, "z") == 0 ? 2 : -1;
      if (axis < 0) error->all(FLERR, "Compute concentration/grid: layer axis must be x, y or z, not '{}'", dim);
      nlayers = utils::inumeric(FLERR, arg[iarg + 2], false, lmp);
      if (nlayers < 1) error->all(FLERR, "Compute concentration/grid: number of layers must be >= 1");
      iarg += 3;
    } else if (strcmp(keyword, "bounds") == 0) {
      if (iarg + 2 >= narg) error->all(FLERR, "Compute concentration/grid: 'bounds' needs LO and HI");
      bound_lo = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      bound_hi = utils::numeric(FLERR, arg[iarg + 2], false, lmp);
      if (!(bound_hi > bound_lo)) error->all(FLERR, "Compute concentration/grid: bounds need LO < HI");
      has_bounds = 1;
      iarg += 3;
    } else if (strcmp(keyword, "classes") == 0) {
      ++iarg;
      while (iarg < narg && utils::is_double(arg[iarg]))
        class_edges.push_back(utils::numeric(FLERR, arg[iarg++], false, lmp));
      if (class_edges.empty())
        error->all(FLERR, "Compute concentration/grid: 'classes' needs at least one diameter");
      for (size_t k = 0; k < class_edges.size(); ++k)
        if (!(class_edges[k] > 0.0) || (k > 0 && !(class_edges[k] > class_edges[k - 1])))
          error->all(FLERR, "Compute concentration/grid: class diameters must be positive and increasing");
    } else if (strcmp(keyword, "types") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Compute concentration/grid: 'types' needs yes or no");
      if (strcmp(arg[iarg + 1], "yes") == 0) by_type = 1;
      else if (strcmp(arg[iarg + 1], "no") == 0) by_type = 0;
      else error->all(FLERR, "Compute concentration/grid: types must be yes or no, not '{}'", arg[iarg + 1]);
      iarg += 2;
    } else if (strcmp(keyword, "thickness") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Compute concentration/grid: 'thickness' needs a value");
      thickness = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(thickness > 0.0)) error->all(FLERR, "Compute concentration/grid: thickness must be > 0");
      iarg += 2;
    } else if (strcmp(keyword, "smooth") == 0) {
      if (iarg + 1 >= narg) error->all(FLERR, "Compute concentration/grid: 'smooth' needs a width");
      smooth_width = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      if (!(smooth_width > 0.0)) error->all(FLERR, "Compute concentration/grid: smooth width must be > 0");
      iarg += 2;
    } else {
      error->all(FLERR, "Compute concentration/grid: unknown keyword '{}' (expected layers, bounds, "
                        "classes, types, thickness or smooth)", keyword);
    }
  }
  if (axis < 0) error->all(FLERR, "Compute concentration/grid: keyword 'layers AXIS N' is required");
  if (!atom->radius_flag) error->all(FLERR, "Compute concentration/grid requires atom attribute radius");
  if (domain->dimension == 2) {
    if (axis == 2) error->all(FLERR, "Compute concentration/grid: layers along z in a 2d simulation");
    if (thickness == 0.0)
      error->all(FLERR, "Compute concentration/grid: a 2d simulation needs 'thickness T' (the slab the "
                        "disc centres represent)");
  } else if (thickness > 0.0) {
    error->all(FLERR, "Compute concentration/grid: 'thickness' is for 2d simulations only");
  }

  ncols = 1 + (class_edges.empty() ? 0 : static_cast<int>(class_edges.size()) + 1) + (by_type ? atom->ntypes : 0);
  array_flag = 1;
  size_array_rows = nlayers;
  size_array_cols = 1 + ncols;
  extarray = 0;
  peratom_flag = 1;
  size_peratom_cols = 0;
  local.assign(static_cast<size_t>(nlayers) * ncols, 0.0);
  fractions = local;
  scratch.assign(nlayers, 0.0);
  memory->create(array, nlayers, 1 + ncols, "concentration/grid:array");
}

ComputeConcentrationGrid::~ComputeConcentrationGrid()
{
  memory->destroy(array);
  memory->destroy(vector_atom);
}

void ComputeConcentrationGrid::init()
{
  const double lo = has_bounds ? bound_lo : domain->boxlo[axis];
  const double hi = has_bounds ? bound_hi : domain->boxhi[axis];
  layers = {lo, (hi - lo) / nlayers, nlayers};
  profiled_step = -1;
}

double ComputeConcentrationGrid::cross_section() const
{
  if (domain->dimension == 2) return domain->prd[1 - axis] * thickness;
  return domain->prd[(axis + 1) % 3] * domain->prd[(axis + 2) % 3];
}

Compute *ComputeConcentrationGrid::find_fraction(LAMMPS *lmp, const char *reference, const char *caller)
{
  const char *name = strncmp(reference, "c_", 2) == 0 ? reference + 2 : reference;
  const int icompute = lmp->modify->find_compute(name);
  if (icompute < 0) lmp->error->all(FLERR, "Fix {}: compute '{}' does not exist", caller, name);
  Compute *compute = lmp->modify->compute[icompute];
  if (!compute->peratom_flag || compute->size_peratom_cols != 0)
    lmp->error->all(FLERR, "Fix {}: compute '{}' does not give a per-atom vector of solid fractions "
                           "(use compute concentration/grid)", caller, name);
  return compute;
}

std::vector<std::string> ComputeConcentrationGrid::column_names() const
{
  std::vector<std::string> names{"total"};
  if (!class_edges.empty())
    for (size_t k = 0; k <= class_edges.size(); ++k) names.push_back("class_" + std::to_string(k));
  if (by_type)
    for (int t = 1; t <= atom->ntypes; ++t) names.push_back("type_" + std::to_string(t));
  return names;
}

int ComputeConcentrationGrid::size_class(double diameter) const
{
  return static_cast<int>(std::upper_bound(class_edges.begin(), class_edges.end(), diameter) - class_edges.begin());
}

void ComputeConcentrationGrid::profile()
{
  if (profiled_step == update->ntimestep) return;
  profiled_step = update->ntimestep;

  std::fill(local.begin(), local.end(), 0.0);
  double **x = atom->x;
  double *radius = atom->radius;
  int *mask = atom->mask;
  int *type = atom->type;
  const int class_col = 1;
  const int type_col = 1 + (class_edges.empty() ? 0 : static_cast<int>(class_edges.size()) + 1);
  const bool periodic = domain->periodicity[axis] && !has_bounds;
  const double period = domain->prd[axis];

  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    int columns[3] = {0, -1, -1};
    if (!class_edges.empty()) columns[1] = class_col + size_class(2.0 * radius[i]);
    if (by_type) columns[2] = type_col + type[i] - 1;
    for (int c : columns) {
      if (c < 0) continue;
      double *column = local.data() + c;
      const double centre = x[i][axis];
      sediment::add_sphere_to_layers(layers, centre, radius[i], column, ncols);
      if (periodic) {    // the parts that stick out of one end belong at the other
        if (centre - radius[i] < layers.lo) sediment::add_sphere_to_layers(layers, centre + period, radius[i], column, ncols);
        if (centre + radius[i] > layers.hi()) sediment::add_sphere_to_layers(layers, centre - period, radius[i], column, ncols);
      }
    }
  }
  MPI_Allreduce(local.data(), fractions.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, world);

  // Solid volume per layer -> solid fraction (a 2d disc of radius r stands for a sphere whose
  // volume is spread over the slab thickness), then optional smoothing column by column.
  const double cell = layers.thickness * cross_section();
  for (double &v : fractions) v /= cell;
  if (smooth_width > 0.0) {
    std::vector<double> column(nlayers);
    for (int c = 0; c < ncols; ++c) {
      for (int k = 0; k < nlayers; ++k) column[k] = fractions[k * ncols + c];
      sediment::smooth_profile(layers, column.data(), smooth_width, scratch.data());
      for (int k = 0; k < nlayers; ++k) fractions[k * ncols + c] = scratch[k];
    }
  }
}

void ComputeConcentrationGrid::compute_array()
{
  invoked_array = update->ntimestep;
  profile();
  for (int k = 0; k < nlayers; ++k) {
    array[k][0] = layers.lo + (k + 0.5) * layers.thickness;
    for (int c = 0; c < ncols; ++c) array[k][1 + c] = fractions[k * ncols + c];
  }
}

void ComputeConcentrationGrid::compute_peratom()
{
  invoked_peratom = update->ntimestep;
  profile();
  if (atom->nmax > nmax) {
    memory->destroy(vector_atom);
    nmax = atom->nmax;
    memory->create(vector_atom, nmax, "concentration/grid:vector_atom");
  }
  double **x = atom->x;
  int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; ++i)
    vector_atom[i] = (mask[i] & groupbit) ? sediment::profile_at(layers, fractions.data(), x[i][axis], ncols) : 0.0;
}

double ComputeConcentrationGrid::memory_usage()
{
  return (3.0 * local.size() + nlayers * (1.0 + ncols) + nmax) * sizeof(double);
}
