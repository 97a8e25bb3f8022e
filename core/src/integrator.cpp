// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/integrator.hpp"

#include "sediment/batch_math.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>

namespace sediment {

namespace {

// Taylor coefficients (-1)^n / (n + 2)! of phi2 for n = 0 .. 15: with |z| < 0.5 the truncated series
// is exact to round-off, where the direct form loses digits to cancellation. phi1 = 1 - z phi2 and
// e^-z = 1 - z phi1 follow without cancellation there (each is near 1), so one series gives all three.
struct SeriesCoefficients {
  static constexpr int most_terms = 16;
  double phi2[most_terms];
  constexpr SeriesCoefficients() : phi2()
  {
    double factorial = 1.0;    // (n + 2)!
    for (int n = 0; n < most_terms; ++n) {
      factorial *= (n + 2);
      phi2[n] = (n % 2 ? -1.0 : 1.0) / factorial;
    }
  }
};
constexpr SeriesCoefficients series;

// phis(z) from e^-z (0 beyond z = 745.2) for z outside the series' range.
inline Phi phis_from_decay(double z, double decay)
{
  const double inverse = 1.0 / z;
  return {decay, (1.0 - decay) * inverse, (z - 1.0 + decay) * inverse * inverse};
}

// Beyond z = 745.13 e^-z rounds to 0, which libm reaches through its slow underflow path (an
// eighth of a sedimentation test's step, where dt is 1e5 relaxation times of the fine grains).
constexpr double decay_limit = 745.2;
// Up to here e^-z is a normal number, which glibc's vector exp computes in its fast path; past it
// (subnormal or zero) the vector exp falls back to the scalar exp, lane by lane, and its slow path.
constexpr double normal_decay_limit = 708.0;

// As many terms of the series as round-off needs at this |z| < 0.5: the first one left out,
// |z|^N / (N + 2)!, is below 4e-20, a tenth of the last bit of phi2 (>= 0.42 there). Steps limited by
// contacts are far below the relaxation time, and z is tiny there: six terms do below 2^-9.
constexpr double series_limit = 0.5;
struct SeriesRange {
  double below;    // |z| below this
  int terms;
};
constexpr SeriesRange series_ranges[] = {{0x1p-9, 6}, {0x1p-6, 8}, {0x1p-4, 10}, {0x1p-3, 12}, {0x1p-2, 14}};
// Always inline: GCC 12 kept it out of line, and each block's AVX-512 stages called this default
// (SSE) code four times with the vector registers' upper halves dirty, which cost more than the
// rest of the series at dt/tau below 0.1 (the Dallavalle step 2.5x the peer on the driver build,
// against 1.5x at dt/tau 1).
[[gnu::always_inline]] inline int series_terms(double z)
{
  const double size = std::abs(z);
  int terms = SeriesCoefficients::most_terms;
  for (int r = std::size(series_ranges) - 1; r >= 0; --r)    // selects, no branch: the block's loops vectorise
    terms = size < series_ranges[r].below ? series_ranges[r].terms : terms;
  return terms;
}

// phi2 from its series' first `terms` terms, summed from the top (Horner): the one sum phis() and
// the block's series take, with `terms` known to the compiler in the block's loops.
[[gnu::always_inline]] inline double series_phi2(double z, int terms)
{
  double p2 = series.phi2[terms - 1];
  for (int n = terms - 2; n >= 0; --n) p2 = p2 * z + series.phi2[n];
  return p2;
}

// phi1 and e^-z from the series' phi2.
inline Phi phis_from_series(double z, double p2)
{
  const double p1 = 1.0 - z * p2;
  return {1.0 - z * p1, p1, p2};
}

}    // namespace

Phi phis(double z)
{
  if (z == 0.0) return {1.0, 1.0, 0.5};
  if (std::abs(z) < series_limit) return phis_from_series(z, series_phi2(z, series_terms(z)));
  return phis_from_decay(z, z > decay_limit ? 0.0 : std::exp(-z));
}

namespace {

// A size (a double >= 0, or NaN) as its bits, and back: sizes compare as their bits do.
inline std::int64_t size_bits(double size)
{
  std::int64_t bits;
  std::memcpy(&bits, &size, sizeof bits);
  return bits;
}
inline double size_of(std::int64_t bits)
{
  double size;
  std::memcpy(&size, &bits, sizeof size);
  return size;
}

// phis() of rates that all take the series with this many terms, in one vector loop.
template <int terms>
[[gnu::always_inline]] inline void series_phis(const double *z, double *decay, double *phi1, double *phi2, int n)
{
  static_assert(terms >= 1 && terms <= SeriesCoefficients::most_terms, "more terms than coefficients");
  for (int k = 0; k < n; ++k) {
    const Phi from_series = phis_from_series(z[k], series_phi2(z[k], terms));
    decay[k] = from_series.decay;
    phi1[k] = from_series.phi1;
    phi2[k] = from_series.phi2;
  }
}

// The body of phis_many, inlined into the block's step of each instruction set. Where the rates fall
// sets the work: at dt/tau below about 0.1 every rate takes the series (no exponential is taken), and
// beyond the normal range of e^-z (dt/tau above about 1e3) every rate's e^-z is 0.
[[gnu::always_inline]] inline void fill_phis(const double *z, double *decay, double *phi1, double *phi2, int n,
                                             BatchMath kind)
{
  // Which forms the rates need, found first in one vector loop, each test without a branch (a scalar
  // test per rate cost more than the rest of this stage): the series near zero (the direct forms
  // lose digits to cancellation there), the direct forms with an exponential, or past the normal
  // range of e^-z the direct forms with e^-z = 0, except in the narrow band where e^-z is subnormal.
  std::int64_t any_small = 0, any_direct = 0, any_large = 0, any_subnormal = 0;    // 64 bits, as a lane of doubles
  for (int k = 0; k < n; ++k) {
    const bool small = std::abs(z[k]) < series_limit, large = z[k] > normal_decay_limit;
    any_small |= small;
    any_direct |= !small & !large;
    any_large |= large;
    any_subnormal |= large & (z[k] <= decay_limit);
  }
  // Every rate takes the series with the same number of terms (most blocks: at one dt/tau a block's
  // rates lie within a factor of a few, and a count's range of z spans 2 to 8), so the sums need no
  // count per rate. The smallest and biggest |z| tell, compared by their bits (ordered as the values,
  // for sizes): a vector loop, which a minimum of doubles (NaN and -0.0 have to stay in place) is
  // not. Only where every rate takes the series (dt/tau below about 0.1): above, this loop cost 1.5 %
  // of the step's instructions.
  if (!any_direct && !any_large) {
    std::int64_t smallest = size_bits(series_limit), biggest = 0;
    for (int k = 0; k < n; ++k) {
      smallest = std::min(smallest, size_bits(std::abs(z[k])));
      biggest = std::max(biggest, size_bits(std::abs(z[k])));
    }
    const int terms = series_terms(size_of(biggest));
    static_assert(std::size(series_ranges) == 5 && series_ranges[0].terms == 6 && series_ranges[1].terms == 8 &&
                      series_ranges[2].terms == 10 && series_ranges[3].terms == 12 && series_ranges[4].terms == 14,
                  "the cases below are the counts series_terms() gives");
    if (series_terms(size_of(smallest)) == terms) {
      switch (terms) {
        case 6: return series_phis<6>(z, decay, phi1, phi2, n);
        case 8: return series_phis<8>(z, decay, phi1, phi2, n);
        case 10: return series_phis<10>(z, decay, phi1, phi2, n);
        case 12: return series_phis<12>(z, decay, phi1, phi2, n);
        case 14: return series_phis<14>(z, decay, phi1, phi2, n);
        default: return series_phis<SeriesCoefficients::most_terms>(z, decay, phi1, phi2, n);
      }
    }
  }
  if (any_direct) {
    for (int k = 0; k < n; ++k) decay[k] = -std::min(z[k], normal_decay_limit);
    exp_many(decay, decay, n, kind);
    for (int k = 0; any_large && k < n; ++k) decay[k] = z[k] > normal_decay_limit ? 0.0 : decay[k];
  } else {
    for (int k = 0; k < n; ++k) decay[k] = 0.0;
  }
  // The direct forms for all (one vector loop); the series and the subnormal band replace theirs below.
  // Not where every rate takes the series (steps limited by contacts): their divisions would be lost.
  for (int k = 0; (any_direct || any_large) && k < n; ++k) {
    const double inverse = 1.0 / z[k];
    phi1[k] = (1.0 - decay[k]) * inverse;
    phi2[k] = (z[k] - 1.0 + decay[k]) * inverse * inverse;
  }
  // The series where |z| < 0.5, for every rate at once (at dt/tau near 0.1 every sphere takes it, and
  // phis() one by one was a third of the step): a vector loop over the rates per term, from the most
  // terms any rate needs. Each rate's Horner sum runs over those terms with the coefficients past its
  // own count at zero, so it stays exactly 0 until its count's last term and then is phis()'s sum,
  // bit for bit.
  constexpr int chunk = 32;    // a block's rates, in registers
  constexpr int nranges = std::size(series_ranges);
  for (int start = 0; any_small && start < n; start += chunk) {
    const int m = std::min(chunk, n - start);
    const double *zc = z + start;
    double terms[chunk], p2[chunk];
    // The most terms a rate needs, from a vector test per range: whether some rate is past it.
    std::int64_t past[nranges] = {};
    for (int k = 0; k < m; ++k) {
      const double size = std::abs(zc[k]);
      const bool small = size < series_limit;
      terms[k] = small ? series_terms(zc[k]) : 0.0;
      for (int r = 0; r < nranges; ++r) past[r] |= small & (size >= series_ranges[r].below);
    }
    int most = series_ranges[0].terms;
    for (int r = 0; r < nranges; ++r)
      if (past[r]) most = r + 1 < nranges ? series_ranges[r + 1].terms : SeriesCoefficients::most_terms;
    // The first term of the sum from zero (0 z + c is c); its coefficient read before the loop, whose
    // load GCC would not take for every rate (it kept the loop scalar, with a branch per rate).
    const double top_coefficient = series.phi2[most - 1], top = most - 1;
    for (int k = 0; k < m; ++k) p2[k] = top < terms[k] ? top_coefficient : 0.0;
    for (int t = most - 2; t >= 0; --t) {
      const double c = series.phi2[t], index = t;
      for (int k = 0; k < m; ++k) p2[k] = p2[k] * zc[k] + (index < terms[k] ? c : 0.0);
    }
    // Every rate's values read and written again, the series' or their own: a store only where the
    // series applies kept this loop scalar.
    double *decay_c = decay + start, *phi1_c = phi1 + start, *phi2_c = phi2 + start;
    for (int k = 0; k < m; ++k) {
      const bool small = terms[k] > 0.0;
      const Phi own{decay_c[k], phi1_c[k], phi2_c[k]};
      const Phi from_series = phis_from_series(zc[k], p2[k]);
      decay_c[k] = small ? from_series.decay : own.decay;
      phi1_c[k] = small ? from_series.phi1 : own.phi1;
      phi2_c[k] = small ? from_series.phi2 : own.phi2;
    }
  }
  // e^-z subnormal: phis(), whose phi1 and phi2 equal the direct forms' with 0 (1 - e^-z rounds to 1
  // and z - 1 + e^-z to z - 1 there), and whose decay is the subnormal e^-z.
  for (int k = 0; any_subnormal && k < n; ++k)
    if (z[k] > normal_decay_limit && z[k] <= decay_limit) decay[k] = phis(z[k]).decay;
}

}    // namespace

void phis_many(const double *z, double *decay, double *phi1, double *phi2, int n, BatchMath kind)
{
  fill_phis(z, decay, phi1, phi2, n, kind);
}

double phi1(double z) { return phis(z).phi1; }

double phi2(double z) { return phis(z).phi2; }

[[gnu::always_inline]] inline void DragBlock::slip()
{
  for (int n = 0; n < size_; ++n) {
    const double w[3] = {v_[0][n] - u_[0], v_[1][n] - u_[1], v_[2][n] - u_[2]};
    const double s = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double inverse = 1.0 / s;    // s = 0: infinite, the direction is set below
    for (int k = 0; k < 3; ++k) dir_[k][n] = w[k] * inverse;
    speed_[n] = s;
  }
  std::int64_t any_at_rest = 0;    // rare: one vector loop finds whether there is any
  for (int n = 0; n < size_; ++n) any_at_rest |= !(speed_[n] > 0.0);
  for (int n = 0; n < size_ && any_at_rest; ++n) {
    if (speed_[n] > 0.0) continue;
    // At rest: along the drive, if there is one (NaN slips come here too and stay NaN below).
    const double a[3] = {a_[0][n], a_[1][n], a_[2][n]};
    const double a_norm = std::sqrt(dot(a, a));
    for (int k = 0; k < 3; ++k) dir_[k][n] = a_norm > 0.0 ? a[k] / a_norm : k == 2 ? 1.0 : 0.0;
  }
  for (int n = 0; n < size_; ++n) {
    a_par_[n] = a_[0][n] * dir_[0][n] + a_[1][n] * dir_[1][n] + a_[2][n] * dir_[2][n];
    reynolds_[n] = reynolds_per_speed_[n] * speed_[n];
  }
}

// rates() under `bingham`: with D = (k s Re G' + k_w s_y Re H') (s + 2 w s_y) / (s + w s_y), the slope
// is F' = k G + D / s and c = a_par - F / m + F' s / m = a_par - k_w s_y H + D (per unit mass).
[[gnu::always_inline]] inline void DragBlock::split_rates(const DragModel &model, double dt, BatchMath kind)
{
  const double weight = model.yield_weight();
  DragCurve yield_curve[capacity];
  model.curves(reynolds_, voidage_, curve_, size_, kind);
  model.yield_curves(reynolds_, yield_curve, size_);
  for (int n = 0; n < size_; ++n) {
    const double k = rate_per_g_[n];
    // the yield part scales with the wetted surface
    const double k_yield = model.smooth_drag_per_speed(diameter_[n], {wetted_[n], wetted_[n], 1.0}) * inverse_mass_[n];
    const double s = speed_[n], sy = yield_speed_[n], wsy = weight * sy;
    const double inverse = 1.0 / s;
    const double d = (k * s * curve_[n].re_dg + k_yield * sy * yield_curve[n].re_dg) * (s + 2.0 * wsy) / (s + wsy);
    c_[n] = a_par_[n] - k_yield * sy * yield_curve[n].g + d;
    z_[0][n] = (k * curve_[n].g + d * inverse) * dt;
    z_[1][n] = (k * curve_[n].g + k_yield * sy * yield_curve[n].g * inverse) * dt;
  }
}

// The rates from one evaluation of the law. Without a yield stress F = k s G(K s): F' = k (G + Re G'),
// F / s = k G and c = a_par + k s Re G', with no division. Under one, F = F_y + k (s + s_y) G(Re'),
// Re' = K s^2 / (s + s_y): F' = k (G + Re' G' (2 s_y + s) / s) and c = a_par - F / m + F' s / m; a
// sphere at rest (s = 0) takes the step in pieces, which replaces what its division by s gives here.
// Under `bingham` (split_rates), F = k s G(Re_w) + k_w s_y H(Re_w) with Re_w = K s^2 / (s + w s_y).
template <bool yield>
[[gnu::always_inline]] inline void DragBlock::rates(const DragModel &model, double dt, BatchMath kind)
{
  if constexpr (yield) {
    const double weight = model.yield_weight();
    for (int n = 0; n < size_; ++n) {
      yield_speed_[n] = model.yield_speed(diameter_[n]);
      yield_accel_[n] = model.yield_force(diameter_[n], {area_[n], wetted_[n], voidage_[n]}) * inverse_mass_[n];
      const double s = speed_[n];
      reynolds_[n] = reynolds_per_speed_[n] * s * s / (s + weight * yield_speed_[n]);
    }
    if (model.split_yield()) return split_rates(model, dt, kind);
  }
  model.curves(reynolds_, voidage_, curve_, size_, kind);
  for (int n = 0; n < size_; ++n) {
    const double k = rate_per_g_[n];
    const double g = curve_[n].g, re_dg = curve_[n].re_dg;
    if constexpr (yield) {
      const double s = speed_[n], sy = yield_speed_[n];
      const double inverse = 1.0 / s;
      c_[n] = a_par_[n] - yield_accel_[n] - k * g * sy + k * re_dg * (2.0 * sy + s);
      z_[0][n] = k * (g + re_dg * (2.0 * sy + s) * inverse) * dt;
      z_[1][n] = (yield_accel_[n] + k * g * (s + sy)) * inverse * dt;
    } else {
      c_[n] = a_par_[n] + speed_[n] * k * re_dg;
      z_[0][n] = k * (g + re_dg) * dt;
      z_[1][n] = k * g * dt;
    }
  }
}

[[gnu::always_inline]] inline void DragBlock::advance_all(double dt)
{
  for (int n = 0; n < size_; ++n) {
    // Along the slip: the slip's exact advance under ds/dt = c - k s; across it, the linear step.
    // The weights of a_n are those of a_{n+1} (along_, across_) taken from the ETD2 weights;
    // drag_step_final adds a_{n+1}.
    const Segment slip = advance(Phi{decay_[0][n], phi1_[0][n], phi2_[0][n]}, speed_[n], c_[n], dt);
    along_[n] = dt * phi2_[0][n];
    across_[n] = dt * phi2_[1][n];
    const double along_now = slip.speed - along_[n] * a_par_[n];    // along the slip, with a_n's share
    const double across_now = dt * (phi1_[1][n] - phi2_[1][n]);
    const double across_drift = dt * dt * phi2_[1][n];
    for (int k = 0; k < 3; ++k) {
      const double a_perp = a_[k][n] - a_par_[n] * dir_[k][n];
      dx_[k][n] = u_[k] * dt + slip.distance * dir_[k][n] + across_drift * a_perp;
      mid_v_[k][n] = u_[k] + along_now * dir_[k][n] + across_now * a_perp;
    }
  }
}

// Which spheres' one-piece step meets a set-valued point of the law, where set_valued_step_initial
// would stop and go on in another piece: a jump's Reynolds number between the start's and the end's
// (Re' grows with s; within a relative margin, which also takes a start that sits on a jump), or,
// under a yield stress, a start at rest or an end below zero speed (the slip would stop). The margin
// (1e-9) is wider than what set_valued_step_initial counts as sitting on a jump (1e-12 of the speed,
// at most 2e-12 of Re'), so a sphere steps in one piece only where it would step in one piece there.
template <bool yield>
[[gnu::always_inline]] inline void DragBlock::find_set_valued_points(const DragModel &model, double dt)
{
  // Each test one loop over the block, which GCC vectorises (with the law's switches inside, the
  // loop stayed scalar and took a third of the block's time under Zhang-Li's law).
  constexpr double margin = 1e-9;
  double end_speed[capacity], low[capacity], high[capacity];    // low, high: the Re' the step passes, with the margin
  for (int n = 0; n < size_; ++n)    // as advance_all found it (kept there, it cost the smooth laws a store)
    end_speed[n] = advance(Phi{decay_[0][n], phi1_[0][n], phi2_[0][n]}, speed_[n], c_[n], dt).speed;
  if constexpr (yield) {
    const double weight = model.yield_weight();
    for (int n = 0; n < size_; ++n) {
      const double s0 = speed_[n], s1 = end_speed[n];
      const double re_end = reynolds_per_speed_[n] * s1 * s1 / (s1 + weight * yield_speed_[n]);
      low[n] = std::min(reynolds_[n], re_end) * (1.0 - margin);
      high[n] = std::max(reynolds_[n], re_end) * (1.0 + margin);
      meets_point_[n] = (!(s0 > 0.0)) | (s1 < 0.0);
    }
  } else {
    for (int n = 0; n < size_; ++n) {
      const double re_end = reynolds_per_speed_[n] * end_speed[n];
      low[n] = std::min(reynolds_[n], re_end) * (1.0 - margin);
      high[n] = std::max(reynolds_[n], re_end) * (1.0 + margin);
      meets_point_[n] = 0;
    }
  }
  const DragModel::Switches &switches = model.switches();
  for (int j = 0; j < switches.count; ++j) {
    const double re = switches.reynolds[j];
    for (int n = 0; n < size_; ++n) meets_point_[n] |= (re >= low[n]) & (re <= high[n]);
  }
  std::int64_t any = 0;
  for (int n = 0; n < size_; ++n) any |= meets_point_[n];
  any_meets_point_ = any;
}

// A sphere whose fluid velocity has jumped (a fix fluid/flow's new solve) starts its step with the jump as its slip,
// far from where the slip ends. Linearised at the start, the step ends one Newton step from the law's terminal slip,
// off it by a share of the jump however many relaxation times the step is (after a jump of 19 mm/s, 0.46 and 27
// terminal slips for quartz grains of 67 and 2.6 um under the standard curve: test
// AfterAFluidJumpTheStepEndsAtTheTerminalSlip), and the flow, solved from the drag, feeds that back (parcels of a
// test's column ran away). So where the share of the distance from the linearisation point that the step keeps,
// (z_along - z_across) / z_along of it, is above RELINEARIZE of the end's slip, the step is taken again from the same
// start, linearised at that end, up to PASSES times: a Newton iteration of the linearisation point. Along the point's
// direction the slip advances from the start's component there, and the component across it decays at the secant rate.
// A sphere whose end lies near its start, or whose drag is linear in its slip around it (Stokes' regime), steps once,
// to the bit as before; each sphere's arithmetic does not depend on the others.
[[gnu::always_inline]] inline void DragBlock::relinearize_at_end(const DragModel &model, double dt, BatchMath kind)
{
  constexpr double RELINEARIZE = 1e-3;
  constexpr int PASSES = 4;
  double start[3][capacity], point[3][capacity], along_start[capacity];
  std::int64_t moved[capacity];    // linearised away from its start
  for (int n = 0; n < size_; ++n) {
    for (int k = 0; k < 3; ++k) point[k][n] = start[k][n] = v_[k][n] - u_[k];
    moved[n] = 0;
  }
  for (int pass = 0; pass < PASSES; ++pass) {
    std::int64_t any_far = 0;
    for (int n = 0; n < size_; ++n) {
      double end[3], gap = 0.0, size = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double a_perp = a_[k][n] - a_par_[n] * dir_[k][n];
        end[k] = mid_v_[k][n] - u_[k] + along_[n] * a_par_[n] * dir_[k][n] + across_[n] * a_perp;
        gap += (end[k] - point[k][n]) * (end[k] - point[k][n]);
        size += end[k] * end[k];
      }
      // The step keeps about (z_along - z_across) / z_along of the distance from its linearisation point
      // (nothing where the drag is linear in the slip there): a share above RELINEARIZE of the end's slip
      // is taken again.
      const double kept = (z_[0][n] - z_[1][n]) * (z_[0][n] - z_[1][n]) * gap;
      const std::int64_t far = (kept > RELINEARIZE * RELINEARIZE * size * z_[0][n] * z_[0][n]) & (size > 0.0);
      any_far |= far;
      moved[n] |= far;
      const double inverse = 1.0 / std::sqrt(size);
      for (int k = 0; k < 3; ++k) {
        point[k][n] = far ? end[k] : point[k][n];
        dir_[k][n] = far ? end[k] * inverse : dir_[k][n];
      }
      speed_[n] = far ? size * inverse : speed_[n];
    }
    if (!any_far) return;
    for (int n = 0; n < size_; ++n) {
      along_start[n] = moved[n] ? start[0][n] * dir_[0][n] + start[1][n] * dir_[1][n] + start[2][n] * dir_[2][n]
                                : speed_[n];
      a_par_[n] = a_[0][n] * dir_[0][n] + a_[1][n] * dir_[1][n] + a_[2][n] * dir_[2][n];
      reynolds_[n] = reynolds_per_speed_[n] * speed_[n];
    }
    rates<false>(model, dt, kind);
    fill_phis(z_[0], decay_[0], phi1_[0], phi2_[0], size_, kind);
    fill_phis(z_[1], decay_[1], phi1_[1], phi2_[1], size_, kind);
    for (int n = 0; n < size_; ++n) {
      const Segment slip = advance(Phi{decay_[0][n], phi1_[0][n], phi2_[0][n]}, along_start[n], c_[n], dt);
      along_[n] = dt * phi2_[0][n];
      across_[n] = dt * phi2_[1][n];
      const double along_now = slip.speed - along_[n] * a_par_[n];
      const double across_now = dt * (phi1_[1][n] - phi2_[1][n]);
      const double across_drift = dt * dt * phi2_[1][n];
      for (int k = 0; k < 3; ++k) {
        const double a_perp = a_[k][n] - a_par_[n] * dir_[k][n];
        // the start's slip across the point's direction (none where the step is not taken again)
        const double across_start = moved[n] ? start[k][n] - along_start[n] * dir_[k][n] : 0.0;
        dx_[k][n] = u_[k] * dt + slip.distance * dir_[k][n] + across_drift * a_perp + dt * phi1_[1][n] * across_start;
        mid_v_[k][n] = u_[k] + along_now * dir_[k][n] + across_now * a_perp + decay_[1][n] * across_start;
      }
    }
  }
}

