// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/drag.hpp"

#include "sediment/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sediment {

namespace {

struct LawName {
  DragLaw law;
  const char *name;
};

constexpr LawName law_names[] = {
    {DragLaw::Stokes, "stokes"},
    {DragLaw::SchillerNaumann, "schiller-naumann"},
    {DragLaw::Dallavalle, "dallavalle"},
    {DragLaw::ZhangLi, "zhang-li"},
    {DragLaw::ZhangLiSmooth, "zhang-li/smooth"},
    {DragLaw::DiFelice, "difelice"},
};

// Reynolds numbers where the faithful laws switch branch.
constexpr double schiller_naumann_switch = 1000.0;
constexpr double zhang_li_low = 1.0;
constexpr double zhang_li_high = 150.0;

}    // namespace

std::optional<DragLaw> drag_law_from_name(std::string_view name)
{
  for (const auto &entry : law_names)
    if (name == entry.name) return entry.law;
  return std::nullopt;
}

const char *drag_law_name(DragLaw law)
{
  for (const auto &entry : law_names)
    if (law == entry.law) return entry.name;
  return "unknown";
}

std::string drag_law_names()
{
  std::string names;
  for (const auto &entry : law_names) {
    if (!names.empty()) names += ", ";
    names += entry.name;
  }
  return names;
}

DragCurve drag_curve(DragLaw law, double re)
{
  switch (law) {
    case DragLaw::Stokes:
      return {24.0, 0.0};
    case DragLaw::SchillerNaumann:
      if (re <= schiller_naumann_switch) {
        const double p = 0.15 * std::pow(re, 0.687);
        return {24.0 * (1.0 + p), re > 0.0 ? 24.0 * 0.687 * p / re : 0.0};
      }
      return {0.44 * re, 0.44};
    case DragLaw::Dallavalle:
    case DragLaw::DiFelice: {    // the single-sphere curve; hindrance is applied per sphere
      // Cd = (0.63 + 4.8 / sqrt(Re))^2  =>  Cd Re = (0.63 sqrt(Re) + 4.8)^2
      const double root = std::sqrt(re);
      const double inner = 0.63 * root + 4.8;
      return {inner * inner, re > 0.0 ? inner * 0.63 / root : 0.0};
    }
    case DragLaw::ZhangLi:
      if (re < zhang_li_low) return {24.0, 0.0};
      if (re <= zhang_li_high) return {29.12 + 0.195 * re, 0.195};
      return {0.4 * re, 0.4};
    case DragLaw::ZhangLiSmooth:
      // Continuous variant: a linear ramp of Cd Re from 24 to 29.315 over Re' < 1, then
      // Cd = max(29.12 / Re' + 0.195, 0.4). Same static force and same law for 1 <= Re' <= 142.
      if (re < zhang_li_low) return {24.0 + 5.315 * re, 5.315};
      if (29.12 + 0.195 * re >= 0.4 * re) return {29.12 + 0.195 * re, 0.195};
      return {0.4 * re, 0.4};
  }
  return {24.0, 0.0};
}

double drag_coefficient(DragLaw law, double re) { return drag_curve(law, re).g / re; }

Exponent di_felice_exponent(double re)
{
  if (!(re > 0.0)) return {3.7, 0.0};
  const double t = 1.5 - std::log10(re);
  const double bump = 0.65 * std::exp(-0.5 * t * t);
  // d/dRe of -bump = -bump * t / (Re ln 10)
  return {3.7 - bump, -bump * t / (re * std::log(10.0))};
}

DragModel::DragModel(DragLaw law, const Fluid &fluid, HindranceBuoyancy buoyancy) :
    law_(law), hindrance_offset_(buoyancy == HindranceBuoyancy::Plain ? 1.0 : 0.0), fluid_(fluid), smooth_(false)
{
  std::array<ForceJump, max_jumps> unused;
  smooth_ = fluid_.yield_stress <= 0.0 && jumps(1.0, unused) == 0;
}

DragCurve DragModel::curve(double re, double voidage) const
{
  const DragCurve single = drag_curve(law_, re);
  if (law_ != DragLaw::DiFelice || voidage >= 1.0) return single;
  // G eps^-(chi(Re) + offset): the exponent depends on Re, so the slope has a second term.
  const Exponent chi = di_felice_exponent(re);
  const double log_eps = std::log(voidage);
  const double factor = std::exp(-(chi.value + hindrance_offset_) * log_eps);
  return {single.g * factor, (single.dg - single.g * log_eps * chi.slope) * factor};
}

