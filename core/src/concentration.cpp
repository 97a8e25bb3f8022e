// SPDX-License-Identifier: GPL-2.0-or-later
// Spheres deposited into the concentration field: the volume of each in the layers or cells it
// crosses, four spheres at a time with AVX2. The field read back at points: concentration_read.cpp.
#include "sediment/concentration.hpp"

#include "sediment/batch_math.hpp"
#include "sediment/geometry.hpp"
#include "sediment/grid_index.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sediment {

using namespace grid_index;

namespace {

// Volume of the sphere below height u above its centre, minus half the sphere: pi (r^2 u - u^3/3).
double below(double radius, double u)
{
  double v = std::min(std::max(u, -radius), radius);
#if defined(__GNUC__) && defined(__SSE2__)
  // Hides v's value from GCC, which otherwise branches on v == radius (to reuse below(r, r)): whether
  // a face cuts a sphere is random, and the branch was mispredicted for about one sphere in two.
  asm("" : "+x"(v));
#endif
  return pi * v * (radius * radius - v * v * (1.0 / 3.0));    // no division: this runs per atom and layer face
}

// The cell of an axis holding unwrapped index k: wrapped when periodic, -1 when outside.
int cell_of(const Layers &axis, int k)
{
  if (axis.periodic) return wrap(k, axis.count);
  return k >= 0 && k < axis.count ? k : -1;
}

// Unwrapped indices of the first and last layer that the interval [lo, hi] touches.
void touched(const Layers &axis, double lo, double hi, int &first, int &last)
{
  first = floor_index((lo - axis.lo) * axis.per_thickness);
  last = floor_index((hi - axis.lo) * axis.per_thickness);
}

// The touched range clamped to the axis unless it is periodic; first > last when it misses.
void clamp_to_axis(const Layers &axis, int &first, int &last)
{
  if (axis.periodic) return;
  first = std::max(first, 0);
  last = std::min(last, axis.count - 1);
}

// Volumes of the sphere of radius r about the origin cut by planes normal to x, y and z. A slice at
// height u along x is a disc of radius rho = sqrt(r^2 - u^2); the part of it with y >= e is the
// segment rho^2 acos(e / rho) - e sqrt(rho^2 - e^2), the part with y >= Y and z >= Z (Y, Z >= 0,
// corner inside the disc) is half of each segment minus a quarter disc plus Y Z. Both integrate
// in closed form along u; atan2 instead of acos/asin keeps the ends (s = 0) accurate.
class SphereCuts {
 public:
  explicit SphereCuts(double radius) : r(radius), r2(radius * radius) {}

  // Volume with x <= u and y >= e (z free).
  double quarter(double u, double e) const { return half(std::clamp(u, -r, r), e); }

  // Volume with x <= u, y >= y0 and z >= z0.
  double corner(double u, double y0, double z0) const
  {
    u = std::clamp(u, -r, r);
    if (z0 < 0.0) return half(u, y0) - corner(u, y0, -z0);    // mirror the part below z0
    if (y0 < 0.0) return half(u, z0) - corner(u, -y0, z0);
    const double q = r2 - y0 * y0 - z0 * z0;
    if (q <= 0.0) return 0.0;
    const double uc = std::sqrt(q);
    if (u <= -uc) return 0.0;
    // Past the corner's whole extent (the common case: a face along x outside the sphere) the
    // antiderivatives are odd in u, so their difference from -uc is twice their value at uc.
    if (u >= uc) return segment(uc, y0) + segment(uc, z0) - 0.5 * pi * disc(uc) + 2.0 * y0 * z0 * uc;
    return 0.5 * (segment(u, y0) - segment(-uc, y0) + segment(u, z0) - segment(-uc, z0)) -
        0.25 * pi * (disc(u) - disc(-uc)) + y0 * z0 * (u + uc);
  }

 private:
  double r, r2;

  // Integral of rho^2 along u.
  double disc(double u) const { return r2 * u - u * u * u / 3.0; }