// The stages, compiled apart for a fluid with a yield stress (with both in one body, the Newtonian
// step ran 3 instructions more per sphere: cachegrind of benchmarks/in.cost's nonlinear scene).
template <bool yield>
[[gnu::always_inline]] inline void DragBlock::stages_of(const DragModel &model, double dt, BatchMath kind)
{
  slip();
  rates<yield>(model, dt, kind);
  fill_phis(z_[0], decay_[0], phi1_[0], phi2_[0], size_, kind);
  fill_phis(z_[1], decay_[1], phi1_[1], phi2_[1], size_, kind);
  advance_all(dt);
  if constexpr (!yield)    // a fix fluid/flow, whose velocity jumps, takes no fluid with a yield stress
    if (fluid_jumps_) relinearize_at_end(model, dt, kind);
  if (!model.smooth()) find_set_valued_points<yield>(model, dt);
}

[[gnu::always_inline]] inline void DragBlock::stages(const DragModel &model, double dt, BatchMath kind)
{
  if (model.fluid().yield_stress > 0.0)
    stages_of<true>(model, dt, kind);
  else
    stages_of<false>(model, dt, kind);
}

// The spheres whose one-piece step met a set-valued point, stepped again from their start in pieces.
void DragBlock::step_in_pieces(const DragModel &model, double dt)
{
  for (int n = 0; n < size_; ++n) {
    if (!meets_point_[n]) continue;
    const SphereDrag drag{&model, diameter_[n], {area_[n], wetted_[n], voidage_[n]}};
    const double a[3] = {a_[0][n], a_[1][n], a_[2][n]};
    double v[3] = {v_[0][n], v_[1][n], v_[2][n]}, dx[3];
    const StepCorrection corr = set_valued_step_initial(drag, 1.0 / inverse_mass_[n], a, u_, dt, v, dx);
    for (int k = 0; k < 3; ++k) {
      mid_v_[k][n] = v[k];
      dx_[k][n] = dx[k];
      dir_[k][n] = corr.dir[k];
    }
    along_[n] = corr.along;
    across_[n] = corr.across;
    state_[n] = corr.state;
  }
}

