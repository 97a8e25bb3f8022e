// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: squeeze-film lubrication between close spheres, with
   the optional exponential repulsion of Bravo et al. (2015). Meant for
   pair_style hybrid/overlay next to a granular contact style.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(lubricate/fluid,PairLubricateFluid);
// clang-format on
#else

#ifndef LMP_PAIR_LUBRICATE_FLUID_H
#define LMP_PAIR_LUBRICATE_FLUID_H

#include "pair.h"

#include "sediment/lubrication.hpp"

namespace LAMMPS_NS {

class PairLubricateFluid : public Pair {
 public:
  PairLubricateFluid(class LAMMPS *);
  ~PairLubricateFluid() override;
  void compute(int, int) override;
  void settings(int, char **) override;
  void coeff(int, char **) override;
  void init_style() override;
  double init_one(int, int) override;
  int pack_forward_comm(int, int *, double *, int, int *) override;
  void unpack_forward_comm(int, int, double *) override;
  int pack_reverse_comm(int, int, double *) override;
  void unpack_reverse_comm(int, int *, double *) override;
  double memory_usage() override;

 private:
  char *fluid_id;
  class FixFluid *fluid;
  sediment::LubricationRange range;
  double repulsion_scale;    // force unit of the Bravo et al. repulsion; 0: off
  int limit;                 // scale damping so that it cannot overshoot at the time step
  double maxrad;
  double *damping_sum;       // per atom: sum of the squeeze coefficients of its pairs
  int nmax;

  void allocate();
  void sum_damping();
  // Calls visit(i, j, x_i - x_j, r, gap) for every neighbour pair of types given a pair_coeff.
  template <class Visit> void for_each_pair(Visit visit);
};

}    // namespace LAMMPS_NS

#endif
#endif
