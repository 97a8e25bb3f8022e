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
#include <cstring>
#include <dlfcn.h>
#include <exception>
#include <link.h>
#include <mpi.h>

namespace {
// Keeps a component of Open MPI (mca_*.so) or of PMIx (pmix_mca_*.so) mapped until the process exits.
int pin_mpi_component(dl_phdr_info *info, size_t, void *)
{
  const char *path = info->dlpi_name;
  const char *name = path ? strrchr(path, '/') : nullptr;
  if (name && (strncmp(name, "/mca_", 5) == 0 || strncmp(name, "/pmix_mca_", 10) == 0))
    dlopen(path, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
  return 0;
}
}    // namespace

// Every MPI_Finalize of the process comes here (MPI's profiling interface), Debian's 2021 LAMMPS's
// inside error->all included. Open MPI 4.1's singleton (a run without mpirun) unloads its PMIx
// component and only then stops the progress thread, which may still run one of that component's
// callbacks: the thread jumps into unmapped code (SIGSEGV, once in thousands of runs under load; a core
// showed the thread in libevent calling into where mca_pmix_ext3x.so had been). With the components
// pinned, their code stays where the callbacks expect it.
extern "C" int MPI_Finalize()
{
  fflush(stdout);    // a last line without its newline
  dl_iterate_phdr(pin_mpi_component, nullptr);
  return PMPI_Finalize();
}

int main(int argc, char **argv)
{
  // LAMMPS's screen is stdout: a line it prints leaves at once, even into a pipe. Debian's 2021 build
  // ends an error inside error->all with MPI_Finalize() and exit(1), so a fault in MPI's shutdown
  // would otherwise take the ERROR line, still in the pipe's buffer, with the process.
  setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
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
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
  return status;
}
