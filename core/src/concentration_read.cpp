// SPDX-License-Identifier: GPL-2.0-or-later
// The concentration field read back: its value at points (linear between layer and cell centres, four
// points at a time with AVX2) and its smoothing. The deposit of spheres: concentration.cpp.
#include "sediment/concentration.hpp"

#include "sediment/batch_math.hpp"
#include "sediment/grid_index.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sediment {

using namespace grid_index;

namespace {

struct Bracket {
  int k0, k1;
  double w;    // weight of k1
};

// The two layer centres around x and the linear weight between them (inline: three calls per atom
// and step in the trilinear read of 3d cells).
[[gnu::always_inline]] inline Bracket bracket(const Layers &axis, double x)
{
  const double s = (x - axis.lo) * axis.per_thickness - 0.5;    // in layers from the first centre
  if (axis.periodic) {
    const int k0 = floor_index(s);
    return {wrap(k0, axis.count), wrap(k0 + 1, axis.count), s - k0};
  }
  if (s <= 0.0) return {0, 0, 0.0};
  if (s >= axis.count - 1) return {axis.count - 1, axis.count - 1, 0.0};
  const int k = static_cast<int>(s);
  return {k, k + 1, s - k};
}

// profile_at, inline in the loop that reads many points.
[[gnu::always_inline]] inline double layers_value_at(const Layers &layers, const double *values, double x, int stride)
{
  const Bracket at = bracket(layers, x);
  return (1.0 - at.w) * values[at.k0 * stride] + at.w * values[at.k1 * stride];
}

}    // namespace

double profile_at(const Layers &layers, const double *values, double x, int stride)
{
  return layers_value_at(layers, values, x, stride);
}

void smooth_profile(const Layers &layers, const double *values, double width, double *out, int stride)
{
  // Each layer's content is spread over its neighbours with Gaussian weights that sum to one;
  // what would leave through an end is reflected back in (mirror ends) or comes in at the other
  // (periodic). So the total is conserved exactly and a uniform profile stays uniform.
  const int n = layers.count;
  const int reach = static_cast<int>(std::ceil(4.0 * width / layers.thickness));
  std::vector<double> kernel(reach + 1);
  double norm = 0.0;
  for (int m = 0; m <= reach; ++m) {
    const double x = m * layers.thickness / width;
    kernel[m] = std::exp(-0.5 * x * x);
    norm += m == 0 ? kernel[m] : 2.0 * kernel[m];
  }
  const bool periodic = layers.periodic;
  auto fold = [n, periodic](int t) {
    if (periodic) return wrap(t, n);
    while (t < 0 || t >= n) t = t < 0 ? -t - 1 : 2 * n - t - 1;
    return t;
  };
  std::fill(out, out + n, 0.0);
  for (int j = 0; j < n; ++j) {
    const double value = values[j * stride];
    if (value == 0.0) continue;
    const double share = value / norm;
    for (int m = -reach; m <= reach; ++m) out[fold(j + m)] += share * kernel[std::abs(m)];
  }
}

namespace {

// grid_value_at on a grid of cells (not layers), inline in the loops that read many points.
[[gnu::always_inline]] inline double cells_value_at(const Grid &grid, const double *values, const double point[3],
                                                    int stride)
{
  Bracket at[3];
  for (int d = 0; d < 3; ++d) at[d] = grid.resolved[d] ? bracket(grid.axes[d], point[d]) : Bracket{0, 0, 0.0};
  // Linear along x on the four edges around the point, then along y, then along z: no branch per
  // corner (an axis not resolved has k0 = k1 = 0 and weight 0, so it reads its one cell twice).
  // Indices become offsets into values once per axis, not once per corner.
  const int step_y = grid.axes[0].count * stride, step_z = step_y * grid.axes[1].count;
  const int x0 = at[0].k0 * stride, x1 = at[0].k1 * stride;
  auto along_x = [&](int offset) {
    const double *row = values + offset;
    return (1.0 - at[0].w) * row[x0] + at[0].w * row[x1];
  };
  auto along_y = [&](int offset) {
    return (1.0 - at[1].w) * along_x(offset + at[1].k0 * step_y) + at[1].w * along_x(offset + at[1].k1 * step_y);
  };
  return (1.0 - at[2].w) * along_y(at[2].k0 * step_z) + at[2].w * along_y(at[2].k1 * step_z);
}

}    // namespace

