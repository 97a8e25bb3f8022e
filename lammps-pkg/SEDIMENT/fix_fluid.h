// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: a fluid at rest (or in uniform motion) around DEM spheres.
   Holds the fluid's properties and geometry; applies no force itself.
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(fluid,FixFluid);
// clang-format on
#else

#ifndef LMP_FIX_FLUID_H
#define LMP_FIX_FLUID_H

#include "fix.h"

#include <string>

#include "sediment/drag.hpp"
#include "sediment/geometry.hpp"

namespace LAMMPS_NS {

class FixFluid : public Fix {
 public:
  FixFluid(class LAMMPS *, int, char **);
  ~FixFluid() override;
  int setmask() override;
  void init() override;

  // Call before immersion() in every step: refreshes a moving region and a surface given by a
  // variable, once per step however many styles ask.
  void prepare();
  // How much of sphere (centre x, radius r) is in the fluid (inline: called per atom and step).
  sediment::Submergence immersion(const double *x, double radius) const
  {
    return fills_space() ? sediment::Submergence{1.0, 1.0, 1.0} : bounded_immersion(x, radius);
  }

  const sediment::Fluid &properties() const { return fluid; }
  bool is_bingham() const { return fluid.yield_stress > 0.0; }
  const double *velocity() const { return flow; }
  // The fluid velocity at local atom i: the uniform one, or where a fix fluid/flow gives the fluid its
  // own velocity, the one it solved for atom i (the styles' general per-atom paths read this; their
  // uniform paths read velocity(), and atom_velocities() where there is a fix fluid/flow).
  const double *velocity_at(int i) const { return atom_flow ? (*atom_flow)[i] : flow; }
  bool has_atom_flow() const { return atom_flow != nullptr; }
  // Whether the fix fluid/flow solved at `step`: the per-atom velocity then jumped, and a drag step
  // that starts from it may start far from where it ends (fix nve/sphere/fluid).
  bool flow_solved_at(bigint step) const;
  // The fix fluid/flow's per-atom velocity rows, or nullptr: read once for a loop over the atoms (the
  // rows move when the atom arrays grow).
  double **atom_velocities() const { return atom_flow ? *atom_flow : nullptr; }
  // Whether every sphere is wholly immersed (no free surface, no region).
  bool fills_space() const { return !has_surface && !region_id; }

  // Finds fix ID `fluid_id` and checks that it is a fix fluid; `caller` names the style asking
  // ("Fix fluid/drag", "Pair lubricate/fluid").
  static FixFluid *find(class LAMMPS *lmp, const char *fluid_id, const std::string &caller);

 private:
  sediment::Fluid fluid;
  double flow[3];
  double **const *atom_flow;    // a fix fluid/flow's per-atom velocity rows (nullptr: none), set in init()
  const class FixFluidFlow *flow_fix;    // and the fix itself
  int has_surface;
  double surface_normal[3];    // unit normal pointing out of the fluid
  double surface_offset;       // surface is {x : x . normal = offset}
  char *surface_variable;      // equal-style variable giving the offset (nullptr: fixed)
  int surface_ivar;
  bool centre_crossing;        // the whole sphere is in the fluid once its centre is (no cap)
  bigint prepared_step;        // the step prepare() last refreshed (-1: none in this run)
  char *region_id;
  class Region *region;
  sediment::Submergence bounded_immersion(const double *x, double radius) const;
};

}    // namespace LAMMPS_NS

#endif
#endif
