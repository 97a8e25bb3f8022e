// SPDX-License-Identifier: GPL-2.0-or-later
// The spectral Stokes operator and the spreading kernel of two-way coupling (sediment/flow.hpp).
#include "sediment/flow.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace sediment {

namespace {
constexpr double pi = 3.14159265358979323846;

// The Nyquist index of an even axis: there k and -k are one mode, which the operator's products
// k_x k_y would give two values; set to zero, the velocity of a real force is real.
bool is_nyquist(int m, int n) { return n % 2 == 0 && m == n / 2; }
}

bool fft_friendly(int n)
{
  if (n < 1) return false;
  for (const int p : {2, 3, 5})
    while (n % p == 0) n /= p;
  return n == 1;
}

double grid_wavenumber(int m, int n, double length)
{
  const int folded = m <= n / 2 ? m : m - n;
  return 2.0 * pi * folded / length;
}

void StokesOperator::apply(const double k[3], const double *f, double *u, double scale) const
{
  const double k2 = k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
  // the mean: no net flux; with vessel_across, no flow uniform across either
  if (!(k2 > 0.0) || (vessel_across && k[0] == 0.0 && k[1] == 0.0)) {
    for (int c = 0; c < 6; ++c) u[c] = 0.0;
    return;
  }
  const double per = scale * (smoothing > 0.0 ? std::exp(-k2 * smoothing) : 1.0) / (viscosity * k2 + brinkman);
  // the longitudinal part k (k . f) / k^2, real and imaginary parts apart
  const double kf_re = (k[0] * f[0] + k[1] * f[2] + k[2] * f[4]) / k2;
  const double kf_im = (k[0] * f[1] + k[1] * f[3] + k[2] * f[5]) / k2;
  for (int c = 0; c < 3; ++c) {
    const double re = f[2 * c] - k[c] * kf_re;
    const double im = f[2 * c + 1] - k[c] * kf_im;
    u[2 * c] = per * re;
    u[2 * c + 1] = per * im;
  }
}

void stokes_apply_brick(const StokesOperator &op, const int n[3], const double length[3], const int lo[3],
                        const int hi[3], double *fx, double *fy, double *fz, double scale)
{
  const int ni = hi[0] - lo[0] + 1, nj = hi[1] - lo[1] + 1;
  for (int kk = lo[2]; kk <= hi[2]; ++kk) {
    const double kz = grid_wavenumber(kk, n[2], length[2]);
    for (int j = lo[1]; j <= hi[1]; ++j) {
      const double ky = grid_wavenumber(j, n[1], length[1]);
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const double k[3] = {grid_wavenumber(i, n[0], length[0]), ky, kz};
        const long at = 2L * ((static_cast<long>(kk - lo[2]) * nj + (j - lo[1])) * ni + (i - lo[0]));
        double f[6] = {fx[at], fx[at + 1], fy[at], fy[at + 1], fz[at], fz[at + 1]};
        double u[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        if (!(is_nyquist(i, n[0]) || is_nyquist(j, n[1]) || is_nyquist(kk, n[2]))) op.apply(k, f, u, scale);
        fx[at] = u[0];
        fx[at + 1] = u[1];
        fy[at] = u[2];
        fy[at + 1] = u[3];
        fz[at] = u[4];
        fz[at + 1] = u[5];
      }
    }
  }
}

void stable_profile(double *profile, int planes)
{
  // Blocks of pooled planes: each holds the mean of its planes; a block below one of greater value is
  // fine (less force downwards above), one above a block of greater value is pooled with it.
  std::vector<double> mean;
  std::vector<int> count;
  for (int k = 0; k < planes; ++k) {
    mean.push_back(profile[k]);
    count.push_back(1);
    while (mean.size() > 1 && mean[mean.size() - 2] > mean.back()) {
      const double value = mean.back();
      const int n = count.back();
      mean.pop_back();
      count.pop_back();
      mean.back() = (mean.back() * count.back() + value * n) / (count.back() + n);
      count.back() += n;
    }
  }
  int k = 0;
  for (size_t b = 0; b < mean.size(); ++b)
    for (int j = 0; j < count[b]; ++j) profile[k++] = mean[b];
}

double carried_excess(double excess, const double *profile, int planes, double spacing, double at, double share,
                      double largest_relative_slope, double lift)
{
  const int below = std::clamp(static_cast<int>(at), 0, planes - 2);
  const double rise = profile[below + 1] - profile[below], here = profile[below] + (at - below) * rise;
  if (here == 0.0) return excess;
  double slope = rise / spacing * share;
  if (const double relative = std::abs(slope / here); relative > largest_relative_slope)
    slope *= largest_relative_slope / relative;
  const auto [lowest, highest] = std::minmax({0.0, profile[0], profile[planes - 1]});    // a stable profile's range
  return std::clamp((1.0 + excess) * here - slope * lift, lowest, highest) / here - 1.0;
}

double gaussian_self_mobility(double viscosity, double sigma)
{
  return 1.0 / (6.0 * pi * viscosity * sigma * std::sqrt(pi));
}

double hard_sphere_structure_factor(double phi)
{
  const double p2 = phi * phi, q = 1.0 - phi, q2 = q * q;
  return q2 * q2 / (1.0 + 4.0 * phi + 4.0 * p2 - 4.0 * p2 * phi + p2 * p2);
}

double cloud_speed(double us, int n, double a, double r)
{
  return us * (1.0 + 1.2 * n * a / r);
}

double hasimoto_mobility_correction(double viscosity, double box)
{
  return -2.837297 / (6.0 * pi * viscosity * box);
}

}    // namespace sediment
