// SPDX-License-Identifier: GPL-2.0-or-later
// Drag laws for a sphere in a Newtonian or Bingham-plastic fluid at rest.
//
// Every law is written as one resisting-force curve of the slip speed s >= 0:
//   F(s) = s_w (pi d / 2)^2 tau_y + s_A (A / 2) (tau_y + eta s / d) G(Re'),
//   Re'  = rho s^2 / (tau_y + eta s / d),   G = Cd(Re') Re',   A = pi d^2 / 4,
// which is the Dedegil form of Zhang & Li (2024) for a Bingham fluid and, with tau_y = 0, exactly
// the Newtonian drag 1/2 rho A Cd(Re) s^2 with Re = rho s d / mu (Stokes: F = 3 pi mu d s).
// s_A and s_w scale the projected area and the yield term for a partly submerged sphere.
// The law `bingham` splits the force into the plastic viscosity's and the yield stress's parts
// (bingham_law below): F(s) = s_A (A / 2) (eta s / d) G(Re_w) + s_w (A / 2) tau_y H(Re_w).
#pragma once

#include "sediment/batch_math.hpp"
#include "sediment/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace sediment {

// How the local solid fraction phi = 1 - eps hinders the drag of any Newtonian law (docs/physics.md 3):
// - difelice: the force times eps^-(chi(Re) + 1) (Di Felice 1994's voidage function);
// - richardson-zaki, garside: the single-sphere force at the speed s eps^-n(Re), so that a uniform
//   suspension settles at u_t eps^n under any law (n from Rowe's 1987 fit of Richardson & Zaki's data,
//   4.7 at low Re, or Garside & Al-Dibouni's 1977 fit of theirs, 5.1 at low Re).
// One line each: the enumerator and the name in decks and on the command line.
#define SEDIMENT_HINDRANCES(HINDRANCE)         \
  HINDRANCE(None, "none")                      \
  HINDRANCE(DiFelice, "difelice")              \
  HINDRANCE(RichardsonZaki, "richardson-zaki") \
  HINDRANCE(Garside, "garside")

#define SEDIMENT_ENUMERATOR(Enumerator, ...) Enumerator,
enum class Hindrance { SEDIMENT_HINDRANCES(SEDIMENT_ENUMERATOR) };

// Which hindrances a law takes, one bit per hindrance: none, Di Felice's alone (a law with a jump in
// Cd: a speed-scaled hindrance would move the jump with each sphere's fraction), or any.
using HindranceSet = unsigned;
constexpr HindranceSet hindrance_bit(Hindrance hindrance) { return 1u << static_cast<unsigned>(hindrance); }
constexpr HindranceSet no_hindrance = hindrance_bit(Hindrance::None);
constexpr HindranceSet di_felice_hindrance = no_hindrance | hindrance_bit(Hindrance::DiFelice);
constexpr HindranceSet any_hindrance =
    di_felice_hindrance | hindrance_bit(Hindrance::RichardsonZaki) | hindrance_bit(Hindrance::Garside);

// The drag laws, one line each; adding one is a line here and its curve (LawCurve below; the recipe:
// docs/recipes-cpp.md). The columns:
// - the enumerator and the name in decks and on the command line;
// - the law whose single-sphere curve it takes (LawCurve): its own, or another's it is built on:
//   difelice is Bravo et al.'s model, Dallavalle's curve under Di Felice's hindrance, kept under its
//   own name to reproduce the paper; bingham takes the standard curve for its plastic viscosity's part
//   (and bingham_law's for its yield stress's);
// - the hindrance it always carries (None: the one a deck names);
// - the hindrances a deck may name for it (a law that carries one takes that one, or none);
// - whether it is a law for a sphere in a Bingham fluid (with a yield stress) or a Newtonian law.
#define SEDIMENT_DRAG_LAWS(LAW)                                                                                   \
  LAW(Stokes, "stokes", Stokes, None, any_hindrance, false)                                                       \
  LAW(SchillerNaumann, "schiller-naumann", SchillerNaumann, None, di_felice_hindrance, false)                     \
  LAW(Dallavalle, "dallavalle", Dallavalle, None, any_hindrance, false)                                           \
  LAW(ZhangLi, "zhang-li", ZhangLi, None, no_hindrance, true)                                                     \
  LAW(ZhangLiSmooth, "zhang-li/smooth", ZhangLiSmooth, None, no_hindrance, true)                                  \
  LAW(DiFelice, "difelice", Dallavalle, DiFelice, di_felice_hindrance, false)                                     \
  LAW(Standard, "standard", Standard, None, any_hindrance, false)                                                 \
  LAW(Bingham, "bingham", Standard, None, no_hindrance, true)

enum class DragLaw { SEDIMENT_DRAG_LAWS(SEDIMENT_ENUMERATOR) };