double grid_value_at(const Grid &grid, const double *values, const double point[3], int stride)
{
  if (const int axis = layer_axis(grid); axis >= 0) return profile_at(grid.axes[axis], values, point[axis], stride);
  return cells_value_at(grid, values, point, stride);
}

namespace {

// grid_value_at of points[i], i < n, one by one (what the vector read leaves, and all of it without AVX2).
void values_at_one_by_one(const Grid &grid, int axis, const double *values, const double (*points)[3], int first,
                          int n, double *out, int stride)
{
  if (axis >= 0)
    for (int i = first; i < n; ++i) out[i] = layers_value_at(grid.axes[axis], values, points[i][axis], stride);
  else
    for (int i = first; i < n; ++i) out[i] = cells_value_at(grid, values, points[i], stride);
}

#ifdef SEDIMENT_GRID_AVX2
// bracket() of four coordinates along an axis: the two centres' indices (whole numbers, as doubles)
// and the weight of the second, by the same operations, so the same values. False when a lane is NaN
// or further than 2^30 layers away: the caller reads those four points one by one.
SEDIMENT_TARGET_AVX2 inline bool brackets4(const Layers &axis, __m256d x, __m256d &k0, __m256d &k1,
                                           __m256d &w)
{
  const __m256d s = _mm256_sub_pd(
      _mm256_mul_pd(_mm256_sub_pd(x, _mm256_set1_pd(axis.lo)), _mm256_set1_pd(axis.per_thickness)),
      _mm256_set1_pd(0.5));
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), last = _mm256_set1_pd(axis.count - 1);
  if (axis.periodic) {
    const __m256d k = _mm256_floor_pd(s);
    w = _mm256_sub_pd(s, k);
    if (_mm256_movemask_pd(within_reach4(k)) != 0xF) return false;
    periodic_cells4(axis, k, k0, k1);
    return true;
  }
  if (_mm256_movemask_pd(_mm256_cmp_pd(s, s, _CMP_ORD_Q)) != 0xF) return false;
  // Flat beyond the outer centres: index 0 at or below the first, count - 1 at or past the last.
  const __m256d high = _mm256_cmp_pd(s, last, _CMP_GE_OQ);
  const __m256d ends = _mm256_or_pd(_mm256_cmp_pd(s, zero, _CMP_LE_OQ), high), end = _mm256_and_pd(high, last);
  const __m256d k = _mm256_round_pd(s, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
  w = _mm256_blendv_pd(_mm256_sub_pd(s, k), zero, ends);
  k0 = _mm256_blendv_pd(k, end, ends);
  k1 = _mm256_blendv_pd(_mm256_add_pd(k, one), end, ends);
  return true;
}

// (1 - w) a + w b, lane by lane, as the scalar read computes it.
SEDIMENT_TARGET_AVX2 inline __m256d between(__m256d a, __m256d b, __m256d w)
{
  return _mm256_add_pd(_mm256_mul_pd(_mm256_sub_pd(_mm256_set1_pd(1.0), w), a), _mm256_mul_pd(w, b));
}

// values at four element offsets (whole numbers below 2^31, as doubles); the masked form with every
// lane on gathers the same, from a defined source (GCC 12 warns of the plain form's undefined one)
SEDIMENT_TARGET_AVX2 inline __m256d gather(const double *values, __m256d offset)
{
  const __m256d every_lane = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  return _mm256_mask_i32gather_pd(_mm256_setzero_pd(), values, _mm256_cvttpd_epi32(offset), every_lane, 8);
}

// Linear along x between the centres' values on the edge at `offset`, then along y between two such
// edges, as cells_value_at (lambdas would not take the target).
SEDIMENT_TARGET_AVX2 inline __m256d along_x(const double *values, __m256d offset, const __m256d lower[3],
                                            const __m256d upper[3], const __m256d w[3])
{
  return between(gather(values, _mm256_add_pd(offset, lower[0])), gather(values, _mm256_add_pd(offset, upper[0])),
                 w[0]);
}

SEDIMENT_TARGET_AVX2 inline __m256d along_y(const double *values, __m256d offset, const __m256d lower[3],
                                            const __m256d upper[3], const __m256d w[3])
{
  return between(along_x(values, _mm256_add_pd(offset, lower[1]), lower, upper, w),
                 along_x(values, _mm256_add_pd(offset, upper[1]), lower, upper, w), w[1]);
}

// grid_values_at four points at a time, bit for bit the scalar read: the corners' values gathered,
// the same operations lane by lane (no fused multiply-add in this target, so the same roundings).
// Layers take a loop of their own, without the bookkeeping of the axes they do not resolve.
SEDIMENT_TARGET_AVX2 void values_at_avx2(const Grid &grid, int axis, const double *values,
                                         const double (*points)[3], int n, double *out, int stride)
{
  int i = 0;
  if (axis >= 0) {
    const Layers &layers = grid.axes[axis];
    const __m256d step = _mm256_set1_pd(stride);
    for (; i + 4 <= n; i += 4) {
      __m256d lower, upper, w;
      if (!brackets4(layers, coordinates4(points, i, axis), lower, upper, w)) {
        values_at_one_by_one(grid, axis, values, points, i, i + 4, out, stride);
        continue;
      }
      _mm256_storeu_pd(out + i, between(gather(values, _mm256_mul_pd(lower, step)),
                                        gather(values, _mm256_mul_pd(upper, step)), w));
    }
  } else {
    const __m256d zero = _mm256_setzero_pd();
    const double step[3] = {static_cast<double>(stride), static_cast<double>(grid.axes[0].count) * stride,
                            static_cast<double>(grid.axes[0].count) * grid.axes[1].count * stride};
    for (; i + 4 <= n; i += 4) {
      __m256d lower[3], upper[3], w[3];    // per axis: the two centres' offsets into values, the weight
      bool in_common_range = true;
      for (int d = 0; d < 3; ++d) {
        if (!grid.resolved[d]) {
          lower[d] = upper[d] = w[d] = zero;
          continue;
        }
        if (!brackets4(grid.axes[d], coordinates4(points, i, d), lower[d], upper[d], w[d])) {
          in_common_range = false;
          break;
        }
        lower[d] = _mm256_mul_pd(lower[d], _mm256_set1_pd(step[d]));
        upper[d] = _mm256_mul_pd(upper[d], _mm256_set1_pd(step[d]));
      }
      if (!in_common_range) {
        values_at_one_by_one(grid, axis, values, points, i, i + 4, out, stride);
        continue;
      }
      _mm256_storeu_pd(out + i, between(along_y(values, lower[2], lower, upper, w),
                                        along_y(values, upper[2], lower, upper, w), w[2]));
    }
  }
  _mm256_zeroupper();    // GCC left the upper halves dirty at the return: the SSE code after it ran 2x slower
  values_at_one_by_one(grid, axis, values, points, i, n, out, stride);
}
#endif

}    // namespace

