// SPDX-License-Identifier: GPL-2.0-or-later
// The spectral Stokes operator and the spreading kernel of two-way coupling (docs/physics.md section 8),
// against closed-form flows: a shear wave, a longitudinal force the pressure takes whole, the return
// flow (no net flux through any plane), and the periodic box's self-mobility of a spread point force
// (Hasimoto). The transforms here are plain separable DFTs (fix fluid/flow uses LAMMPS's FFT3d).
#include "sediment/flow.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
#include <vector>

using namespace sediment;
using cplx = std::complex<double>;

namespace {
constexpr double pi = 3.14159265358979323846;

// In-place 3d DFT of an n[0] x n[1] x n[2] complex field (x fastest); sign -1 forward, +1 inverse
// (unscaled, as FFT3d with scaled = 0).
void dft3(std::vector<cplx> &a, const int n[3], int sign)
{
  const int stride[3] = {1, n[0], n[0] * n[1]};
  const int total = n[0] * n[1] * n[2];
  for (int axis = 0; axis < 3; ++axis) {
    const int m = n[axis], s = stride[axis];
    std::vector<cplx> line(m), out(m);
    for (int start = 0; start < total; ++start) {
      if ((start / s) % m != 0) continue;    // the first point of each line along this axis
      for (int q = 0; q < m; ++q) line[q] = a[start + q * s];
      for (int p = 0; p < m; ++p) {
        cplx sum = 0.0;
        for (int q = 0; q < m; ++q) sum += line[q] * std::polar(1.0, sign * 2.0 * pi * p * q / m);
        out[p] = sum;
      }
      for (int q = 0; q < m; ++q) a[start + q * s] = out[q];
    }
  }
}

// The grid's velocity from its force density: transform, operator, inverse (scaled 1 / N).
void solve(const StokesOperator &op, const int n[3], const double length[3], std::vector<cplx> f[3])
{
  for (int c = 0; c < 3; ++c) dft3(f[c], n, -1);
  const int lo[3] = {0, 0, 0}, hi[3] = {n[0] - 1, n[1] - 1, n[2] - 1};
  stokes_apply_brick(op, n, length, lo, hi, reinterpret_cast<double *>(f[0].data()),
                     reinterpret_cast<double *>(f[1].data()), reinterpret_cast<double *>(f[2].data()),
                     1.0 / (n[0] * n[1] * n[2]));
  for (int c = 0; c < 3; ++c) dft3(f[c], n, +1);
}

int wrap(int i, int n)
{
  return ((i % n) + n) % n;
}

// Spreads point forces (force density: force / cell volume) or reads the field at a point, with the kernel.
struct Grid {
  int n[3];
  double length[3];
  FlowKernel kernel;
  double h(int d) const { return length[d] / n[d]; }
  template <class Visit> void visit(const double *x, Visit visit_node) const
  {
    int first[3], count[3];
    double w[3][FlowKernel::max_nodes];
    for (int d = 0; d < 3; ++d) count[d] = kernel.weights(x[d] / h(d) - 0.5, first[d], w[d]);
    for (int c = 0; c < count[2]; ++c)
      for (int b = 0; b < count[1]; ++b)
        for (int a = 0; a < count[0]; ++a) {
          const int at = (wrap(first[2] + c, n[2]) * n[1] + wrap(first[1] + b, n[1])) * n[0] + wrap(first[0] + a, n[0]);
          visit_node(at, w[0][a] * w[1][b] * w[2][c]);
        }
  }
  void spread(const double *x, const double *force, std::vector<cplx> f[3]) const
  {
    const double per_volume = 1.0 / (h(0) * h(1) * h(2));
    visit(x, [&](int at, double w) {
      for (int c = 0; c < 3; ++c) f[c][at] += force[c] * w * per_volume;
    });
  }
  void read(const double *x, const std::vector<cplx> u[3], double *out) const
  {
    out[0] = out[1] = out[2] = 0.0;
    visit(x, [&](int at, double w) {
      for (int c = 0; c < 3; ++c) out[c] += u[c][at].real() * w;
    });
  }
};
}    // namespace

