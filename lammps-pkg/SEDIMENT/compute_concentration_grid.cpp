// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: compute concentration/grid
------------------------------------------------------------------------- */

#include "compute_concentration_grid.h"
#include "sediment_args.h"
#include "sediment_rows.h"

#include "atom.h"
#include "comm.h"
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

namespace {
// Values per cell: the total, one per size class (edges + 1), one per atom type.
int ncols_for(size_t nedges, int ntypes)
{
  return 1 + (nedges == 0 ? 0 : static_cast<int>(nedges) + 1) + ntypes;
}
// The largest grid (cells x columns) a rank allocates: 2e8 values, 4.8 GB in its three copies.
constexpr bigint max_grid_values = 200000000;
}    // namespace

ComputeConcentrationGrid::ComputeConcentrationGrid(LAMMPS *lmp, int narg, char **arg) :
    Compute(lmp, narg, arg), axis(-1), counts{0, 0, 0}, has_bounds(0), bounds{}, ncentres(0), by_type(0),
    thickness(0.0), smooth_width(0.0), weight_index(-1), every(1), ncols(1), grid{}, cell_volume(1.0), profiled_step(-1),
    nmax(0)
{
  const int dimension = domain->dimension;
  int nbounds = 0;
  StyleArgs args(lmp, FLERR, "Compute concentration/grid", narg, arg, 3);
  while (args.more()) {
    int nvalues = 1;
    if (args.is("layers") || args.is("cells")) {
      if (counts[0] > 0) args.fail("give either 'layers' or 'cells', once");
      if (args.is("layers")) {
        args.need(2, "an axis and a count");
        axis = args.axis(1, "layer axis");
        counts[0] = counts[1] = counts[2] = 1;
        counts[axis] = args.count(2, max_grid_values);
        nvalues = 2;
      } else {
        if (!args.has(dimension))
          args.fail("'cells' needs {} counts in a {}d simulation", dimension, dimension);
        counts[2] = 1;
        for (int d = 0; d < dimension; ++d) counts[d] = args.count(1 + d, max_grid_values);
        nvalues = dimension;
      }
    } else if (args.is("bounds")) {
      // LO HI along the layer axis, or xlo xhi ylo yhi [zlo zhi] for cells; checked after the grid.
      nbounds = std::min(args.numbers_after(), 2 * dimension);
      for (int k = 0; k < nbounds; ++k) bounds[k / 2][k % 2] = args.number(1 + k);
      has_bounds = 1;
      nvalues = nbounds;
    } else if (args.is("classes")) {
      nvalues = args.numbers_after();
      if (nvalues == 0) args.fail("'classes' needs at least one diameter");
      for (int k = 1; k <= nvalues; ++k) class_edges.push_back(args.number(k));
      for (size_t k = 0; k < class_edges.size(); ++k)
        if (!(class_edges[k] > 0.0) || (k > 0 && !(class_edges[k] > class_edges[k - 1])))
          args.fail("class diameters must be finite, positive and increasing");
    } else if (args.is("types")) {
      args.need(1, "yes or no");
      by_type = args.yes_no(1);
    } else if (args.is("thickness")) {
      args.need(1, "a value");
      thickness = args.positive(1, "thickness");
    } else if (args.is("smooth")) {
      args.need(1, "a width");
      smooth_width = args.positive(1, "smooth width");
    } else if (args.is("weight")) {
      weight_name = args.weight(1);
    } else if (args.is("every")) {
      args.need(1, "a number of steps");
      every = args.count(1, MAXSMALLINT);
    } else {
      args.unknown("layers, cells, bounds, classes, types, thickness, smooth, weight or every");
    }
    args.next(nvalues);
  }
  if (counts[0] == 0)
    error->all(FLERR, "Compute concentration/grid: the grid is required: 'layers AXIS N' or 'cells NX NY{}'",
               dimension == 3 ? " NZ" : "");
  if (!atom->radius_flag) error->all(FLERR, "Compute concentration/grid requires atom attribute radius");
  if (has_bounds) {
    const int expected = axis >= 0 ? 2 : 2 * dimension;
    if (nbounds != expected)
      error->all(FLERR, "Compute concentration/grid: 'bounds' needs {} values ({})", expected,
                 axis >= 0 ? "LO HI along the layer axis" : dimension == 3 ? "xlo xhi ylo yhi zlo zhi" : "xlo xhi ylo yhi");
    if (axis >= 0) std::swap(bounds[0], bounds[axis]);
    for (int d = 0; d < 3; ++d)
      if ((axis < 0 ? d < dimension : d == axis) && !(bounds[d][1] > bounds[d][0]))
        error->all(FLERR, "Compute concentration/grid: bounds need LO < HI along {}", "xyz"[d]);
  }
  if (dimension == 2) {
    if (axis == 2) error->all(FLERR, "Compute concentration/grid: layers along z in a 2d simulation");
    if (thickness == 0.0)
      error->all(FLERR, "Compute concentration/grid: a 2d simulation needs 'thickness T' (the slab the "
                        "disc centres represent)");
  } else if (thickness > 0.0) {
    error->all(FLERR, "Compute concentration/grid: 'thickness' is for 2d simulations only");
  }

  for (int d = 0; d < 3; ++d) grid.resolved[d] = axis >= 0 ? d == axis : d < dimension;
  ncentres = axis >= 0 ? 1 : dimension;
  ncols = ncols_for(class_edges.size(), by_type ? atom->ntypes : 0);
  // Every rank holds the whole grid three times (local sums, their reduction, the output array):
  // refuse sizes that cannot be held instead of failing in the allocator or overflowing the index.
  const double values = static_cast<double>(counts[0]) * counts[1] * counts[2] * ncols;
  if (values > static_cast<double>(max_grid_values))
    error->all(FLERR, "Compute concentration/grid: {}x{}x{} cells x {} columns is more than {:.0e} values "
               "(about {:.0f} GB per rank); use fewer layers, cells or classes", counts[0], counts[1], counts[2],
               ncols, static_cast<double>(max_grid_values), 3.0 * values * sizeof(double) / 1e9);
  const int ncells = counts[0] * counts[1] * counts[2];
  array_flag = 1;
  size_array_rows = ncells;
  size_array_cols = ncentres + ncols;
  extarray = 0;
  peratom_flag = 1;
  size_peratom_cols = 0;
  local.assign(static_cast<size_t>(ncells) * ncols, 0.0);
  fractions = local;
  scratch.assign(*std::max_element(counts, counts + 3), 0.0);
  memory->create(array, ncells, ncentres + ncols, "concentration/grid:array");
}