// Which buoyancy the hindrance goes with (docs/physics.md 3.1): plain Archimedes buoyancy or buoyancy
// from the mixture density, which already carries a factor eps of the net weight (Di Felice: eps^-chi
// instead of eps^-(chi+1); the speed-scaled hindrances: the force times eps).
#define SEDIMENT_HINDRANCE_BUOYANCIES(BUOYANCY) \
  BUOYANCY(Plain, "plain")                      \
  BUOYANCY(Mixture, "mixture")

enum class HindranceBuoyancy { SEDIMENT_HINDRANCE_BUOYANCIES(SEDIMENT_ENUMERATOR) };
#undef SEDIMENT_ENUMERATOR

std::optional<DragLaw> drag_law_from_name(std::string_view name);
const char *drag_law_name(DragLaw law);
// The names accepted by drag_law_from_name, separated by ", " (for error messages).
std::string drag_law_names();
std::optional<Hindrance> hindrance_from_name(std::string_view name);
const char *hindrance_name(Hindrance hindrance);
std::string hindrance_names();
std::optional<HindranceBuoyancy> hindrance_buoyancy_from_name(std::string_view name);
const char *hindrance_buoyancy_name(HindranceBuoyancy buoyancy);
// "plain or mixture" (for error messages).
std::string hindrance_buoyancy_names();
// Whether a deck may name this hindrance for this law (the list's hindrances column).
bool law_takes_hindrance(DragLaw law, Hindrance hindrance);
// Why a law does not take a hindrance and what to name instead, for an error message that starts
// "law L takes no hindrance H" (law_takes_hindrance must be false).
std::string hindrance_refusal(DragLaw law, Hindrance hindrance);

struct Fluid {
  double density = 0.0;         // rho_f
  double viscosity = 0.0;       // mu (Newtonian) or plastic viscosity eta_B (Bingham)
  double yield_stress = 0.0;    // tau_y; 0 for a Newtonian fluid
};

// Cd * Re and Re times its derivative with respect to Re (in this form no law divides by Re).
struct DragCurve {
  double g;
  double re_dg;
};

constexpr double ln10 = 2.30258509299404568402;

// Reynolds numbers where the faithful laws switch branch.
constexpr double schiller_naumann_switch = 1000.0;
constexpr double zhang_li_low = 1.0;
constexpr double zhang_li_high = 150.0;

// Schiller-Naumann's Cd Re given power = Re^0.687 (used below the switch only): a batch takes the
// powers from exp_many and log_many, one sphere from std::pow.
constexpr double schiller_naumann_exponent = 0.687;
[[gnu::always_inline]] inline DragCurve schiller_naumann_curve(double re, double power)
{
  if (re <= schiller_naumann_switch) {
    const double p = 0.15 * power;
    return {24.0 * (1.0 + p), 24.0 * schiller_naumann_exponent * p};
  }
  return {0.44 * re, 0.44 * re};
}

// The standard drag curve of a sphere: Clift, Grace & Weber's (1978, Table 5.2) recommended
// correlation, fitted to critically selected measurements, made continuous (docs/physics.md 2.1):
//   Re < 25.66:       Cd Re / 24 = 1 + 0.1315 Re^(0.82 - 0.05 w),  w = log10 Re  (their piece for
//                     0.01 < Re <= 20, kept down to Re -> 0, where it tends to Stokes' 24 / Re, and up
//                     to where it meets the next piece, 0.74 % below theirs at Re = 20 at most)
//   25.66 <= Re < 260: Cd Re / 24 = 1 + 0.1935 Re^0.6305
//   Re >= 260:         log10 Cd = a polynomial in w per range, the constant terms moved by at most
//                     3.3e-4 (0.07 % in Cd) so that each range starts where the last ends.
// Every piece is one power or exponential: the caller gives ln Re (NaN stays NaN; ln Re below -700,
// Re = 0 included, is the Stokes limit) and the exponential of argument().
namespace standard_curve {
constexpr double low_to_mid = 25.661577155540865;    // where the two lower pieces cross
constexpr double mid_to_high = 260.0;
constexpr double log_low_coeff = -2.028748427364318;    // ln 0.1315
constexpr double log_mid_coeff = -1.6424777665123005;    // ln 0.1935
constexpr double mid_power = 0.6305;
struct Range {
  double upper;    // Reynolds number where the next range starts
  double c[4];     // log10 Cd = c0 + c1 w + c2 w^2 + c3 w^3
};
constexpr Range high[4] = {
    {1.5e3, {1.6434605163278249, -1.1242, 0.1558, 0.0}},
    {1.2e4, {-2.4574219625021343, 2.5558, -0.9295, 0.1049}},
    {4.4e4, {-1.91838447528945, 0.637, -0.0636, 0.0}},
    {1e300, {-4.3392290555769892, 1.5809, -0.1546, 0.0}},
};
[[gnu::always_inline]] inline const Range &range_of(double re)
{
  return re < high[0].upper ? high[0] : re < high[1].upper ? high[1] : re < high[2].upper ? high[2] : high[3];
}
[[gnu::always_inline]] inline double clamp_log(double log_re) { return log_re < -700.0 ? -700.0 : log_re; }
// The lowest piece (Re < low_to_mid, where a settling grain's Reynolds number mostly is) on its own,
// for a batch that lies wholly in it: no look-up of the ranges above.
[[gnu::always_inline]] inline double low_argument(double log_re)
{
  const double w = log_re * (1.0 / ln10);
  return log_low_coeff + (0.82 - 0.05 * w) * log_re;
}
[[gnu::always_inline]] inline DragCurve low_curve(double log_re, double power)
{
  const double w = log_re * (1.0 / ln10);
  return {24.0 * (1.0 + power), 24.0 * power * (0.82 - 0.1 * w)};
}
// The argument whose exponential the piece of Re needs.
[[gnu::always_inline]] inline double argument(double re, double log_re)
{
  const double w = log_re * (1.0 / ln10);
  if (re < low_to_mid) return low_argument(log_re);
  if (re < mid_to_high) return log_mid_coeff + mid_power * log_re;
  const Range &r = range_of(re);
  return log_re + ln10 * (r.c[0] + w * (r.c[1] + w * (r.c[2] + w * r.c[3])));
}
// Cd Re and Re d(Cd Re)/dRe from Re, ln Re and the exponential of argument().
[[gnu::always_inline]] inline DragCurve curve(double re, double log_re, double power)
{
  const double w = log_re * (1.0 / ln10);
  if (re < low_to_mid) return low_curve(log_re, power);
  if (re < mid_to_high) return {24.0 * (1.0 + power), 24.0 * mid_power * power};
  const Range &r = range_of(re);
  return {power, power * (1.0 + r.c[1] + w * (2.0 * r.c[2] + 3.0 * w * r.c[3]))};
}
inline DragCurve curve(double re)
{
  const double log_re = clamp_log(std::log(re));
  return curve(re, log_re, std::exp(argument(re, log_re)));
}
}    // namespace standard_curve