TEST(Flow, FftFriendlySizes)
{
  for (int n : {1, 2, 8, 12, 30, 48, 64, 100, 360}) EXPECT_TRUE(fft_friendly(n)) << n;
  for (int n : {0, -4, 7, 14, 22, 49, 97}) EXPECT_FALSE(fft_friendly(n)) << n;
}

TEST(Flow, Wavenumbers)
{
  EXPECT_DOUBLE_EQ(grid_wavenumber(0, 8, 2.0), 0.0);
  EXPECT_DOUBLE_EQ(grid_wavenumber(1, 8, 2.0), pi);
  EXPECT_DOUBLE_EQ(grid_wavenumber(4, 8, 2.0), 4 * pi);     // Nyquist: +n/2
  EXPECT_DOUBLE_EQ(grid_wavenumber(7, 8, 2.0), -pi);
  EXPECT_DOUBLE_EQ(grid_wavenumber(3, 7, 1.0), 6 * pi);
  EXPECT_DOUBLE_EQ(grid_wavenumber(4, 7, 1.0), -6 * pi);
}

TEST(Flow, OperatorOnOneMode)
{
  const StokesOperator stokes{2e-3, 0.0}, brinkman{2e-3, 5.0};
  const double k[3] = {0.0, 0.0, 3.0};
  // a shear wave: force across k moves the fluid by f / (mu k^2 + alpha)
  const double across[6] = {1.5, -0.5, 0.0, 0.0, 0.0, 0.0};
  double u[6];
  stokes.apply(k, across, u);
  EXPECT_DOUBLE_EQ(u[0], 1.5 / (2e-3 * 9.0));
  EXPECT_DOUBLE_EQ(u[1], -0.5 / (2e-3 * 9.0));
  brinkman.apply(k, across, u, 0.25);
  EXPECT_DOUBLE_EQ(u[0], 0.25 * 1.5 / (2e-3 * 9.0 + 5.0));
  // a force along k: the pressure takes it whole
  const double along[6] = {0.0, 0.0, 0.0, 0.0, 2.0, 1.0};
  stokes.apply(k, along, u);
  for (double value : u) EXPECT_EQ(value, 0.0);
  // the mean mode: no net flux, whatever the mean force
  const double zero[3] = {0.0, 0.0, 0.0};
  stokes.apply(zero, across, u);
  for (double value : u) EXPECT_EQ(value, 0.0);
  // a sample of a wider vessel: the shear wave uniform across moves nothing; a mode that varies
  // across moves the fluid as in a periodic array
  StokesOperator vessel = stokes;
  vessel.vessel_across = true;
  vessel.apply(k, across, u);
  for (double value : u) EXPECT_EQ(value, 0.0);
  const double tilted[3] = {2.0, 0.0, 3.0};
  double periodic[6];
  stokes.apply(tilted, across, periodic);
  vessel.apply(tilted, across, u);
  for (int c = 0; c < 6; ++c) EXPECT_EQ(u[c], periodic[c]);
  EXPECT_NE(periodic[0], 0.0);
  // any mode: divergence-free, and mu k^2 u + alpha u + i k p = f for some p
  const double kk[3] = {1.0, -2.0, 0.5};
  const double f[6] = {0.3, 0.1, -0.7, 0.2, 0.4, -0.9};
  brinkman.apply(kk, f, u);
  EXPECT_NEAR(kk[0] * u[0] + kk[1] * u[2] + kk[2] * u[4], 0.0, 1e-14);
  EXPECT_NEAR(kk[0] * u[1] + kk[1] * u[3] + kk[2] * u[5], 0.0, 1e-14);
  const double k2 = 5.25, denominator = 2e-3 * k2 + 5.0;
  // the remainder f - (mu k^2 + alpha) u is parallel to k (the pressure gradient)
  double rest[6];
  for (int c = 0; c < 6; ++c) rest[c] = f[c] - denominator * u[c];
  for (int part = 0; part < 2; ++part) {
    const double p = (kk[0] * rest[part] + kk[1] * rest[2 + part] + kk[2] * rest[4 + part]) / k2;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rest[2 * c + part], p * kk[c], 1e-14);
  }
}

