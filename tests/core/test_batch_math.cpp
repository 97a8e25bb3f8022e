// SPDX-License-Identifier: GPL-2.0-or-later
// The batched exponentials and logarithms (sediment/batch_math.hpp), and the batched drag curves
// and phi functions built on them, against the one-value functions.
#include "sediment/batch_math.hpp"
#include "sediment/drag.hpp"
#include "sediment/integrator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

using namespace sediment;

namespace {

// Distance in units in the last place between two finite doubles of the same sign.
int64_t ulps(double a, double b)
{
  int64_t ia, ib;
  std::memcpy(&ia, &a, sizeof a);
  std::memcpy(&ib, &b, sizeof b);
  return ia > ib ? ia - ib : ib - ia;
}

std::vector<double> uniform(double lo, double hi, int n, unsigned seed)
{
  std::mt19937_64 random(seed);
  std::vector<double> out(n);
  for (double &x : out) x = std::uniform_real_distribution<double>(lo, hi)(random);
  return out;
}

}    // namespace

TEST(BatchMath, WithinFourUlpOfTheScalarFunctionsOnEveryKindHere)
{
  // exp over what the drag step and the hindrance meet (down to the underflow), log over 60 decades.
  const std::vector<double> exponents = uniform(-745.0, 10.0, 10001, 1);
  std::vector<double> logs_in = uniform(-70.0, 70.0, 10001, 2);
  for (double &x : logs_in) x = std::exp(x);
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    SCOPED_TRACE(batch_math_name(kind));
    std::vector<double> e(exponents.size()), l(logs_in.size());
    exp_many(exponents.data(), e.data(), static_cast<int>(e.size()), kind);
    log_many(logs_in.data(), l.data(), static_cast<int>(l.size()), kind);
    int64_t worst_exp = 0, worst_log = 0;
    for (size_t k = 0; k < e.size(); ++k) {
      // below e^-708 the result is subnormal and its precision is absolute, not relative
      if (exponents[k] > -708.0) worst_exp = std::max(worst_exp, ulps(e[k], std::exp(exponents[k])));
      else EXPECT_NEAR(e[k], std::exp(exponents[k]), 1e-320);
      worst_log = std::max(worst_log, ulps(l[k], std::log(logs_in[k])));
    }
    EXPECT_LE(worst_exp, 4);
    EXPECT_LE(worst_log, 4);
  }
}

TEST(BatchMath, SpecialValuesAsTheScalarFunctions)
{
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  // exp: 1, 1, inf, 0, nan, inf (overflow), 0 (underflow); log: -inf, -inf, inf, nan, nan, nan, 0
  const double exp_in[] = {0.0, -0.0, inf, -inf, nan, 1000.0, -1000.0};
  const double log_in[] = {0.0, -0.0, inf, -inf, nan, -1.0, 1.0};
  constexpr int n = 7;
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    SCOPED_TRACE(batch_math_name(kind));
    double e[n], l[n];
    exp_many(exp_in, e, n, kind);
    log_many(log_in, l, n, kind);
    for (int k = 0; k < n; ++k) {
      const double expected_exp = std::exp(exp_in[k]), expected_log = std::log(log_in[k]);
      if (std::isnan(expected_exp)) EXPECT_TRUE(std::isnan(e[k])) << exp_in[k];
      else EXPECT_EQ(e[k], expected_exp) << exp_in[k];
      if (std::isnan(expected_log)) EXPECT_TRUE(std::isnan(l[k])) << log_in[k];
      else EXPECT_EQ(l[k], expected_log) << log_in[k];
    }
  }
}

TEST(BatchMath, AValueDoesNotDependOnItsPlaceOrOnTheOthersInTheBatch)
{
  // What the integrator relies on for results independent of block and rank layout: the same value
  // at any position of a batch of any length gives the same bits, whatever its neighbours are.
  const std::vector<double> x = uniform(-20.0, 2.0, 7, 3);
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    SCOPED_TRACE(batch_math_name(kind));
    double alone[7];
    for (int k = 0; k < 7; ++k) exp_many(&x[k], &alone[k], 1, kind);
    for (int length = 1; length <= 7; ++length)
      for (int start = 0; start + length <= 7; ++start) {
        double out[7];
        exp_many(&x[start], out, length, kind);
        for (int k = 0; k < length; ++k) EXPECT_EQ(out[k], alone[start + k]) << "length " << length;
      }
    double in_place[7];
    std::copy(x.begin(), x.end(), in_place);
    exp_many(in_place, in_place, 7, kind);
    for (int k = 0; k < 7; ++k) EXPECT_EQ(in_place[k], alone[k]);
  }
}