// The same stages in 4-wide vectors (the 2-wide SSE2 of the default build takes 1.3-1.4x as long:
// bench_core_kernels SmoothStepBlocks against SmoothStepBlocksSSE2), and in 8-wide ones.
SEDIMENT_TARGET_AVX2 void DragBlock::stages_avx2(const DragModel &model, double dt)
{
  stages(model, dt, BatchMath::AVX2);
}
SEDIMENT_TARGET_AVX512 void DragBlock::stages_avx512(const DragModel &model, double dt)
{
  stages(model, dt, BatchMath::AVX512);
}

void DragBlock::step(double dt, BatchMath kind)
{
  const DragModel &model = *model_;
  if (kind == BatchMath::AVX512 && batch_math_available(kind))
    stages_avx512(model, dt);
  else if (kind == BatchMath::AVX2 && batch_math_available(kind))
    stages_avx2(model, dt);
  else
    stages(model, dt, kind);
  in_pieces_ = keeps_for_pieces_ && any_meets_point_;
  if (in_pieces_) step_in_pieces(model, dt);
}

// step_spheres' loads: add_smooth's (set_for_one_piece), with 1 / m and a_n = f / m taken here in
// vectors. The rows come as restricted parameters: with them in locals, GCC did not take them as
// restricted and left the loops scalar (it could not check every pair of arrays for overlap).
template <class Atom>
[[gnu::always_inline]] inline void DragBlock::add_spheres(Atom atom, int count, double ftm2v,
                                                           const double (*__restrict v)[3],
                                                           const double (*__restrict flow)[3],
                                                           const double (*__restrict force)[3],
                                                           const double *__restrict radius,
                                                           const double *__restrict mass,
                                                           const double *__restrict fraction, double max_fraction)
{
  for (int n = 0; n < count; ++n) {
    const int i = atom(n);
    const double inverse_mass = ftm2v / mass[i];
    const double a[3] = {force[i][0] * inverse_mass, force[i][1] * inverse_mass, force[i][2] * inverse_mass};
    DragScale scale;
    if (fraction) scale.voidage = voidage_of(fraction[i], max_fraction);
    if (flow) {
      const double slip[3] = {v[i][0] - flow[i][0], v[i][1] - flow[i][1], v[i][2] - flow[i][2]};
      set_for_one_piece(n, {model_, 2.0 * radius[i], scale}, inverse_mass, a, slip);
    } else {
      set_for_one_piece(n, {model_, 2.0 * radius[i], scale}, inverse_mass, a, v[i]);
    }
    inverse_mass_[n] = inverse_mass;
  }
  size_ = count;
}