// A sinusoidal force density on the grid has an exact Stokes velocity: the shear waves
// f_x = A sin(2 pi z / Lz) and f_z = B cos(4 pi x / Lx) move the fluid by f / (mu k^2); a
// longitudinal f_z = C sin(2 pi z / Lz) moves nothing.
TEST(Flow, SinusoidalForceDensityOnTheGrid)
{
  const int n[3] = {8, 6, 10};
  const double length[3] = {2.0, 1.5, 3.0};
  const double mu = 1e-3, A = 2.0, B = -0.5, C = 7.0;
  const StokesOperator op{mu, 0.0};
  std::vector<cplx> f[3];
  for (auto &field : f) field.assign(n[0] * n[1] * n[2], 0.0);
  const double kz = 2 * pi / length[2], kx = 4 * pi / length[0];
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const double x = (i + 0.5) * length[0] / n[0], z = (k + 0.5) * length[2] / n[2];
        const int at = (k * n[1] + j) * n[0] + i;
        f[0][at] = A * std::sin(kz * z);
        f[2][at] = B * std::cos(kx * x) + C * std::sin(kz * z);
      }
  solve(op, n, length, f);
  double worst = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int i = 0; i < n[0]; ++i) {
      const double x = (i + 0.5) * length[0] / n[0], z = (k + 0.5) * length[2] / n[2];
      const int at = (k * n[1]) * n[0] + i;
      worst = std::max(worst, std::abs(f[0][at].real() - A * std::sin(kz * z) / (mu * kz * kz)));
      worst = std::max(worst, std::abs(f[1][at].real()));
      worst = std::max(worst, std::abs(f[2][at].real() - B * std::cos(kx * x) / (mu * kx * kx)));
    }
  EXPECT_LT(worst, 1e-9 * A / (mu * kz * kz));
}

