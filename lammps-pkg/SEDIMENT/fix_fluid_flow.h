// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: the flow the spheres drive (two-way coupling). Each
   sphere's force on the fluid (its drag, with the opposite sign) is spread
   onto a grid, the Stokes (or Brinkman) equations are solved spectrally with
   LAMMPS's FFT3d (KSPACE), and the fluid velocity read back at every sphere
   is the one its drag is taken against in the next step (fix fluid's
   velocity_at()). Periodic in x and y; in z periodic or a closed column
   (free-slip bottom and top, by mirror images).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(fluid/flow,FixFluidFlow);
// clang-format on
#else

#ifndef LMP_FIX_FLUID_FLOW_H
#define LMP_FIX_FLUID_FLOW_H

#include "fix.h"

#include "sediment/flow.hpp"

#include <string>
#include <utility>
#include <vector>

namespace LAMMPS_NS {

class FixFluidFlow : public Fix {
 public:
  FixFluidFlow(class LAMMPS *, int, char **);
  ~FixFluidFlow() override;
  int setmask() override;
  void post_integrate() override;
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  double compute_vector(int) override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;
  double memory_usage() override;

  // The fix fluid whose velocity this fix gives (fix fluid attaches it in its init()).
  const char *fluid_name() const { return fluid_id; }
  // The per-atom fluid velocity, as the address of the fix's row pointer (rows move when they grow).
  double **const *velocity_rows() const { return &velocity; }
  // Whether the flow was solved at `step` (its per-atom velocity then jumped).
  bool solved_at(bigint step) const { return last_solve == step; }

 private:
  char *fluid_id;
  class FixFluid *fluid;
  std::vector<class FixFluidDrag *> drags;    // the fluid/drag fixes of this fluid (setup())
  std::vector<class FixNVESphereFluid *> floors;    // the nve/sphere/fluid fixes with a floor or a surface (setup())
  int grid[3];           // cells of the fluid: x, y, and z of the box (periodic) or of the column
  int nzt;               // planes of the transform: grid[2], or 2 grid[2] with the column's mirror
  bool column;           // closed in z: free slip at column_lo and column_hi
  double column_lo, column_hi;
  double relax;          // u <- (1 - relax) u + relax u_solved
  std::string weight_name;    // per-atom property: the real grains each sphere (a parcel) stands for
  int weight_index;
  // stratification grains: the column's mean density profile, displaced by the flow, pushes back with
  // the real grains' force (w per parcel), not the parcels' sqrt(w S(0)) (stratification_force)
  bool stratify;
  double *excess;             // per atom: its class's density where it is over the class's mean there, less 1
  const double *gravity;      // stratification grains: fix gravity's acceleration (the grains' weight)
  double displaced_time;      // the time up to which excess is summed
  double solve_interval;      // the time between the last two solves
  int lowest_class;           // the settling class of profiles' first row (settling_class())
  bool excess_in_file;        // the restart file read holds each sphere's excess (restart())
  double drift_limit;    // > 0: solve once the spheres may have moved this many cells since the last solve,
                         // or their largest speed has changed by this fraction
  static constexpr double DEFAULT_DRIFT = 0.2;    // without every or drift
  double drift;          // cells the fastest sphere of each step has moved since the last solve, summed
  double cfl;            // > 0: the step is shortened so that the flow carries no sphere more than this many
                         // cells in one step (with every N, between two solves)
  double longest_dt;     // the input's timestep: the step cfl shortens and lengthens back to
  double applied_dt;     // the step cfl last set (0: none), to tell it from a new timestep command
  bool told_shortened;   // the first shortening of a run is reported
  double solved_speed;   // the largest speed at the last solve
  bool unsettled;        // the last solve changed the spheres' fluid velocities by more than drift_limit
  double solved_uniform[3], solved_viscosity;    // the fluid's uniform velocity and viscosity at the last solve
  sediment::StokesOperator stokes;
  sediment::FlowKernel kernel;
  double **velocity;     // per atom: the fluid velocity its drag is taken against
  // per atom: the voidage its drag's hindrance read in this step (post_integrate()); < 0: none yet
  double *stepped_voidage;
  bool hindered;         // some drag's hindrance reads a concentration
  bool solved;           // velocity holds a solve (or was read from a restart)
  class FFT3d *fft;
  int plane_lo, plane_hi;         // this rank's planes of the transform grid
  std::vector<int> first_plane;   // rank r's planes are first_plane[r] to first_plane[r + 1] - 1
  std::vector<double> slab;       // this rank's planes of the force density, then of the velocity, [k][j][i][c]
  std::vector<double> field[3];   // this rank's planes, complex (re, im), one per component
  // The nodes of the transform grid a rank spreads onto and reads from: per axis, the global indices
  // its spheres' kernels touch and those of its subdomain (where a sphere created between solves
  // reads the last solve's flow); a brick of the grid, wrapped, with gaps where no sphere is near.
  struct Brick {
    std::vector<int> nodes[3];    // global indices held, increasing
    std::vector<int> local[3];    // global index -> its place in nodes (-1: not held)
    long size() const { return static_cast<long>(nodes[0].size() * nodes[1].size() * nodes[2].size()); }
  };
  // Every rank's node lists: rank r's along axis d are size[3 r + d] values of nodes from offset[3 r + d].
  struct Bricks {
    std::vector<int> size, offset, nodes;
  };
  Brick brick;                    // this rank's, at the last solve
  Bricks bricks;
  std::vector<double> spread;     // the force density on brick's nodes, [k][j][i][c]
  std::vector<double> flow;       // the last solve's velocity on brick's nodes, [k][j][i][c]
  std::vector<double> sent, received;    // planes in flight between bricks and slabs
  std::vector<int> send_counts, send_offsets, recv_counts, recv_offsets;
  // The planes nzt - k (mod nzt) this rank needs for its planes k (the waves -k of its modes), to
  // tell the transforms of f_x and f_y apart when f_x + i f_y is transformed as one: which of its
  // own planes it sends (in order, counts and offsets per rank in doubles), and which of its
  // planes each received one serves.
  std::vector<int> mirror_sent, mirror_serves;
  std::vector<int> mirror_send_counts, mirror_send_offsets, mirror_recv_counts, mirror_recv_offsets;
  std::vector<double> mirror_out, mirror_in;
  double origin[3], spacing[3], length[3];
  double self_flow[3];    // per axis: the flow a unit force gives back where it is spread (images too)
  // A closed column: per axis, the flow a unit force's mirror image gives back at its source, by their
  // separation along z in steps of 1 / IMAGE_STEPS cell, 0 to the column's height ([separation][axis])
  std::vector<double> image_flow;
  static constexpr int IMAGE_STEPS = 8;
  // Diagnostics of the last solve (compute_vector)
  enum { FX, FY, FZ, FLUX, PEAK, LEFT_OUT, SOLVES, NDIAG };
  double diag[NDIAG];
  // count, solved, drift, speed, unsettled, viscosity, uniform, diag (UNSTRATIFIED: files written
  // before stratification grains kept its state), then solve_interval, lowest_class, planes, then
  // (files whose solved value is STEP_STATE more) the longest and the applied step of cfl
  static constexpr int UNSTRATIFIED = 9 + NDIAG, RESTART_VALUES = 12 + NDIAG, STEP_VALUES = 2;
  static constexpr double STEP_STATE = 2.0;