// step_spheres' stores: velocity(), displacement() and pack_weights(correction(), 1 / m) of each
// sphere, and its rotation's kick.
template <class Atom>
[[gnu::always_inline]] inline double DragBlock::finish_spheres(Atom atom, HalfKick kick, double dt,
                                                                double (*__restrict x)[3], double (*__restrict v)[3],
                                                                const double (*__restrict flow)[3],
                                                                double (*__restrict omega)[3],
                                                                const double (*__restrict torque)[3],
                                                                const double *__restrict radius,
                                                                const double *__restrict mass,
                                                                double (*__restrict weights)[PACKED_WEIGHTS_SIZE]) const
{
  double states[capacity];    // summed after the loop: a running sum would keep it from vectors
  for (int n = 0; n < size_; ++n) {
    const int i = atom(n);
    double new_x[3], new_v[3];
    displacement(n, new_x);
    velocity(n, new_v);
    if (flow)    // back from the sphere's fluid's frame
      for (int k = 0; k < 3; ++k) {
        new_v[k] += flow[i][k];
        new_x[k] += flow[i][k] * dt;
      }
    for (int k = 0; k < 3; ++k) {
      new_x[k] += x[i][k];
      x[i][k] = new_x[k];
      v[i][k] = new_v[k];
    }
    states[n] = state_sum(new_x, new_v);
    const double spin = spin_weight(kick, radius[i], mass[i]);
    for (int k = 0; k < 3; ++k) omega[i][k] += spin * torque[i][k];
    double packed[PACKED_WEIGHTS_SIZE];    // stored below: through its pointer, a store could be anywhere
    pack_weights(correction(n), inverse_mass_[n], packed);
    for (int k = 0; k < PACKED_WEIGHTS_SIZE; ++k) weights[i][k] = packed[k];
  }
  double state = 0.0;
  for (int n = 0; n < size_; ++n) state += states[n];
  return state;
}