  // Volume with x <= u and y >= e.
  double half(double u, double e) const
  {
    if (e < 0.0) return pi * (disc(u) - disc(-r)) - half(u, -e);
    const double k2 = r2 - e * e;
    if (k2 <= 0.0) return 0.0;
    const double k = std::sqrt(k2);
    if (u <= -k) return 0.0;
    if (u >= k) return pi / 3.0 * (r - e) * (r - e) * (2.0 * r + e);    // the whole cap beyond y = e
    return segment(u, e) - segment_from(k2, e);
  }

  // segment(-k, e), where the segment closes (sqrt(rho^2 - e^2) = 0): its three angles are 0 (pi/2 at
  // e = 0), -pi/2 and -pi/2 (0 at e = 0), which leave one closed form, without atan2.
  double segment_from(double k2, double e) const
  {
    return 0.5 * pi * (e * k2 / 3.0 + 2.0 / 3.0 * e * r2 - 2.0 / 3.0 * r2 * r);
  }

  // Antiderivative along u of the segment area with y >= e >= 0, for |u| <= sqrt(r^2 - e^2):
  // by parts on rho^2 acos(e / rho), the rest in asin and atan.
  double segment(double u, double e) const
  {
    const double k2 = r2 - e * e;
    const double s = std::sqrt(std::max(0.0, k2 - u * u));    // sqrt(rho^2 - e^2)
    const double angle = e == 0.0 ? 0.5 * pi : std::atan2(s, e);    // acos(e / rho)
    const double arc = std::atan2(u, s);                            // asin(u / k)
    return disc(u) * angle + e * (k2 * arc - u * s) / 6.0 - e * 2.0 / 3.0 * r2 * arc +
        2.0 / 3.0 * r2 * r * std::atan2(u * e, r * s) - 0.5 * e * (u * s + k2 * arc);
  }
};

// Spreads the sphere over the cells it crosses along two or three axes: each cell's volume is the
// inclusion-exclusion of SphereCuts::corner at its eight vertices, so the cells telescope to the
// whole sphere. Along an axis not crossed the one cell spans [-r, r].
double spread_over_cells(const Grid &grid, const double centre[3], double radius, const int first[3],
                         const int last[3], const bool crossing[3], double *values, int stride, double weight)
{
  // Scratch kept between calls: this runs for every sphere crossing faces along two axes, each step.
  thread_local std::vector<double> edges[3], vertex;
  thread_local std::vector<int> cells[3];
  for (int d = 0; d < 3; ++d) {
    edges[d].clear();
    cells[d].clear();
    if (!crossing[d]) {
      edges[d] = {-radius, radius};
      cells[d] = {grid.resolved[d] ? cell_of(grid.axes[d], first[d]) : 0};
      continue;
    }
    const Layers &axis = grid.axes[d];
    for (int k = first[d]; k <= last[d] + 1; ++k) edges[d].push_back(axis.lo + k * axis.thickness - centre[d]);
    for (int k = first[d]; k <= last[d]; ++k) cells[d].push_back(cell_of(axis, k));
  }
  const int n[3] = {static_cast<int>(cells[0].size()), static_cast<int>(cells[1].size()),
                    static_cast<int>(cells[2].size())};
  const SphereCuts cuts(radius);
  vertex.resize((n[0] + 1) * (n[1] + 1) * (n[2] + 1));
  auto at = [&](int i, int j, int k) -> double & { return vertex[i + (n[0] + 1) * (j + (n[1] + 1) * k)]; };
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i) at(i, j, k) = cuts.corner(edges[0][i], edges[1][j], edges[2][k]);

  const int nx = grid.axes[0].count, ny = grid.axes[1].count;
  double inside = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (cells[0][i] < 0 || cells[1][j] < 0 || cells[2][k] < 0) continue;
        const double volume = at(i + 1, j, k) - at(i, j, k) - at(i + 1, j + 1, k) + at(i, j + 1, k) -
            at(i + 1, j, k + 1) + at(i, j, k + 1) + at(i + 1, j + 1, k + 1) - at(i, j + 1, k + 1);
        values[(cells[0][i] + nx * (cells[1][j] + ny * cells[2][k])) * stride] += weight * volume;
        inside += volume;
      }
  return inside;
}