TEST(BatchMath, PhisManyFollowPhisOnBothSidesOfTheSeriesAndTheUnderflow)
{
  std::vector<double> z = uniform(-0.6, 4.0, 2000, 4);
  for (double extra : {0.0, -0.0, 0.5, 1e-12, 707.9, 708.0, 708.1, 745.0, 745.3, 5000.0, 1e-300}) z.push_back(extra);
  // every count of the series' terms, on both sides of its limits (6 below 2^-9, 8, 10, 12 and 14 below
  // 2^-6, 2^-4, 2^-3 and 2^-2, 16 below 1/2)
  for (double limit : {0x1p-9, 0x1p-6, 0x1p-4, 0x1p-3, 0x1p-2, 0.5})
    for (double extra : {limit, std::nextafter(limit, 0.0), -std::nextafter(limit, 0.0), 0.7 * limit})
      z.push_back(extra);
  for (double extra : {1e-5, -1e-5, -0.49}) z.push_back(extra);
  const size_t n = z.size();
  std::vector<double> decay(n), p1(n), p2(n);
  phis_many(z.data(), decay.data(), p1.data(), p2.data(), static_cast<int>(n));
  for (size_t k = 0; k < n; ++k) {
    const Phi one = phis(z[k]);
    SCOPED_TRACE(z[k]);
    // phi2 = (z - 1 + e^-z) / z^2 loses a few bits to cancellation at z = 0.5: 4 ulp of e^-z
    // there are 2e-15 of phi2.
    EXPECT_NEAR(decay[k], one.decay, 1e-15 * one.decay + 1e-300);
    EXPECT_NEAR(p1[k], one.phi1, 1e-15 * one.phi1);
    EXPECT_NEAR(p2[k], one.phi2, 4e-15 * one.phi2);
    if (std::abs(z[k]) < 0.5 || z[k] > 708.0) {    // the same sums there (the series vectorised), bit for bit
      EXPECT_EQ(decay[k], one.decay);
      EXPECT_EQ(p1[k], one.phi1);
      EXPECT_EQ(p2[k], one.phi2);
    }
  }
}

// A block's rates often all fall in one regime (every z tiny in a bed's short steps, every e^-z
// underflowing in a sedimentation test's long ones), where phis_many skips the forms none needs.
TEST(BatchMath, PhisManyOfOneRegimeFollowPhis)
{
  const std::vector<std::vector<double>> groups = {
      {1e-5, -3e-4, 2e-6, 1e-12},                              // six terms
      {0.0, -0.0, 1e-300, -0x1p-10, 0x1.fffffffffffffp-10},    // six terms, up to the first range's end
      {0x1p-9, 0.01, -0.003},                                  // eight terms each
      {0.02, -0.05, 0x1.fffffffffffffp-5},                     // ten
      {0.07, 0.1, -0.12},                                      // twelve
      {0.13, -0.2, 0.24},                                      // fourteen
      {0.25, 0.3, -0.45, 0x1.fffffffffffffp-2},                // sixteen
      {1e-5, 0.03, -0.05, 0x1p-9},                             // six to ten
      {0.3, -0.2, 1e-7, 0.49},                                 // up to sixteen
      {800.0, 708.5, 745.0, 1e6, 5000.0},                      // e^-z subnormal or zero
      {0.01, 900.0, 720.0},                                    // series and underflow, no direct form
  };
  for (const std::vector<double> &z : groups) {
    const int n = static_cast<int>(z.size());
    std::vector<double> decay(n), p1(n), p2(n);
    phis_many(z.data(), decay.data(), p1.data(), p2.data(), n);
    for (int k = 0; k < n; ++k) {
      const Phi one = phis(z[k]);
      SCOPED_TRACE(z[k]);
      EXPECT_EQ(decay[k], one.decay);
      EXPECT_EQ(p1[k], one.phi1);
      EXPECT_EQ(p2[k], one.phi2);
    }
  }
}

