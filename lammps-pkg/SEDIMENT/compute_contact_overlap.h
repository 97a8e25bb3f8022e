// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: the largest overlap of touching spheres, to check that
   soft contacts stay within an overlap tolerance.
------------------------------------------------------------------------- */

#ifdef COMPUTE_CLASS
// clang-format off
ComputeStyle(contact/overlap,ComputeContactOverlap);
// clang-format on
#else

#ifndef LMP_COMPUTE_CONTACT_OVERLAP_H
#define LMP_COMPUTE_CONTACT_OVERLAP_H

#include "compute.h"

namespace LAMMPS_NS {

class ComputeContactOverlap : public Compute {
 public:
  ComputeContactOverlap(class LAMMPS *, int, char **);
  ~ComputeContactOverlap() override;
  void init() override;
  void init_list(int, class NeighList *) override;
  double compute_scalar() override;
  void compute_vector() override;

 private:
  class NeighList *list;
  bigint measured_step;    // the step vector[] was last measured on
  void measure();
};

}    // namespace LAMMPS_NS

#endif
#endif