// Spreads a sphere that crosses one face along each of two or three axes (crossing[d]) and none along
// the others (in cell[d] there) over its four or eight cells, by inclusion-exclusion of the parts
// below the faces: below the faces of a set of axes lies the sphere, a slab, a slab less a quarter
// volume, or (three axes) two faces' part less a quarter volume plus a corner volume, where the
// vertices' inclusion-exclusion took 18 or 27 corner volumes. face[d] is the face's unwrapped index
// along d. Returns the volume put in cells.
double spread_across_faces(const Grid &grid, const double centre[3], double radius, const bool crossing[3],
                           const int face[3], const int cell[3], double *values, int stride, double weight)
{
  int axes[3], n = 0;
  double offset[3];    // of each crossing axis's face from the centre
  for (int d = 0; d < 3; ++d)
    if (crossing[d]) {
      axes[n] = d;
      offset[n++] = grid.axes[d].lo + face[d] * grid.axes[d].thickness - centre[d];
    }
  const SphereCuts cuts(radius);
  const double half = below(radius, radius);
  // part[set]: below the faces of the crossing axes whose bits are set (bit k for axes[k])
  double part[8];
  part[0] = 2.0 * half;
  for (int k = 0; k < n; ++k) part[1 << k] = below(radius, offset[k]) + half;
  for (int j = 0; j < n; ++j)
    for (int k = j + 1; k < n; ++k) part[1 << j | 1 << k] = part[1 << j] - cuts.quarter(offset[j], offset[k]);
  if (n == 3) part[7] = part[3] - cuts.quarter(offset[0], offset[2]) + cuts.corner(offset[0], offset[1], offset[2]);

  int sides[3][2];    // each crossing axis's cells below and above its face (-1: beyond a bounded end)
  for (int k = 0; k < n; ++k)
    for (int above = 0; above < 2; ++above) sides[k][above] = cell_of(grid.axes[axes[k]], face[axes[k]] - 1 + above);
  constexpr double parity[8] = {1.0, -1.0, -1.0, 1.0, -1.0, 1.0, 1.0, -1.0};    // (-1)^(bits set)
  const int nx = grid.axes[0].count, ny = grid.axes[1].count, all = (1 << n) - 1;
  double inside = 0.0;
  for (int above = 0; above <= all; ++above) {    // bit k: the cell beyond the face along axes[k]
    int index[3] = {cell[0], cell[1], cell[2]};
    bool outside = false;
    for (int k = 0; k < n; ++k) {
      index[axes[k]] = sides[k][above >> k & 1];
      outside = outside || index[axes[k]] < 0;
    }
    if (outside) continue;
    double volume = 0.0;
    for (int beyond = above;; beyond = (beyond - 1) & above) {    // every subset of above
      volume += parity[beyond] * part[(all & ~above) | beyond];
      if (beyond == 0) break;
    }
    values[(index[0] + nx * (index[1] + ny * index[2])) * stride] += weight * volume;
    inside += volume;
  }
  return inside;
}

}    // namespace

double sphere_slab_volume(double centre, double radius, double a, double b)
{
  return below(radius, b - centre) - below(radius, a - centre);
}

double add_sphere_to_layers(const Layers &layers, double centre, double radius, double *values, int stride,
                            double weight)
{
  int first, last;
  touched(layers, centre - radius, centre + radius, first, last);
  // below() of the whole sphere is +-half, so the volumes telescope to 2 half exactly.
  const double half = below(radius, radius), total = 2.0 * half;
  double inside = 0.0;
  auto add = [&](int k, double volume) {    // layer k's share, if the axis has that layer
    const int cell = cell_of(layers, k);
    if (cell < 0) return;
    values[cell * stride] += weight * volume;
    inside += volume;
  };
  if (last - first <= 1) {
    // In one layer or across one face, as most spheres are when layers are not thinner than grains:
    // one split at the face above the first layer (the upper part is exactly 0 for a sphere inside
    // it), without the loop's branches, which the processor mispredicted about once per sphere.
    const double lower = below(radius, layers.lo + (first + 1) * layers.thickness - centre) + half;
    add(first, lower);
    add(first + 1, total - lower);
    return total - inside;
  }
  clamp_to_axis(layers, first, last);
  double lower = below(radius, layers.lo + first * layers.thickness - centre);
  for (int k = first; k <= last; ++k) {
    const double upper = below(radius, layers.lo + (k + 1) * layers.thickness - centre);
    add(k, upper - lower);
    lower = upper;
  }
  return total - inside;
}