// The cubic B-spline on the grid: 4 nodes around the point, weights that sum to 1, centred on the
// point (a linear field is read back exactly) with the variance 1/3 of a cell squared.
TEST(Flow, KernelWeights)
{
  const FlowKernel kernel{1.0};
  for (double p : {0.0, 0.25, 0.5, 3.999, -2.3, 17.71}) {
    int first;
    double w[FlowKernel::max_nodes];
    const int count = kernel.weights(p, first, w);
    EXPECT_EQ(count, 4);
    double sum = 0.0, moment = 0.0, variance = 0.0;
    for (int m = 0; m < count; ++m) {
      EXPECT_GE(w[m], 0.0);
      EXPECT_LE(std::abs(first + m - p), 2.0);
      sum += w[m];
      moment += w[m] * (first + m);
      variance += w[m] * (first + m - p) * (first + m - p);
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_NEAR(moment, p, 1e-13) << p;
    EXPECT_NEAR(variance, 1.0 / 3.0, 1e-13) << p;
  }
  EXPECT_DOUBLE_EQ(FlowKernel{1.5}.fourier_variance(), 2.25 - 1.0 / 3.0);
}

// One point force in a periodic cube: what it reads back is the kernel's unbounded self-mobility plus
// Hasimoto's correction for the images and the return flow, wherever the point lies between nodes:
// a sphere of radius a_h = sigma sqrt(pi) in a cubic array of volume fraction phi moves at
// (1 - 1.7601 phi^1/3 + phi) / (6 pi mu a_h), the first two terms those of hasimoto_mobility_correction.
// sigma sqrt(pi) is a Gaussian blob's radius; the kernel, a B-spline on the grid and a Gaussian in
// Fourier space, is close to one of the same variance: 0.997-1.000 of it over the points tried (the
// fix measures its own self-flow, so nothing hangs on this).
TEST(Flow, SelfMobilityInAPeriodicBox)
{
  const int n[3] = {16, 16, 16};
  const double length[3] = {1.0, 1.0, 1.0}, mu = 1e-3;
  const Grid grid{{16, 16, 16}, {1.0, 1.0, 1.0}, FlowKernel{1.0}};
  const double sigma = grid.h(0);
  const double a_h = sigma * std::sqrt(pi), phi = 4.0 * pi / 3.0 * a_h * a_h * a_h;
  EXPECT_NEAR(gaussian_self_mobility(mu, sigma) * 1.7601 * std::cbrt(phi), -hasimoto_mobility_correction(mu, 1.0),
              1e-4 * gaussian_self_mobility(mu, sigma));
  const double expected = gaussian_self_mobility(mu, sigma) * (1.0 - 1.7601 * std::cbrt(phi) + phi);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int trial = 0; trial < 4; ++trial) {
    const double x[3] = {uniform(rng), uniform(rng), uniform(rng)};
    for (int axis : {0, 2}) {
      std::vector<cplx> f[3];
      for (auto &field : f) field.assign(n[0] * n[1] * n[2], 0.0);
      double force[3] = {0.0, 0.0, 0.0};
      force[axis] = 1.0;
      grid.spread(x, force, f);
      solve(StokesOperator{mu, 0.0, grid.kernel.fourier_variance() * sigma * sigma}, n, length, f);
      double u[3];
      grid.read(x, f, u);
      EXPECT_NEAR(u[axis] / expected, 1.0, 0.004) << "trial " << trial << " axis " << axis;
      EXPECT_LT(std::abs(u[2 - axis]) / expected, 0.01);
    }
  }
}

// Forces anywhere, the mean among them: the flux through every horizontal plane of nodes is zero.
TEST(Flow, NoNetFluxThroughAnyPlane)
{
  const int n[3] = {8, 8, 12};
  const double length[3] = {1.0, 1.0, 1.5};
  const Grid grid{{8, 8, 12}, {1.0, 1.0, 1.5}, FlowKernel{1.0}};
  std::vector<cplx> f[3];
  for (auto &field : f) field.assign(n[0] * n[1] * n[2], 0.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int p = 0; p < 20; ++p) {
    const double x[3] = {uniform(rng), uniform(rng), 1.5 * uniform(rng)};
    const double force[3] = {uniform(rng) - 0.5, uniform(rng) - 0.5, -uniform(rng)};    // net downwards
    grid.spread(x, force, f);
  }
  solve(StokesOperator{1e-3, 0.0}, n, length, f);
  double peak = 0.0;
  for (const cplx &u : f[2]) peak = std::max(peak, std::abs(u.real()));
  for (int k = 0; k < n[2]; ++k) {
    double flux = 0.0;
    for (int at = k * n[0] * n[1]; at < (k + 1) * n[0] * n[1]; ++at) flux += f[2][at].real();
    EXPECT_LT(std::abs(flux), 1e-12 * peak * n[0] * n[1]) << "plane " << k;
  }
  EXPECT_GT(peak, 0.0);
}

TEST(Flow, CloudSpeed)
{
  EXPECT_DOUBLE_EQ(cloud_speed(2.0, 100, 0.1, 1.0), 2.0 * (1.0 + 12.0));
  EXPECT_NEAR(hasimoto_mobility_correction(1.0, 1.0) * 6 * pi, -2.837297, 1e-12);
}

// Carnahan & Starling's S(0) of hard spheres: 1 at phi = 0, 1 - 8 phi to first order (the volume of
// radius 2a each sphere keeps clear), and the value at 5 %, 0.8145 / 1.2095 (computed by hand).
TEST(Flow, HardSphereStructureFactor)
{
  EXPECT_DOUBLE_EQ(hard_sphere_structure_factor(0.0), 1.0);
  EXPECT_NEAR((1.0 - hard_sphere_structure_factor(1e-6)) / 1e-6, 8.0, 1e-4);
  EXPECT_NEAR(hard_sphere_structure_factor(0.05), 0.81450625 / 1.20950625, 1e-12);
}