// SEDIMENT's law for a sphere in a Bingham fluid (docs/physics.md 4.1), continuous and increasing in s:
//   F = (pi d^2 / 8) [ (eta s / d) G_std(Re_w) + tau_y H(Re_w) ],   Re_w = rho s^2 / (w tau_y + eta s / d),
//   H = 4 / (3 Y_c) + rise x / (1 + x),   x = w Re_w.
// The plastic viscosity's part is the standard curve of a sphere (so a Newtonian fluid gets exactly
// the `standard` law), at a Reynolds number in which the yield stress counts with the weight w; the
// yield stress's part holds a sphere at rest up to Beris et al.'s (1985) critical yield number
// Y_c = 0.048 (full flow simulations of creeping flow) and rises by `rise` where inertia starts to
// count: x = rho s^2 / (tau_y + eta s / (w d)) is Dedegil's Re' where the yield stress dominates, and
// Zhang & Li's law jumps at Re' = 1. w and rise are fitted on Valentik & Whitmore's (1965) suspensions
// 1, 3 and 5 alone by benchmarks/fit_bingham.py (its output: docs/physics.md 4.1).
namespace bingham_law {
constexpr double critical_yield_number = 0.048;
constexpr double static_curve = 4.0 / (3.0 * critical_yield_number);    // H(0)
struct Constants {
  double yield_weight;    // w
  double rise;
};
constexpr Constants fitted{0.0101, 8.05};
// H and Re dH/dRe.
[[gnu::always_inline]] inline DragCurve yield_curve(double re, Constants constants)
{
  const double x = constants.yield_weight * re;
  const double inverse = 1.0 / (1.0 + x);
  const double share = x * inverse;
  return {static_curve + constants.rise * share, constants.rise * share * inverse};
}
}    // namespace bingham_law

// The Reynolds numbers Re' at which a curve's Cd jumps (where a step may have to stop), in increasing order.
constexpr int max_curve_jumps = 2;
struct CurveJumps {
  int count = 0;
  double reynolds[max_curve_jumps] = {0.0, 0.0};
};

