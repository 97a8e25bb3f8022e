// SPDX-License-Identifier: GPL-2.0-or-later
// Exact sphere volume per layer (docs/sedimentation-tests.md section 2).
#include "sediment/concentration.hpp"
#include "sediment/geometry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

using namespace sediment;

TEST(Layers, SlabVolumeMatchesCapFormula)
{
  const double r = 2.0;
  EXPECT_NEAR(sphere_slab_volume(0.0, r, -5, 5), 4.0 / 3.0 * pi * 8.0, 1e-12);
  EXPECT_NEAR(sphere_slab_volume(0.0, r, -5, 0), 2.0 / 3.0 * pi * 8.0, 1e-12);
  const double h = 0.7;    // cap of height h at the top
  EXPECT_NEAR(sphere_slab_volume(0.0, r, r - h, 10), pi * h * h * (3 * r - h) / 3, 1e-12);
  EXPECT_EQ(sphere_slab_volume(0.0, r, 3, 4), 0.0);
}

TEST(Layers, ThinLayersConserveVolumeAndFollowTheDiscArea)
{
  const Layers layers{0.0, 1e-3, 1000};
  std::vector<double> values(1000, 0.0);
  const double r = 0.05, c = 0.3217;
  const double outside = add_sphere_to_layers(layers, c, r, values.data());
  double sum = 0.0;
  for (double v : values) sum += v;
  const double total = 4.0 / 3.0 * pi * r * r * r;
  EXPECT_NEAR(outside, total - sum, 1e-15 * total);
  EXPECT_NEAR(sum, total, 1e-15 * total);
  // A layer through the centre holds about pi r^2 h.
  EXPECT_NEAR(values[321], pi * r * r * 1e-3, 1e-3 * pi * r * r * 1e-3);
}

TEST(Layers, SphereCutByTheEndsKeepsOnlyTheInsidePart)
{
  const Layers layers{0.0, 0.1, 10};
  std::vector<double> values(10, 0.0);
  const double r = 0.05;
  const double outside = add_sphere_to_layers(layers, 0.0, r, values.data());
  EXPECT_NEAR(outside, 2.0 / 3.0 * pi * r * r * r, 1e-18);
  EXPECT_NEAR(values[0], 2.0 / 3.0 * pi * r * r * r, 1e-18);
  std::vector<double> none(10, 0.0);
  EXPECT_NEAR(add_sphere_to_layers(layers, 5.0, r, none.data()), 4.0 / 3.0 * pi * r * r * r, 1e-18);
}

TEST(Layers, StrideWritesIntoOneColumn)
{
  const Layers layers{0.0, 1.0, 3};
  std::vector<double> table(9, 0.0);
  add_sphere_to_layers(layers, 1.5, 0.4, table.data() + 2, 3);
  EXPECT_GT(table[5], 0.0);
  EXPECT_EQ(table[3] + table[4], 0.0);
}

TEST(Layers, ProfileInterpolatesBetweenCentres)
{
  const Layers layers{0.0, 1.0, 3};
  const double values[3] = {1.0, 3.0, 7.0};
  EXPECT_DOUBLE_EQ(profile_at(layers, values, 0.5), 1.0);
  EXPECT_DOUBLE_EQ(profile_at(layers, values, 1.0), 2.0);
  EXPECT_DOUBLE_EQ(profile_at(layers, values, 2.25), 6.0);
  EXPECT_DOUBLE_EQ(profile_at(layers, values, -3.0), 1.0);
  EXPECT_DOUBLE_EQ(profile_at(layers, values, 9.0), 7.0);
}

TEST(Layers, SmoothingKeepsUniformProfilesConservesAndSpreadsASpike)
{
  const Layers layers{0.0, 1.0, 50};
  std::vector<double> flat(50, 0.3), out(50);
  smooth_profile(layers, flat.data(), 2.0, out.data());
  for (double v : out) EXPECT_NEAR(v, 0.3, 1e-15);
  std::vector<double> spike(50, 0.0);
  spike[25] = 1.0;
  smooth_profile(layers, spike.data(), 2.0, out.data());
  EXPECT_NEAR(out[25] / out[27], std::exp(0.5), 1e-12);
  // A deposit against an end keeps its total (what would leave is reflected back).
  std::vector<double> deposit(50, 0.0);
  deposit[0] = 0.6;
  deposit[1] = 0.2;
  smooth_profile(layers, deposit.data(), 3.0, out.data());
  double total = 0.0;
  for (double v : out) total += v;
  EXPECT_NEAR(total, 0.8, 1e-15);
  // Wider than the whole profile: still conservative and uniform-preserving.
  const Layers few{0.0, 1.0, 3};
  const double three[3] = {1.0, 0.0, 0.0};
  double smoothed[3];
  smooth_profile(few, three, 5.0, smoothed);
  EXPECT_NEAR(smoothed[0] + smoothed[1] + smoothed[2], 1.0, 1e-15);
}