double DragModel::viscous_scale(double d, double speed) const
{
  return fluid_.yield_stress + fluid_.viscosity * speed / d;
}

double DragModel::reynolds(double d, double speed) const
{
  if (speed <= 0.0) return 0.0;
  return fluid_.density * speed * speed / viscous_scale(d, speed);
}

double DragModel::speed_at_reynolds(double d, double re) const
{
  // rho s^2 - (re eta / d) s - re tau_y = 0, positive root
  const double b = re * fluid_.viscosity / d;
  const double disc = b * b + 4.0 * fluid_.density * re * fluid_.yield_stress;
  return (b + std::sqrt(disc)) / (2.0 * fluid_.density);
}

double DragModel::force_at(double d, double speed, double g, DragScale scale) const
{
  const double yield = pi * pi * d * d / 4.0 * fluid_.yield_stress;
  return scale.wetted * yield + scale.area * 0.5 * sphere_area(d) * viscous_scale(d, speed) * g;
}

double DragModel::force(double d, double speed, DragScale scale) const
{
  return force_at(d, speed, curve(reynolds(d, speed), scale.voidage).g, scale);
}

double DragModel::static_force(double d, DragScale scale) const
{
  if (fluid_.yield_stress <= 0.0) return 0.0;
  return force_at(d, 0.0, curve(0.0, scale.voidage).g, scale);
}

double DragModel::slope_at(double d, double speed, DragCurve g, DragScale scale) const
{
  double dforce = fluid_.viscosity / d * g.g;
  if (speed > 0.0) {
    // dRe'/ds = rho s (2 tau_y + eta s / d) / (tau_y + eta s / d)^2
    const double visc = viscous_scale(d, speed);
    const double dre =
        fluid_.density * speed * (2.0 * fluid_.yield_stress + fluid_.viscosity * speed / d) /
        (visc * visc);
    dforce += visc * g.dg * dre;
  }
  return scale.area * 0.5 * sphere_area(d) * dforce;
}

double DragModel::tangent(double d, double speed, DragScale scale) const
{
  const double re = reynolds(d, speed);
  return slope_at(d, speed, curve(re, scale.voidage), scale);
}

DragModel::ForceSlope DragModel::force_and_tangent(double d, double speed, DragScale scale) const
{
  const double re = reynolds(d, speed);
  const DragCurve g = curve(re, scale.voidage);
  return {force_at(d, speed, g.g, scale), slope_at(d, speed, g, scale)};
}

int DragModel::jumps(double d, std::array<ForceJump, max_jumps> &out, DragScale scale) const
{
  double switches[max_jumps];
  int n = 0;
  if (law_ == DragLaw::ZhangLi) {
    switches[n++] = zhang_li_low;
    switches[n++] = zhang_li_high;
  } else if (law_ == DragLaw::SchillerNaumann) {
    switches[n++] = schiller_naumann_switch;
  }
  const double inf = std::numeric_limits<double>::infinity();
  for (int k = 0; k < n; ++k) {
    const double speed = speed_at_reynolds(d, switches[k]);
    const double g_below = drag_curve(law_, std::nextafter(switches[k], 0.0)).g;
    const double g_above = drag_curve(law_, std::nextafter(switches[k], inf)).g;
    out[k] = {speed, force_at(d, speed, g_below, scale), force_at(d, speed, g_above, scale)};
  }
  return n;
}

double relaxation_time(const DragModel &model, double d, double particle_density)
{
  return particle_density * sphere_volume(d) / model.tangent(d, 0.0);
}

double explicit_step_limit(const DragModel &model, double d, double speed, double mass, DragScale scale)
{
  const double slope = std::max(model.tangent(d, speed, scale), model.tangent(d, 0.0, scale));
  return 2.0 * mass / slope;
}

double rotation_drag_rate(double viscosity, double d, double mass, double wetted)
{
  return wetted * pi * viscosity * d * d * d / sphere_inertia(mass, 0.5 * d);
}

}    // namespace sediment
