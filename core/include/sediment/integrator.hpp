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
inline Phi phis(double z, double memo[PHI_MEMO_SIZE])
{
  if (z != memo[0]) {
    const Phi p = phis(z);
    memo[0] = z;
    memo[1] = p.decay;
    memo[2] = p.phi1;
    memo[3] = p.phi2;
  }
  return {memo[1], memo[2], memo[3]};
}

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

// drag_step_initial for a drag that is not linear in the slip (out of line: Newton linearisation,
// set-valued points).
StepCorrection nonlinear_step_initial(const SphereDrag &drag, double mass, const double a[3],
                                      const double u[3], double dt, double v[3], double dx[3]);

// First half: advances x by dx and replaces v with the mid-step velocity, given the non-drag
// acceleration a_n = f_n / m and the uniform fluid velocity u. A memo (see phis) saves the
// exponential of a linear drag from step to step. Inline: the per-atom loops of the integrator
// take the linear and no-drag cases without a call.
inline StepCorrection drag_step_initial(const SphereDrag &drag, double mass, const double a[3],
                                        const double u[3], double dt, double v[3], double dx[3],
                                        double *memo = nullptr)
{
  StepCorrection corr;
  if (drag.model == nullptr || (drag.scale.area <= 0.0 && drag.scale.wetted <= 0.0)) {
    for (int k = 0; k < 3; ++k) {
      v[k] += 0.5 * dt * a[k];
      dx[k] = dt * v[k];
    }
    corr.along = corr.across = 0.5 * dt;
    return corr;
  }
  // Drag linear in the slip: the same step with equal rates along and across the slip and no
  // set-valued points, in closed form.
  const double linear = drag.model->linear_coefficient(drag.diameter, drag.scale);
  if (!(linear > 0.0)) return nonlinear_step_initial(drag, mass, a, u, dt, v, dx);
  const double z = linear / mass * dt;
  const Phi p = memo ? phis(z, memo) : phis(z);
  // Copies first: the stores into v could alias u or a, which would then be read anew each time.
  const double flow[3] = {u[0], u[1], u[2]}, accel[3] = {a[0], a[1], a[2]};
  const double slip[3] = {v[0] - flow[0], v[1] - flow[1], v[2] - flow[2]};
  const double weight_now = dt * (p.phi1 - p.phi2), weight_drift = dt * p.phi2;
  for (int k = 0; k < 3; ++k) {
    v[k] = flow[k] + slip[k] * p.decay + weight_now * accel[k];
    dx[k] = dt * (flow[k] + p.phi1 * slip[k] + weight_drift * accel[k]);
  }
  corr.along = corr.across = weight_drift;
  return corr;
}

// Second half: adds the weighted acceleration a_{n+1} = f_{n+1} / m.
inline void drag_step_final(const StepCorrection &corr, const double a[3], double v[3])
{
  if (corr.along == corr.across) {    // isotropic: linear drag, no drag, or held
    for (int k = 0; k < 3; ++k) v[k] += corr.along * a[k];
    return;
  }
  const double a_par = a[0] * corr.dir[0] + a[1] * corr.dir[1] + a[2] * corr.dir[2];
  for (int k = 0; k < 3; ++k)
    v[k] += corr.along * a_par * corr.dir[k] + corr.across * (a[k] - a_par * corr.dir[k]);
}

// Rotation with a linear drag torque -k I omega: same ETD2 weights, isotropic.
// Returns the weight of alpha_{n+1} for the second half (dt / 2 when k = 0).
inline double rotation_step_initial(double rate, const double alpha[3], double dt, double omega[3],
                                    double *memo = nullptr)
{
  if (rate == 0.0) {    // phis(0) = {1, 1, 1/2}: the same values without the memo
    for (int k = 0; k < 3; ++k) omega[k] += dt * 0.5 * alpha[k];
    return dt * 0.5;
  }
  const Phi p = memo ? phis(rate * dt, memo) : phis(rate * dt);
  const double weight_now = dt * (p.phi1 - p.phi2);
  for (int k = 0; k < 3; ++k) omega[k] = omega[k] * p.decay + weight_now * alpha[k];
  return dt * p.phi2;
}

}    // namespace sediment
