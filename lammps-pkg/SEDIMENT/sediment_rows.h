// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: per-atom 2d arrays indexed as rows of a fixed width, and runs of atoms.
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_ROWS_H
#define LMP_SEDIMENT_ROWS_H

namespace LAMMPS_NS {

// LAMMPS's memory->create and memory->grow keep a 2d array in one block behind its row pointers.
// Indexed as rows of `columns` doubles, an atom's row is found from its index, without loading its
// row pointer: a stream of 8 bytes per atom and array less in a per-atom loop (what the OPENMP
// package's styles do with their dbl3_t). nullptr for an array not allocated yet.
template <int columns> inline double (*flat_rows(double **array))[columns]
{
  return array ? reinterpret_cast<double(*)[columns]>(array[0]) : nullptr;
}

// Calls run(first, count) for each run of consecutive atoms i < n for which in_run(i) holds (the
// core's loops over rows take a run in vectors), and other(i) for each atom between the runs, in the
// order of the atoms.
template <class InRun, class Run, class Other> inline void for_each_run(int n, InRun in_run, Run run, Other other)
{
  for (int i = 0; i < n;) {
    int end = i;
    while (end < n && in_run(end)) ++end;
    if (end > i) {
      run(i, end - i);
      i = end;
    } else {
      other(i++);
    }
  }
}

}    // namespace LAMMPS_NS

#endif
