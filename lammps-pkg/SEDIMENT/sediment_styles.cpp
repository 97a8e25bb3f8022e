/* ----------------------------------------------------------------------
   SEDIMENT package: style registration and the LAMMPS plugin entry point.
------------------------------------------------------------------------- */

#include "sediment_styles.h"

#include "compute_concentration_grid.h"
#include "fix_fluid.h"
#include "fix_fluid_buoyancy.h"
#include "fix_fluid_drag.h"
#include "fix_layers_hdf5.h"
#include "fix_nve_sphere_fluid.h"

#include "lammps.h"
#include "lammpsplugin.h"
#include "modify.h"
#include "version.h"

using namespace LAMMPS_NS;

namespace {

template <typename T> Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new T(lmp, narg, arg);
}

template <typename T> Compute *create_compute(LAMMPS *lmp, int narg, char **arg)
{
  return new T(lmp, narg, arg);
}

struct FixEntry {
  const char *name;
  const char *info;
  Modify::FixCreator creator;
};

const FixEntry fix_styles[] = {
    {"fluid", "fluid properties and geometry", &create_fix<FixFluid>},
    {"fluid/buoyancy", "Archimedes buoyancy with partial submergence", &create_fix<FixFluidBuoyancy>},
    {"fluid/drag", "Newtonian and Bingham drag laws", &create_fix<FixFluidDrag>},
    {"nve/sphere/fluid", "drag-implicit sphere integrator", &create_fix<FixNVESphereFluid>},
    {"layers/hdf5", "layer profiles to HDF5", &create_fix<FixLayersHDF5>},
};

struct ComputeEntry {
  const char *name;
  const char *info;
  Modify::ComputeCreator creator;
};

const ComputeEntry compute_styles[] = {
    {"concentration/grid", "solid fraction per layer, size class and type", &create_compute<ComputeConcentrationGrid>},
};

}    // namespace

void LAMMPS_NS::sediment_register_styles(LAMMPS *lmp)
{
  for (const FixEntry &style : fix_styles) (*lmp->modify->fix_map)[style.name] = style.creator;
  for (const ComputeEntry &style : compute_styles) (*lmp->modify->compute_map)[style.name] = style.creator;
}

extern "C" void sediment_register(void *lmp)
{
  sediment_register_styles(static_cast<LAMMPS *>(lmp));
}

// For LAMMPS builds with the PLUGIN package: `plugin load libsediment_lammps.so`.
extern "C" void lammpsplugin_init(void *lmp, void *handle, void *regfunc)
{
  auto reg = reinterpret_cast<lammpsplugin_regfunc>(regfunc);
  auto add = [&](const char *kind, const char *name, const char *info, void *creator) {
    lammpsplugin_t plugin;
    plugin.version = LAMMPS_VERSION;
    plugin.style = kind;
    plugin.name = name;
    plugin.info = info;
    plugin.author = "SEDIMENT developers";
    plugin.creator.v2 = reinterpret_cast<lammpsplugin_factory2 *>(creator);
    plugin.handle = handle;
    (*reg)(&plugin, lmp);
  };
  for (const FixEntry &style : fix_styles)
    add("fix", style.name, style.info, reinterpret_cast<void *>(style.creator));
  for (const ComputeEntry &style : compute_styles)
    add("compute", style.name, style.info, reinterpret_cast<void *>(style.creator));
}
