/* ----------------------------------------------------------------------
   SEDIMENT package: the index of an axis named in an input argument.
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_AXIS_H
#define LMP_SEDIMENT_AXIS_H

#include <cstring>

namespace LAMMPS_NS {

// 0, 1, 2 for "x", "y", "z"; -1 for anything else (the caller names the keyword in its error).
inline int sediment_axis(const char *name)
{
  for (int d = 0; d < 3; ++d)
    if (strcmp(name, d == 0 ? "x" : d == 1 ? "y" : "z") == 0) return d;
  return -1;
}

}    // namespace LAMMPS_NS

#endif
