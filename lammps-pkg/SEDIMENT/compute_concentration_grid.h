// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: solid volume fraction of spheres in layers along one
   axis or in 3d cells (exact sphere-cell volumes), optionally by size class
   and atom type.
------------------------------------------------------------------------- */

#ifdef COMPUTE_CLASS
// clang-format off
ComputeStyle(concentration/grid,ComputeConcentrationGrid);
// clang-format on
#else

#ifndef LMP_COMPUTE_CONCENTRATION_GRID_H
#define LMP_COMPUTE_CONCENTRATION_GRID_H

#include "compute.h"

#include "sediment/concentration.hpp"

#include <string>
#include <vector>

namespace LAMMPS_NS {

class ComputeConcentrationGrid : public Compute {
 public:
  ComputeConcentrationGrid(class LAMMPS *, int, char **);
  ~ComputeConcentrationGrid() override;
  void init() override;
  void compute_array() override;
  void compute_peratom() override;
  double memory_usage() override;

  // The compute `reference` (c_ID or ID) giving a per-atom vector of solid fractions, checked;
  // errors name the style asking.
  static Compute *find_fraction(class LAMMPS *lmp, const char *reference, const std::string &caller);

  // For fix layers/hdf5: the layers (when the grid is layers), the names of the fraction
  // columns, the class edges.
  bool is_layers() const { return axis >= 0; }
  const sediment::Layers &layer_geometry() const { return grid.axes[axis]; }
  std::vector<std::string> column_names() const;
  const std::vector<double> &class_diameters() const { return class_edges; }
  int layer_axis() const { return axis; }
  double slab_thickness() const { return thickness; }
  double cross_section() const;

 private:
  int axis;                           // layers: 0, 1, 2 = x, y, z; cells: -1
  int counts[3];                      // cells along x, y, z (1 where not resolved)
  int has_bounds;
  double bounds[3][2];
  int ncentres;                       // array columns before the fractions: cell centre coordinates
  std::vector<double> class_edges;    // diameters separating the size classes
  int by_type;
  double thickness;                   // 2d: slab thickness converting areas to volumes
  double smooth_width;                // 0: no smoothing
  std::string weight_name;            // per-atom property: real spheres each atom stands for
  int weight_index;
  int every;                          // steps between refreshes of the field behind the per-atom values
  int ncols;                          // fraction columns: total, classes, types

  sediment::Grid grid;
  double cell_volume;
  std::vector<double> local, fractions, scratch;
  bigint profiled_step;
  int nmax;

  void profile();
  int size_class(double diameter) const;
  double extent(int dim) const;
};

}    // namespace LAMMPS_NS

#endif
#endif
