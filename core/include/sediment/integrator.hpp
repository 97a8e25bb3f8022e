// SPDX-License-Identifier: GPL-2.0-or-later
// Drag-implicit time step for one sphere, split like velocity Verlet so that LAMMPS can compute
// the non-drag forces between the two halves.
//
// The slip w = v - u obeys m dw/dt = f(t) - F(|w|) w/|w|. Over a step the drag is linearised
// around the slip at the start (Newton: tangent rate F'(s)/m along the slip, secant rate
// F(s)/(s m) across it) and the resulting linear ODE is integrated exactly with the force
// interpolated linearly in time (exponential time differencing, ETD2):
//   v(dt) = u + w e^{-z} + dt [(phi1 - phi2) a_n + phi2 a_{n+1}],  z = k dt,
//   x(dt) = x + u dt + dt phi1 w + dt^2 phi2 a_n,
// with phi1 = (1 - e^{-z}) / z and phi2 = (z - 1 + e^{-z}) / z^2. This is exact for a constant
// force with linear drag at any dt, second order otherwise, and velocity Verlet when k = 0.
// Along the slip the step is advanced piecewise through the points where the force curve is
// set-valued: at rest under a yield stress (a sphere sticks while |f| <= F(0+)) and at Cd jumps
// (the speed is held at the jump while the drive lies inside the jump). A held sphere does not
// take the Verlet correction, so it stays exactly still instead of chattering.
#pragma once

#include "sediment/drag.hpp"

namespace sediment {

double phi1(double z);
double phi2(double z);

// e^{-z}, phi1(z) and phi2(z) from one exponential.
struct Phi {
  double decay;
  double phi1;
  double phi2;
};
Phi phis(double z);

// phis(z) remembered for the last z a sphere saw, in memo = {z, decay, phi1, phi2} (z NaN: empty).
// With a fixed step and a linear drag z does not change, so the exponential is taken once.
constexpr int PHI_MEMO_SIZE = 4;
Phi phis(double z, double memo[PHI_MEMO_SIZE]);

// The drag seen by one sphere during a step.
struct SphereDrag {
  const DragModel *model = nullptr;    // nullptr: no drag (plain velocity Verlet)
  double diameter = 0.0;
  DragScale scale;
};

enum class SlipState { Free, Stuck, HeldAtJump };

// What the first half of the step leaves for the second: the weights of a_{n+1} along and
// across the slip direction. Zero weights mean the sphere is held (stuck or at a jump).
struct StepCorrection {
  double along = 0.0;
  double across = 0.0;
  double dir[3] = {0.0, 0.0, 1.0};
  SlipState state = SlipState::Free;
};

// First half: advances x by dx and replaces v with the mid-step velocity, given the non-drag
// acceleration a_n = f_n / m and the uniform fluid velocity u. A memo (see phis) saves the
// exponential of a linear drag from step to step.
StepCorrection drag_step_initial(const SphereDrag &drag, double mass, const double a[3],
                                 const double u[3], double dt, double v[3], double dx[3],
                                 double *memo = nullptr);

// Second half: adds the weighted acceleration a_{n+1} = f_{n+1} / m.
void drag_step_final(const StepCorrection &corr, const double a[3], double v[3]);

// Rotation with a linear drag torque -k I omega: same ETD2 weights, isotropic.
// Returns the weight of alpha_{n+1} for the second half (dt / 2 when k = 0).
double rotation_step_initial(double rate, const double alpha[3], double dt, double omega[3],
                             double *memo = nullptr);

}    // namespace sediment
