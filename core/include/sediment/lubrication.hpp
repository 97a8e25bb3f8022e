// SPDX-License-Identifier: GPL-2.0-or-later
// Lubrication between two close spheres (docs/physics.md section 5): the leading-order Reynolds
// squeeze-film force and the exponential repulsion of Bravo et al. (2015).
#pragma once

namespace sediment {

// Where the squeeze film acts, in units of the effective radius a = r_i r_j / (r_i + r_j).
struct LubricationRange {
  double inner = 0.01;    // gap h_in / a below which the force is frozen (surface roughness)
  double outer = 0.5;     // gap h_out / a beyond which there is none
};

inline double effective_radius(double ri, double rj) { return ri * rj / (ri + rj); }

// Coefficient c of the squeeze-film force -c v_n (v_n = dh/dt): 6 pi mu a^2 / h, with h held at
// the inner gap below it and c = 0 from the outer gap on.
double squeeze_coefficient(double viscosity, double ri, double rj, double gap, const LubricationRange &range);

// The Bravo et al. repulsion on sphere i from sphere j, in units of the user's force scale:
// 10 q^3 exp(-10 g / q) with q = 2 d_i / (d_i + d_j) and g = h / d_i; zero from bravo_reach on.
double bravo_repulsion(double di, double dj, double gap);

// The gap where the repulsion on sphere i has fallen to 1e-3 of its contact value and is cut:
// g / q = ln(1000) / 10, i.e. 0.69 q d_i (at most 1.39 d_i, as d_j -> 0).
double bravo_reach(double di, double dj);

// The largest share of c_ij that keeps an explicit velocity update damped monotonically: with
// S_i = sum_j c_ij over sphere i's neighbours, every c_ij scaled by
// min(1, m_i / (2 dt S_i), m_j / (2 dt S_j)) gives dt M^-1 C eigenvalues <= 1 (Gershgorin), so
// approach speeds decay without reversing at any dt. Returns that factor.
double damping_share(double dt, double mi, double si, double mj, double sj);

}    // namespace sediment
