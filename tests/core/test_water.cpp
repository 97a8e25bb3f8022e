// SPDX-License-Identifier: GPL-2.0-or-later
// Water at the laboratory's temperature against published tables (docs/physics.md 2.2).
#include "sediment/water.hpp"

#include <gtest/gtest.h>

using namespace sediment;

TEST(Water, DensityAsTanakaEtAlTabulate)
{
  // Tanaka et al. (2001), Table 4 (air-free water, 101.325 kPa).
  EXPECT_NEAR(water_density(4.0), 999.9750, 1e-3);
  EXPECT_NEAR(water_density(20.0), 998.2067, 1e-3);
  EXPECT_NEAR(water_density(40.0), 992.2152, 1e-3);
  EXPECT_GT(water_density(4.0), water_density(0.0));    // the maximum near 4 C
  EXPECT_GT(water_density(4.0), water_density(8.0));
}

TEST(Water, ViscosityWithinATenthOfAPercentOfIapws)
{
  // IAPWS 2008 at 101.325 kPa [mPa s].
  const double table[][2] = {{0.0, 1.7914}, {4.0, 1.5673}, {10.0, 1.3059}, {20.0, 1.0016},
                             {25.0, 0.8900}, {30.0, 0.7972}, {40.0, 0.6527}};
  for (const auto &row : table) EXPECT_NEAR(water_viscosity(row[0]) * 1e3, row[1], 1e-3 * row[1]) << row[0];
  // About 2.5 % per degree near 20 C: what a reading's temperature is worth.
  EXPECT_NEAR(water_viscosity(19.0) / water_viscosity(20.0) - 1.0, 0.025, 0.002);
}
