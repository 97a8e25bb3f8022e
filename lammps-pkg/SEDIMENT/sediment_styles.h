// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: registration of the package's styles into a LAMMPS
   instance (Debian's LAMMPS has no PLUGIN package, so styles are added to
   the creator maps at run time).
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_STYLES_H
#define LMP_SEDIMENT_STYLES_H

namespace LAMMPS_NS {
class LAMMPS;
void sediment_register_styles(LAMMPS *lmp);
}    // namespace LAMMPS_NS

// C entry point for ctypes / other languages: lmp is a LAMMPS* (e.g. lammps.lammps().lmp).
extern "C" void sediment_register(void *lmp);

#endif
