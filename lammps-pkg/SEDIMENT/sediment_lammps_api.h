// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: the few LAMMPS calls whose form changed between the
   29 Sep 2021 release (Debian 12) and current releases. LAMMPS has no API
   version macro, so each call is chosen from the headers at compile time:
   the current form where it exists (overload taking int, preferred),
   the 2021 form otherwise (overload taking long). The styles call only
   the sediment_* functions below, never either form directly.
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_LAMMPS_API_H
#define LMP_SEDIMENT_LAMMPS_API_H

#include "comm.h"
#include "compute.h"
#include "domain.h"
#include "exceptions.h"
#include "fix.h"
#include "modify.h"
#include "neigh_request.h"
#include "neighbor.h"
#include "output.h"
#include "pair.h"
#include "region.h"

#include <mpi.h>
#include <string>

namespace LAMMPS_NS {
namespace sediment_api {

  template <class M> auto fix_by_id(M *modify, const std::string &id, int) -> decltype(modify->get_fix_by_id(id))
  {
    return modify->get_fix_by_id(id);
  }
  template <class M> Fix *fix_by_id(M *modify, const std::string &id, long)
  {
    const int ifix = modify->find_fix(id);
    return ifix < 0 ? nullptr : modify->fix[ifix];
  }

  template <class M, class Visit>
  auto for_each_fix(M *modify, Visit &visit, int) -> decltype(modify->get_fix_list(), void())
  {
    for (Fix *fix : modify->get_fix_list()) visit(fix);
  }
  template <class M, class Visit> void for_each_fix(M *modify, Visit &visit, long)
  {
    for (int i = 0; i < modify->nfix; ++i) visit(modify->fix[i]);
  }

  template <class M>
  auto compute_by_id(M *modify, const std::string &id, int) -> decltype(modify->get_compute_by_id(id))
  {
    return modify->get_compute_by_id(id);
  }
  template <class M> Compute *compute_by_id(M *modify, const std::string &id, long)
  {
    const int icompute = modify->find_compute(id);
    return icompute < 0 ? nullptr : modify->compute[icompute];
  }

  template <class D>
  auto region_by_id(D *domain, const std::string &id, int) -> decltype(domain->get_region_by_id(id))
  {
    return domain->get_region_by_id(id);
  }
  template <class D> Region *region_by_id(D *domain, const std::string &id, long)
  {
    const int iregion = domain->find_region(id);
    return iregion < 0 ? nullptr : domain->regions[iregion];
  }

  template <class N, class P>
  auto request_half_list(N *neighbor, P *pair, int, int) -> decltype(neighbor->add_request(pair), void())
  {
    neighbor->add_request(pair);
  }
  template <class N, class P> void request_half_list(N *neighbor, P *pair, int instance, long)
  {
    neighbor->request(pair, instance);
  }

  template <class N, class C>
  auto request_compute_list(N *neighbor, C *compute, int, int) -> decltype(neighbor->add_request(compute), void())
  {
    neighbor->add_request(compute);
  }
  template <class N, class C> void request_compute_list(N *neighbor, C *compute, int instance, long)
  {
    const int irequest = neighbor->request(compute, instance);
    neighbor->requests[irequest]->pair = 0;
    neighbor->requests[irequest]->compute = 1;
  }

  template <class C, class P> auto forward_comm(C *comm, P *pair, int) -> decltype(comm->forward_comm(pair), void())
  {
    comm->forward_comm(pair);
  }
  template <class C, class P> void forward_comm(C *comm, P *pair, long)
  {
    comm->forward_comm_pair(pair);
  }

  template <class C, class P> auto reverse_comm(C *comm, P *pair, int) -> decltype(comm->reverse_comm(pair), void())
  {
    comm->reverse_comm(pair);
  }
  template <class C, class P> void reverse_comm(C *comm, P *pair, long)
  {
    comm->reverse_comm_pair(pair);
  }

  template <class E> auto universe(const E &abort, int) -> decltype(abort.get_universe())
  {
    return abort.get_universe();
  }
  template <class E> MPI_Comm universe(const E &abort, long)
  {
    return abort.universe;
  }

