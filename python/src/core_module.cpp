// SPDX-License-Identifier: GPL-2.0-or-later
// sediment._core: the C++ physics core for Python. It links no LAMMPS: the styles are registered
// into a Python LAMMPS through the styles library (sediment.sim.styles).

#include "sediment/drag.hpp"
#include "sediment/flow.hpp"
#include "sediment/geometry.hpp"
#include "sediment/integrator.hpp"
#include "sediment/terminal.hpp"
#include "sediment/version.hpp"
#include "sediment/water.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <iterator>
#include <optional>
#include <stdexcept>

namespace py = pybind11;
using namespace sediment;

namespace {

// The core's lists (sediment/drag.hpp) as Python sees them.
constexpr Hindrance hindrances[] = {
#define SEDIMENT_HINDRANCE_VALUE(Value, name) Hindrance::Value,
    SEDIMENT_HINDRANCES(SEDIMENT_HINDRANCE_VALUE)
#undef SEDIMENT_HINDRANCE_VALUE
};
constexpr const char *buoyancy_names[] = {
#define SEDIMENT_BUOYANCY_NAME(Value, name) name,
    SEDIMENT_HINDRANCE_BUOYANCIES(SEDIMENT_BUOYANCY_NAME)
#undef SEDIMENT_BUOYANCY_NAME
};

HindranceBuoyancy parse_buoyancy(const std::string &name)
{
  const auto buoyancy = hindrance_buoyancy_from_name(name);
  if (buoyancy) return *buoyancy;
  std::string quoted;    // 'plain' or 'mixture'
  for (const char *choice : buoyancy_names) quoted += (quoted.empty() ? "'" : " or '") + std::string(choice) + "'";
  throw py::value_error("buoyancy must be " + quoted + ", not '" + name + "'");
}

DragScale voidage_scale(double voidage)
{
  if (!(voidage > 0.0 && voidage <= 1.0)) throw py::value_error("voidage must be in (0, 1]");
  return {1.0, 1.0, voidage};
}

DragLaw parse_law(const std::string &name)
{
  const auto law = drag_law_from_name(name);
  if (!law) throw py::value_error("unknown drag law '" + name + "' (expected one of " + drag_law_names() + ")");
  return *law;
}

Hindrance parse_hindrance(const std::string &name, DragLaw law)
{
  const auto hindrance = hindrance_from_name(name);
  if (!hindrance)
    throw py::value_error("unknown hindrance '" + name + "' (expected one of " + hindrance_names() + ")");
  if (!law_takes_hindrance(law, *hindrance))
    throw py::value_error(std::string("law ") + drag_law_name(law) + " does not take hindrance " + name + " (" +
                          hindrance_refusal(law, *hindrance) + ")");
  return *hindrance;
}

double checked_temperature(double celsius)
{
  if (!(celsius >= water_min_temperature && celsius <= water_max_temperature))
    throw py::value_error("water temperature must be within 0-40 C (the range of the correlations), not " +
                          std::to_string(celsius));
  return celsius;
}

Fluid make_fluid(double density, double viscosity, double yield_stress)
{
  if (!(density > 0.0)) throw py::value_error("fluid density must be > 0");
  if (!(viscosity > 0.0)) throw py::value_error("fluid viscosity must be > 0");
  if (!(yield_stress >= 0.0)) throw py::value_error("yield stress must be >= 0");
  return {density, viscosity, yield_stress};
}

const char *regime_name(TerminalRegime regime)
{
  switch (regime) {
    case TerminalRegime::Moving: return "moving";
    case TerminalRegime::AtRest: return "at_rest";
    case TerminalRegime::AtJump: return "at_jump";
  }
  return "moving";
}

}    // namespace

