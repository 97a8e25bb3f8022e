// SPDX-License-Identifier: GPL-2.0-or-later
// Terminal (steady settling) velocity of a sphere under a drag law.
#pragma once

#include "sediment/drag.hpp"

namespace sediment {

enum class TerminalRegime {
  Moving,     // F(v) equals the net weight
  AtRest,     // the net weight does not exceed the static yield resistance
  AtJump,     // the net weight falls inside a jump of the force curve: v sits at the jump
};

struct TerminalState {
  double speed;
  TerminalRegime regime;
};

// Stokes' law: terminal speed (rho_p - rho_f) g d^2 / (18 mu) of a sphere at Re << 1 (negative: rising).
// The readouts of the sedimentation tests invert it for the largest diameter left at a depth.
inline double stokes_velocity(double particle_density, double fluid_density, double viscosity, double g, double d)
{
  return (particle_density - fluid_density) * g * d * d / (18.0 * viscosity);
}

// Net weight (rho_p - rho_f) g V of a fully immersed sphere; g is the magnitude of gravity.
double net_weight(const Fluid &fluid, double d, double particle_density, double g);

// Steady speed where the resisting force balances `driving_force` (a magnitude >= 0).
// The force curve is monotone, so bisection finds the unique (set-valued) root.
TerminalState steady_speed(const DragModel &model, double d, double driving_force,
                           DragScale scale = {});

// Terminal settling (or rising, for rho_p < rho_f) speed of a fully immersed sphere.
TerminalState terminal_velocity(const DragModel &model, double d, double particle_density,
                                double g);

// Time for a sphere released at rest to reach `fraction` of its terminal speed (exact ODE
// solution by adaptive quadrature of dt = m dv / (W - F(v))).
double time_to_fraction(const DragModel &model, double d, double particle_density, double g,
                        double fraction);

// Yield number Y = tau_y / ((rho_p - rho_f) g d) below which a sphere moves (zhang-li: 0.0440, bingham:
// 0.048); the model's fluid must have a yield stress.
double critical_yield_number(const DragModel &model);

}    // namespace sediment