void grid_values_at(const Grid &grid, const double *values, const double (*points)[3], int n, double *out,
                    int stride)
{
  // A copy: a store into out could otherwise change the grid, for all the compiler knows, and every
  // point would load it anew.
  const Grid local = grid;
  const int axis = layer_axis(local);
#ifdef SEDIMENT_GRID_AVX2
  if (processor_has_avx2()) {    // four points at a time
    values_at_avx2(local, axis, values, points, n, out, stride);
    return;
  }
#endif
  values_at_one_by_one(local, axis, values, points, 0, n, out, stride);
}

void smooth_grid(const Grid &grid, double *values, double width, double *scratch, int stride)
{
  const int count[3] = {grid.axes[0].count, grid.axes[1].count, grid.axes[2].count};
  const int step[3] = {1, count[0], count[0] * count[1]};
  for (int d = 0; d < 3; ++d) {
    if (!grid.resolved[d] || count[d] < 2) continue;
    const int b = (d + 1) % 3, c = (d + 2) % 3;
    for (int j = 0; j < count[b]; ++j)
      for (int k = 0; k < count[c]; ++k) {
        double *line = values + (j * step[b] + k * step[c]) * stride;
        smooth_profile(grid.axes[d], line, width, scratch, step[d] * stride);
        for (int m = 0; m < count[d]; ++m) line[m * step[d] * stride] = scratch[m];
      }
  }
}

}    // namespace sediment