namespace {

double sum(const std::vector<double> &values)
{
  double total = 0.0;
  for (double v : values) total += v;
  return total;
}

Grid cube_grid(double lo, double spacing, int n, bool periodic = false)
{
  const Layers axis{lo, spacing, n, periodic};
  return Grid{{axis, axis, axis}, {true, true, true}};
}

}    // namespace

TEST(Grid, PeriodicLayersWrapTheOverhang)
{
  const Layers ring{0.0, 0.1, 10, true};
  std::vector<double> values(10, 0.0);
  const double r = 0.05;
  EXPECT_NEAR(add_sphere_to_layers(ring, 0.01, r, values.data()), 0.0, 1e-18);
  EXPECT_NEAR(values[9], sphere_slab_volume(0.01, r, -0.1, 0.0), 1e-18);
  EXPECT_NEAR(values[0], sphere_slab_volume(0.01, r, 0.0, 0.1), 1e-18);
  const double wrapped[10] = {2.0, 0, 0, 0, 0, 0, 0, 0, 0, 4.0};
  EXPECT_DOUBLE_EQ(profile_at(ring, wrapped, 1.0), 3.0);    // between the last and the first centre
}

TEST(Grid, SphereOnAVertexGivesAnEighthToEachCell)
{
  const Grid grid = cube_grid(-1.0, 1.0, 2);
  std::vector<double> values(8, 0.0);
  const double centre[3] = {0.0, 0.0, 0.0}, r = 0.4, total = 4.0 / 3.0 * pi * r * r * r;
  EXPECT_NEAR(add_sphere_to_grid(grid, centre, r, values.data()), 0.0, 1e-15 * total);
  for (double v : values) EXPECT_NEAR(v, total / 8.0, 1e-14 * total);
}

TEST(Grid, CellsOfAColumnAddUpToTheSlabVolume)
{
  // Crossing x and y faces: the cells of an x column must add up to the layer formula's slab.
  const Grid grid{{{0.0, 0.3, 4}, {0.0, 0.3, 4}, {0.0, 2.0, 1}}, {true, true, true}};
  std::vector<double> values(16, 0.0);
  const double centre[3] = {0.61, 0.52, 1.0}, r = 0.35;
  add_sphere_to_grid(grid, centre, r, values.data());
  for (int i = 0; i < 4; ++i) {
    double column = 0.0;
    for (int j = 0; j < 4; ++j) column += values[i + 4 * j];
    const double exact = sphere_slab_volume(centre[0], r, 0.3 * i, 0.3 * (i + 1));
    EXPECT_NEAR(column, exact, 1e-14 * 4.0 / 3.0 * pi * r * r * r) << "x cell " << i;
  }
}

TEST(Grid, CoarseCellsAgreeWithTheirRefinedSubcellsAndVolumeIsConserved)
{
  // Two independent splits (different kinks and integration slabs) of the same sphere.
  const double centre[3] = {0.437, 0.331, 0.612}, r = 0.29, total = 4.0 / 3.0 * pi * r * r * r;
  const Grid coarse = cube_grid(0.0, 0.25, 4), fine = cube_grid(0.0, 0.0625, 16);
  std::vector<double> coarse_values(64, 0.0), fine_values(4096, 0.0);
  EXPECT_NEAR(add_sphere_to_grid(coarse, centre, r, coarse_values.data()), 0.0, 1e-15 * total);
  EXPECT_NEAR(add_sphere_to_grid(fine, centre, r, fine_values.data()), 0.0, 1e-14 * total);
  EXPECT_NEAR(sum(coarse_values), total, 1e-14 * total);
  EXPECT_NEAR(sum(fine_values), total, 1e-14 * total);
  double worst = 0.0;
  for (int cell = 0; cell < 64; ++cell) {
    const int i = cell % 4, j = cell / 4 % 4, k = cell / 16;
    double refined = 0.0;
    for (int sub = 0; sub < 64; ++sub)
      refined += fine_values[(4 * i + sub % 4) + 16 * ((4 * j + sub / 4 % 4) + 16 * (4 * k + sub / 16))];
    worst = std::max(worst, std::abs(refined - coarse_values[cell]) / total);
  }
  EXPECT_LT(worst, 1e-14);
  std::printf("coarse vs refined cells: worst difference %.2e of the sphere volume\n", worst);
}

