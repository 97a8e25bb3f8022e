// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: per-atom 2d arrays indexed as rows of a fixed width.
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

}    // namespace LAMMPS_NS

#endif
