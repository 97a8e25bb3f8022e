// Sphere geometry: volumes, areas and partial submergence below a plane free surface.
#pragma once

#include "sediment/drag.hpp"

namespace sediment {

constexpr double pi = 3.14159265358979323846;

inline double sphere_volume(double d) { return pi * d * d * d / 6.0; }
inline double sphere_area(double d) { return pi * d * d / 4.0; }

// How much of a sphere of radius r lies below a plane surface, given the signed distance of its
// centre above the surface (positive: centre out of the fluid).
struct Submergence {
  double volume;     // submerged volume fraction, pi h^2 (3r - h) / 3 / V
  double area;       // fraction of the cross-section below the waterline, seen along the normal
  double wetted;     // wetted fraction of the surface, h / d
  bool any() const { return volume > 0.0; }
  DragScale drag_scale() const { return {area, wetted}; }
};

Submergence submergence(double radius, double centre_height);

// Rayleigh time pi r sqrt(rho / G) / (0.1631 nu + 0.8766), G = E / (2 (1 + nu)).
double rayleigh_time(double radius, double density, double youngs_modulus, double poisson_ratio);

}    // namespace sediment
