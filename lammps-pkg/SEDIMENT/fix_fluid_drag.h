// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: drag of a fluid on spheres (Newtonian or Bingham laws).
   Applied explicitly in post_force, except on the atoms a drag-implicit
   integrator (fix nve/sphere/fluid) advances: it reads the law from here.
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(fluid/drag,FixFluidDrag);
// clang-format on
#else

#ifndef LMP_FIX_FLUID_DRAG_H
#define LMP_FIX_FLUID_DRAG_H

#include "fix.h"
#include "sediment_rank_sums.h"

#include "sediment/integrator.hpp"

#include <algorithm>
#include <memory>

namespace LAMMPS_NS {

class FixFluidDrag : public Fix {
 public:
  FixFluidDrag(class LAMMPS *, int, char **);
  ~FixFluidDrag() override;
  int setmask() override;
  void init() override;
  void setup(int) override;
  void post_force(int) override;
  double compute_vector(int) override;

  class FixFluid *fluid_fix() const { return fluid; }
  // Call once per step before sphere_drag(): refreshes the fluid region.
  void prepare_step();
  // The drag on local atom i during this step (model nullptr if it is not in the group/fluid).
  sediment::SphereDrag sphere_drag(int i) const;
  // True if the local solid fraction of atom i exceeds max_fraction (its drag uses max_fraction).
  bool fraction_capped(int i) const { return immersed().capped(i); }
  // Linear rate of the rotational drag torque, torque = -rate * I * omega (0 if off).
  double rotation_rate(int i, const sediment::SphereDrag &drag) const;
  // True when every atom of the group is wholly immersed (a fluid without surface or region) and has
  // no rotational drag: then immersed_drag(i) is sphere_drag(i) for the atoms of the group, and an
  // integrator may skip the per-atom region, surface and rotation look-ups (the fluid's velocity
  // may still be per atom: fix fluid/flow).
  bool immersed_everywhere() const;
  // immersed_everywhere(), with the fluid's velocity uniform (no fix fluid/flow).
  bool uniform() const;
  // True when the drag of a wholly immersed sphere is not linear in the slip (any law but Stokes in a
  // Newtonian fluid).
  bool nonlinear() const { return !(linear_per_diameter() > 0.0); }
  // c when the drag of a wholly immersed sphere of diameter d is F = c d w, else 0.
  double linear_per_diameter() const { return model->linear_coefficient(1.0); }
  const sediment::DragModel *drag_model() const { return model.get(); }
  // True when the hindrance reads a concentration compute's local fractions.
  bool reads_concentration() const { return concentration_id != nullptr; }
  // The drag on local atom i of the group when uniform(): its diameter and local fraction only.
  sediment::SphereDrag immersed_drag(int i) const { return immersed().drag(i); }
  // immersed_drag() with the per-atom arrays taken once, for an integrator's per-atom loop (inline
  // there: a call per atom into this fix cost as much as the look-up).
  struct Immersed {
    const sediment::DragModel *model;
    const double *radius;
    const double *fraction;    // local solid fraction per atom; nullptr without a concentration
    double max_fraction;
    sediment::SphereDrag drag(int i) const
    {
      sediment::SphereDrag drag;
      drag.model = model;
      drag.diameter = 2.0 * radius[i];
      if (fraction) drag.scale.voidage = sediment::voidage_of(fraction[i], max_fraction);
      return drag;
    }
    bool capped(int i) const { return fraction && fraction[i] > max_fraction; }
  };
  Immersed immersed() const;

 private:
  char *fluid_id;
  class FixFluid *fluid;
  sediment::DragLaw law;
  sediment::HindranceBuoyancy hindrance_buoyancy;
  sediment::Hindrance hindrance;
  std::unique_ptr<sediment::DragModel> model;
  char *concentration_id;
  class Compute *concentration;    // per-atom local solid fraction (under a hindrance)
  double max_fraction;             // local fractions are capped here
  int rotation;
  int implicit_groupbit;    // atoms advanced by fix nve/sphere/fluid: no explicit drag
  bool all_implicit;        // every atom of the group is one of them
  // Explicitly integrated atoms: drag force (x, y, z), spheres outside the fluid, capped fractions.
  enum { FX, FY, FZ, OUTSIDE, CAPPED, NTOTALS };
  RankSums<NTOTALS> totals;

  // visit(i, drag, slip[3]) for every local atom of the group that this fix drags explicitly
  // (drag.model is nullptr outside the fluid).
  template <class Visit> void for_each_explicit(Visit visit);
  int count_unstable_explicit();
  void refresh_concentration();
};

}    // namespace LAMMPS_NS

#endif
#endif
