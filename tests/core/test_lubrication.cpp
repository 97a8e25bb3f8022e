// SPDX-License-Identifier: GPL-2.0-or-later
// Squeeze-film coefficient, Bravo et al. repulsion and the damping cap (docs/physics.md section 5).
#include "sediment/geometry.hpp"
#include "sediment/lubrication.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace sediment;

TEST(Lubrication, ReynoldsCoefficientBetweenTheCutoffs)
{
  const LubricationRange range{0.01, 0.5};
  const double mu = 1e-3, r = 5e-5, a = r / 2;
  EXPECT_DOUBLE_EQ(effective_radius(r, r), a);
  EXPECT_NEAR(squeeze_coefficient(mu, r, r, 0.1 * a, range), 6 * pi * mu * a * a / (0.1 * a), 1e-20);
  // frozen below the inner cutoff, even at overlap; none from the outer cutoff on
  EXPECT_DOUBLE_EQ(squeeze_coefficient(mu, r, r, 0.001 * a, range), squeeze_coefficient(mu, r, r, 0.01 * a, range));
  EXPECT_DOUBLE_EQ(squeeze_coefficient(mu, r, r, -0.1 * a, range), squeeze_coefficient(mu, r, r, 0.01 * a, range));
  EXPECT_EQ(squeeze_coefficient(mu, r, r, 0.5 * a, range), 0.0);
  // unequal spheres use a = r_i r_j / (r_i + r_j), symmetric in i and j
  EXPECT_DOUBLE_EQ(squeeze_coefficient(mu, r, 3 * r, 1e-6, range), squeeze_coefficient(mu, 3 * r, r, 1e-6, range));
}

TEST(Lubrication, BravoRepulsion)
{
  EXPECT_DOUBLE_EQ(bravo_repulsion(1.0, 1.0, 0.0), 10.0);
  EXPECT_NEAR(bravo_repulsion(1.0, 1.0, 0.1), 10.0 * std::exp(-1.0), 1e-14);
  // on the larger sphere q > 1: stronger at contact, longer reach
  EXPECT_NEAR(bravo_repulsion(3.0, 1.0, 0.0), 10.0 * 1.5 * 1.5 * 1.5, 1e-12);
  EXPECT_NEAR(bravo_repulsion(1.0, 3.0, 0.0), 10.0 * 0.125, 1e-14);
}

TEST(Lubrication, DampingShareCapsOnlyWhatWouldOvershoot)
{
  EXPECT_EQ(damping_share(1e-6, 1.0, 1.0, 1.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(damping_share(1.0, 1.0, 2.0, 1.0, 1.0), 0.25);    // m_i / (2 dt S_i)
  EXPECT_DOUBLE_EQ(damping_share(1.0, 4.0, 1.0, 1.0, 4.0), 0.125);   // the stricter sphere sets it
}

TEST(Lubrication, BravoRepulsionIsCutAtAThousandthOfItsContactValue)
{
  const double reach = bravo_reach(1.0, 1.0);
  EXPECT_NEAR(reach, std::log(1000.0) / 10.0, 1e-15);
  // just inside: 1e-3 of the contact value, raised by exp(0.01 reach) = 1.007
  EXPECT_NEAR(bravo_repulsion(1.0, 1.0, 0.999 * reach), 1e-3 * bravo_repulsion(1.0, 1.0, 0.0) * std::exp(0.01 * reach), 1e-12);
  EXPECT_EQ(bravo_repulsion(1.0, 1.0, reach), 0.0);
  EXPECT_NEAR(bravo_reach(1.0, 0.0), 2.0 * std::log(1000.0) / 10.0, 1e-15);    // q -> 2
}
