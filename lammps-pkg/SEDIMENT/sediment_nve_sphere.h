// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix nve/sphere's own step, written as it does, for the
   spheres fix nve/sphere/fluid steps outside any fluid (and the rotation of
   those without a rotational drag): a scene without fluid is then bitwise
   the same as with fix nve/sphere.
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_NVE_SPHERE_H
#define LMP_SEDIMENT_NVE_SPHERE_H

#include "sediment/integrator.hpp"

#include <array>

namespace LAMMPS_NS {

// The rotational half of fix nve/sphere's kick (below), which is also the rotation of a sphere in a
// fluid without a rotational drag. Returns the torque's weight, dtf / I.
static inline double nve_sphere_spin(double *omega, const double *torque, double radius, double rmass,
                                     sediment::HalfKick kick)
{
  const double dtirotate = sediment::spin_weight(kick, radius, rmass);
  omega[0] += dtirotate * torque[0];
  omega[1] += dtirotate * torque[1];
  omega[2] += dtirotate * torque[2];
  return dtirotate;
}

// The kick of fix nve/sphere. Returns the new velocity: read back from v, it would wait for the
// stores just made.
static inline std::array<double, 3> nve_sphere_kick(double *v, double *omega, const double *f, const double *torque,
                                                    double radius, double rmass, sediment::HalfKick kick)
{
  const double dtfm = kick.dtf / rmass;
  const std::array<double, 3> kicked = {v[0] + dtfm * f[0], v[1] + dtfm * f[1], v[2] + dtfm * f[2]};
  v[0] = kicked[0];
  v[1] = kicked[1];
  v[2] = kicked[2];
  nve_sphere_spin(omega, torque, radius, rmass, kick);
  return kicked;
}

// The first half of fix nve/sphere's step: kick, then drift over the whole step. Returns the sum of
// the new position's components, for the check of a finite state: the position is x + dt v, so a
// non-finite velocity makes it non-finite too, and summing the velocity as well would add nothing.
static inline double nve_sphere_kick_drift(double *x, double *v, double *omega, const double *f,
                                           const double *torque, double radius, double rmass, sediment::HalfKick kick,
                                           double dt)
{
  const std::array<double, 3> kicked = nve_sphere_kick(v, omega, f, torque, radius, rmass, kick);
  const double new_x[3] = {x[0] + dt * kicked[0], x[1] + dt * kicked[1], x[2] + dt * kicked[2]};
  x[0] = new_x[0];
  x[1] = new_x[1];
  x[2] = new_x[2];
  return new_x[0] + new_x[1] + new_x[2];
}

}    // namespace LAMMPS_NS

#endif
