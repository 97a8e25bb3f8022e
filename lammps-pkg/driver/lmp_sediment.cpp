// SPDX-License-Identifier: GPL-2.0-or-later
// lmp_sediment: the LAMMPS command line with the SEDIMENT styles registered.
// Accepts every LAMMPS command-line switch (-in, -var, -log, -screen, ...) and runs under mpirun.
// Errors end the run as LAMMPS's own main() ends it: current LAMMPS throws them as exceptions
// (already printed), Debian's 2021 build exits inside error->all.

#include "input.h"
#include "lammps.h"
#include "sediment_lammps_api.h"
#include "sediment_styles.h"

#include <cstdio>
#include <exception>
#include <mpi.h>

int main(int argc, char **argv)
{
  MPI_Init(&argc, &argv);
  int status = 0;
  try {
    auto lmp = new LAMMPS_NS::LAMMPS(argc, argv, MPI_COMM_WORLD);
    LAMMPS_NS::sediment_register_styles(lmp);
    lmp->input->file();
    delete lmp;
  } catch (LAMMPS_NS::LAMMPSAbortException &abort) {    // error->one on some ranks: the others cannot know
    MPI_Abort(LAMMPS_NS::sediment_abort_universe(abort), 1);
  } catch (LAMMPS_NS::LAMMPSException &) {    // error->all: every rank is here, the message printed
    status = 1;
  } catch (std::exception &e) {    // e.g. std::bad_alloc: not printed yet, and the ranks may disagree
    fprintf(stderr, "ERROR: %s\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  // What LAMMPS printed (its results, its ERROR line) is out before MPI's shutdown: a pipe's buffer
  // would go with the process if it died there (a run in a suite died of SIGSEGV at exit with no line
  // of its output, once in thousands, under load).
  fflush(stdout);
  fflush(stderr);
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
  return status;
}
