// SPDX-License-Identifier: GPL-2.0-or-later
// Sphere geometry: volumes, areas, inertia and partial submergence below a plane free surface.
#pragma once

#include "sediment/batch_math.hpp"

namespace sediment {

constexpr double pi = 3.14159265358979323846;

// 4 pi / 3 r^3 in the order LAMMPS takes a sphere's mass from its density (set density, read_data),
// so that a sphere as dense as the fluid displaces exactly its own mass; and no division per sphere.
inline double sphere_volume(double d)
{
  const double r = 0.5 * d;
  return 4.0 * pi / 3.0 * r * r * r;
}
inline double sphere_area(double d) { return pi * d * d / 4.0; }

// Moment of inertia of a solid sphere, I = 2/5 m r^2; the factor is LAMMPS's fix nve/sphere's.
constexpr double solid_sphere_inertia = 0.4;
inline double sphere_inertia(double mass, double radius) { return solid_sphere_inertia * mass * radius * radius; }

// Density of a suspension of solid fraction phi, rho_f + (rho_s - rho_f) phi: the density a sphere
// displaces when buoyancy is taken from the mixture (hindered settling, docs/physics.md 3.1).
inline double mixture_density(double fluid_density, double solid_density, double fraction)
{
  return fluid_density + (solid_density - fluid_density) * fraction;
}

// How much of a sphere of radius r lies below a plane surface, given the signed distance of its
// centre above the surface (positive: centre out of the fluid).
struct Submergence {
  double volume;     // submerged volume fraction, pi h^2 (3r - h) / 3 / V
  double area;       // fraction of the cross-section below the waterline, seen along the normal
  double wetted;     // wetted fraction of the surface, h / d
  bool any() const { return volume > 0.0; }
};

Submergence submergence(double radius, double centre_height);

// Mass of fluid of `density` displaced by the submerged part of a sphere of radius r:
// Archimedes' buoyancy is this mass times -g.
inline double displaced_mass(double density, double radius, const Submergence &sub)
{
  return density * sub.volume * sphere_volume(2.0 * radius);
}

// Archimedes' buoyancy -displaced_mass g added to the forces (rows of 3, indexed by atom, as LAMMPS
// keeps them) of the atoms first..first + count - 1, each wholly immersed in a fluid of this density:
// bit for bit the per-atom sum. Returns their displaced mass. In vectors of the kind's width.
double add_immersed_buoyancy(double (*force)[3], const double *radius, int first, int count, double density,
                             const double g[3], BatchMath kind = batch_math_kind());

// Rayleigh time pi r sqrt(rho / G) / (0.1631 nu + 0.8766), G = E / (2 (1 + nu)).
double rayleigh_time(double radius, double density, double youngs_modulus, double poisson_ratio);

// Largest overlap, relative to the diameter, of an undamped Hertz impact at normal speed v: a sphere
// on a wall of its own material (R = d/2, m_eff = m) or two equal spheres (R = d/4, m_eff = m/2).
// From m_eff v^2 / 2 = (8/15) E* sqrt(R) delta^(5/2) with E* = E / (2 (1 - nu^2)):
//   wall: (delta/d)^(5/2) = 15 sqrt(2) pi rho v^2 / (96 E*),  pair: 15 pi rho v^2 / (96 E*),
// independent of the size. Damping only lowers it.
enum class Impact { Wall, Pair };
double hertz_impact_overlap(Impact impact, double density, double speed, double youngs_modulus,
                            double poisson_ratio);
// The Young's modulus whose impacts at `speed` reach `overlap` (relative to the diameter): the
// softest contact that keeps the overlap within that tolerance.
double hertz_modulus_for_overlap(Impact impact, double density, double speed, double overlap,
                                 double poisson_ratio);
// The Young's modulus at which a sphere pressed on a wall of its own material by the force p d^2 (a
// pressure p carried over its cross-section, e.g. the buoyant weight of a deposit above it) overlaps
// by `overlap` of its diameter: F = (4/3) E* sqrt(d/2) delta^(3/2) gives E* = 3 sqrt(2) p / (4 (delta/d)^(3/2)).
double hertz_modulus_for_load(double pressure, double overlap, double poisson_ratio);

// Angular frequency sqrt(k / m_eff) of a Hertz contact linearised at `overlap` (relative to the
// diameter d): k = dF/d delta = 2 E* sqrt(R delta); on a wall (R = d/2, m_eff = m) or between two
// equal spheres (R = d/4, m_eff = m/2, the stiffer per unit mass by 2^(1/4)).
double hertz_contact_frequency(Impact impact, double d, double density, double youngs_modulus, double poisson_ratio,
                               double overlap);

}    // namespace sediment