// Members, not lambdas, always inlined: a lambda's body would be compiled apart, for the default
// instruction set, not for the vector width of the step_spheres_* it is called from. The stages are
// called, not inlined: inlined into both ways of finding the atoms, they outgrew GCC's limits, and
// the law's curve (drag_curve) was no longer inlined into their vector loops (1.2x slower, Dallavalle).
template <class Atom>
[[gnu::always_inline]] inline double DragBlock::step_spheres_of(const SphereRows &rows, Atom atom, int count,
                                                                 const HalfKick &kick, double dt, BatchMath kind)
{
  add_spheres(atom, count, kick.ftm2v, rows.v, rows.flow, rows.force, rows.radius, rows.mass, rows.fraction,
              rows.max_fraction);
  step(dt, kind);
  const double state = finish_spheres(atom, kick, dt, rows.x, rows.v, rows.flow, rows.omega, rows.torque, rows.radius,
                                      rows.mass, rows.weights);
  clear();
  return state;
}

[[gnu::always_inline]] inline double DragBlock::step_spheres_in(const SphereRows &rows, const int *atoms, int count,
                                                                 const HalfKick &kick, double dt, BatchMath kind)
{
  const int first = atoms[0];
  if (atoms[count - 1] - first == count - 1)
    return step_spheres_of(rows, ConsecutiveAtoms{first}, count, kick, dt, kind);
  return step_spheres_of(rows, ListedAtoms{atoms}, count, kick, dt, kind);
}

