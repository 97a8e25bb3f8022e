// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: style registration and the LAMMPS plugin entry point.
------------------------------------------------------------------------- */

#include "sediment_styles.h"

#include "compute_concentration_grid.h"
#include "compute_contact_overlap.h"
#include "fix_fluid.h"
#include "fix_fluid_buoyancy.h"
#include "fix_fluid_drag.h"
#include "fix_fluid_flow.h"
#include "fix_layers_hdf5.h"
#include "fix_nve_sphere_fluid.h"
#include "pair_lubricate_fluid.h"

#include "force.h"
#include "lammps.h"
#include "lammpsplugin.h"
#include "modify.h"
#include "version.h"

using namespace LAMMPS_NS;

namespace {

template <typename Base, typename Style> Base *create(LAMMPS *lmp, int narg, char **arg)
{
  return new Style(lmp, narg, arg);
}

template <typename Style> Pair *create_pair(LAMMPS *lmp)
{
  return new Style(lmp);
}

template <typename Creator> struct StyleEntry {
  const char *name;
  const char *info;
  Creator creator;
};

const StyleEntry<Modify::FixCreator> fix_styles[] = {
    {"fluid", "fluid properties and geometry", &create<Fix, FixFluid>},
    {"fluid/buoyancy", "Archimedes buoyancy with partial submergence", &create<Fix, FixFluidBuoyancy>},
    {"fluid/drag", "Newtonian and Bingham drag laws", &create<Fix, FixFluidDrag>},
    {"fluid/flow", "the flow the spheres drive, solved spectrally (two-way coupling)", &create<Fix, FixFluidFlow>},
    {"nve/sphere/fluid", "drag-implicit sphere integrator", &create<Fix, FixNVESphereFluid>},
    {"layers/hdf5", "layer profiles to HDF5", &create<Fix, FixLayersHDF5>},
};

const StyleEntry<Modify::ComputeCreator> compute_styles[] = {
    {"concentration/grid", "solid fraction per layer, size class and type", &create<Compute, ComputeConcentrationGrid>},
    {"contact/overlap", "largest overlap of touching spheres", &create<Compute, ComputeContactOverlap>},
};

const StyleEntry<Force::PairCreator> pair_styles[] = {
    {"lubricate/fluid", "squeeze-film lubrication between close spheres", &create_pair<PairLubricateFluid>},
};

}    // namespace

void LAMMPS_NS::sediment_register_styles(LAMMPS *lmp)
{
  for (const auto &style : fix_styles) (*lmp->modify->fix_map)[style.name] = style.creator;
  for (const auto &style : compute_styles) (*lmp->modify->compute_map)[style.name] = style.creator;
  for (const auto &style : pair_styles) (*lmp->force->pair_map)[style.name] = style.creator;
}

extern "C" void sediment_register(void *lmp)
{
  sediment_register_styles(static_cast<LAMMPS *>(lmp));
}

// For LAMMPS builds with the PLUGIN package: `plugin load libsediment_lammps.so`.
extern "C" void lammpsplugin_init(void *lmp, void *handle, void *regfunc)
{
  auto reg = reinterpret_cast<lammpsplugin_regfunc>(regfunc);
  auto add = [&](const char *kind, const char *name, const char *info, void *creator, bool takes_args) {
    lammpsplugin_t plugin;
    plugin.version = LAMMPS_VERSION;
    plugin.style = kind;
    plugin.name = name;
    plugin.info = info;
    plugin.author = "SEDIMENT developers";
    if (takes_args) plugin.creator.v2 = reinterpret_cast<lammpsplugin_factory2 *>(creator);
    else plugin.creator.v1 = reinterpret_cast<lammpsplugin_factory1 *>(creator);
    plugin.handle = handle;
    (*reg)(&plugin, lmp);
  };
  for (const auto &style : fix_styles)
    add("fix", style.name, style.info, reinterpret_cast<void *>(style.creator), true);
  for (const auto &style : compute_styles)
    add("compute", style.name, style.info, reinterpret_cast<void *>(style.creator), true);
  for (const auto &style : pair_styles)
    add("pair", style.name, style.info, reinterpret_cast<void *>(style.creator), false);
}
