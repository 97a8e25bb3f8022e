// SPDX-License-Identifier: GPL-2.0-or-later
// Indices of layers and cells along the axes of a Grid, inline: what the deposit of spheres
// (concentration.cpp) and the read of the field at points (concentration_read.cpp) share, per atom.
#pragma once

#include "sediment/batch_math.hpp"
#include "sediment/concentration.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#define SEDIMENT_GRID_AVX2 1
#include <immintrin.h>
#endif

namespace sediment::grid_index {

inline int wrap(int k, int n)
{
  if (k >= 0 && k < n) return k;    // most indices: no integer division
  k %= n;
  return k < 0 ? k + n : k;
}

// floor(s) as an int, without the libm call or its emulation on processors before SSE4.1.
inline int floor_index(double s)
{
  const int t = static_cast<int>(s);
  return t - (s < t);
}

// The one resolved axis of a grid of layers, or -1: such a grid takes the one-axis functions, which
// give the same values without the per-axis bookkeeping of a grid of cells.
inline int layer_axis(const Grid &grid)
{
  const int resolved = grid.resolved[0] + grid.resolved[1] + grid.resolved[2];
  return resolved != 1 ? -1 : grid.resolved[0] ? 0 : grid.resolved[1] ? 1 : 2;
}

#ifdef SEDIMENT_GRID_AVX2
// Lanes whose whole number k (as a double) lies within 2^30 layers: those cast to int as they are.
SEDIMENT_TARGET_AVX2 inline __m256d within_reach4(__m256d k)
{
  return _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), k), _mm256_set1_pd(1 << 30), _CMP_LE_OQ);
}

// cell_of(axis, k) and cell_of(axis, k + 1) of a periodic axis for four whole numbers k within reach,
// without a branch: wrap() in doubles. With |k| and count below 2^31, k / count rounds on the right
// side of every whole number, so the floor and the rest are exact. (A branch on whether all four lie
// within the period, which most do at small steps, was mispredicted for a quarter of the groups at
// dt/tau = 1e4, where atoms outrun the neighbor skin and lie whole periods away between LAMMPS's
// remaps into the box.)
SEDIMENT_TARGET_AVX2 inline void periodic_cells4(const Layers &axis, __m256d k, __m256d &k0, __m256d &k1)
{
  const __m256d count = _mm256_set1_pd(axis.count);
  k0 = _mm256_sub_pd(k, _mm256_mul_pd(_mm256_floor_pd(_mm256_div_pd(k, count)), count));
  const __m256d next = _mm256_add_pd(k0, _mm256_set1_pd(1.0));
  k1 = _mm256_blendv_pd(next, _mm256_setzero_pd(), _mm256_cmp_pd(next, count, _CMP_EQ_OQ));    // n wraps to 0
}

// Coordinate d of rows i to i + 3.
SEDIMENT_TARGET_AVX2 inline __m256d coordinates4(const double (*rows)[3], int i, int d)
{
  return _mm256_set_pd(rows[i + 3][d], rows[i + 2][d], rows[i + 1][d], rows[i][d]);
}
#endif

}    // namespace sediment::grid_index
