// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: constant-NVE integration of finite-size spheres with the
   fluid drag of fix fluid/drag treated implicitly (exponential integrator).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(nve/sphere/fluid,FixNVESphereFluid);
// clang-format on
#else

#ifndef LMP_FIX_NVE_SPHERE_FLUID_H
#define LMP_FIX_NVE_SPHERE_FLUID_H

#include "fix.h"
#include "sediment_rank_sums.h"

#include "sediment/integrator.hpp"

#include <array>
#include <vector>

namespace LAMMPS_NS {

class FixNVESphereFluid : public Fix {
 public:
  FixNVESphereFluid(class LAMMPS *, int, char **);
  ~FixNVESphereFluid() override;
  int setmask() override;
  void init() override;
  void setup(int) override;
  void initial_integrate(int) override;
  void final_integrate() override;
  double compute_vector(int) override;

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  double memory_usage() override;

  // Whether sphere i lies stopped on this fix's floor (its lowest point on it, at rest): part of the
  // deposit, which fix fluid/flow leaves out of the fluid it resolves.
  bool at_rest_on_floor(int i) const;
  // Whether sphere i is held at this fix's surface (its highest point on it), carried into it this step:
  // fix fluid/flow spreads no force of its (the surface holds it) and gives it the flow where it is.
  bool held_at_surface(int i) const;
  bool has_floor_or_surface() const { return floor_axis >= 0; }

 private:
  // Per atom, from the first half of the step to the second: the weights of the new force along and
  // across the slip (per unit mass) and the slip's direction, packed in 4 doubles
  // (sediment::pack_weights). The second half of a uniform step reads nothing else: the row's 32
  // bytes written and read again per atom and step are what its memory traffic adds to fix
  // nve/sphere's (the Linear step has none).
  enum { NWEIGHTS = sediment::PACKED_WEIGHTS_SIZE };
  double **weights;
  // Per atom, what else the step keeps when it is not uniform (below): whether the atom was in a
  // fluid (outside, the step is fix nve/sphere's, operation for operation) and the weight of the new
  // torque (per moment of inertia), in a row of 2 doubles that the second half reads with the
  // weights (together 48 bytes, less than the one row of 64 that held all of it with the memo). A
  // uniform step takes both anew in the second half: the drag fix's group bit, and fix nve/sphere's
  // division for the torque.
  enum { IN_FLUID, SPIN, NGENERAL };
  double **general;
  // Per atom, the exponentials of the last step's linear drag and of the last rotational drag
  // (sediment::phis memos), apart: read in the first half only, and then only where the law is
  // linear (the Linear step, only when the atom before had another rate) or there is a rotational drag.
  double **drag_memos, **spin_memos;
  int nmax_rows;    // rows with initialised memos
  // The per-atom arrays above, in the order they travel in an exchange: every allocation, copy,
  // exchange and memory count goes through this one table.
  struct PerAtomArray {
    double **FixNVESphereFluid::*array;
    int columns;
    const char *name;
  };
  static const std::array<PerAtomArray, 4> per_atom_arrays;
  static int doubles_per_atom();
  std::vector<class FixFluidDrag *> drags;
  // Set in setup() when there is one fluid/drag and it is immersed_everywhere() (every atom of its
  // group wholly immersed, no rotational drag): the step then skips the per-atom region and surface
  // look-ups, and the atoms in a fluid are those of the drag fix's group. Its fluid's velocity is
  // uniform, or per atom with a fix fluid/flow (atom_flow).
  class FixFluidDrag *uniform;
  // How the first half steps the spheres in a fluid, decided in setup(): General (linear laws, one
  // sphere at a time), Blocked (some fluid/drag has a nonlinear law: its spheres are stepped in
  // blocks, sediment::DragBlock), Smooth (Blocked, with every law smooth: no block prepares a step in
  // pieces, and no sphere is asked whether it needs one), LinearOnFloor (the uniform drag, in a fluid
  // of one velocity, is linear in the slip, F = c d w: c is taken once per run, and the step is
  // sediment::linear_step_initial with no per-sphere choice of law) or Linear (LinearOnFloor without a floor: the weights then depend on
  // the sphere's diameter and mass only, and the second half takes them anew, with fix nve/sphere's
  // two divisions, instead of from the weights row, which is neither written nor read).
  enum class HalfStep { General, Blocked, Smooth, LinearOnFloor, Linear };
  HalfStep half_step;
  bool atom_flow = false;    // some drag's fluid has a per-atom velocity (fix fluid/flow): setup()
  bool flow_jumped = false;  // and its fix fluid/flow solved at the last step: initial_integrate()
  bool reported_vectors = false;    // the log names the vector copy of the block step once
  double linear_per_diameter;    // c of the Linear step
  // The first half of the step for every atom of the group, with the drag found by lookup(i, sphere,
  // flow, spin_rate) (one loop, compiled for each look-up, way of stepping and floor or none:
  // step_first_half picks General, Blocked or Smooth, initial_integrate takes Linear with a look-up of
  // the diameter only); is_uniform: the look-up is the uniform drag's, and the step keeps only the
  // weights.
  template <HalfStep path, bool is_uniform, bool on_floor, class Lookup> void first_half(Lookup lookup);
  template <bool is_uniform, class Lookup> void step_first_half(Lookup lookup);
  // first_half of the uniform drag of a smooth law: every sphere of its group is wholly immersed, and
  // the block takes it through its whole first half (sediment::DragBlock::step_spheres).
  template <bool on_floor> void first_half_immersed();
  void check_column();    // every sphere of the group at or above the floor, or an error; under the surface

  int floor_axis;         // the axis across which the floor and the surface lie; -1: neither
  double floor_level;     // spheres stop with their lowest point here (-inf: no floor)
  double surface_level;   // spheres stop with their highest point here (+inf: no surface)

  // Diagnostics of the last step (compute_vector): spheres stuck by the yield stress, held at a
  // Cd jump, outside every fluid, and with their local solid fraction capped (hindered drag).
  enum { STUCK, AT_JUMP, OUTSIDE, CAPPED, NCOUNTS };
  RankSums<NCOUNTS> counts;
  // A NaN or inf spreads through contacts and grids without a trace: after the first half-step
  // the sum of the group's new positions and velocities is checked (NaN and inf survive a sum),
  // and the run stops at the first atom whose own sum is not finite, before the forces and grids
  // see it.
  void check_finite(double state) const;    // after the first half: stops at a NaN or inf state
  void find_non_finite() const;    // names the atom
};

}    // namespace LAMMPS_NS

#endif
#endif