TEST(Grid, AWeightedSphereCountsAsThatManySpheresInEveryPath)
{
  // Inside one cell, sliced along one axis, and split along three: each adds weight x its volume;
  // the volume returned as outside is the sphere's own.
  const double r = 0.05, weight = 2.5e7, total = 4.0 / 3.0 * pi * r * r * r;
  const Grid grid = cube_grid(0.0, 0.1, 10);
  for (const double shift : {0.05, 0.1, 0.0}) {
    const double centre[3] = {0.45, 0.45, 0.45 + shift};
    const double at_edge[3] = {shift, 0.5, 0.5};
    std::vector<double> one(1000, 0.0), many(1000, 0.0);
    add_sphere_to_grid(grid, centre, r, one.data());
    EXPECT_NEAR(add_sphere_to_grid(grid, centre, r, many.data(), 1, weight), 0.0, 1e-15 * total);
    for (int cell = 0; cell < 1000; ++cell) EXPECT_NEAR(many[cell], weight * one[cell], 1e-15 * weight * total);
    std::vector<double> clipped(1000, 0.0);
    const double outside = add_sphere_to_grid(grid, at_edge, r, clipped.data(), 1, weight);
    EXPECT_NEAR(sum(clipped), weight * (total - outside), 1e-14 * weight * total);
  }
}

TEST(Grid, OuterFacesClipUnlessPeriodic)
{
  // Centred on the x = lo and z = hi faces: a quarter of the sphere is inside the bounded grid.
  const double centre[3] = {0.0, 0.5, 1.0}, r = 0.05, total = 4.0 / 3.0 * pi * r * r * r;
  std::vector<double> bounded(1000, 0.0), periodic(1000, 0.0);
  const double outside = add_sphere_to_grid(cube_grid(0.0, 0.1, 10), centre, r, bounded.data());
  EXPECT_NEAR(sum(bounded), total - outside, 1e-15 * total);
  EXPECT_NEAR(sum(bounded), 0.25 * total, 1e-14 * total);
  EXPECT_NEAR(add_sphere_to_grid(cube_grid(0.0, 0.1, 10, true), centre, r, periodic.data()), 0.0, 1e-14 * total);
  EXPECT_NEAR(sum(periodic), total, 1e-14 * total);
  EXPECT_NEAR(periodic[9 + 10 * (4 + 10 * 0)], total / 8.0, 1e-14 * total);    // wrapped to x = hi, z = lo
}

TEST(Grid, InterpolatesTrilinearlyAndSmoothsConservatively)
{
  const Grid grid = cube_grid(0.0, 1.0, 3);
  std::vector<double> values(27);
  for (int cell = 0; cell < 27; ++cell) values[cell] = cell % 3 + 10.0 * (cell / 3 % 3) + 100.0 * (cell / 9);
  const double point[3] = {1.25, 0.75, 2.0};    // a linear field is reproduced between centres
  EXPECT_NEAR(grid_value_at(grid, values.data(), point), 0.75 + 10.0 * 0.25 + 100.0 * 1.5, 1e-12);
  std::vector<double> scratch(3), smoothed = values;
  smooth_grid(grid, smoothed.data(), 0.8, scratch.data());
  EXPECT_NEAR(sum(smoothed), sum(values), 1e-12 * sum(values));
  std::vector<double> flat(27, 0.25);
  smooth_grid(grid, flat.data(), 2.0, scratch.data());
  for (double v : flat) EXPECT_NEAR(v, 0.25, 1e-15);
}

