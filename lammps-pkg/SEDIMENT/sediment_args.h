/* ----------------------------------------------------------------------
   SEDIMENT package: reading the input arguments the styles share.
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_ARGS_H
#define LMP_SEDIMENT_ARGS_H

#include "error.h"
#include "lammps.h"
#include "utils.h"

#include <cmath>
#include <cstring>
#include <string>

namespace LAMMPS_NS {

// 0, 1, 2 for "x", "y", "z"; -1 for anything else (the caller names the keyword in its error).
inline int sediment_axis(const char *name)
{
  for (int d = 0; d < 3; ++d)
    if (strcmp(name, d == 0 ? "x" : d == 1 ? "y" : "z") == 0) return d;
  return -1;
}

// An argument that must be a finite number > 0, or the error "<what> must be finite and > 0<hint>".
// utils::numeric turns 1e400 into inf, so finiteness is checked here, once for every style.
inline double sediment_positive(LAMMPS *lmp, const char *text, const std::string &what, const char *hint = "")
{
  const double value = utils::numeric(FLERR, text, false, lmp);
  if (!(value > 0.0) || !std::isfinite(value)) lmp->error->all(FLERR, "{} must be finite and > 0{}", what, hint);
  return value;
}

}    // namespace LAMMPS_NS

#endif
