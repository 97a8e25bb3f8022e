// SPDX-License-Identifier: GPL-2.0-or-later
// The step of one sphere under a law with set-valued points (a yield stress, a jump in Cd): along the
// slip in pieces, each ending where the slip meets such a point or where the step ends. The
// block step (integrator.cpp) takes it for the spheres whose one-piece step meets such a point.
#include "sediment/integrator.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace sediment {

namespace {

Segment advance(double s0, double c, double k, double t) { return advance(phis(k * t), s0, c, t); }

// Time for ds/dt = c - k s to go from s0 to `target`, which lies between s0 and the asymptote.
double time_to_reach(double s0, double c, double k, double target)
{
  if (k > 0.0) return std::log1p((s0 - target) / (target - c / k)) / k;
  return (target - s0) / c;
}

// Newton linearisation F(w) ~ F(s_eval) + F'(s_eval) (w - s) of the drag about the slip s, as the
// slip's equation ds/dt = c - rate s; force is F(s_eval), for the secant rate across the slip.
struct Linearised {
  double force;
  double rate;
  double c;
};

Linearised linearise(const SphereDrag &drag, double mass, double s_eval, double s, double a_par)
{
  const auto [force, slope] = drag.model->force_and_tangent(drag.diameter, s_eval, drag.scale);
  return {force, slope / mass, a_par - (force - slope * s) / mass};
}

struct AlongSlip {
  double speed;
  double distance;
  double rate;    // k of the last piece, for the weight of a_{n+1}
  SlipState state;
};

// Advances the slip speed s >= 0 along a fixed direction over dt, under the acceleration a_par
// along it, stopping at the points where the force curve is set-valued (static_force = F(0+)).
AlongSlip advance_along(const SphereDrag &drag, double mass, double s, double a_par, double dt,
                        double static_force)
{
  const DragModel &model = *drag.model;
  const double d = drag.diameter;
  std::array<ForceJump, DragModel::max_jumps> jumps;
  const int njumps = model.jumps(d, jumps, drag.scale);
  const double drive = mass * a_par;
  constexpr double at_jump = 1e-12;    // relative distance that counts as sitting on a jump

  double left = dt;
  double distance = 0.0;
  double rate = 0.0;
  for (int piece = 0; piece <= njumps + 1; ++piece) {
    // Which side of a jump the linearisation takes, when the speed sits on one.
    double s_eval = s;
    for (int j = 0; j < njumps; ++j) {
      if (std::abs(s - jumps[j].speed) > at_jump * jumps[j].speed) continue;
      if (drive >= jumps[j].force_below && drive <= jumps[j].force_above)
        return {s, distance + s * left, rate, SlipState::HeldAtJump};
      s_eval = drive > jumps[j].force_above ? s * (1.0 + 1e-11) : s * (1.0 - 1e-11);
    }

    const Linearised lin = linearise(drag, mass, s_eval, s, a_par);
    rate = lin.rate;
    const double c = lin.c;
    const Segment full = advance(s, c, rate, left);

    // First set-valued point crossed on the way from s to full.speed.
    double event = -1.0;
    int event_jump = -1;
    if (full.speed > s) {
      for (int j = 0; j < njumps; ++j)
        if (jumps[j].speed > s * (1.0 + at_jump) && jumps[j].speed < full.speed &&
            (event_jump < 0 || jumps[j].speed < event)) {
          event = jumps[j].speed;
          event_jump = j;
        }
    } else {
      for (int j = 0; j < njumps; ++j)
        if (jumps[j].speed < s * (1.0 - at_jump) && jumps[j].speed > full.speed &&
            (event_jump < 0 || jumps[j].speed > event)) {
          event = jumps[j].speed;
          event_jump = j;
        }
      if (event_jump < 0 && static_force > 0.0 && full.speed < 0.0) event = 0.0;
    }
    if (event < 0.0) return {full.speed, distance + full.distance, rate, SlipState::Free};

    const double t_event = std::clamp(time_to_reach(s, c, rate, event), 0.0, left);
    distance += advance(s, c, rate, t_event).distance;
    left -= t_event;
    s = event;
    if (event_jump < 0) return {0.0, distance, rate, SlipState::Stuck};
  }
  return {s, distance + s * left, rate, SlipState::Free};
}

}    // namespace

StepCorrection set_valued_step_initial(const SphereDrag &drag, double mass, const double a[3],
                                       const double u[3], double dt, double v[3], double dx[3])
{
  StepCorrection corr;
  const double w[3] = {v[0] - u[0], v[1] - u[1], v[2] - u[2]};
  const double s = std::sqrt(dot(w, w));
  const double a_norm = s > 0.0 ? 0.0 : std::sqrt(dot(a, a));    // needed only at rest
  double *dir = corr.dir;
  if (s > 0.0) {
    for (int k = 0; k < 3; ++k) dir[k] = w[k] / s;
  } else if (a_norm > 0.0) {
    for (int k = 0; k < 3; ++k) dir[k] = a[k] / a_norm;
  }
  const double a_par = dot(a, dir);
  const double a_perp[3] = {a[0] - a_par * dir[0], a[1] - a_par * dir[1], a[2] - a_par * dir[2]};

  const double static_force = drag.model->static_force(drag.diameter, drag.scale);
  const bool stays_at_rest = s == 0.0 && static_force > 0.0 && mass * a_norm <= static_force;
  const AlongSlip along = stays_at_rest ? AlongSlip{0.0, 0.0, 0.0, SlipState::Stuck}
                                        : advance_along(drag, mass, s, a_par, dt, static_force);
  corr.state = along.state;
  if (along.state == SlipState::Stuck) {
    for (int k = 0; k < 3; ++k) {
      v[k] = u[k];
      dx[k] = u[k] * dt + along.distance * dir[k];
    }
    corr.along = corr.across = 0.0;
    return corr;
  }
  // Across the slip the force turns with the slip: secant rate F(s) / s.
  const double rate_across = s > 0.0 ? drag.model->force(drag.diameter, s, drag.scale) / (s * mass)
                                     : drag.model->tangent(drag.diameter, 0.0, drag.scale) / mass;
  corr.along = along.state == SlipState::Free ? dt * phi2(along.rate * dt) : 0.0;
  const Phi across = phis(rate_across * dt);
  const double p1 = across.phi1;
  const double p2 = across.phi2;
  corr.across = dt * p2;
  for (int k = 0; k < 3; ++k) {
    v[k] = u[k] + along.speed * dir[k] + a_perp[k] * dt * p1;
    dx[k] = u[k] * dt + along.distance * dir[k] + a_perp[k] * dt * dt * p2;
    // The share of a_n in the ETD2 weights; drag_step_final adds the same share of a_{n+1}.
    v[k] -= corr.along * a_par * dir[k] + corr.across * a_perp[k];
  }
  return corr;
}
}    // namespace sediment
