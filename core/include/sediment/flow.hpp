// SPDX-License-Identifier: GPL-2.0-or-later
// The flow that the spheres drive (two-way coupling, docs/physics.md section 8): each sphere's force
// on the fluid is spread onto a regular grid with a Gaussian kernel, the incompressible Stokes (or
// Brinkman) equations are solved mode by mode in Fourier space, and the velocity is read back at the
// spheres with the same kernel. No FFT here: the caller transforms (LAMMPS's FFT3d in fix
// fluid/flow, a plain DFT in the tests) and calls these per mode and per sphere.
#pragma once

#include <cmath>

namespace sediment {

// Whether n is a grid size the FFTs take: n >= 1 with no prime factor other than 2, 3 and 5 (LAMMPS's
// KISS FFT and PPPM's own rule; FFTW takes these fastest).
bool fft_friendly(int n);

// The wavenumber of index m of an n-point periodic grid of length L: 2 pi m' / L with m' = m for
// m <= n / 2, else m - n (the Nyquist mode of an even n is taken as +n/2; the operator below is even in k).
double grid_wavenumber(int m, int n, double length);

// Stokes (brinkman = 0) or Brinkman: mu lap u - brinkman u - grad p + f = 0, div u = 0. In Fourier
// space u(k) = (I - k k / k^2) f(k) / (mu k^2 + brinkman): the pressure takes the longitudinal part
// of the force. The k = 0 mode is set to zero: the mean force is held by the mean pressure gradient
// of a closed column (or the periodic box's frame), so the net volume flux is zero (the return flow).
// With vessel_across, so are the modes uniform across: in a periodic box, a horizontal force whose mean
// over the box's section is not zero in some plane acts the same in every image, over the whole of an
// infinitely wide plane, and drives a shear flow of mobility 1 / (mu kz^2), for a column of height H
// up to (H / pi)^2 / mu: (H / W)^2 / 4 times the box-wide mode's. In a vessel much wider than the box,
// the neighbouring parts of a plane are pushed independently, their mean over the vessel's section is
// nil, and its walls hold what is left; such a flow would also take H^2 / nu (hours) to grow.
// With `smoothing` s^2 > 0 every mode is also multiplied by exp(-k^2 s^2): a Gaussian of variance
// s^2 / 2 applied to the force as it is spread and again to the velocity as it is read (the part of
// the kernel's width the grid does not take, FlowKernel).
struct StokesOperator {
  double viscosity = 1.0;
  double brinkman = 0.0;     // 0: Stokes; > 0: the resistance per unit volume of a Brinkman medium
  double smoothing = 0.0;    // s^2 [length^2]
  // true: the box across is a sample of a much wider vessel, and the modes uniform across (kx = ky =
  // 0, a flow the same over each whole horizontal plane) carry no flow; false: a periodic array.
  bool vessel_across = false;
  // u(k) from f(k), one mode, complex values as (re, im) pairs: f[2 c] + i f[2 c + 1], c = 0, 1, 2.
  // `scale` multiplies the result (1 / N for an unscaled inverse transform). u may be f.
  void apply(const double k[3], const double *f, double *u, double scale = 1.0) const;
};

// Applies the operator to a brick of a periodic grid in Fourier space, in place (and sets every mode
// at the Nyquist index of an even axis to zero: k and -k are one mode there, so the velocity of a
// real force stays real, and the fix may bring back two of its components in one transform): three complex fields
// (x, y, z components), each (re, im) interleaved, index ((k - klo) * nj + (j - jlo)) * ni + (i - ilo)
// with i fastest, over [ilo, ihi] x [jlo, jhi] x [klo, khi] of the global n[0] x n[1] x n[2] grid of
// lengths length[3]; scale as above.
void stokes_apply_brick(const StokesOperator &op, const int n[3], const double length[3], const int lo[3],
                        const int hi[3], double *fx, double *fy, double *fz, double scale);

// The spreading and interpolation kernel, split as PPPM splits its own: on the grid the cubic B-spline
// (4 nodes per axis, variance 1/3 of a cell squared; its weights sum to 1 and centre on the point, so
// the spread force is the sphere's force exactly and momentum is conserved to round-off), the rest of
// a Gaussian of standard deviation `width` cells in Fourier space (StokesOperator::smoothing), where it
// costs nothing per sphere and damps the B-spline's aliasing. Nodes sit at integer positions (a
// cell-centred grid: node k at lo + (k + 1/2) h has position k).
struct FlowKernel {
  static constexpr int max_nodes = 4;    // per axis
  double width = 1.0;                    // the whole kernel's standard deviation, in cells (>= 1)
  // Nodes first, ..., first + 3 (unwrapped: the caller wraps them onto a periodic axis) and their
  // weights for a point at `position` (in grid spacings); returns their count, 4.
  // Inline: fix fluid/flow takes them for every sphere and axis at each solve.
  int weights(double position, int &first, double *w) const
  {
    const double below = std::floor(position);
    const double t = position - below, u = 1.0 - t;
    first = static_cast<int>(below) - 1;
    w[0] = u * u * u / 6.0;
    w[1] = (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0;
    w[2] = (3.0 * u * u * u - 6.0 * u * u + 4.0) / 6.0;
    w[3] = t * t * t / 6.0;
    return max_nodes;
  }
  int max_count() const { return max_nodes; }
  // The variance left to the Fourier-space Gaussian, in cells squared: width^2 - 1/3.
  double fourier_variance() const { return width * width - 1.0 / 3.0; }
};

// The velocity a sphere's own spread force gives it back in unbounded fluid, per unit force: a
// Gaussian force blob of standard deviation sigma read with the same Gaussian moves as a sphere of
// radius sigma sqrt(pi) (Maxey & Patel's force-coupling result): 1 / (6 pi mu sigma sqrt(pi)). A
// sphere's drag is taken relative to the velocity the others (and its periodic or mirror images)
// give it, so this is subtracted from what it reads on the grid.
double gaussian_self_mobility(double viscosity, double sigma);

// The long-wave structure factor of a suspension of hard spheres at solid fraction phi, S(0) = 1 + n
// int (g - 1) dV, from Carnahan & Starling's equation of state: (1 - phi)^4 / (1 + 4 phi + 4 phi^2
// - 4 phi^3 + phi^4); 1 - 8 phi at low phi, the volume of radius 2a each sphere keeps clear. On a grid
// whose kernel is wider than the spheres' correlations, a sphere reads its neighbours' flow as if they
// were spread with S(0) times their number minus itself: the closure of docs/physics.md section 8.
double hard_sphere_structure_factor(double phi);

// The mean force density of a settling column along z (its planes from the bottom up), made monotone:
// the least-squares fit that never grows upwards (pool adjacent violators; a force density is negative,
// downwards, so "never grows" means the column is nowhere lighter below than above). A settling
// column's mean density is stably stratified; the parcels' profile, a few per plane, is not, and its
// noise would be read as heavy fluid over light, which the displaced profile of fix fluid/flow's
// stratification grains would then drive as it restores a real one.
void stable_profile(double *profile, int planes);

// stratification grains: a sphere's excess r, how much denser its settling class is around it than
// the class's mean at its height, relative to that mean, once the flow has lifted it by `lift` along z.
// `profile` is the class's stable profile (`planes` planes from the bottom up, `spacing` apart), `at`
// the sphere's place in planes (0 to planes - 1), `share` the part of the slope there the lagged flow
// can follow, `largest_relative_slope` the most of |Q'/Q| the sphere's own force may follow. The
// density its class brings with it is kept, (1 + r) Q changing by -Q' lift, within the profile's range
// and above none; where the profile is empty, r stays.
double carried_excess(double excess, const double *profile, int planes, double spacing, double at, double share,
                      double largest_relative_slope, double lift);

// Nitsche & Batchelor (1997): a cloud of n spheres of radius a, terminal speed us alone, within a
// sphere of radius r settles for n a / r >> 1 as a drop of the same viscosity, u = us (1 + 6/5 n a / r).
double cloud_speed(double us, int n, double a, double r);
// The leading correction to a body's mobility in a cubic periodic box of side L with no net flux
// (Hasimoto 1959): -2.837297 / (6 pi mu L), the same for a sphere, a drop or a cloud of any size
// to this order (the next term is O(volume fraction of the body in the box)).
double hasimoto_mobility_correction(double viscosity, double box);

}    // namespace sediment