ComputeConcentrationGrid::~ComputeConcentrationGrid()
{
  memory->destroy(array);
  memory->destroy(vector_atom);
}

void ComputeConcentrationGrid::init()
{
  // The grid spans the bounds or the box; it wraps along a periodic dimension it spans whole.
  cell_volume = 1.0;
  for (int d = 0; d < 3; ++d) {
    const bool own_bounds = has_bounds && grid.resolved[d];
    const double lo = own_bounds ? bounds[d][0] : domain->boxlo[d];
    const double hi = own_bounds ? bounds[d][1] : domain->boxhi[d];
    if (own_bounds && (hi <= domain->boxlo[d] || lo >= domain->boxhi[d]))
      error->all(FLERR, "Compute concentration/grid: its bounds {} to {} along {} lie wholly outside the box ({} to {}): "
                 "it would see no atom", lo, hi, "xyz"[d], domain->boxlo[d], domain->boxhi[d]);
    grid.axes[d] = {lo, (hi - lo) / counts[d], counts[d], domain->periodicity[d] && !own_bounds};
    cell_volume *= grid.resolved[d] ? grid.axes[d].thickness : extent(d);
  }
  profiled_step = -1;

  if (!weight_name.empty())
    weight_index = sediment_find_weights(lmp, weight_name, groupbit, "Compute concentration/grid");
}

// Extent of the cells along an axis the grid does not resolve: the box, or the 2d slab thickness.
double ComputeConcentrationGrid::extent(int dim) const
{
  return dim == 2 && domain->dimension == 2 ? thickness : domain->prd[dim];
}

double ComputeConcentrationGrid::cross_section() const
{
  return axis < 0 ? 0.0 : extent((axis + 1) % 3) * extent((axis + 2) % 3);
}