// Each law's own single-sphere curve: Cd Re and Re (Cd Re)' at Re (at()), and where Cd jumps. Always
// inline: the integrator's per-atom loops evaluate it with the law fixed for the whole run, in the
// vectors of their instruction set (GCC 12 kept it out of line, a call per sphere into SSE code).
// A law that takes another's curve (the list's third column) has none of its own.
template <DragLaw law> struct LawCurve;
template <> struct LawCurve<DragLaw::Stokes> {
  static constexpr CurveJumps jumps{};
  [[gnu::always_inline]] static DragCurve at(double) { return {24.0, 0.0}; }
};
template <> struct LawCurve<DragLaw::SchillerNaumann> {
  static constexpr CurveJumps jumps{1, {schiller_naumann_switch}};
  [[gnu::always_inline]] static DragCurve at(double re)
  {
    return schiller_naumann_curve(re, re <= schiller_naumann_switch ? std::pow(re, schiller_naumann_exponent) : 0.0);
  }
};
template <> struct LawCurve<DragLaw::Standard> {
  static constexpr CurveJumps jumps{};
  [[gnu::always_inline]] static DragCurve at(double re) { return standard_curve::curve(re); }
};
template <> struct LawCurve<DragLaw::Dallavalle> {
  static constexpr CurveJumps jumps{};
  [[gnu::always_inline]] static DragCurve at(double re)
  {
    // Cd = (0.63 + 4.8 / sqrt(Re))^2  =>  Cd Re = (0.63 sqrt(Re) + 4.8)^2
    const double root = std::sqrt(re);
    const double inner = 0.63 * root + 4.8;
    return {inner * inner, 0.63 * inner * root};
  }
};
template <> struct LawCurve<DragLaw::ZhangLi> {
  static constexpr CurveJumps jumps{2, {zhang_li_low, zhang_li_high}};
  [[gnu::always_inline]] static DragCurve at(double re)
  {
    if (re < zhang_li_low) return {24.0, 0.0};
    if (re <= zhang_li_high) return {29.12 + 0.195 * re, 0.195 * re};
    return {0.4 * re, 0.4 * re};
  }
};
template <> struct LawCurve<DragLaw::ZhangLiSmooth> {
  static constexpr CurveJumps jumps{};
  // Continuous variant: a linear ramp of Cd Re from 24 to 29.315 over Re' < 1, then
  // Cd = max(29.12 / Re' + 0.195, 0.4). Same static force and same law for 1 <= Re' <= 142.
  [[gnu::always_inline]] static DragCurve at(double re)
  {
    if (re < zhang_li_low) return {24.0 + 5.315 * re, 5.315 * re};
    if (29.12 + 0.195 * re >= 0.4 * re) return {29.12 + 0.195 * re, 0.195 * re};
    return {0.4 * re, 0.4 * re};
  }
};

// The list's columns of one law, and where its curve jumps.
struct DragLawTraits {
  const char *name;
  DragLaw curve;               // the law whose LawCurve it takes
  Hindrance own_hindrance;     // None: the deck's
  HindranceSet hindrances;     // those a deck may name
  bool bingham_fluid;          // a law for a sphere in a Bingham fluid
  CurveJumps jumps;
};
inline constexpr DragLawTraits drag_law_table[] = {
#define SEDIMENT_LAW_TRAITS(Law, name, Curve, own_hindrance, hindrances, bingham_fluid) \
  {name, DragLaw::Curve, Hindrance::own_hindrance, hindrances, bingham_fluid, LawCurve<DragLaw::Curve>::jumps},
    SEDIMENT_DRAG_LAWS(SEDIMENT_LAW_TRAITS)
#undef SEDIMENT_LAW_TRAITS
};
constexpr const DragLawTraits &drag_law_traits(DragLaw law) { return drag_law_table[static_cast<int>(law)]; }
// The names of the laws whose traits pass `keep`, the last after " or " (for error messages).
std::string drag_law_names(bool (*keep)(const DragLawTraits &));

// A branch per law for the switches on a law chosen at run time (drag_curve, DragModel::single_curves),
// which are given a law whose curve is its own: a law built on another's curve takes none, so that
// each curve's code is there once, as the per-block loops want it (drag_law_table's static_assert).
#define SEDIMENT_CURVE_BRANCH(Law, Curve, ...)                               \
  case DragLaw::Law:                                                         \
    if constexpr (DragLaw::Law != DragLaw::Curve) __builtin_unreachable(); \
    return __VA_ARGS__;

// Cd Re' and Re' (Cd Re')' of a law's own curve (a DragModel's single_law(); of any law:
// drag_law_traits(law).curve).
[[gnu::always_inline]] inline DragCurve drag_curve(DragLaw law, double re)
{
  switch (law) {
#define SEDIMENT_LAW_CURVE(Law, name, Curve, ...) SEDIMENT_CURVE_BRANCH(Law, Curve, LawCurve<DragLaw::Curve>::at(re))
    SEDIMENT_DRAG_LAWS(SEDIMENT_LAW_CURVE)
#undef SEDIMENT_LAW_CURVE
  }
  return {24.0, 0.0};
}
double drag_coefficient(DragLaw law, double re);

// A speed at which the force curve jumps (Cd discontinuity), with the one-sided forces.
struct ForceJump {
  double speed;
  double force_below;
  double force_above;
};

// Per-sphere surroundings: projected-area and yield (wetted-surface) scale factors, both 1 for a
// fully immersed sphere, and the local fluid fraction eps = 1 - phi (used by the Di Felice law).
struct DragScale {
  double area = 1.0;
  double wetted = 1.0;
  double voidage = 1.0;
};
// The voidage around a sphere from the local solid fraction, capped at max_fraction (where grains stop
// on a floor without contacts their grid fraction exceeds any packing, even 1).
[[gnu::always_inline]] inline double voidage_of(double fraction, double max_fraction) { return 1.0 - std::clamp(fraction, 0.0, max_fraction); }