namespace {

// add_sphere_to_grid on a grid of cells (not layers), inline in the loop that deposits many spheres.
[[gnu::always_inline]] inline double cells_deposit(const Grid &grid, const double centre[3], double radius,
                                                   double *values, int stride, double weight)
{
  const double total = 4.0 / 3.0 * pi * radius * radius * radius;
  int first[3], last[3], face[3], ncrossing = 0, along = -1;
  bool crosses[3] = {false, false, false}, one_face = true;
  for (int d = 0; d < 3; ++d) {
    first[d] = last[d] = 0;
    if (!grid.resolved[d]) continue;
    const Layers &axis = grid.axes[d];
    touched(axis, centre[d] - radius, centre[d] + radius, first[d], last[d]);
    // A sphere crossing a face (an outer one too) is split along d; the range is clamped after.
    if (first[d] != last[d]) {
      crosses[d] = true;
      along = d;
      ++ncrossing;
      face[d] = first[d] + 1;
      one_face = one_face && last[d] == face[d];
    }
    clamp_to_axis(axis, first[d], last[d]);
    if (first[d] > last[d]) return total;
  }
  if (ncrossing > 1 && one_face) {    // the common splits in two or three axes: around one edge or vertex
    int cell[3];
    for (int d = 0; d < 3; ++d) {
      cell[d] = crosses[d] || !grid.resolved[d] ? 0 : cell_of(grid.axes[d], first[d]);
      if (cell[d] < 0) return total;
    }
    return total - spread_across_faces(grid, centre, radius, crosses, face, cell, values, stride, weight);
  }
  if (ncrossing > 1)
    return total - spread_over_cells(grid, centre, radius, first, last, crosses, values, stride, weight);

  // Whole in one cell, or sliced like layers along the one crossing axis within the cell of the others.
  int cell[3];
  for (int d = 0; d < 3; ++d) cell[d] = d == along || !grid.resolved[d] ? 0 : cell_of(grid.axes[d], first[d]);
  if (cell[0] < 0 || cell[1] < 0 || cell[2] < 0) return total;
  const int nx = grid.axes[0].count, ny = grid.axes[1].count;
  double *base = values + (cell[0] + nx * (cell[1] + ny * cell[2])) * stride;
  if (along < 0) {
    *base += weight * total;
    return 0.0;
  }
  const int step[3] = {1, nx, nx * ny};
  return add_sphere_to_layers(grid.axes[along], centre[along], radius, base, step[along] * stride, weight);
}

}    // namespace

double add_sphere_to_grid(const Grid &grid, const double centre[3], double radius, double *values, int stride,
                          double weight)
{
  if (const int axis = layer_axis(grid); axis >= 0)
    return add_sphere_to_layers(grid.axes[axis], centre[axis], radius, values, stride, weight);
  return cells_deposit(grid, centre, radius, values, stride, weight);
}

namespace {

#ifdef SEDIMENT_GRID_AVX2
// cell_of(axis, k) of a bounded axis for four whole numbers k: k, or -1 outside the axis.
SEDIMENT_TARGET_AVX2 inline __m256d bounded_cells4(const Layers &axis, __m256d k)
{
  const __m256d outside = _mm256_or_pd(_mm256_cmp_pd(k, _mm256_setzero_pd(), _CMP_LT_OQ),
                                       _mm256_cmp_pd(k, _mm256_set1_pd(axis.count), _CMP_GE_OQ));
  return _mm256_blendv_pd(k, _mm256_set1_pd(-1.0), outside);
}

// below() of four heights, by the same operations (min and max with their operands in this order
// pick as std::min and std::max do, NaN included).
SEDIMENT_TARGET_AVX2 inline __m256d below4(__m256d radius, __m256d u)
{
  const __m256d v = _mm256_min_pd(radius, _mm256_max_pd(_mm256_xor_pd(radius, _mm256_set1_pd(-0.0)), u));
  return _mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(pi), v),
                       _mm256_sub_pd(_mm256_mul_pd(radius, radius),
                                     _mm256_mul_pd(_mm256_mul_pd(v, v), _mm256_set1_pd(1.0 / 3.0))));
}