SEDIMENT_TARGET_AVX2 double DragBlock::step_spheres_avx2(const SphereRows &rows, const int *atoms, int count,
                                                          const HalfKick &kick, double dt)
{
  return step_spheres_in(rows, atoms, count, kick, dt, BatchMath::AVX2);
}
SEDIMENT_TARGET_AVX512 double DragBlock::step_spheres_avx512(const SphereRows &rows, const int *atoms, int count,
                                                              const HalfKick &kick, double dt)
{
  return step_spheres_in(rows, atoms, count, kick, dt, BatchMath::AVX512);
}

double DragBlock::step_spheres(const SphereRows &rows, const int *atoms, int count, const HalfKick &kick, double dt,
                               BatchMath kind)
{
  assert(size_ == 0 && count > 0 && count <= capacity && model_->smooth());
  assert(!rows.flow || (u_[0] == 0.0 && u_[1] == 0.0 && u_[2] == 0.0));
  if (kind == BatchMath::AVX512 && batch_math_available(kind))
    return step_spheres_avx512(rows, atoms, count, kick, dt);
  if (kind == BatchMath::AVX2 && batch_math_available(kind)) return step_spheres_avx2(rows, atoms, count, kick, dt);
  return step_spheres_in(rows, atoms, count, kick, dt, kind);
}

