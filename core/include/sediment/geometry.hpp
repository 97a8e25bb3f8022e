// SPDX-License-Identifier: GPL-2.0-or-later
// Sphere geometry: volumes, areas, inertia and partial submergence below a plane free surface.
#pragma once

namespace sediment {

constexpr double pi = 3.14159265358979323846;

inline double sphere_volume(double d) { return pi * d * d * d / 6.0; }
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

// Rayleigh time pi r sqrt(rho / G) / (0.1631 nu + 0.8766), G = E / (2 (1 + nu)).
double rayleigh_time(double radius, double density, double youngs_modulus, double poisson_ratio);

}    // namespace sediment