// touched() of four spheres: the first and last layer (whole numbers, as doubles).
SEDIMENT_TARGET_AVX2 inline void touched4(const Layers &axis, __m256d c, __m256d r, __m256d &first,
                                          __m256d &last)
{
  const __m256d lo = _mm256_set1_pd(axis.lo), per = _mm256_set1_pd(axis.per_thickness);
  first = _mm256_floor_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_sub_pd(c, r), lo), per));
  last = _mm256_floor_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_add_pd(c, r), lo), per));
}

// The part of four spheres below the face above their first layer, as add_sphere_to_layers' fast path
// computes it (half: below4(r, r)).
SEDIMENT_TARGET_AVX2 inline __m256d below_next_face4(const Layers &axis, __m256d c, __m256d r,
                                                     __m256d first, __m256d half)
{
  const __m256d face = _mm256_sub_pd(
      _mm256_add_pd(_mm256_set1_pd(axis.lo),
                    _mm256_mul_pd(_mm256_add_pd(first, _mm256_set1_pd(1.0)), _mm256_set1_pd(axis.thickness))),
      c);
  return _mm256_add_pd(below4(r, face), half);
}

// Where four spheres' shares of one side go: the addresses of their cells (whole numbers as doubles) in
// values, and sink's for lanes that add nothing there (a cell outside a bounded axis, or a sphere that
// takes add_sphere_to_layers), so that the adds need no branch.
SEDIMENT_TARGET_AVX2 inline __m256i cell_addresses4(__m256d cell, __m256d near, double *values, int stride,
                                                     double *sink, __m256d &kept)
{
  kept = _mm256_and_pd(near, _mm256_cmp_pd(cell, _mm256_setzero_pd(), _CMP_GE_OQ));
  // byte offsets below 2^31: cells lie within the axis where kept, and the grid is smaller than that
  const __m256d offset = _mm256_and_pd(kept, _mm256_mul_pd(cell, _mm256_set1_pd(stride * sizeof(double))));
  const __m256i address = _mm256_add_epi64(_mm256_set1_epi64x(reinterpret_cast<std::intptr_t>(values)),
                                           _mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(offset)));
  return _mm256_castpd_si256(_mm256_blendv_pd(
      _mm256_castsi256_pd(_mm256_set1_epi64x(reinterpret_cast<std::intptr_t>(sink))), _mm256_castsi256_pd(address),
      kept));
}