namespace {
// drag_step_final_rows' loop, the rows as restricted parameters (see DragBlock::add_spheres).
[[gnu::always_inline]] inline void final_rows(int first, int count, HalfKick kick, double (*__restrict v)[3],
                                              double (*__restrict omega)[3], const double (*__restrict force)[3],
                                              const double (*__restrict torque)[3], const double *__restrict radius,
                                              const double *__restrict mass,
                                              const double (*__restrict weights)[PACKED_WEIGHTS_SIZE])
{
  for (int i = first; i < first + count; ++i) {
    double new_v[3] = {v[i][0], v[i][1], v[i][2]};
    add_packed_weighted_acceleration(weights[i], force[i], new_v);
    for (int k = 0; k < 3; ++k) v[i][k] = new_v[k];
    const double spin = spin_weight(kick, radius[i], mass[i]);
    for (int k = 0; k < 3; ++k) omega[i][k] += spin * torque[i][k];
  }
}

// Inline, so that each caller's instruction set vectorises the loop.
[[gnu::always_inline]] inline void final_rows_of(const SphereRows &rows, int first, int count, const HalfKick &kick)
{
  final_rows(first, count, kick, rows.v, rows.omega, rows.force, rows.torque, rows.radius, rows.mass, rows.weights);
}
SEDIMENT_TARGET_AVX2 void final_rows_avx2(const SphereRows &rows, int first, int count, const HalfKick &kick)
{
  final_rows_of(rows, first, count, kick);
}
SEDIMENT_TARGET_AVX512 void final_rows_avx512(const SphereRows &rows, int first, int count, const HalfKick &kick)
{
  final_rows_of(rows, first, count, kick);
}
}  // namespace