  // Output's reset_dt (its dumps and thermo by simulated time) came after 29 Sep 2021, which has none.
  template <class O> auto reset_output_dt(O *output, int) -> decltype(output->reset_dt(), void())
  {
    output->reset_dt();
  }
  template <class O> void reset_output_dt(O *, long) {}

}    // namespace sediment_api

// Fix `id`, or nullptr.
inline Fix *sediment_fix_by_id(Modify *modify, const std::string &id)
{
  return sediment_api::fix_by_id(modify, id, 0);
}
// visit(fix) for every fix, in the order they were defined.
template <class Visit> void sediment_for_each_fix(Modify *modify, Visit visit)
{
  sediment_api::for_each_fix(modify, visit, 0);
}
// Compute `id`, or nullptr.
inline Compute *sediment_compute_by_id(Modify *modify, const std::string &id)
{
  return sediment_api::compute_by_id(modify, id, 0);
}
// Region `id`, or nullptr.
inline Region *sediment_region_by_id(Domain *domain, const std::string &id)
{
  return sediment_api::region_by_id(domain, id, 0);
}
// A default (half) neighbour list for a pair style, requested in init_style(); `instance` is the
// style's instance_me (the 2021 request names it).
inline void sediment_request_half_list(Neighbor *neighbor, Pair *pair, int instance)
{
  sediment_api::request_half_list(neighbor, pair, instance, 0);
}
// A half neighbour list for a compute, kept with the pair style's (built at every reneighboring, a
// copy of the pair's list where they agree); requested in init().
inline void sediment_request_compute_list(Neighbor *neighbor, Compute *compute, int instance)
{
  sediment_api::request_compute_list(neighbor, compute, instance, 0);
}
// Ghost values of a pair style's pack/unpack_forward_comm, and the reverse sum.
inline void sediment_forward_comm(Comm *comm, Pair *pair)
{
  sediment_api::forward_comm(comm, pair, 0);
}
inline void sediment_reverse_comm(Comm *comm, Pair *pair)
{
  sediment_api::reverse_comm(comm, pair, 0);
}
// After a style changed the timestep mid-run: output's intervals by simulated time, where it keeps them.
inline void sediment_reset_output_dt(Output *output)
{
  sediment_api::reset_output_dt(output, 0);
}
// The communicator an aborting error (error->one) was raised on.
inline MPI_Comm sediment_abort_universe(const LAMMPSAbortException &abort)
{
  return sediment_api::universe(abort, 0);
}

}    // namespace LAMMPS_NS

#endif

// LAMMPS's distributed 3d FFT (KSPACE's fft3d_wrap.h, included before this header by the styles that
// use it): 29 Sep 2021's constructor takes 17 sizes and bounds, the buffer size and `usecollective`;
// current releases add `usenonblocking`. Planes in = out, unscaled, not permuted, point-to-point remaps.
#if defined(LMP_FFT3D_WRAP_H) && !defined(LMP_SEDIMENT_FFT3D_API_H)
#define LMP_SEDIMENT_FFT3D_API_H
#include <type_traits>
namespace LAMMPS_NS {
template <class F = FFT3d>
F *sediment_make_fft3d(LAMMPS *lmp, MPI_Comm comm, int nfast, int nmid, int nslow, int ilo, int ihi, int jlo, int jhi,
                       int klo, int khi, int *nbuf)
{
  if constexpr (std::is_constructible<F, LAMMPS *, MPI_Comm, int, int, int, int, int, int, int, int, int, int,
                                      int, int, int, int, int, int, int, int *, int, int>::value)
    return new F(lmp, comm, nfast, nmid, nslow, ilo, ihi, jlo, jhi, klo, khi, ilo, ihi, jlo, jhi, klo, khi, 0, 0, nbuf,
                 0, 0);
  else
    return new F(lmp, comm, nfast, nmid, nslow, ilo, ihi, jlo, jhi, klo, khi, ilo, ihi, jlo, jhi, klo, khi, 0, 0, nbuf, 0);
}
}    // namespace LAMMPS_NS
#endif