// add_sphere_to_layers of n spheres in turn (their coordinate along the layers' axis), four at a
// time splitting those in one layer or across one face (most) in vectors, by the same operations as
// its fast path, down to the two adds per sphere; the others take add_sphere_to_layers. Deposits go
// in sphere order, so the sums are the same as one by one.
SEDIMENT_TARGET_AVX2 double layers_deposit_avx2(const Layers &layers, int axis,
                                                const double (*centres)[3], const double *radius,
                                                const double *weight, int n, double *values, int stride)
{
  const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd();
  double outside = 0.0, sink = 0.0;
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d r = _mm256_loadu_pd(radius + i), c = coordinates4(centres, i, axis), half = below4(r, r);
    __m256d first, last;
    touched4(layers, c, r, first, last);
    // At most one face crossed, and indices an int holds as they are (NaN: neither)
    const __m256d near =
        _mm256_and_pd(_mm256_cmp_pd(_mm256_sub_pd(last, first), one, _CMP_LE_OQ), within_reach4(first));
    const int split = _mm256_movemask_pd(near);
    // The two layers' cells as cell_of gives them, in vectors (a branch per sphere on whether it lies
    // in the box was mispredicted for one atom in four at dt/tau = 1e4, half the atoms lying outside)
    __m256d cell[2];
    if (layers.periodic) {
      periodic_cells4(layers, first, cell[0], cell[1]);
    } else {
      cell[0] = bounded_cells4(layers, first);
      cell[1] = bounded_cells4(layers, _mm256_add_pd(first, one));
    }
    const __m256d total = _mm256_mul_pd(_mm256_set1_pd(2.0), half), lower = below_next_face4(layers, c, r, first, half);
    const __m256d count = weight ? _mm256_loadu_pd(weight + i) : one;
    const __m256d part[2] = {lower, _mm256_sub_pd(total, lower)};
    alignas(32) double *to[2][4];
    alignas(32) double add[2][4], rest[4];
    __m256d inside = zero;    // as add_sphere_to_layers sums it: 0, plus each part that lands in the axis
    for (int side = 0; side < 2; ++side) {
      __m256d kept;
      _mm256_store_si256(reinterpret_cast<__m256i *>(to[side]),
                         cell_addresses4(cell[side], near, values, stride, &sink, kept));
      _mm256_store_pd(add[side], _mm256_mul_pd(count, part[side]));
      inside = _mm256_add_pd(inside, _mm256_and_pd(kept, part[side]));
    }
    _mm256_store_pd(rest, _mm256_sub_pd(total, inside));
    auto add_lane = [&](int k) {
      *to[0][k] += add[0][k];
      *to[1][k] += add[1][k];
      outside += rest[k];
    };
    if (split == 0xF) {    // the common case apart, without the call: the sums stay in registers
      for (int k = 0; k < 4; ++k) add_lane(k);
      continue;
    }
    for (int k = 0; k < 4; ++k) {
      if (split >> k & 1) {
        add_lane(k);
      } else {
        _mm256_zeroupper();    // before the SSE code: this processor ran it 1.5-2x slower after dirty upper halves
        outside += add_sphere_to_layers(layers, centres[i + k][axis], radius[i + k], values, stride,
                                        weight ? weight[i + k] : 1.0);
      }
    }
  }
  _mm256_zeroupper();
  for (; i < n; ++i)
    outside += add_sphere_to_layers(layers, centres[i][axis], radius[i], values, stride, weight ? weight[i] : 1.0);
  return outside;
}