TEST(Grid, InterpolatesAcrossPeriodicFacesAndAlongUnresolvedAxes)
{
  // x not resolved (one cell), y bounded, z periodic: 1 x 3 x 3 cells of unit size.
  const Layers one{0.0, 5.0, 1}, bounded{0.0, 1.0, 3}, ring{0.0, 1.0, 3, true};
  const Grid grid{{one, bounded, ring}, {false, true, true}};
  std::vector<double> values(9);
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) values[j + 3 * k] = 10.0 * j + 100.0 * k;
  // z = 0.25 lies a quarter layer below the first centre: 0.25 of the last layer, 0.75 of the first.
  const double wrapped[3] = {4.0, 1.25, 0.25};
  EXPECT_NEAR(grid_value_at(grid, values.data(), wrapped), 7.5 + 0.25 * 200.0, 1e-12);
  // Beyond the outer centre of the bounded y axis the value is flat; x has no say.
  const double flat[3] = {-7.0, 2.9, 1.5};
  EXPECT_NEAR(grid_value_at(grid, values.data(), flat), 20.0 + 100.0, 1e-12);
}

TEST(Grid, ACornerCellMatchesDirectIntegrationOfChords)
{
  // Independent of the closed form: integrate the x chord of the sphere inside the cell over a
  // fine midpoint grid in y and z (error ~1e-6 from the disc edge).
  const Grid grid = cube_grid(0.0, 0.2, 5);
  std::vector<double> values(125, 0.0);
  const double centre[3] = {0.47, 0.33, 0.55}, r = 0.23;
  add_sphere_to_grid(grid, centre, r, values.data());
  const int i = 2, j = 1, k = 3;    // x in [0.4, 0.6], y in [0.2, 0.4], z in [0.6, 0.8]
  const int n = 2000;
  double direct = 0.0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const double y = 0.2 * j + 0.2 * (a + 0.5) / n - centre[1], z = 0.2 * k + 0.2 * (b + 0.5) / n - centre[2];
      const double half = std::sqrt(std::max(0.0, r * r - y * y - z * z));
      const double lo = std::max(0.2 * i - centre[0], -half), hi = std::min(0.2 * (i + 1) - centre[0], half);
      direct += std::max(0.0, hi - lo);
    }
  direct *= 0.04 / (static_cast<double>(n) * n);
  EXPECT_NEAR(values[i + 5 * (j + 5 * k)], direct, 1e-5 * direct);
}

TEST(Grid, ManySpheresAtOnceAreTheSpheresOneByOne)
{
  // add_spheres_to_grid and grid_values_at, which compute concentration/grid calls for group all,
  // give bit for bit what add_sphere_to_grid and grid_value_at give one sphere at a time: on layers
  // and on cells, bounded and periodic, spheres inside, across faces and edges, partly and far
  // outside (the read goes four points at a time where the processor has AVX2).
  const Layers one{0.0, 1.0, 1}, column{0.0, 0.1, 10, true}, bounded_column{0.0, 0.1, 10};
  const std::vector<Grid> grids = {Grid{{one, one, column}, {false, false, true}},
                                   Grid{{one, one, bounded_column}, {false, false, true}}, cube_grid(0.0, 0.1, 10),
                                   cube_grid(0.0, 0.1, 10, true)};
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> coordinate(-0.05, 1.05), size(0.005, 0.12), count(0.5, 3.0);
  const int n = 500;
  const auto rows = std::make_unique<double[][3]>(n);    // one block, as LAMMPS keeps positions
  std::vector<double> radius(n), weight(n);
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) rows[i][d] = coordinate(random);
    radius[i] = size(random);
    weight[i] = count(random);
  }
  // Some far outside along one axis: beyond the flat ends, or periods away along a periodic axis.
  for (int i = 0; i < 12; ++i) rows[7 * i][i % 3] += i % 2 ? 3.3 : -4.7;
  for (const Grid &grid : grids) {
    for (const double *weights : {static_cast<const double *>(nullptr), static_cast<const double *>(weight.data())}) {
      // Two columns, as the compute interleaves them: the batch fills the second.
      std::vector<double> alone(2 * grid.cells(), 0.0), together(2 * grid.cells(), 0.0);
      double outside_alone = 0.0;
      for (int i = 0; i < n; ++i)
        outside_alone += add_sphere_to_grid(grid, rows[i], radius[i], alone.data() + 1, 2, weights ? weights[i] : 1.0);
      const double outside = add_spheres_to_grid(grid, rows.get(), radius.data(), weights, n, together.data() + 1, 2);
      EXPECT_EQ(outside, outside_alone);
      ASSERT_EQ(together, alone);

      std::vector<double> read(n);
      grid_values_at(grid, alone.data() + 1, rows.get(), n, read.data(), 2);
      for (int i = 0; i < n; ++i) EXPECT_EQ(read[i], grid_value_at(grid, alone.data() + 1, rows[i], 2)) << "sphere " << i;
    }
  }
}

