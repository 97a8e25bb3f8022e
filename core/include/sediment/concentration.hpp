// Solid volume of spheres in layers along one axis: exact, so that the profile is smooth when
// layers are thinner than grains and the total solid volume is conserved to round-off.
#pragma once

namespace sediment {

// Volume of a sphere (centre c, radius r along the axis) between the planes a <= b.
double sphere_slab_volume(double centre, double radius, double a, double b);

// Regular layers [lo + k h, lo + (k + 1) h), k = 0 .. n - 1.
struct Layers {
  double lo;
  double thickness;
  int count;
  double hi() const { return lo + thickness * count; }
};

// Adds the sphere's volume in every layer it overlaps to values[k * stride]; returns the part of
// its volume outside [lo, hi]. The layer volumes telescope, so they sum exactly to the inside part.
double add_sphere_to_layers(const Layers &layers, double centre, double radius, double *values, int stride = 1);

// The piecewise-linear profile through the layer centres at x (flat beyond the outer centres).
double profile_at(const Layers &layers, const double *values, double x, int stride = 1);

// Gaussian smoothing (standard deviation `width`, truncated at 4 widths) of the layer values into
// out, with mirror ends: conserves the total exactly and keeps a uniform profile uniform.
void smooth_profile(const Layers &layers, const double *values, double width, double *out);

}    // namespace sediment