// The displaced profile of stratification grains needs a stable one: pooled where the parcels' noise
// makes a plane heavier (more negative) than the one below it, the mean force kept.
TEST(Flow, StableProfile)
{
  std::vector<double> stable = {-5.0, -4.0, -4.0, -1.0, 0.0};
  stable_profile(stable.data(), 5);
  EXPECT_EQ(stable, (std::vector<double>{-5.0, -4.0, -4.0, -1.0, 0.0}));
  std::vector<double> noisy = {-5.0, -3.0, -4.0, -2.0, -2.5, 0.0};    // planes 1-2 and 3-4 inverted
  stable_profile(noisy.data(), 6);
  EXPECT_EQ(noisy, (std::vector<double>{-5.0, -3.5, -3.5, -2.25, -2.25, 0.0}));
  std::vector<double> inverted = {0.0, -1.0, -2.0};    // heaviest on top: one pool at the mean
  stable_profile(inverted.data(), 3);
  EXPECT_EQ(inverted, (std::vector<double>{-1.0, -1.0, -1.0}));
}

TEST(Flow, CarriedExcess)
{
  // A class's profile falling linearly from -4 on the floor to none at plane 4, planes 1 mm apart
  const std::vector<double> q = {-4.0, -3.0, -2.0, -1.0, 0.0};
  const double mm = 1e-3, free = HUGE_VAL;
  // Lifted 0.5 mm from plane 2 it brings plane 1.5's density, -2.5: half as dense again as the mean there
  EXPECT_DOUBLE_EQ(carried_excess(0.0, q.data(), 5, mm, 2.0, 1.0, free, 0.5 * mm), 0.25);
  // and lowered back it has none; settling (no lift) leaves it as it is
  EXPECT_NEAR(carried_excess(0.25, q.data(), 5, mm, 2.0, 1.0, free, -0.5 * mm), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(carried_excess(0.25, q.data(), 5, mm, 3.0, 1.0, free, 0.0), 0.25);
  // The lagged flow's share of the slope, and the sphere's own limit on |Q'/Q| (0.5 /mm here), scale it
  EXPECT_DOUBLE_EQ(carried_excess(0.0, q.data(), 5, mm, 2.0, 0.5, free, 0.5 * mm), 0.125);
  EXPECT_DOUBLE_EQ(carried_excess(0.0, q.data(), 5, mm, 2.0, 1.0, 0.25 / mm, 0.5 * mm), 0.125);
  // Never denser than the floor's -4, nor below none: lifted 5 mm from plane 3, lowered 5 mm from plane 1
  EXPECT_DOUBLE_EQ(carried_excess(0.0, q.data(), 5, mm, 3.0, 1.0, free, 5.0 * mm), 3.0);
  EXPECT_DOUBLE_EQ(carried_excess(0.0, q.data(), 5, mm, 1.0, 1.0, free, -5.0 * mm), -1.0);
  // A uniform class gains nothing however far it is stirred, and is nowhere denser than itself; an
  // empty profile leaves the excess
  const std::vector<double> uniform = {-2.0, -2.0, -2.0};
  EXPECT_NEAR(carried_excess(-0.1, uniform.data(), 3, mm, 1.0, 1.0, free, 0.3 * mm), -0.1, 1e-15);
  EXPECT_DOUBLE_EQ(carried_excess(0.1, uniform.data(), 3, mm, 1.0, 1.0, free, 0.0), 0.0);
  const std::vector<double> empty = {0.0, 0.0, 0.0};
  EXPECT_DOUBLE_EQ(carried_excess(0.1, empty.data(), 3, mm, 1.0, 1.0, free, 0.3 * mm), 0.1);
}