TEST(Grid, ManySpheresWholePeriodsAwayLandInTheirLayers)
{
  // On 49 periodic layers of thickness 1, k / 49 is a whole number m for a sphere whose lowest point
  // lies in layer 49 m; a wrap through k times the rounded 1 / 49 would come out just under m for most
  // m, one period off (tried). The vector deposit must give layer 0 as the scalar wrap does, and the
  // read, layers 48 and 0 around centres in the first half of layer 0.
  const Layers periodic{0.0, 1.0, 49, true};
  const Grid grid{{Layers{0.0, 1.0, 1}, Layers{0.0, 1.0, 1}, periodic}, {false, false, true}};
  const int n = 2 * 40 * 4;
  const auto rows = std::make_unique<double[][3]>(n);
  std::vector<double> radius(n);
  for (int i = 0; i < n; ++i) {
    const int m = i / 4 % 40 - 20;    // -20 to 19 periods away
    rows[i][0] = rows[i][1] = 0.5;
    rows[i][2] = 49.0 * m + (i < n / 2 ? 0.55 : 0.95);    // inside layer 49 m, or across into 49 m + 1
    radius[i] = i < n / 2 ? 0.3 : 0.25 + 0.01 * (i % 4);
  }
  std::vector<double> alone(grid.cells(), 0.0), together(grid.cells(), 0.0);
  double outside_alone = 0.0;
  for (int i = 0; i < n; ++i) outside_alone += add_sphere_to_grid(grid, rows[i], radius[i], alone.data());
  EXPECT_EQ(add_spheres_to_grid(grid, rows.get(), radius.data(), nullptr, n, together.data()), outside_alone);
  ASSERT_EQ(together, alone);
  EXPECT_GT(alone[0], 0.0);
  EXPECT_GT(alone[1], 0.0);

  std::vector<double> read(n);
  grid_values_at(grid, alone.data(), rows.get(), n, read.data());
  for (int i = 0; i < n; ++i) EXPECT_EQ(read[i], grid_value_at(grid, alone.data(), rows[i])) << "sphere " << i;
}

TEST(Grid, ASphereAcrossOneFaceInEachOfTwoOrThreeAxesAgreesWithRefinedCells)
{
  // On cells of 0.25 each sphere crosses one face along two axes and none along the third (its four
  // cells from one quarter volume), or one along each of the three (its eight from three quarter
  // volumes and a corner volume); on cells of 0.0625 it crosses several along all three (the
  // vertices' inclusion-exclusion). Inside, across an outer face of a bounded grid (the part beyond
  // is outside), and across a periodic one (it wraps).
  struct Case {
    double centre[3];
    bool periodic;
  };
  const double r = 0.1, total = 4.0 / 3.0 * pi * r * r * r;
  for (const Case &c : {Case{{0.27, 0.52, 0.62}, false}, Case{{0.45, 0.97, 0.125}, false},
                        Case{{0.03, 0.55, 0.375}, true}, Case{{0.27, 0.52, 0.73}, false},
                        Case{{0.95, 0.48, 0.27}, false}, Case{{0.03, 0.74, 0.52}, true}}) {
    const Grid coarse = cube_grid(0.0, 0.25, 4, c.periodic), fine = cube_grid(0.0, 0.0625, 16, c.periodic);
    std::vector<double> coarse_values(64, 0.0), fine_values(4096, 0.0);
    const double outside = add_sphere_to_grid(coarse, c.centre, r, coarse_values.data());
    EXPECT_NEAR(outside, add_sphere_to_grid(fine, c.centre, r, fine_values.data()), 1e-14 * total);
    EXPECT_NEAR(sum(coarse_values), total - outside, 1e-14 * total);
    for (int cell = 0; cell < 64; ++cell) {
      const int i = cell % 4, j = cell / 4 % 4, k = cell / 16;
      double refined = 0.0;
      for (int sub = 0; sub < 64; ++sub)
        refined += fine_values[(4 * i + sub % 4) + 16 * ((4 * j + sub / 4 % 4) + 16 * (4 * k + sub / 16))];
      EXPECT_NEAR(coarse_values[cell], refined, 1e-14 * total) << "cell " << cell;
    }
  }
}