// Di Felice (1994) exponent chi(Re) = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2) and Re d chi / d Re.
struct Exponent {
  double value;
  double re_slope;
};
// chi from t = 1.5 - log10 Re and gauss = exp(-t^2 / 2).
[[gnu::always_inline]] inline Exponent di_felice_exponent(double t, double gauss)
{
  const double bump = 0.65 * gauss;
  return {3.7 - bump, -bump * t / ln10};    // Re d/dRe of -bump = -bump t / ln 10
}
inline Exponent di_felice_exponent(double re)
{
  if (!(re > 0.0)) return {3.7, 0.0};
  const double t = 1.5 - std::log10(re);
  return di_felice_exponent(t, std::exp(-0.5 * t * t));
}

// A Richardson-Zaki exponent n(Re) = (low + high K) / (1 + K), K = scale Re^power, smooth between its
// low- and high-Re limits: Rowe (1987) 4.7 to 2.34, Garside & Al-Dibouni (1977) 5.1 to 2.7.
struct ExponentFit {
  double low, high, scale, power;
};
constexpr ExponentFit rowe_exponent{4.7, 0.41 / 0.175, 0.175, 0.75};
constexpr ExponentFit garside_exponent{5.1, 2.7, 0.1, 0.9};
// n and Re dn/dRe from k = K (scale Re^power).
[[gnu::always_inline]] inline Exponent richardson_zaki_exponent(const ExponentFit &fit, double k)
{
  const double inverse = 1.0 / (1.0 + k);
  return {(fit.low + fit.high * k) * inverse, (fit.high - fit.low) * fit.power * k * inverse * inverse};
}
inline Exponent richardson_zaki_exponent_at(const ExponentFit &fit, double re)
{
  return richardson_zaki_exponent(fit, re > 0.0 ? fit.scale * std::pow(re, fit.power) : 0.0);
}

class DragModel {
 public:
  static constexpr int max_jumps = max_curve_jumps;

  // A law that carries a hindrance (difelice) takes it whatever `hindrance` says; any other law
  // takes `hindrance` (law_takes_hindrance must hold). `bingham` takes its fitted
  // constants (another set: benchmarks/fit_bingham.py trying them).
  DragModel(DragLaw law, const Fluid &fluid, HindranceBuoyancy buoyancy = HindranceBuoyancy::Plain,
            Hindrance hindrance = Hindrance::None, bingham_law::Constants bingham = bingham_law::fitted);

  DragLaw law() const { return law_; }
  DragLaw single_law() const { return single_law_; }    // whose single-sphere curve (Dallavalle's for DiFelice)
  Hindrance hindrance() const { return hindrance_; }
  const Fluid &fluid() const { return fluid_; }