TEST(BatchMath, DragCurvesFollowTheCurveOfEachSphere)
{
  const Fluid water{998.2, 1.002e-3, 0.0};
  const std::vector<double> re = uniform(0.0, 50.0, 500, 5), eps = uniform(0.4, 1.2, 500, 6);
  std::vector<double> reynolds = re, voidage = eps;
  reynolds[0] = 0.0;    // chi at rest: 3.7
  voidage[1] = 1.0;     // no hindrance
  // Each law's branches: at and around the switches of Zhang-Li (1, 150) and Schiller-Naumann (1000).
  const double branches[] = {0.5, 1.0, 1.5, 149.0, 150.0, 151.0, 999.0, 1000.0, 1001.0, 5e4};
  for (size_t k = 0; k < std::size(branches); ++k) reynolds[2 + k] = branches[k];
  struct Case {
    DragLaw law;
    Hindrance hindrance;
  };
  const Case cases[] = {{DragLaw::Stokes, Hindrance::None},          {DragLaw::Dallavalle, Hindrance::None},
                        {DragLaw::DiFelice, Hindrance::None},        {DragLaw::SchillerNaumann, Hindrance::None},
                        {DragLaw::ZhangLi, Hindrance::None},         {DragLaw::ZhangLiSmooth, Hindrance::None},
                        {DragLaw::Standard, Hindrance::None},        {DragLaw::Standard, Hindrance::RichardsonZaki},
                        {DragLaw::Standard, Hindrance::Garside},     {DragLaw::Standard, Hindrance::DiFelice},
                        {DragLaw::Stokes, Hindrance::RichardsonZaki}, {DragLaw::Dallavalle, Hindrance::RichardsonZaki},
                        {DragLaw::SchillerNaumann, Hindrance::DiFelice}};
  for (const Case &c : cases) {
    for (const HindranceBuoyancy buoyancy : {HindranceBuoyancy::Plain, HindranceBuoyancy::Mixture}) {
      const DragModel model(c.law, water, buoyancy, c.hindrance);
      for (const BatchMath kind : batch_math_kinds) {
        if (!batch_math_available(kind)) continue;
        std::vector<DragCurve> many(reynolds.size());
        model.curves(reynolds.data(), voidage.data(), many.data(), static_cast<int>(many.size()), kind);
        for (size_t k = 0; k < many.size(); ++k) {
          const DragCurve one = model.curve(reynolds[k], voidage[k]);
          SCOPED_TRACE(testing::Message() << drag_law_name(c.law) << " " << hindrance_name(c.hindrance) << " "
                                          << batch_math_name(kind) << " " << k);
          // eps^-(chi + 1) at eps = 0.4: |ln eps (chi + 1)| < 4.4, so 4 ulp in each of log and exp
          // and one in log10 against log / ln 10 stay below 1e-14 of the factor; eps^-n, n <= 5.1, the
          // same. Schiller-Naumann's Re^0.687 is e^(0.687 ln Re) in a batch: |0.687 ln Re| < 4.8 below the
          // switch, the same bound; the standard curve's argument stays below 12 in size up to Re = 5e4.
          EXPECT_NEAR(many[k].g, one.g, 1e-14 * std::abs(one.g));
          EXPECT_NEAR(many[k].re_dg, one.re_dg, 1e-14 * std::abs(one.re_dg) + 1e-14 * std::abs(one.g));
          const bool unhindered = model.hindrance() == Hindrance::None || voidage[k] >= 1.0;
          const bool batch_powers = c.law == DragLaw::Standard || (c.law == DragLaw::SchillerNaumann && reynolds[k] <= 1000.0);
          if (unhindered && !batch_powers) {    // the same curve, bit for bit
            EXPECT_EQ(many[k].g, one.g);
            EXPECT_EQ(many[k].re_dg, one.re_dg);
          }
        }
      }
    }
  }
}

TEST(BatchMath, DiFeliceCurvesInClearFluidAreDallavallesBitForBit)
{
  // Every sphere unhindered (eps >= 1, a chunk in clear fluid, which the hindrance skips): the
  // single-sphere curve of Dallavalle's law, unchanged.
  const Fluid water{998.2, 1.002e-3, 0.0};
  const std::vector<double> re = uniform(0.0, 50.0, 200, 7), voidage = uniform(1.0, 1.5, 200, 8);
  const DragModel felice(DragLaw::DiFelice, water), dalla(DragLaw::Dallavalle, water);
  for (const BatchMath kind : batch_math_kinds) {
    if (!batch_math_available(kind)) continue;
    std::vector<DragCurve> hindered(re.size()), single(re.size());
    felice.curves(re.data(), voidage.data(), hindered.data(), static_cast<int>(re.size()), kind);
    dalla.curves(re.data(), voidage.data(), single.data(), static_cast<int>(re.size()), kind);
    for (size_t k = 0; k < re.size(); ++k) {
      EXPECT_EQ(hindered[k].g, single[k].g) << batch_math_name(kind) << " " << k;
      EXPECT_EQ(hindered[k].re_dg, single[k].re_dg) << batch_math_name(kind) << " " << k;
    }
  }
}