  bigint last_solve;         // the step of the last solve (-1: none yet in this fix)
  bool warned_carry;         // the warning that the flow carries spheres a cell between solves was given
  int carries;               // solves in a row at which it did (check_carry)
  double carry_start;        // and the grid's largest velocity at the first of them
  int reversals;             // solves in a row whose fluid velocities reversed and grew (check_stable)
  double reversal_growth;    // and how much the squared velocities grew over them
  // A point's kernel on the transform grid: per axis, its nodes (global indices wrapped onto the
  // periodic grid, then offsets into a brick's values, [k][j][i][c]: place()) and their weights.
  struct Stencil {
    long node[3][sediment::FlowKernel::max_nodes];
    double w[3][sediment::FlowKernel::max_nodes];
  };
  // Each solve's spheres in the fluid (local indices, increasing), their kernels, their forces on the
  // fluid (3 per sphere) and the local solid fractions their hindrance reads (0 without one).
  std::vector<int> spheres;
  std::vector<Stencil> stencils;
  std::vector<double> forces, fractions;
  std::vector<char> held;    // the solve's spheres held at a surface (their force not spread)
  std::vector<double> scales;    // with weight: each force's factor sqrt(w S(0)) (weigh_forces)
  // stratify: per settling class, the mean missing force density of each plane of nodes (made stable;
  // [class][plane]) and the mean missing force per sphere; the share of the sum of their slopes the
  // lagged flow can follow, per cell along z; and each solve's sphere's restoring force along z
  std::vector<double> profiles, class_force, slope_share, restoring;
  std::vector<double> diameter, speed, voidage, per_speed;    // sphere_forces' columns for the drag law

  void solve();
  bool outside_column(const double *x) const;
  bool left_out(int i) const;
  bool held_at_surface(int i) const;
  bool fluid_changed() const;
  void report_settings() const;
  double largest_speed(double *const *v) const;
  bool stale(double speed) const;
  void limit_step();
  void set_step(double dt);
  void check_stable(const double *change);
  void check_carry(double peak, double carried_by);
  void transform_solve();
  void plan_mirror_exchange();
  void separate_xy();
  void measure_self_flow();
  void image_flow_at(double z, double *u) const;
  Stencil stencil_at(const double *x) const;
  void build_brick(Brick &b, const std::vector<Stencil> &at, bool subdomain) const;
  static bool holds(const Stencil &at, const Brick &b);
  static void place(Stencil &at, const Brick &b);
  int owner(int q) const;
  void routes(int q, int to, bool mirror, bool &direct, bool &mirrored) const;
  void gather_bricks(const Brick &b);
  void sum_into_slabs(const Brick &b, const std::vector<double> &force, bool mirror);
  void read_from_slabs(const Brick &b, std::vector<double> &velocity);
  void spread_point(const Stencil &at, const double *force, std::vector<double> &density) const;
  void read_point(const Stencil &at, const std::vector<double> &velocity, double *u) const;
  void sphere_forces();
  void weigh_forces();
  void displace();
  void stratification_force();
  std::pair<int, double> profile_place(double z) const;
  int settling_class(int i) const;
  void share_slopes();
  double sphere_force(int i, double *force) const;
  double stepped(int i, double now) const { return stepped_voidage[i] >= 0.0 ? stepped_voidage[i] : now; }
};

}    // namespace LAMMPS_NS

#endif
#endif