  double reynolds(double d, double speed) const;
  // Resisting force magnitude for speed > 0 (limit from above at speed = 0).
  double force(double d, double speed, DragScale scale = {}) const;
  // dF/ds for speed >= 0 (right derivative at 0).
  double tangent(double d, double speed, DragScale scale = {}) const;
  // force() and tangent() at the same speed from one evaluation of the law (the costly part with
  // the Di Felice hindrance); the same values, bit for bit.
  struct ForceSlope {
    double force;
    double slope;
  };
  ForceSlope force_and_tangent(double d, double speed, DragScale scale = {}) const;
  // True when F(s) is single-valued and continuous: no yield stress and no Cd jump, so a step
  // needs no event handling (Stokes, Dallavalle, Di Felice, zhang-li/smooth in a Newtonian fluid).
  bool smooth() const { return smooth_; }
  // True for `bingham`, whose yield stress's part has a curve of its own (yield_curve), scaled with the
  // wetted surface, and whose Reynolds number weighs the yield stress by yield_weight(); false for the
  // Dedegil form, where both parts share G(Re') and the area's scale.
  bool split_yield() const { return split_yield_; }
  double yield_weight() const { return yield_weight_; }
  // H(Re) and Re H'(Re) of the yield stress's part under `bingham` (G of the law otherwise).
  DragCurve yield_curve(double re) const { return bingham_law::yield_curve(re, {yield_weight_, yield_rise_}); }
  // yield_curve() of n spheres.
  [[gnu::always_inline]] void yield_curves(const double *re, DragCurve *out, int n) const
  {
    for (int k = 0; k < n; ++k) out[k] = bingham_law::yield_curve(re[k], {yield_weight_, yield_rise_});
  }
  // Every law is F(s) = F_y + k (s + s_y) G(Re'), Re' = K s^2 / (s + s_y), with k = s_A pi eta d / 8,
  // K = rho d / eta, the yield force F_y = s_w (pi d / 2)^2 tau_y and the yield speed s_y = tau_y d / eta
  // (both 0 in a Newtonian fluid, where Re = K s): a step takes its rates from k, G and Re G' without
  // dividing by the slip where there is no yield stress. Under `bingham`, F(s) = k s G(Re_w) +
  // k_w s_y H(Re_w), Re_w = K s^2 / (s + w s_y), k_w = s_w pi eta d / 8 and no F_y.
  double smooth_drag_per_speed(double d, DragScale scale) const { return scale.area * pi / 8.0 * fluid_.viscosity * d; }
  double smooth_reynolds_per_speed(double d) const { return density_per_viscosity_ * d; }
  double yield_force(double d, DragScale scale) const
  {
    return split_yield_ ? 0.0 : scale.wetted * (pi * pi * d * d / 4.0 * fluid_.yield_stress);
  }
  double yield_speed(double d) const { return yield_per_viscosity_ * d; }
  // The Reynolds numbers Re' at which Cd jumps (where a step may have to stop: jumps()), in increasing order.
  using Switches = CurveJumps;
  const Switches &switches() const { return switches_; }
  // Cd Re' of the law at this sphere, with the hindrance when it applies.
  DragCurve curve(double re, double voidage) const
  {
    if (!hindered(voidage)) return drag_curve(single_law_, re);
    const double log_eps = std::log(voidage);
    if (hindrance_ == Hindrance::DiFelice) {
      const Exponent chi = di_felice_exponent(re);
      return hindered_curve(drag_curve(single_law_, re), chi, log_eps,
                            std::exp(-(chi.value + hindrance_offset_) * log_eps));
    }
    const Exponent n = richardson_zaki_exponent_at(exponent_fit_, re);
    const double stretch = std::exp(-n.value * log_eps);    // eps^-n
    return stretched_curve(drag_curve(single_law_, stretch * re), n, log_eps, stretch, voidage);
  }
  // curve() of n spheres at once, the hindrance's logarithms and exponentials taken together
  // (exp_many, log_many, of this kind): within a few ulp of curve(). Inline, so that the loops run
  // in the vectors of the caller's instruction set (DragBlock's AVX2 step).
  [[gnu::always_inline]] void curves(const double *re, const double *voidage, DragCurve *out, int n,
                                     BatchMath kind = batch_math_kind()) const
  {
    if (hindrance_ == Hindrance::RichardsonZaki || hindrance_ == Hindrance::Garside)
      return stretched_curves(re, voidage, out, n, kind);
    single_curves(re, out, n, kind);
    hinder(re, voidage, out, n, kind);
  }
  // The two parts of curves() under no or Di Felice's hindrance. The single-sphere curves inline, for
  // a caller's loop compiled for its own instruction set; the law is fixed outside the loop, so each
  // law's loop is vectorised (with the switch inside, each sphere took an indirect jump and stayed
  // scalar), and the powers of Schiller-Naumann and the standard curve come from exp_many and
  // log_many of this kind.
  [[gnu::always_inline]] void single_curves(const double *re, DragCurve *out, int n, BatchMath kind) const
  {
    switch (single_law_) {
#define SEDIMENT_LAW_CURVES(Law, name, Curve, ...) \
  SEDIMENT_CURVE_BRANCH(Law, Curve, curves_of<DragLaw::Curve>(re, out, n, kind))
      SEDIMENT_DRAG_LAWS(SEDIMENT_LAW_CURVES)
#undef SEDIMENT_LAW_CURVES
    }
  }
  // The standard curve of m <= 64 spheres from their Re and ln Re (log_re is overwritten).
  [[gnu::always_inline]] static void standard_curves(const double *re, double *log_re, DragCurve *out, int m,
                                                     BatchMath kind)
  {
    double power[64];
    // A chunk wholly on the lowest piece (most, in a settling test) takes it without the selects
    // and table look-ups of the others (a quarter of the block's step under this law).
    std::int64_t all_low = 1;
    for (int j = 0; j < m; ++j) all_low &= re[j] < standard_curve::low_to_mid;
    if (all_low) {
      for (int j = 0; j < m; ++j) {
        log_re[j] = standard_curve::clamp_log(log_re[j]);
        power[j] = standard_curve::low_argument(log_re[j]);
      }
      exp_many(power, power, m, kind);
      for (int j = 0; j < m; ++j) out[j] = standard_curve::low_curve(log_re[j], power[j]);
      return;
    }
    for (int j = 0; j < m; ++j) {
      log_re[j] = standard_curve::clamp_log(log_re[j]);
      power[j] = standard_curve::argument(re[j], log_re[j]);
    }
    exp_many(power, power, m, kind);
    for (int j = 0; j < m; ++j) out[j] = standard_curve::curve(re[j], log_re[j], power[j]);
  }
  // Di Felice's hindrance applied to single-sphere curves (nothing under another law), each stage one
  // loop over a chunk of spheres with no gather of the hindered ones: an unhindered sphere (eps >= 1)
  // takes ln 1 = 0 and e^-0 = 1, so its curve comes out unchanged, bit for bit. Inline, so that the
  // loops run in the vectors of the caller's instruction set (DragBlock's AVX2 step).
  [[gnu::always_inline]] void hinder(const double *re, const double *voidage, DragCurve *out, int n,
                                     BatchMath kind) const
  {
    if (hindrance_ != Hindrance::DiFelice) return;
    constexpr int chunk = 64;
    double log_re[chunk], log_eps[chunk], t[chunk], gauss[chunk], value[chunk], slope[chunk], factor[chunk];
    for (int start = 0; start < n; start += chunk) {
      const int m = std::min(n - start, chunk);
      std::int64_t any = 0;    // a chunk in clear fluid costs nothing (64 bits, as a lane: one vector loop)
      for (int j = 0; j < m; ++j) any |= hindered(voidage[start + j]);
      if (!any) continue;
      for (int j = 0; j < m; ++j) {
        log_re[j] = re[start + j] > 0.0 ? re[start + j] : 1.0;    // chi is 3.7 at Re = 0 (see di_felice_exponent)
        log_eps[j] = std::min(voidage[start + j], 1.0);           // eps >= 1: no hindrance; NaN stays NaN
      }
      log_many(log_re, log_re, m, kind);
      log_many(log_eps, log_eps, m, kind);
      for (int j = 0; j < m; ++j) {
        t[j] = 1.5 - log_re[j] * (1.0 / ln10);
        gauss[j] = -0.5 * t[j] * t[j];
      }
      exp_many(gauss, gauss, m, kind);
      for (int j = 0; j < m; ++j) {
        const Exponent chi = re[start + j] > 0.0 ? di_felice_exponent(t[j], gauss[j]) : Exponent{3.7, 0.0};
        value[j] = chi.value;
        slope[j] = chi.re_slope;
        factor[j] = -(chi.value + hindrance_offset_) * log_eps[j];
      }
      exp_many(factor, factor, m, kind);
      for (int j = 0; j < m; ++j)
        out[start + j] = hindered_curve(out[start + j], {value[j], slope[j]}, log_eps[j], factor[j]);
    }
  }
  // The Richardson-Zaki hindrances for n spheres: each chunk's exponents, stretches eps^-n and
  // stretched Reynolds numbers in loops over the chunk, then the single-sphere curves at those
  // numbers. An unhindered sphere (eps >= 1) takes ln 1 = 0, a stretch of 1 and its own curve.
  [[gnu::always_inline]] void stretched_curves(const double *re, const double *voidage, DragCurve *out, int n,
                                               BatchMath kind) const
  {
    constexpr int chunk = 64;
    double log_re[chunk], log_eps[chunk], k[chunk], stretch[chunk], stretched_re[chunk], value[chunk],
        slope[chunk];
    for (int start = 0; start < n; start += chunk) {
      const int m = std::min(n - start, chunk);
      std::int64_t any = 0;    // a chunk in clear fluid costs its curves alone (one vector loop)
      for (int j = 0; j < m; ++j) any |= hindered(voidage[start + j]);
      if (!any) {
        single_curves(re + start, out + start, m, kind);
        continue;
      }
      // eps >= 1: no hindrance; NaN stays NaN
      for (int j = 0; j < m; ++j) log_eps[j] = std::min(voidage[start + j], 1.0);
      log_many(re + start, log_re, m, kind);    // ln 0 = -inf and e^-inf = 0: K = 0 at rest
      log_many(log_eps, log_eps, m, kind);
      for (int j = 0; j < m; ++j) k[j] = exponent_fit_.power * log_re[j] + log_scale_;
      exp_many(k, k, m, kind);
      for (int j = 0; j < m; ++j) {
        const Exponent e = richardson_zaki_exponent(exponent_fit_, k[j]);
        value[j] = e.value;
        slope[j] = e.re_slope;
        stretch[j] = -e.value * log_eps[j];
      }
      // The standard curve takes ln(S Re) as ln Re + ln S, ln S being the exponent just taken: one
      // logarithm less (within round-off of curve(), which takes the logarithm of S Re).
      if (single_law_ == DragLaw::Standard)
        for (int j = 0; j < m; ++j) log_re[j] += stretch[j];
      exp_many(stretch, stretch, m, kind);
      for (int j = 0; j < m; ++j) stretched_re[j] = stretch[j] * re[start + j];
      if (single_law_ == DragLaw::Standard)
        standard_curves(stretched_re, log_re, out + start, m, kind);
      else
        single_curves(stretched_re, out + start, m, kind);
      for (int j = 0; j < m; ++j)
        out[start + j] = stretched_curve(out[start + j], {value[j], slope[j]}, log_eps[j], stretch[j],
                                         std::min(voidage[start + j], 1.0));
    }
  }
  // F(0+): the largest force a sphere at rest resists (zero for a Newtonian fluid).
  double static_force(double d, DragScale scale = {}) const;
  // c when F(s) = c s exactly (Stokes in a Newtonian fluid), else 0.
  double linear_coefficient(double d, DragScale scale = {}) const
  {
    if (law_ != DragLaw::Stokes || fluid_.yield_stress > 0.0 || hindrance_ != Hindrance::None) return 0.0;
    return scale.area * 3.0 * pi * fluid_.viscosity * d;
  }
  // F(s) / s of n wholly immersed spheres in a Newtonian fluid (no yield stress), diameters d, slip
  // speeds s >= 0 and voidages of the hindrance, from curves() in chunks: within a few ulp of
  // force(d, s, scale) / s with scale.voidage (its limit at s = 0). Any law, jumps of Cd included: a
  // sphere's own drag, not a step across them.
  void drags_per_speed(const double *d, const double *speed, const double *voidage, double *out, int n,
                       BatchMath kind = batch_math_kind()) const;
  // Jumps of F in increasing speed; returns how many were written.
  int jumps(double d, std::array<ForceJump, max_jumps> &out, DragScale scale = {}) const;

