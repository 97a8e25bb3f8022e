// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: per-step sums of a fix's diagnostics, accumulated on
   each rank and reduced over all ranks when first read (compute_vector).
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_RANK_SUMS_H
#define LMP_SEDIMENT_RANK_SUMS_H

#include <array>
#include <mpi.h>

namespace LAMMPS_NS {

template <int N> class RankSums {
 public:
  RankSums() { clear(); }
  void clear()
  {
    local.fill(0.0);
    reduced = false;
  }
  double &operator[](int k) { return local[k]; }
  // Collective on first call after clear(): every rank must ask (as compute_vector does).
  double total(int k, MPI_Comm comm)
  {
    if (!reduced) {
      MPI_Allreduce(local.data(), global.data(), N, MPI_DOUBLE, MPI_SUM, comm);
      reduced = true;
    }
    return global[k];
  }

 private:
  std::array<double, N> local, global{};
  bool reduced;
};

}    // namespace LAMMPS_NS

#endif
