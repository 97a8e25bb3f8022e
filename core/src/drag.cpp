// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/drag.hpp"

#include "sediment/geometry.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>

namespace sediment {

namespace {

// A choice and its name in decks and on the command line.
template <class Choice> struct Named {
  Choice value;
  const char *name;
};

constexpr Named<DragLaw> law_names[] = {
#define SEDIMENT_NAMED_LAW(Law, name, ...) {DragLaw::Law, name},
    SEDIMENT_DRAG_LAWS(SEDIMENT_NAMED_LAW)
#undef SEDIMENT_NAMED_LAW
};

constexpr Named<Hindrance> hindrance_names_table[] = {
#define SEDIMENT_NAMED_HINDRANCE(Hindrance_, name) {Hindrance::Hindrance_, name},
    SEDIMENT_HINDRANCES(SEDIMENT_NAMED_HINDRANCE)
#undef SEDIMENT_NAMED_HINDRANCE
};

constexpr Named<HindranceBuoyancy> buoyancy_names[] = {
#define SEDIMENT_NAMED_BUOYANCY(Buoyancy, name) {HindranceBuoyancy::Buoyancy, name},
    SEDIMENT_HINDRANCE_BUOYANCIES(SEDIMENT_NAMED_BUOYANCY)
#undef SEDIMENT_NAMED_BUOYANCY
};

// The table is indexed by the enumerator (drag_law_traits): its order is the enum's.
constexpr bool table_in_enum_order()
{
  for (const auto &entry : law_names)
    if (drag_law_table[static_cast<int>(entry.value)].name != entry.name) return false;
  return true;
}
static_assert(table_in_enum_order(), "drag_law_table and DragLaw come from the same list");
// The switches on a law's own curve (SEDIMENT_CURVE_BRANCH) have a branch for each law a curve column names.
constexpr bool curves_are_their_own()
{
  for (const auto &law : drag_law_table)
    if (drag_law_traits(law.curve).curve != law.curve) return false;
  return true;
}
static_assert(curves_are_their_own(), "a law's curve column names a law whose curve is its own");

template <class Choice, size_t n> std::optional<Choice> from_name(const Named<Choice> (&table)[n], std::string_view name)
{
  for (const auto &entry : table)
    if (name == entry.name) return entry.value;
  return std::nullopt;
}

template <class Choice, size_t n> const char *name_of(const Named<Choice> (&table)[n], Choice value)
{
  for (const auto &entry : table)
    if (value == entry.value) return entry.name;
  return "unknown";
}

// The names of the table's entries that pass `keep`, separated by `comma` and the last by `last`.
template <class Choice, size_t n, class Keep>
std::string joined_names(const Named<Choice> (&table)[n], Keep keep, const char *comma = ", ", const char *last = ", ")
{
  std::string names;
  size_t kept = 0, count = 0;
  for (const auto &entry : table) count += keep(entry.value);
  for (const auto &entry : table) {
    if (!keep(entry.value)) continue;
    if (kept > 0) names += kept + 1 == count ? last : comma;
    names += entry.name;
    ++kept;
  }
  return names;
}
template <class Choice, size_t n> std::string joined_names(const Named<Choice> (&table)[n])
{
  return joined_names(table, [](Choice) { return true; });
}

// A number as a deck writes it (1000, 1.5).
std::string number_text(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}    // namespace

std::optional<DragLaw> drag_law_from_name(std::string_view name) { return from_name(law_names, name); }
const char *drag_law_name(DragLaw law) { return name_of(law_names, law); }
std::string drag_law_names() { return joined_names(law_names); }
std::string drag_law_names(bool (*keep)(const DragLawTraits &))
{
  return joined_names(law_names, [&](DragLaw law) { return keep(drag_law_traits(law)); }, ", ", " or ");
}

std::optional<Hindrance> hindrance_from_name(std::string_view name) { return from_name(hindrance_names_table, name); }
const char *hindrance_name(Hindrance hindrance) { return name_of(hindrance_names_table, hindrance); }
std::string hindrance_names() { return joined_names(hindrance_names_table); }

std::optional<HindranceBuoyancy> hindrance_buoyancy_from_name(std::string_view name)
{
  return from_name(buoyancy_names, name);
}
const char *hindrance_buoyancy_name(HindranceBuoyancy buoyancy) { return name_of(buoyancy_names, buoyancy); }
std::string hindrance_buoyancy_names()
{
  return joined_names(buoyancy_names, [](HindranceBuoyancy) { return true; }, ", ", " or ");
}

bool law_takes_hindrance(DragLaw law, Hindrance hindrance)
{
  return (drag_law_traits(law).hindrances & hindrance_bit(hindrance)) != 0;
}

std::string hindrance_refusal(DragLaw law, Hindrance hindrance)
{
  const DragLawTraits &traits = drag_law_traits(law);
  // The laws a deck may name with this hindrance (not those that carry one of their own).
  const std::string laws = joined_names(
      law_names,
      [&](DragLaw other) {
        return drag_law_traits(other).own_hindrance == Hindrance::None && law_takes_hindrance(other, hindrance);
      },
      ", ", " or ");
  const std::string goes_with = "hindrance " + std::string(hindrance_name(hindrance)) + " goes with law " + laws;
  if (traits.own_hindrance != Hindrance::None)
    return "law " + std::string(drag_law_name(law)) + " carries hindrance " + hindrance_name(traits.own_hindrance) +
           "; " + goes_with;
  if (traits.bingham_fluid) return "the hindrances are for the Newtonian laws; " + goes_with;
  const std::string taken = joined_names(
      hindrance_names_table,
      [&](Hindrance other) { return other != Hindrance::None && law_takes_hindrance(law, other); }, ", ", " or ");
  std::string why;
  if (traits.jumps.count > 0) {
    why = "its jump in Cd at Re = ";
    for (int k = 0; k < traits.jumps.count; ++k) why += (k > 0 ? " and " : "") + number_text(traits.jumps.reynolds[k]);
    why += " would move with each sphere's fraction; ";
  }
  if (taken.empty()) return why + goes_with;
  return why + "use hindrance " + taken + ", or law " + laws;
}

double drag_coefficient(DragLaw law, double re) { return drag_curve(drag_law_traits(law).curve, re).g / re; }

DragModel::DragModel(DragLaw law, const Fluid &fluid, HindranceBuoyancy buoyancy, Hindrance hindrance,
                     bingham_law::Constants bingham) :
    law_(law),
    single_law_(drag_law_traits(law).curve),
    hindrance_(drag_law_traits(law).own_hindrance != Hindrance::None ? drag_law_traits(law).own_hindrance : hindrance),
    exponent_fit_(hindrance == Hindrance::Garside ? garside_exponent : rowe_exponent),
    log_scale_(std::log(exponent_fit_.scale)), hindrance_offset_(buoyancy == HindranceBuoyancy::Plain ? 1.0 : 0.0),
    fluid_(fluid),
    density_per_viscosity_(fluid.viscosity > 0.0 ? fluid.density / fluid.viscosity : 0.0),
    yield_per_viscosity_(fluid.viscosity > 0.0 ? fluid.yield_stress / fluid.viscosity : 0.0),
    split_yield_(law == DragLaw::Bingham), yield_weight_(split_yield_ ? bingham.yield_weight : 1.0),
    yield_rise_(bingham.rise), switches_(drag_law_traits(law).jumps),
    smooth_(fluid_.yield_stress <= 0.0 && switches_.count == 0)
{
}

double DragModel::viscous_scale(double d, double speed) const
{
  return yield_weight_ * fluid_.yield_stress + fluid_.viscosity * speed / d;
}

double DragModel::reynolds(double d, double speed) const
{
  if (speed <= 0.0) return 0.0;
  return fluid_.density * speed * speed / viscous_scale(d, speed);
}

double DragModel::speed_at_reynolds(double d, double re) const
{
  // rho s^2 - (re eta / d) s - re w tau_y = 0, positive root
  const double b = re * fluid_.viscosity / d;
  const double disc = b * b + 4.0 * fluid_.density * re * yield_weight_ * fluid_.yield_stress;
  return (b + std::sqrt(disc)) / (2.0 * fluid_.density);
}

double DragModel::force_at(double d, double speed, double g, double g_yield, DragScale scale) const
{
  const double half_area = 0.5 * sphere_area(d);
  if (!split_yield_) return yield_force(d, scale) + scale.area * half_area * viscous_scale(d, speed) * g;
  return half_area * (scale.area * fluid_.viscosity * speed / d * g + scale.wetted * fluid_.yield_stress * g_yield);
}

double DragModel::force(double d, double speed, DragScale scale) const
{
  const double re = reynolds(d, speed);
  const DragCurve g = curve(re, scale.voidage);
  return force_at(d, speed, g.g, yield_part(re, g).g, scale);
}

void DragModel::drags_per_speed(const double *d, const double *speed, const double *voidage, double *out, int n,
                                BatchMath kind) const
{
  assert(fluid_.yield_stress <= 0.0);
  constexpr int chunk = 64;
  double re[chunk];
  DragCurve g[chunk];
  for (int start = 0; start < n; start += chunk) {
    const int m = std::min(n - start, chunk);
    for (int j = 0; j < m; ++j) re[j] = smooth_reynolds_per_speed(d[start + j]) * speed[start + j];
    curves(re, voidage + start, g, m, kind);
    for (int j = 0; j < m; ++j) out[start + j] = smooth_drag_per_speed(d[start + j], {}) * g[j].g;
  }
}

double DragModel::static_force(double d, DragScale scale) const
{
  if (fluid_.yield_stress <= 0.0) return 0.0;
  const DragCurve g = curve(0.0, scale.voidage);
  return force_at(d, 0.0, g.g, yield_part(0.0, g).g, scale);
}

double DragModel::slope_at(double d, double speed, DragCurve g, DragCurve g_yield, DragScale scale) const
{
  const double half_area = 0.5 * sphere_area(d);
  const double eta_d = fluid_.viscosity / d;
  if (!split_yield_) {
    double dforce = eta_d * g.g;
    // (tau_y + eta s / d) G' dRe'/ds with dRe'/ds = Re' (2 tau_y + eta s / d) / (s (tau_y + eta s / d))
    if (speed > 0.0) dforce += g.re_dg * (2.0 * fluid_.yield_stress + fluid_.viscosity * speed / d) / speed;
    return scale.area * half_area * dforce;
  }
  // d/ds of (eta s / d) G + tau_y H at Re_w: dRe_w/ds = Re_w (2 w tau_y + eta s / d) / (s (w tau_y + eta s / d))
  double dforce = scale.area * eta_d * g.g;
  if (speed > 0.0) {
    const double yield = yield_weight_ * fluid_.yield_stress;
    const double stretch = (2.0 * yield + eta_d * speed) / (speed * (yield + eta_d * speed));
    dforce += (scale.area * eta_d * speed * g.re_dg + scale.wetted * fluid_.yield_stress * g_yield.re_dg) * stretch;
  }
  return half_area * dforce;
}

double DragModel::tangent(double d, double speed, DragScale scale) const
{
  const double re = reynolds(d, speed);
  const DragCurve g = curve(re, scale.voidage);
  return slope_at(d, speed, g, yield_part(re, g), scale);
}

DragModel::ForceSlope DragModel::force_and_tangent(double d, double speed, DragScale scale) const
{
  const double re = reynolds(d, speed);
  const DragCurve g = curve(re, scale.voidage);
  const DragCurve g_yield = yield_part(re, g);
  return {force_at(d, speed, g.g, g_yield.g, scale), slope_at(d, speed, g, g_yield, scale)};
}

int DragModel::jumps(double d, std::array<ForceJump, max_jumps> &out, DragScale scale) const
{
  const double inf = std::numeric_limits<double>::infinity();
  for (int k = 0; k < switches_.count; ++k) {
    const double re = switches_.reynolds[k];
    const double speed = speed_at_reynolds(d, re);
    const double g_below = drag_curve(single_law_, std::nextafter(re, 0.0)).g;
    const double g_above = drag_curve(single_law_, std::nextafter(re, inf)).g;
    out[k] = {speed, force_at(d, speed, g_below, g_below, scale), force_at(d, speed, g_above, g_above, scale)};
  }
  return switches_.count;
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
