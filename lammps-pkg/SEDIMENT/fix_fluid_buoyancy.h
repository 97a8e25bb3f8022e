// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: Archimedes buoyancy with partial submergence.
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(fluid/buoyancy,FixFluidBuoyancy);
// clang-format on
#else

#ifndef LMP_FIX_FLUID_BUOYANCY_H
#define LMP_FIX_FLUID_BUOYANCY_H

#include "fix.h"
#include "sediment_rank_sums.h"

namespace LAMMPS_NS {

class FixFluidBuoyancy : public Fix {
 public:
  FixFluidBuoyancy(class LAMMPS *, int, char **);
  ~FixFluidBuoyancy() override;
  int setmask() override;
  void init() override;
  void setup(int) override;
  void post_force(int) override;
  double compute_vector(int) override;
  class FixFluid *fluid_fix() const { return fluid; }

 private:
  void warn_of_bobbing();    // a floating sphere's time step against its bobbing period
  char *fluid_id, *gravity_id, *mixture_id;
  class Compute *mixture;       // per-atom local solid fraction: buoyancy of the suspension
  double solid_density;         // density of the suspended solids, for the mixture density
  double max_fraction;          // the local solid fraction is capped here
  class FixFluid *fluid;
  const double *gravity;      // acceleration vector owned by the fix gravity
  RankSums<4> totals;         // force on the group (3) and number of spheres in the fluid
};

}    // namespace LAMMPS_NS

#endif
#endif