Compute *ComputeConcentrationGrid::find_fraction(LAMMPS *lmp, const char *reference, const std::string &caller)
{
  Compute *compute = sediment_find_compute(lmp, reference, caller);
  if (!compute->peratom_flag || compute->size_peratom_cols != 0)
    lmp->error->all(FLERR, "{}: compute '{}' does not give a per-atom vector of solid fractions "
                           "(use compute concentration/grid)", caller, compute->id);
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
  const auto x = flat_rows<3>(atom->x);
  const double *radius = atom->radius;
  int *mask = atom->mask;
  int *type = atom->type;
  const int class_col = 1;
  const int type_col = 1 + (class_edges.empty() ? 0 : static_cast<int>(class_edges.size()) + 1);

  const double *weight = weight_index >= 0 ? atom->dvector[weight_index] : nullptr;

  // Layers take the one-axis deposit directly (add_sphere_to_grid would find the axis per sphere).
  auto deposit = [&](int i, int column, double count) {
    if (axis >= 0)
      sediment::add_sphere_to_layers(grid.axes[axis], x[i][axis], radius[i], local.data() + column, ncols, count);
    else
      sediment::add_sphere_to_grid(grid, x[i], radius[i], local.data() + column, ncols, count);
  };
  // Group all deposits every local atom's total in one call (what depends on the grid alone taken
  // once); the same sums in the same order as one by one.
  const bool all = groupbit == 1;
  if (all) sediment::add_spheres_to_grid(grid, x, radius, weight, atom->nlocal, local.data(), ncols);
  if (!all || !class_edges.empty() || by_type)
    for (int i = 0; i < atom->nlocal; ++i) {
      if (!(mask[i] & groupbit)) continue;
      const double count = weight ? weight[i] : 1.0;
      if (!all) deposit(i, 0, count);
      if (!class_edges.empty()) deposit(i, class_col + size_class(2.0 * radius[i]), count);
      if (by_type) deposit(i, type_col + type[i] - 1, count);
    }
  // Solid volume per cell -> solid fraction (in 2d a disc of radius r stands for a sphere whose
  // volume is spread over the slab thickness), then optional smoothing column by column. On one rank
  // the sum is the rank's own: one pass instead of MPI's copy and a second pass over the cells.
  const double *sums = local.data();
  if (comm->nprocs > 1) {
    MPI_Allreduce(local.data(), fractions.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, world);
    sums = fractions.data();
  }
  // By the reciprocal: the division per cell was all of this loop's time (cost.py's cells scene has
  // two cells per sphere), and the product differs from the quotient in the last bits only.
  const double per_volume = 1.0 / cell_volume;
  for (size_t k = 0; k < fractions.size(); ++k) fractions[k] = sums[k] * per_volume;
  if (smooth_width > 0.0)
    for (int c = 0; c < ncols; ++c) sediment::smooth_grid(grid, fractions.data() + c, smooth_width, scratch.data(), ncols);
}

void ComputeConcentrationGrid::compute_array()
{
  invoked_array = update->ntimestep;
  profile();
  const int ncells = size_array_rows;
  for (int cell = 0; cell < ncells; ++cell) {
    const int index[3] = {cell % counts[0], cell / counts[0] % counts[1], cell / (counts[0] * counts[1])};
    int col = 0;
    for (int d = 0; d < 3; ++d)
      if (grid.resolved[d]) array[cell][col++] = grid.axes[d].lo + (index[d] + 0.5) * grid.axes[d].thickness;
    for (int c = 0; c < ncols; ++c) array[cell][ncentres + c] = fractions[cell * ncols + c];
  }
}

void ComputeConcentrationGrid::compute_peratom()
{
  invoked_peratom = update->ntimestep;
  // The field the per-atom values are read from is refreshed every `every` steps (and at the start
  // of a run, or when the step number went back); the values themselves follow the atoms each step.
  const bigint step = update->ntimestep;
  if (profiled_step < 0 || step < profiled_step || step - profiled_step >= every) profile();
  if (atom->nmax > nmax) {
    memory->destroy(vector_atom);
    nmax = atom->nmax;
    memory->create(vector_atom, nmax, "concentration/grid:vector_atom");
  }
  const double *total = fractions.data();    // column 0
  if (groupbit == 1) {    // group all: every local atom, what depends on the grid alone taken once
    sediment::grid_values_at(grid, total, flat_rows<3>(atom->x), atom->nlocal, vector_atom, ncols);
    return;
  }
  // Atoms outside the group are not read: their positions are not this compute's to trust.
  const auto x = flat_rows<3>(atom->x);
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; ++i)
    vector_atom[i] = (mask[i] & groupbit) ? sediment::grid_value_at(grid, total, x[i], ncols) : 0.0;
}

double ComputeConcentrationGrid::memory_usage()
{
  return (3.0 * local.size() + static_cast<double>(size_array_rows) * size_array_cols + nmax) * sizeof(double);
}
