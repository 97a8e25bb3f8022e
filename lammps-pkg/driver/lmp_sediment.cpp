// SPDX-License-Identifier: GPL-2.0-or-later
// lmp_sediment: the LAMMPS command line with the SEDIMENT styles registered.
// Accepts every LAMMPS command-line switch (-in, -var, -log, -screen, ...) and runs under mpirun.

#include "input.h"
#include "lammps.h"
#include "sediment_styles.h"

#include <mpi.h>

int main(int argc, char **argv)
{
  MPI_Init(&argc, &argv);
  auto lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
  LAMMPS_NS::sediment_register_styles(lmp);
  lmp->input->file();
  delete lmp;
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
  return 0;
}
