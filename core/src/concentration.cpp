#include "sediment/concentration.hpp"

#include "sediment/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace sediment {

namespace {

// Volume of the sphere below height u above its centre, minus half the sphere: pi (r^2 u - u^3/3).
double below(double radius, double u)
{
  const double v = std::clamp(u, -radius, radius);
  return pi * (radius * radius * v - v * v * v / 3.0);
}

}    // namespace

double sphere_slab_volume(double centre, double radius, double a, double b)
{
  return below(radius, b - centre) - below(radius, a - centre);
}

double add_sphere_to_layers(const Layers &layers, double centre, double radius, double *values, int stride)
{
  const double total = 4.0 / 3.0 * pi * radius * radius * radius;
  const int first = std::max(0, static_cast<int>(std::floor((centre - radius - layers.lo) / layers.thickness)));
  const int last = std::min(layers.count - 1,
                            static_cast<int>(std::floor((centre + radius - layers.lo) / layers.thickness)));
  if (first > last) return total;
  double lower = below(radius, layers.lo + first * layers.thickness - centre);
  const double start = lower;
  for (int k = first; k <= last; ++k) {
    const double upper = below(radius, layers.lo + (k + 1) * layers.thickness - centre);
    values[k * stride] += upper - lower;
    lower = upper;
  }
  return total - (lower - start);
}

double profile_at(const Layers &layers, const double *values, double x, int stride)
{
  const double s = (x - layers.lo) / layers.thickness - 0.5;    // in units of layers from centre 0
  if (s <= 0.0) return values[0];
  if (s >= layers.count - 1) return values[(layers.count - 1) * stride];
  const int k = static_cast<int>(s);
  const double w = s - k;
  return (1.0 - w) * values[k * stride] + w * values[(k + 1) * stride];
}

void smooth_profile(const Layers &layers, const double *values, double width, double *out)
{
  // Each layer's content is spread over its neighbours with Gaussian weights that sum to one;
  // what would leave through an end is reflected back in (mirror ends). So the total is
  // conserved exactly and a uniform profile stays uniform.
  const int n = layers.count;
  const int reach = static_cast<int>(std::ceil(4.0 * width / layers.thickness));
  std::vector<double> kernel(reach + 1);
  double norm = 0.0;
  for (int m = 0; m <= reach; ++m) {
    const double x = m * layers.thickness / width;
    kernel[m] = std::exp(-0.5 * x * x);
    norm += m == 0 ? kernel[m] : 2.0 * kernel[m];
  }
  auto fold = [n](int t) {
    while (t < 0 || t >= n) t = t < 0 ? -t - 1 : 2 * n - t - 1;
    return t;
  };
  std::fill(out, out + n, 0.0);
  for (int j = 0; j < n; ++j) {
    if (values[j] == 0.0) continue;
    const double share = values[j] / norm;
    for (int m = -reach; m <= reach; ++m) out[fold(j + m)] += share * kernel[std::abs(m)];
  }
}

}    // namespace sediment