 private:
  // single_curves' loops for one law's curve, fixed at compile time: a sphere at a time, or for the
  // curves with a power of Re, the powers of a chunk from exp_many and log_many of this kind.
  template <DragLaw law>
  [[gnu::always_inline]] static void curves_of(const double *re, DragCurve *out, int n, BatchMath kind)
  {
    constexpr int chunk = 64;
    if constexpr (law == DragLaw::SchillerNaumann) {
      double power[chunk];
      for (int start = 0; start < n; start += chunk) {
        const int m = std::min(n - start, chunk);
        log_many(re + start, power, m, kind);    // Re = 0: ln 0 = -inf, and e^-inf = 0 = 0^0.687
        for (int j = 0; j < m; ++j) power[j] *= schiller_naumann_exponent;
        exp_many(power, power, m, kind);
        for (int j = 0; j < m; ++j) out[start + j] = schiller_naumann_curve(re[start + j], power[j]);
      }
    } else if constexpr (law == DragLaw::Standard) {
      double log_re[chunk];
      for (int start = 0; start < n; start += chunk) {
        const int m = std::min(n - start, chunk);
        log_many(re + start, log_re, m, kind);
        standard_curves(re + start, log_re, out + start, m, kind);
      }
    } else {
      for (int k = 0; k < n; ++k) out[k] = LawCurve<law>::at(re[k]);
    }
  }
  bool hindered(double voidage) const { return hindrance_ != Hindrance::None && !(voidage >= 1.0); }
  // G eps^-(chi(Re) + offset), factor = eps^-(chi + offset): the exponent depends on Re, so the
  // slope has a second term.
  static DragCurve hindered_curve(DragCurve single, Exponent chi, double log_eps, double factor)
  {
    return {single.g * factor, (single.re_dg - single.g * log_eps * chi.re_slope) * factor};
  }
  // G_h(Re) = P G(S Re) with the stretch S = eps^-n(Re) and P = S (plain buoyancy) or S eps (mixture),
  // from the single curve at S Re: Re G_h' = L G_h + P (1 + L) (S Re) G'(S Re), L = -ln(eps) Re n'(Re).
  DragCurve stretched_curve(DragCurve at_stretched, Exponent n, double log_eps, double stretch, double voidage) const
  {
    const double prefactor = hindrance_offset_ > 0.0 ? stretch : stretch * voidage;
    const double l = -log_eps * n.re_slope;
    const double g = prefactor * at_stretched.g;
    return {g, l * g + prefactor * (1.0 + l) * at_stretched.re_dg};
  }
  double viscous_scale(double d, double speed) const;    // w tau_y + eta s / d (w = 1 but under `bingham`)
  double speed_at_reynolds(double d, double re) const;  // inverse of reynolds()
  // F from the curves of the viscous and the yield part (the same curve but under `bingham`).
  double force_at(double d, double speed, double g, double g_yield, DragScale scale) const;
  // dF/ds from the law's curves evaluated at this speed.
  double slope_at(double d, double speed, DragCurve g, DragCurve g_yield, DragScale scale) const;
  // The curve of the yield part at Re: yield_curve() under `bingham`, else `single` (the law's own).
  DragCurve yield_part(double re, DragCurve single) const { return split_yield_ ? yield_curve(re) : single; }