// cells_deposit of n spheres in turn, four at a time sorting out in vectors, by the same operations as
// touched(), cells_deposit and add_sphere_to_layers, those wholly inside one cell (most, where cells
// are wider than grains: 61 % in cost.py's cells scene), with their cell and volume, and those across
// one face between inner cells (33 %), with their two cells and the split of add_sphere_to_layers' fast
// path; the others take cells_deposit. Deposits go in sphere order, so the sums are the same as one
// by one.
SEDIMENT_TARGET_AVX2 double cells_deposit_avx2(const Grid &grid, const double (*centres)[3],
                                               const double *radius, const double *weight, int n,
                                               double *values, int stride)
{
  const double step[3] = {1.0, static_cast<double>(grid.axes[0].count),
                          static_cast<double>(grid.axes[0].count) * grid.axes[1].count};
  const double resolved = grid.resolved[0] + grid.resolved[1] + grid.resolved[2];
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  double outside = 0.0;
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d r = _mm256_loadu_pd(radius + i), half = below4(r, r);
    // per sphere: axes in one inner cell and across one face between inner cells, the first cell's
    // index, and along the crossing axis the index step and the part below the face
    __m256d within = zero, across = zero, cell = zero, next = zero, lower = zero;
    for (int d = 0; d < 3; ++d) {
      if (!grid.resolved[d]) continue;    // one cell along d
      const Layers &axis = grid.axes[d];
      const __m256d c = coordinates4(centres, i, d);
      __m256d first, last;
      touched4(axis, c, r, first, last);
      const __m256d inner = _mm256_and_pd(_mm256_cmp_pd(first, zero, _CMP_GE_OQ),
                                          _mm256_cmp_pd(last, _mm256_set1_pd(axis.count - 1), _CMP_LE_OQ));
      const __m256d same = _mm256_and_pd(inner, _mm256_cmp_pd(first, last, _CMP_EQ_OQ));
      const __m256d crossing = _mm256_and_pd(inner, _mm256_cmp_pd(_mm256_sub_pd(last, first), one, _CMP_EQ_OQ));
      within = _mm256_add_pd(within, _mm256_and_pd(same, one));
      across = _mm256_add_pd(across, _mm256_and_pd(crossing, one));
      cell = _mm256_add_pd(cell, _mm256_mul_pd(first, _mm256_set1_pd(step[d])));    // used where inner
      next = _mm256_add_pd(next, _mm256_and_pd(crossing, _mm256_set1_pd(step[d])));
      lower = _mm256_add_pd(lower, _mm256_and_pd(crossing, below_next_face4(axis, c, r, first, half)));
    }
    const __m256d all_within = _mm256_cmp_pd(within, _mm256_set1_pd(resolved), _CMP_EQ_OQ);
    const __m256d one_face = _mm256_and_pd(_mm256_cmp_pd(across, one, _CMP_EQ_OQ),
                                           _mm256_cmp_pd(within, _mm256_set1_pd(resolved - 1.0), _CMP_EQ_OQ));
    const int whole = _mm256_movemask_pd(all_within), split = _mm256_movemask_pd(one_face);
    alignas(32) double volume[4], below_face[4], both[4];
    alignas(16) int index[4], beyond[4];
    _mm256_store_pd(volume, _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(4.0 / 3.0 * pi), r), r), r));
    _mm256_store_pd(below_face, lower);
    _mm256_store_pd(both, _mm256_mul_pd(_mm256_set1_pd(2.0), half));    // add_sphere_to_layers' total
    _mm_store_si128(reinterpret_cast<__m128i *>(index), _mm256_cvttpd_epi32(cell));
    _mm_store_si128(reinterpret_cast<__m128i *>(beyond), _mm256_cvttpd_epi32(_mm256_add_pd(cell, next)));
    _mm256_zeroupper();    // before the SSE code, as in layers_deposit_avx2
    for (int k = 0; k < 4; ++k) {
      const double count = weight ? weight[i + k] : 1.0;
      if (whole >> k & 1) {
        values[index[k] * stride] += count * volume[k];
      } else if (split >> k & 1) {
        const double upper = both[k] - below_face[k];
        values[index[k] * stride] += count * below_face[k];
        values[beyond[k] * stride] += count * upper;
        double inside = 0.0;    // summed as add_sphere_to_layers sums it: the same outside
        inside += below_face[k];
        inside += upper;
        outside += both[k] - inside;
      } else {
        outside += cells_deposit(grid, centres[i + k], radius[i + k], values, stride, count);
      }
    }
  }
  _mm256_zeroupper();
  for (; i < n; ++i) outside += cells_deposit(grid, centres[i], radius[i], values, stride, weight ? weight[i] : 1.0);
  return outside;
}
#endif

}    // namespace

double add_spheres_to_grid(const Grid &grid, const double (*centres)[3], const double *radius,
                           const double *weight, int n, double *values, int stride)
{
  const Grid local = grid;    // a copy: the stores into values could otherwise change the grid
  double outside = 0.0;
  const int axis = layer_axis(local);
#ifdef SEDIMENT_GRID_AVX2
  // Four spheres at a time, on grids whose byte offsets an int holds (the compute's limit on its values
  // keeps them there)
  if (processor_has_avx2() && static_cast<double>(local.cells()) * stride * sizeof(double) < 0x1p31)
    return axis >= 0 ? layers_deposit_avx2(local.axes[axis], axis, centres, radius, weight, n, values, stride)
                     : cells_deposit_avx2(local, centres, radius, weight, n, values, stride);
#endif
  if (axis >= 0) {
    for (int i = 0; i < n; ++i)
      outside += add_sphere_to_layers(local.axes[axis], centres[i][axis], radius[i], values, stride,
                                      weight ? weight[i] : 1.0);
    return outside;
  }
  for (int i = 0; i < n; ++i)
    outside += cells_deposit(local, centres[i], radius[i], values, stride, weight ? weight[i] : 1.0);
  return outside;
}

}    // namespace sediment
