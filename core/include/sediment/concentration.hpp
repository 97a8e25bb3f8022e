// SPDX-License-Identifier: GPL-2.0-or-later
// Solid volume of spheres on a regular grid of layers or 3d cells, split among the cells by the
// exact (closed-form) volume of the sphere inside each. Volumes are split by geometric overlap, not lumped at centres, so the field is smooth when cells
// are smaller than grains and the solid volume is conserved to round-off.
#pragma once

namespace sediment {

// Volume of a sphere (centre c, radius r along the axis) between the planes a <= b.
double sphere_slab_volume(double centre, double radius, double a, double b);

// Regular layers [lo + k h, lo + (k + 1) h), k = 0 .. n - 1; along a periodic axis index k stands
// for every k + m n.
struct Layers {
  double lo = 0.0;
  double thickness = 1.0;
  int count = 1;
  bool periodic = false;
  // 1 / thickness, set by the constructor (assign a new Layers, never thickness alone): finding a
  // sphere's layer multiplies (a division per sphere cost more).
  double per_thickness = 1.0;

  Layers() = default;
  Layers(double lo_, double thickness_, int count_, bool periodic_ = false) :
      lo(lo_), thickness(thickness_), count(count_), periodic(periodic_), per_thickness(1.0 / thickness_)
  {
  }
  double hi() const { return lo + thickness * count; }
};

// Adds the sphere's volume in every layer it overlaps, times `weight` (the number of real spheres
// it stands for), to values[k * stride]; returns the part of its own volume outside [lo, hi] (none
// along a periodic axis). Volumes telescope, so they sum exactly to the inside part.
double add_sphere_to_layers(const Layers &layers, double centre, double radius, double *values, int stride = 1,
                            double weight = 1.0);

// The piecewise-linear profile through the layer centres at x (flat beyond the outer centres, or
// wrapped along a periodic axis).
double profile_at(const Layers &layers, const double *values, double x, int stride = 1);

// Gaussian smoothing (standard deviation `width`, truncated at 4 widths) of the layer values into
// out, with mirror ends (or wrapped, periodic): conserves the total exactly and keeps a uniform
// profile uniform. values[k * stride] in, out[k] out.
void smooth_profile(const Layers &layers, const double *values, double width, double *out, int stride = 1);

// A regular grid of cells, x index fastest: cell (i, j, k) is i + nx (j + ny k). An axis that is not
// resolved has a single cell without bounds: spheres are never clipped along it (layers are a grid
// resolved along one axis only).
struct Grid {
  Layers axes[3];
  bool resolved[3];
  int cells() const { return axes[0].count * axes[1].count * axes[2].count; }
};

// Adds the sphere's volume in every cell it overlaps, times `weight`, to values[cell * stride];
// returns the part of its own volume outside the grid. A sphere crossing faces along one axis is sliced like layers; one
// crossing faces along two or three is split by inclusion-exclusion of the closed-form volume of
// the sphere beyond three perpendicular planes (cost: the sphere's cell vertices).
double add_sphere_to_grid(const Grid &grid, const double centre[3], double radius, double *values, int stride = 1,
                          double weight = 1.0);
// add_sphere_to_grid of n spheres in turn (centres[i] a row of three coordinates, the rows one after
// another as LAMMPS keeps positions; weight nullptr: one each), with what depends on the grid alone
// decided once: the same sums in the same order. Returns the sum of their volumes outside the grid.
double add_spheres_to_grid(const Grid &grid, const double (*centres)[3], const double *radius,
                           const double *weight, int n, double *values, int stride = 1);

// Trilinear interpolation between cell centres (flat beyond the outer centres, wrapped along
// periodic axes).
double grid_value_at(const Grid &grid, const double *values, const double point[3], int stride = 1);
// grid_value_at of n points, out[i] for points[i] (rows of three coordinates, one after another as
// LAMMPS keeps positions): the same values, with what depends on the grid alone decided once.
void grid_values_at(const Grid &grid, const double *values, const double (*points)[3], int n, double *out,
                    int stride = 1);

// smooth_profile along every resolved axis in turn (a separable Gaussian), in place; scratch needs
// as many entries as the longest axis.
void smooth_grid(const Grid &grid, double *values, double width, double *scratch, int stride = 1);

}    // namespace sediment