void drag_step_final_rows(const SphereRows &rows, int first, int count, const HalfKick &kick, BatchMath kind)
{
  if (kind == BatchMath::AVX512 && batch_math_available(kind)) return final_rows_avx512(rows, first, count, kick);
  if (kind == BatchMath::AVX2 && batch_math_available(kind)) return final_rows_avx2(rows, first, count, kick);
  final_rows_of(rows, first, count, kick);
}

StepCorrection nonlinear_step_initial(const SphereDrag &drag, double inverse_mass, const double a[3],
                                      const double u[3], double dt, double v[3], double dx[3], bool fluid_jumps)
{
  DragBlock block;
  block.set_law(*drag.model, u, fluid_jumps);
  block.add(drag, inverse_mass, a, v);
  block.step(dt);
  block.velocity(0, v);
  block.displacement(0, dx);
  return block.correction(0);
}

namespace {

bool spring_step_stable(double omega, double rate, double dt)
{
  const Phi p = phis(rate * dt);
  const double h2 = omega * omega * dt * dt;
  const double trace = 1.0 - h2 * p.phi2 + p.decay - h2 * p.phi1 * p.phi2;
  const double det = p.decay + h2 * (p.phi1 * p.phi1 - p.phi1 * p.phi2 - p.phi2 * p.decay);
  return det <= 1.0 && std::abs(trace) <= 1.0 + det;
}

}    // namespace

double spring_step_limit(double omega, double rate)
{
  if (omega == 0.0) return std::numeric_limits<double>::infinity();    // no spring, no limit
  // Stable from 0 up to the limit: bracket it by doubling from the undamped limit, then bisect.
  double stable = 0.0, unstable = 2.0 / omega;
  while (spring_step_stable(omega, rate, unstable)) {
    stable = unstable;
    unstable *= 2.0;
  }
  for (int n = 0; n < 200 && unstable - stable > 1e-15 * unstable; ++n) {
    const double mid = 0.5 * (stable + unstable);
    (spring_step_stable(omega, rate, mid) ? stable : unstable) = mid;
  }
  return stable;
}

}    // namespace sediment
