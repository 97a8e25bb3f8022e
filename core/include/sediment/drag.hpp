// SPDX-License-Identifier: GPL-2.0-or-later
// Drag laws for a sphere in a Newtonian or Bingham-plastic fluid at rest.
//
// Every law is written as one resisting-force curve of the slip speed s >= 0:
//   F(s) = s_w (pi d / 2)^2 tau_y + s_A (A / 2) (tau_y + eta s / d) G(Re'),
//   Re'  = rho s^2 / (tau_y + eta s / d),   G = Cd(Re') Re',   A = pi d^2 / 4,
// which is the Dedegil form of Zhang & Li (2024) for a Bingham fluid and, with tau_y = 0, exactly
// the Newtonian drag 1/2 rho A Cd(Re) s^2 with Re = rho s d / mu (Stokes: F = 3 pi mu d s).
// s_A and s_w scale the projected area and the yield term for a partly submerged sphere.
#pragma once

#include "sediment/batch_math.hpp"
#include "sediment/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

namespace sediment {

enum class DragLaw { Stokes, SchillerNaumann, Dallavalle, ZhangLi, ZhangLiSmooth, DiFelice };

// Which buoyancy the Di Felice hindrance goes with (docs/physics.md 3.1): plain Archimedes buoyancy
// (factor eps^-(chi+1)) or buoyancy from the mixture density (factor eps^-chi).
enum class HindranceBuoyancy { Plain, Mixture };

std::optional<DragLaw> drag_law_from_name(std::string_view name);
const char *drag_law_name(DragLaw law);
// The names accepted by drag_law_from_name, separated by ", " (for error messages).
std::string drag_law_names();

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
inline DragCurve schiller_naumann_curve(double re, double power)
{
  if (re <= schiller_naumann_switch) {
    const double p = 0.15 * power;
    return {24.0 * (1.0 + p), 24.0 * schiller_naumann_exponent * p};
  }
  return {0.44 * re, 0.44 * re};
}

// Inline: the integrator's per-atom loops evaluate it with the law fixed for the whole run.
inline DragCurve drag_curve(DragLaw law, double re)
{
  switch (law) {
    case DragLaw::Stokes:
      return {24.0, 0.0};
    case DragLaw::SchillerNaumann:
      return schiller_naumann_curve(re, re <= schiller_naumann_switch ? std::pow(re, schiller_naumann_exponent) : 0.0);
    case DragLaw::Dallavalle:
    case DragLaw::DiFelice: {    // the single-sphere curve; hindrance is applied per sphere
      // Cd = (0.63 + 4.8 / sqrt(Re))^2  =>  Cd Re = (0.63 sqrt(Re) + 4.8)^2
      const double root = std::sqrt(re);
      const double inner = 0.63 * root + 4.8;
      return {inner * inner, 0.63 * inner * root};
    }
    case DragLaw::ZhangLi:
      if (re < zhang_li_low) return {24.0, 0.0};
      if (re <= zhang_li_high) return {29.12 + 0.195 * re, 0.195 * re};
      return {0.4 * re, 0.4 * re};
    case DragLaw::ZhangLiSmooth:
      // Continuous variant: a linear ramp of Cd Re from 24 to 29.315 over Re' < 1, then
      // Cd = max(29.12 / Re' + 0.195, 0.4). Same static force and same law for 1 <= Re' <= 142.
      if (re < zhang_li_low) return {24.0 + 5.315 * re, 5.315 * re};
      if (29.12 + 0.195 * re >= 0.4 * re) return {29.12 + 0.195 * re, 0.195 * re};
      return {0.4 * re, 0.4 * re};
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

// Di Felice (1994) exponent chi(Re) = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2) and Re d chi / d Re.
struct Exponent {
  double value;
  double re_slope;
};
// chi from t = 1.5 - log10 Re and gauss = exp(-t^2 / 2).
inline Exponent di_felice_exponent(double t, double gauss)
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

class DragModel {
 public:
  static constexpr int max_jumps = 2;

  DragModel(DragLaw law, const Fluid &fluid, HindranceBuoyancy buoyancy = HindranceBuoyancy::Plain);

  DragLaw law() const { return law_; }
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
  // Every law is F(s) = F_y + k (s + s_y) G(Re'), Re' = K s^2 / (s + s_y), with k = s_A pi eta d / 8,
  // K = rho d / eta, the yield force F_y = s_w (pi d / 2)^2 tau_y and the yield speed s_y = tau_y d / eta
  // (both 0 in a Newtonian fluid, where Re = K s): a step takes its rates from k, G and Re G' without
  // dividing by the slip where there is no yield stress.
  double smooth_drag_per_speed(double d, DragScale scale) const { return scale.area * pi / 8.0 * fluid_.viscosity * d; }
  double smooth_reynolds_per_speed(double d) const { return density_per_viscosity_ * d; }
  double yield_force(double d, DragScale scale) const { return scale.wetted * (pi * pi * d * d / 4.0 * fluid_.yield_stress); }
  double yield_speed(double d) const { return yield_per_viscosity_ * d; }
  // The Reynolds numbers Re' at which Cd jumps (where a step may have to stop: jumps()), in increasing order.
  struct Switches {
    int count = 0;
    double reynolds[max_jumps] = {0.0, 0.0};
  };
  const Switches &switches() const { return switches_; }
  // Cd Re' of the law at this sphere, with the Di Felice hindrance when it applies.
  DragCurve curve(double re, double voidage) const
  {
    const DragCurve single = drag_curve(law_, re);
    if (!hindered(voidage)) return single;
    const Exponent chi = di_felice_exponent(re);
    const double log_eps = std::log(voidage);
    return hindered_curve(single, chi, log_eps, std::exp(-(chi.value + hindrance_offset_) * log_eps));
  }
  // curve() of n spheres at once, the hindrance's logarithms and exponentials taken together
  // (exp_many, log_many, of this kind): within a few ulp of curve().
  void curves(const double *re, const double *voidage, DragCurve *out, int n,
              BatchMath kind = batch_math_kind()) const
  {
    single_curves(re, out, n, kind);
    hinder(re, voidage, out, n, kind);
  }
  // The two parts of curves(). The single-sphere curves inline, for a caller's loop compiled for
  // its own instruction set; the law is fixed outside the loop, so each law's loop is vectorised
  // (with the switch inside, each sphere took an indirect jump and stayed scalar), and
  // Schiller-Naumann's powers come from exp_many and log_many of this kind.
  [[gnu::always_inline]] void single_curves(const double *re, DragCurve *out, int n, BatchMath kind) const
  {
    switch (law_) {
      case DragLaw::Dallavalle:
      case DragLaw::DiFelice:
        return curves_of<DragLaw::Dallavalle>(re, out, n);
      case DragLaw::ZhangLi:
        return curves_of<DragLaw::ZhangLi>(re, out, n);
      case DragLaw::ZhangLiSmooth:
        return curves_of<DragLaw::ZhangLiSmooth>(re, out, n);
      case DragLaw::Stokes:
        return curves_of<DragLaw::Stokes>(re, out, n);
      case DragLaw::SchillerNaumann: {
        constexpr int chunk = 64;
        double power[chunk];
        for (int start = 0; start < n; start += chunk) {
          const int m = std::min(n - start, chunk);
          log_many(re + start, power, m, kind);    // Re = 0: ln 0 = -inf, and e^-inf = 0 = 0^0.687
          for (int j = 0; j < m; ++j) power[j] *= schiller_naumann_exponent;
          exp_many(power, power, m, kind);
          for (int j = 0; j < m; ++j) out[start + j] = schiller_naumann_curve(re[start + j], power[j]);
        }
        return;
      }
    }
  }
  // Di Felice's hindrance applied to single-sphere curves (nothing under another law), each stage one
  // loop over a chunk of spheres with no gather of the hindered ones: an unhindered sphere (eps >= 1)
  // takes ln 1 = 0 and e^-0 = 1, so its curve comes out unchanged, bit for bit. Inline, so that the
  // loops run in the vectors of the caller's instruction set (DragBlock's AVX2 step).
  [[gnu::always_inline]] void hinder(const double *re, const double *voidage, DragCurve *out, int n,
                                     BatchMath kind) const
  {
    if (law_ != DragLaw::DiFelice) return;
    constexpr int chunk = 64;
    double log_re[chunk], log_eps[chunk], t[chunk], gauss[chunk], value[chunk], slope[chunk], factor[chunk];
    for (int start = 0; start < n; start += chunk) {
      const int m = std::min(n - start, chunk);
      bool any = false;    // a chunk in clear fluid costs nothing
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
  // F(0+): the largest force a sphere at rest resists (zero for a Newtonian fluid).
  double static_force(double d, DragScale scale = {}) const;
  // c when F(s) = c s exactly (Stokes in a Newtonian fluid), else 0.
  double linear_coefficient(double d, DragScale scale = {}) const
  {
    if (law_ != DragLaw::Stokes || fluid_.yield_stress > 0.0) return 0.0;
    return scale.area * 3.0 * pi * fluid_.viscosity * d;
  }
  // Jumps of F in increasing speed; returns how many were written.
  int jumps(double d, std::array<ForceJump, max_jumps> &out, DragScale scale = {}) const;

 private:
  // single_curves' loop for one law, fixed at compile time.
  template <DragLaw law> [[gnu::always_inline]] static void curves_of(const double *re, DragCurve *out, int n)
  {
    for (int k = 0; k < n; ++k) out[k] = drag_curve(law, re[k]);
  }
  bool hindered(double voidage) const { return law_ == DragLaw::DiFelice && !(voidage >= 1.0); }
  // G eps^-(chi(Re) + offset), factor = eps^-(chi + offset): the exponent depends on Re, so the
  // slope has a second term.
  static DragCurve hindered_curve(DragCurve single, Exponent chi, double log_eps, double factor)
  {
    return {single.g * factor, (single.re_dg - single.g * log_eps * chi.re_slope) * factor};
  }
  double viscous_scale(double d, double speed) const;    // tau_y + eta s / d
  double speed_at_reynolds(double d, double re) const;  // inverse of reynolds()
  double force_at(double d, double speed, double g, DragScale scale) const;
  // dF/ds from the law's curve evaluated at this speed.
  double slope_at(double d, double speed, DragCurve g, DragScale scale) const;

  DragLaw law_;
  double hindrance_offset_;    // 1: eps^-(chi+1), 0: eps^-chi
  Fluid fluid_;
  double density_per_viscosity_;    // rho / eta (0 without viscosity)
  double yield_per_viscosity_;      // tau_y / eta (0 without viscosity)
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