PYBIND11_MODULE(_core, m)
{
  m.doc() = "SEDIMENT physics core: drag laws, terminal velocities, submergence, time scales.";

  m.def("drag_law_names", [] {
    std::vector<std::string> names;
    for (const DragLawTraits &law : drag_law_table) names.emplace_back(law.name);
    return names;
  }, "Names of the drag laws.");
  m.def("drag_laws", [] {
    py::list laws;
    for (int k = 0; k < static_cast<int>(std::size(drag_law_table)); ++k) {
      py::list taken;
      for (Hindrance hindrance : hindrances)
        if (law_takes_hindrance(static_cast<DragLaw>(k), hindrance)) taken.append(hindrance_name(hindrance));
      py::dict law;
      law["name"] = drag_law_table[k].name;
      law["hindrances"] = taken;
      law["bingham_fluid"] = drag_law_table[k].bingham_fluid;
      laws.append(law);
    }
    return laws;
  }, "The core's list of drag laws, in its order: each law's name, the hindrances a deck may name for it "
     "('none' included) and whether it is a law for a sphere in a Bingham fluid (else a Newtonian law).");
  m.def("hindrance_names", [] {
    std::vector<std::string> names;
    for (Hindrance hindrance : hindrances) names.emplace_back(hindrance_name(hindrance));
    return names;
  }, "Names of the hindrances ('none' included).");

  m.attr("BOLTZMANN") = boltzmann;
  m.attr("VERSION") = version;
  m.def("water_density", [](double celsius) { return water_density(checked_temperature(celsius)); },
        py::arg("celsius"), "Density of water [kg/m3] at 0-40 C (Tanaka et al. 2001).");
  m.def("water_viscosity", [](double celsius) { return water_viscosity(checked_temperature(celsius)); },
        py::arg("celsius"), "Viscosity of water [Pa s] at 0-40 C (Kestin et al. 1978 with IAPWS 2008's 20 C value).");

  m.def("drag_coefficient", [](const std::string &law, double re) {
    if (!(re > 0.0)) throw py::value_error("Reynolds number must be > 0");
    return drag_coefficient(parse_law(law), re);
  }, py::arg("law"), py::arg("reynolds"), "Cd(Re) of a law (Re' for the Bingham laws).");

  py::class_<DragModel>(m, "DragModel", "Resisting-force curve of a sphere under one drag law.")
      .def(py::init([](const std::string &law, double density, double viscosity, double yield_stress,
                       const std::string &buoyancy, const std::string &hindrance, std::optional<double> yield_weight,
                       std::optional<double> yield_rise) {
             const DragLaw parsed = parse_law(law);
             bingham_law::Constants constants = bingham_law::fitted;
             if (yield_weight || yield_rise) {
               if (parsed != DragLaw::Bingham)
                 throw py::value_error("yield_weight and yield_rise are constants of law bingham, not of " + law);
               constants = {yield_weight.value_or(constants.yield_weight), yield_rise.value_or(constants.rise)};
               if (!(constants.yield_weight > 0.0) || !(constants.rise >= 0.0) || !std::isfinite(constants.rise))
                 throw py::value_error("yield_weight must be > 0 and yield_rise >= 0");
             }
             return DragModel(parsed, make_fluid(density, viscosity, yield_stress), parse_buoyancy(buoyancy),
                              parse_hindrance(hindrance, parsed), constants);
           }),
           py::arg("law"), py::arg("density"), py::arg("viscosity"), py::arg("yield_stress") = 0.0,
           py::arg("buoyancy") = "plain", py::arg("hindrance") = "none", py::arg("yield_weight") = py::none(),
           py::arg("yield_rise") = py::none(),
           "yield_weight, yield_rise: other constants for law bingham (its fit tries them; default: the fitted ones).")
      .def("reynolds", &DragModel::reynolds, py::arg("d"), py::arg("speed"))
      .def("force", [](const DragModel &model, double d, double speed, double voidage, double area,
                       double wetted) {
             DragScale scale = voidage_scale(voidage);
             if (!(area >= 0.0 && area <= 1.0 && wetted >= 0.0 && wetted <= 1.0))
               throw py::value_error("area and wetted fractions must be in [0, 1]");
             scale.area = area;
             scale.wetted = wetted;
             return model.force(d, speed, scale);
           }, py::arg("d"), py::arg("speed"), py::arg("voidage") = 1.0, py::arg("area") = 1.0,
           py::arg("wetted") = 1.0,
           "Resisting force magnitude [N] at slip speed > 0 (voidage: local fluid fraction, under a hindrance; "
           "area, wetted: submerged fractions of a sphere at a free surface, see submergence()).")
      .def("tangent", [](const DragModel &model, double d, double speed, double voidage) {
             return model.tangent(d, speed, voidage_scale(voidage));
           }, py::arg("d"), py::arg("speed"), py::arg("voidage") = 1.0, "dF/ds [N s/m].")
      .def("steady_speed", [](const DragModel &model, double d, double driving_force, double voidage) {
             const TerminalState state = steady_speed(model, d, driving_force, voidage_scale(voidage));
             return py::make_tuple(state.speed, regime_name(state.regime));
           }, py::arg("d"), py::arg("driving_force"), py::arg("voidage") = 1.0,
           "Speed where the resisting force balances a driving force [N], and the regime.")
      .def("static_force", [](const DragModel &model, double d) { return model.static_force(d); },
           py::arg("d"), "Largest force a sphere at rest resists (yield) [N].")
      .def("jumps", [](const DragModel &model, double d) {
             std::array<ForceJump, DragModel::max_jumps> jumps;
             const int n = model.jumps(d, jumps);
             py::list out;
             for (int k = 0; k < n; ++k)
               out.append(py::make_tuple(jumps[k].speed, jumps[k].force_below, jumps[k].force_above));
             return out;
           }, py::arg("d"), "Speeds where the force jumps, with the forces just below and above [(m/s, N, N)].");

  m.def("terminal_velocity",
        [](const std::string &law, double density, double viscosity, double yield_stress, double d,
           double particle_density, double g) {
          const DragModel model(parse_law(law), make_fluid(density, viscosity, yield_stress));
          if (!(d > 0.0)) throw py::value_error("diameter must be > 0");
          const TerminalState state = terminal_velocity(model, d, particle_density, g);
          return py::make_tuple(state.speed, regime_name(state.regime));
        },
        py::arg("law"), py::arg("density"), py::arg("viscosity"), py::arg("yield_stress"), py::arg("d"),
        py::arg("particle_density"), py::arg("g") = 9.81,
        "Terminal speed [m/s] and regime ('moving', 'at_rest', 'at_jump').");

  m.def("stokes_velocity", py::vectorize(stokes_velocity), py::arg("particle_density"), py::arg("fluid_density"),
        py::arg("viscosity"), py::arg("g"), py::arg("d"),
        "Stokes' terminal speed (rho_p - rho_f) g d^2 / (18 mu) [m/s] (numpy arrays too).");

  m.def("time_to_fraction",
        [](const std::string &law, double density, double viscosity, double yield_stress, double d,
           double particle_density, double g, double fraction) {
          if (!(fraction > 0.0 && fraction < 1.0)) throw py::value_error("fraction must be in (0, 1)");
          const DragModel model(parse_law(law), make_fluid(density, viscosity, yield_stress));
          return time_to_fraction(model, d, particle_density, g, fraction);
        },
        py::arg("law"), py::arg("density"), py::arg("viscosity"), py::arg("yield_stress"), py::arg("d"),
        py::arg("particle_density"), py::arg("g") = 9.81, py::arg("fraction") = 0.99,
        "Time [s] for a sphere released at rest to reach a fraction of its terminal speed.");

  m.def("relaxation_time",
        [](const std::string &law, double density, double viscosity, double d, double particle_density) {
          const DragModel model(parse_law(law), make_fluid(density, viscosity, 0.0));
          return relaxation_time(model, d, particle_density);
        },
        py::arg("law"), py::arg("density"), py::arg("viscosity"), py::arg("d"), py::arg("particle_density"),
        "Linear relaxation time m / F'(0) [s].");

  m.def("critical_yield_number", [](const std::string &law) {
    return critical_yield_number(DragModel(parse_law(law), Fluid{1.0, 1.0, 1.0}));
  }, py::arg("law") = "zhang-li", "Y = tau_y / ((rho_p - rho_f) g d) at which a sphere stops.");

  m.def("explicit_step_limit",
        [](const std::string &law, double density, double viscosity, double yield_stress, double d,
           double particle_density, double speed) {
          if (!(d > 0.0) || !(particle_density > 0.0)) throw py::value_error("diameter and particle density must be > 0");
          if (!(speed >= 0.0)) throw py::value_error("speed must be >= 0");
          const DragModel model(parse_law(law), make_fluid(density, viscosity, yield_stress));
          return explicit_step_limit(model, d, speed, particle_density * sphere_volume(d));
        },
        py::arg("law"), py::arg("density"), py::arg("viscosity"), py::arg("yield_stress"), py::arg("d"),
        py::arg("particle_density"), py::arg("speed") = 0.0,
        "Largest step [s] at which explicit drag is stable at a slip speed (2 tau for Stokes).");

  m.def("rotation_drag_rate",
        [](double viscosity, double d, double particle_density, double wetted) {
          if (!(viscosity > 0.0) || !(d > 0.0) || !(particle_density > 0.0))
            throw py::value_error("viscosity, diameter and particle density must be > 0");
          return rotation_drag_rate(viscosity, d, particle_density * sphere_volume(d), wetted);
        },
        py::arg("viscosity"), py::arg("d"), py::arg("particle_density"), py::arg("wetted") = 1.0,
        "Rate k [1/s] of the Stokes rotlet torque -pi mu d^3 omega = -k I omega of a solid sphere.");

  m.def("sphere_inertia", &sphere_inertia, py::arg("mass"), py::arg("radius"),
        "Moment of inertia 2/5 m r^2 of a solid sphere [kg m2].");

  m.def("mixture_density", py::vectorize(mixture_density), py::arg("fluid_density"), py::arg("solid_density"),
        py::arg("fraction"), "Suspension density rho_f + (rho_s - rho_f) phi [kg/m3] (numpy arrays too).");

  m.def("rayleigh_time", &rayleigh_time, py::arg("radius"), py::arg("density"), py::arg("youngs_modulus"),
        py::arg("poisson_ratio"), "Rayleigh time [s].");

  m.def("hard_sphere_structure_factor", &hard_sphere_structure_factor, py::arg("phi"),
        "The long-wave structure factor S(0) of hard spheres at solid fraction phi (Carnahan & Starling).");
  m.def("fft_friendly", &fft_friendly, py::arg("n"),
        "Whether n is a grid size the FFTs of fix fluid/flow take (no prime factor but 2, 3 and 5).");

  const auto impact_of = [](const std::string &name) {
    if (name == "wall") return Impact::Wall;
    if (name == "pair") return Impact::Pair;
    throw py::value_error("impact must be 'wall' or 'pair', not '" + name + "'");
  };
  m.def("hertz_impact_overlap", [impact_of](const std::string &impact, double density, double speed, double youngs,
                                            double poisson) {
    return hertz_impact_overlap(impact_of(impact), density, speed, youngs, poisson);
  }, py::arg("impact"), py::arg("density"), py::arg("speed"), py::arg("youngs_modulus"), py::arg("poisson_ratio"),
     "Largest overlap / diameter of an undamped Hertz impact at `speed` ('wall' or 'pair' of equal spheres).");
  m.def("hertz_modulus_for_overlap", [impact_of](const std::string &impact, double density, double speed,
                                                 double overlap, double poisson) {
    return hertz_modulus_for_overlap(impact_of(impact), density, speed, overlap, poisson);
  }, py::arg("impact"), py::arg("density"), py::arg("speed"), py::arg("overlap"), py::arg("poisson_ratio"),
     "Young's modulus [Pa] whose impacts at `speed` reach `overlap` (relative to the diameter).");
  m.def("hertz_modulus_for_load", &hertz_modulus_for_load, py::arg("pressure"), py::arg("overlap"),
        py::arg("poisson_ratio"),
        "Young's modulus [Pa] at which a sphere pressed on a wall by pressure * d^2 overlaps by `overlap` of d.");

  m.def("hertz_contact_frequency", [impact_of](const std::string &impact, double d, double density, double youngs,
                                               double poisson, double overlap) {
    return hertz_contact_frequency(impact_of(impact), d, density, youngs, poisson, overlap);
  }, py::arg("impact"), py::arg("diameter"), py::arg("density"), py::arg("youngs_modulus"), py::arg("poisson_ratio"),
     py::arg("overlap"), "Angular frequency [1/s] of a Hertz contact linearised at `overlap` ('wall' or 'pair').");
  m.def("spring_step_limit", [](double omega, double rate) {
    if (!(omega >= 0.0 && rate >= 0.0 && std::isfinite(omega) && std::isfinite(rate)))
      throw py::value_error("omega and rate must be finite and >= 0");
    return spring_step_limit(omega, rate);
  }, py::arg("omega"), py::arg("rate"),
        "Largest stable time step [s] of the drag-implicit step for a linear spring of angular frequency omega "
        "(explicit) under a linear drag of rate `rate` [1/s] (exact): 2/omega without drag, 2 rate/omega^2 overdamped.");

  m.def("submergence", [](double radius, double centre_height) {
    const Submergence sub = submergence(radius, centre_height);
    return py::dict(py::arg("volume") = sub.volume, py::arg("area") = sub.area, py::arg("wetted") = sub.wetted);
  }, py::arg("radius"), py::arg("centre_height"),
     "Submerged volume, area and wetted fractions of a sphere whose centre is centre_height above the surface.");
}
