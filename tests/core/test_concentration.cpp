// Exact sphere volume per layer (sedimentation-tests.md section 2).
#include "sediment/concentration.hpp"
#include "sediment/geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
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