  DragLaw law_;
  DragLaw single_law_;
  Hindrance hindrance_;
  ExponentFit exponent_fit_;    // of a Richardson-Zaki hindrance
  double log_scale_;            // ln of its scale
  double hindrance_offset_;    // 1: plain buoyancy, 0: mixture
  Fluid fluid_;
  double density_per_viscosity_;    // rho / eta (0 without viscosity)
  double yield_per_viscosity_;      // tau_y / eta (0 without viscosity)
  bool split_yield_;                // `bingham`
  double yield_weight_;             // w of the Reynolds number (1 but under `bingham`)
  double yield_rise_;               // rise of H under `bingham`
  Switches switches_;
  bool smooth_;
};

// Linear relaxation time m / F'(0) of a sphere of density rho_p (Stokes: rho_p d^2 / (18 mu)).
double relaxation_time(const DragModel &model, double d, double particle_density);

// Largest time step at which explicit (forward) drag on a sphere of mass m at slip speed s is
// stable: 2 m / F', with F' the steeper of the tangents at s and at rest (2 tau for Stokes).
double explicit_step_limit(const DragModel &model, double d, double speed, double mass, DragScale scale = {});

// Rate k of the Stokes rotlet torque -pi mu d^3 omega on a solid sphere of mass m, written as
// torque = -k I omega, scaled by the wetted fraction of its surface.
double rotation_drag_rate(double viscosity, double d, double mass, double wetted = 1.0);

}    // namespace sediment
