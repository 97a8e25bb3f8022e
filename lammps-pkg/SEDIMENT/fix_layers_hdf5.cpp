// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix layers/hdf5
------------------------------------------------------------------------- */

#include "fix_layers_hdf5.h"
#include "sediment_args.h"
#include "sediment_hdf5.h"
#include "sediment/version.hpp"

#include "compute_concentration_grid.h"
#include "fix_fluid.h"

#include "comm.h"
#include "domain.h"
#include "error.h"
#include "input.h"
#include "modify.h"
#include "output.h"
#include "update.h"
#include "utils.h"
#include "variable.h"

#include <hdf5.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mpi.h>
#include <stdexcept>
#include <vector>

using namespace LAMMPS_NS;
using namespace FixConst;
using namespace LAMMPS_NS::SedimentHDF5;

namespace {

constexpr const char *SCHEMA = "sediment-layers";
constexpr int SCHEMA_VERSION = 1;

// The frame datasets, in the order of FixLayersHDF5::frame_sets; the last, the fluid's density and
// viscosity per frame, only in the files of a fix with a fluid.
constexpr const char *FRAME_SETS[4] = {"time", "step", "fraction", "fluid"};
constexpr int FLUID_SET = 3;

// The attribute that counts the frames written whole: set after their datasets are flushed, so that
// a run killed while it wrote (or a full disk) leaves the frames past it, which may be torn (HDF5's
// fill value, a chunk half written), outside the file's frames. Files of earlier versions have none:
// all their frames count.
constexpr const char *WRITTEN = "frames";

long long frames_written(hid_t handle)
{
  if (H5Aexists(handle, WRITTEN) > 0) return static_cast<long long>(read_double_attribute(handle, WRITTEN));
  Handle set(H5Dopen2(handle, "step", H5P_DEFAULT), H5Dclose, "dataset step");
  Handle space(H5Dget_space(set), H5Sclose, "dataspace");
  hsize_t count = 0;
  H5Sget_simple_extent_dims(space, &count, nullptr);
  return static_cast<long long>(count);
}

long long frames_before(hid_t handle, LAMMPS_NS::bigint step)
{
  const std::vector<long long> steps = read_frames<long long>(handle, "step", H5T_NATIVE_LLONG);
  const long long written = std::min(frames_written(handle), static_cast<long long>(steps.size()));
  long long kept = 0;
  while (kept < written && steps[kept] < step) ++kept;
  return kept;
}

// The frames written (frames_written) read back whole, each chunk's checksum checked, one frame at a
// time (a large file is not held in memory), with their datasets' shapes; `equal`: every dataset holds
// exactly those frames (a finished file: a run killed while it wrote leaves them longer). Throws saying
// what does not read back.
void read_back(hid_t handle, bool equal)
{
  const hsize_t written = static_cast<hsize_t>(frames_written(handle));
  hsize_t centres = 0, counts[4] = {0, 0, 0, 0};
  {
    Handle set(H5Dopen2(handle, "layer_centre", H5P_DEFAULT), H5Dclose, "dataset layer_centre");
    Handle space(H5Dget_space(set), H5Sclose, "dataspace");
    H5Sget_simple_extent_dims(space, &centres, nullptr);
  }
  const std::string columns = read_string_attribute(handle, "columns");
  const hsize_t column_count = columns.empty() ? 0 : 1 + std::count(columns.begin(), columns.end(), ',');
  const int sets = has_dataset(handle, FRAME_SETS[FLUID_SET]) ? 4 : 3;
  for (int k = 0; k < sets; ++k) {
    const char *name = FRAME_SETS[k];
    const int expected_rank = k == 2 ? 3 : k == FLUID_SET ? 2 : 1;
    Handle set(H5Dopen2(handle, name, H5P_DEFAULT), H5Dclose, std::string("dataset ") + name);
    Handle space(H5Dget_space(set), H5Sclose, "dataspace");
    const int rank = H5Sget_simple_extent_ndims(space);
    hsize_t dims[3] = {0, 1, 1};
    if (rank != expected_rank || H5Sget_simple_extent_dims(space, dims, nullptr) < 0)
      throw std::runtime_error(fmt::format("dataset {} has {} dimensions", name, rank));
    if (k == 2 && (dims[1] != centres || dims[2] != column_count))
      throw std::runtime_error(fmt::format("dataset fraction has {} layers x {} columns, the file names {} x {}",
                                           dims[1], dims[2], centres, column_count));
    if (k == FLUID_SET && dims[1] != 2)
      throw std::runtime_error(fmt::format("dataset fluid has {} values per frame, not 2", dims[1]));
    counts[k] = dims[0];
    if (dims[0] < written)
      throw std::runtime_error(fmt::format("dataset {} holds {} frames of the {} written", name, dims[0], written));
    const hsize_t block[3] = {k == 2 ? 1 : written, dims[1], dims[2]};
    if (written == 0) continue;
    Handle memory(H5Screate_simple(rank, block, nullptr), H5Sclose, "dataspace");
    std::vector<double> values(block[0] * block[1] * block[2]);
    for (hsize_t first = 0; first < written; first += block[0]) {
      const hsize_t start[3] = {first, 0, 0};
      check(H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, block, nullptr), "selection");
      if (H5Dread(set, H5T_NATIVE_DOUBLE, memory, space, H5P_DEFAULT, values.data()) < 0)
        throw std::runtime_error(k == 2 ? fmt::format("frame {} of dataset fraction does not read back (damaged: its "
                                                      "checksum fails)", first)
                                        : fmt::format("dataset {} does not read back (damaged: its checksum fails)", name));
    }
  }
  if (equal && (counts[0] != written || counts[1] != written || counts[2] != written || (sets == 4 && counts[3] != written)))
    throw std::runtime_error(fmt::format("the frame datasets hold {} times, {} steps and {} fractions{} of the {} "
                                         "frames written", counts[0], counts[1], counts[2],
                                         sets == 4 ? fmt::format(" and {} fluids", counts[3]) : std::string(), written));
}


}    // namespace

FixLayersHDF5::FixLayersHDF5(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), compute_id(nullptr), particle_density(0.0), grid(nullptr),
    fluid_now{0.0, 0.0}, fluid_run{0.0, 0.0}, file(-1), frame_sets{-1, -1, -1, -1}, is_open(false), frames(0), last_write(0.0),
    overwrite(false), end_time(-1.0), resumed_frames(-1), last_frame_step(-1), summed_restart(-1)
{
  if (narg < 6)
    error->all(FLERR, "Fix layers/hdf5: expected 'fix ID group layers/hdf5 N FILE.h5 c_ID [keyword value ...]'");
  nevery = utils::inumeric(FLERR, arg[3], false, lmp);
  if (nevery <= 0) error->all(FLERR, "Fix layers/hdf5: N must be > 0");
  path = arg[4];
  if (path.empty() || path.back() == '/')
    error->all(FLERR, "Fix layers/hdf5: '{}' names no file: give a file name such as layers.h5", path);
  if (strncmp(arg[5], "c_", 2) != 0)
    error->all(FLERR, "Fix layers/hdf5: expected a compute reference c_ID, not '{}'", arg[5]);
  compute_id = utils::strdup(arg[5] + 2);
  StyleArgs args(lmp, FLERR, "Fix layers/hdf5", narg, arg, 6);
  while (args.more()) {
    args.need(1, "a value");
    if (args.is("fluid")) {
      fluid_id = args.text(1);
    } else if (args.is("particle_density")) {
      particle_density = args.positive(1, "particle_density");
    } else if (args.is("overwrite")) {
      overwrite = args.yes_no(1);
    } else if (args.is("end_time")) {
      end_time = args.positive(1, "end_time");
    } else {
      args.unknown("fluid, particle_density, overwrite or end_time");
    }
    args.next(1);
  }
  if (!fluid_id.empty()) {
    const sediment::Fluid &fluid =
        FixFluid::find(lmp, fluid_id.c_str(), "Fix layers/hdf5 (define the fluid before it)")->properties();
    water = {{"fluid_density", fluid.density}, {"fluid_viscosity", fluid.viscosity},
             {"fluid_yield_stress", fluid.yield_stress}};
    fluid_now[0] = fluid_run[0] = fluid.density;
    fluid_now[1] = fluid_run[1] = fluid.viscosity;
  }
  scalar_flag = 1;
  global_freq = 1;
  restart_global = 1;    // the simulated time, which restart files of LAMMPS 2021 do not keep
  extscalar = 0;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);    // errors are reported through LAMMPS
}

FixLayersHDF5::~FixLayersHDF5()
{
  for (long long &set : frame_sets)
    if (set >= 0) H5Dclose(set);
  if (file >= 0) H5Fclose(file);
  // LAMMPS is done with the fix (end of input, unfix or clear; never after an error): the frames
  // are complete if they run without a gap up to end_time. Only then does the file replace an
  // earlier result under its name.
  if (comm->me == 0 && !writing.empty()) {
    try {
      Handle done(H5Fopen(writing.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose, "reopening");
      read_back(done, true);    // nothing is marked complete that does not read back whole
      const std::string why = incomplete_reason(done);
      if (!why.empty()) throw std::runtime_error(why);
      set_attribute(done, "complete", 1.0);
      done.close();
      if (rename(writing.c_str(), path.c_str()) != 0) throw std::runtime_error(std::string("renaming: ") + strerror(errno));
    } catch (const std::exception &e) {
      fprintf(stderr, "ERROR: Fix layers/hdf5: %s: %s; the frames stay in %s, marked incomplete\n", path.c_str(),
              e.what(), writing.c_str());
    }
  }
  delete[] compute_id;
}

int FixLayersHDF5::setmask()
{
  return END_OF_STEP;
}

template <typename Action> void FixLayersHDF5::on_rank0(Action action)
{
  std::string message;
  if (comm->me == 0) {
    try {
      action();
    } catch (const std::exception &e) {
      message = e.what();
    }
  }
  int length = static_cast<int>(message.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, world);
  if (length == 0) return;
  message.resize(length);
  MPI_Bcast(&message[0], length, MPI_CHAR, 0, world);
  error->all(FLERR, "Fix layers/hdf5: {}: {}", path, message);
}

void FixLayersHDF5::init()
{
  if (!fluid_id.empty()) {    // the fluid of this run (a deck may re-issue it between runs), from its first step
    const sediment::Fluid &fluid =
        FixFluid::find(lmp, fluid_id.c_str(), "Fix layers/hdf5 (its fluid was deleted?)")->properties();
    fluid_run[0] = fluid.density;
    fluid_run[1] = fluid.viscosity;
  }
  Compute *compute = sediment_find_compute(lmp, compute_id, "Fix layers/hdf5");
  grid = dynamic_cast<ComputeConcentrationGrid *>(compute);
  if (!grid)
    error->all(FLERR, "Fix layers/hdf5: compute '{}' is a compute {}, not a compute concentration/grid",
               compute_id, compute->style);
  if (!grid->is_layers())
    error->all(FLERR, "Fix layers/hdf5: compute '{}' bins into 3d cells; layer files need 'layers AXIS N'", compute_id);
}

void FixLayersHDF5::setup(int /*vflag*/)
{
  if (!is_open) open_file();
  // a frame at a run's start is the state the previous run's water left (the first: the fluid's when
  // this fix was defined); this run's steps are in its own
  if (update->ntimestep % nevery == 0) take_frame(true);
  std::copy(fluid_run, fluid_run + 2, fluid_now);
}

void FixLayersHDF5::end_of_step()
{
  sum_restart();
  take_frame(false);
}

void FixLayersHDF5::post_run()
{
  sum_restart();
  close_file();
}

void FixLayersHDF5::sum_restart()
{
  // Rank 0 wrote the newest of the two restart files and closed it (LAMMPS writes them between steps):
  // its checksum goes beside it, in NAME.crc32, so that `sediment run --resume` can tell a damaged one.
  // A kill before this leaves the file newer than its checksum, which --resume passes over. Restart
  // files per rank (%) or by MPI-IO get none.
  if (comm->me != 0 || !output->restart_flag_double || output->last_restart < 0 ||
      output->last_restart == summed_restart)
    return;
  summed_restart = output->last_restart;
  const std::string name = output->restart_toggle == 1 ? output->restart2a : output->restart2b;
  if (name.find_first_of("%*") != std::string::npos || (name.size() >= 6 && name.compare(name.size() - 6, 6, ".mpiio") == 0)) return;
  uint32_t crc = 0;
  long long size = 0;
  const std::string sum = name + ".crc32", writing_sum = sum + ".tmp";
  FILE *out = file_crc32(name, crc, size) ? fopen(writing_sum.c_str(), "w") : nullptr;
  bool ok = out && fprintf(out, "crc32 %08x size %lld step %lld\n", crc, size,
                           static_cast<long long>(summed_restart)) > 0;
  ok = out && fclose(out) == 0 && ok && rename(writing_sum.c_str(), sum.c_str()) == 0;
  if (!ok) {
    remove(writing_sum.c_str());
    error->warning(FLERR, "Fix layers/hdf5: the checksum of {} cannot be written ({}): --resume will pass it over",
                   name, strerror(errno));
  }
}

void FixLayersHDF5::open_file()
{
  // The grid is evaluated once so that its layer geometry is known.
  if (grid->invoked_array != update->ntimestep) grid->compute_array();
  const sediment::Layers layers = grid->layer_geometry();
  const std::vector<std::string> names = grid->column_names();
  const hsize_t shape[2] = {static_cast<hsize_t>(layers.count), names.size()};
  const bigint step_now = update->ntimestep;

  const std::vector<std::pair<const char *, double>> identity = parameters(layers);
  const char *run_id = input->variable->retrieve("sediment_run_id");

  on_rank0([&] {
    if (!writing.empty() && !file_exists(writing))
      throw std::runtime_error(fmt::format("{} vanished while this run wrote it (deleted?): the frames before step "
                                           "{} are lost; start the run anew", writing, step_now));
    if (writing.empty()) writing = choose_file(step_now, shape[0], shape[1], identity, run_id ? run_id : "");
    if (file_exists(writing)) {
      // Continue the file: keep the frames before this step, so that a restarted run neither
      // loses nor repeats frames.
      file = H5Fopen(writing.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      if (file < 0) throw std::runtime_error("cannot be opened for writing");
      frames = frames_before(file, step_now);
      open_frame_sets();
      for (int k = 0; k < 4; ++k)
        if (frame_sets[k] >= 0) put_frames(frame_sets[k], FRAME_SETS[k], H5T_NATIVE_DOUBLE, frames, 0, nullptr);
      set_attribute(file, WRITTEN, static_cast<double>(frames));
      set_attribute(file, "complete", 0.0);
      check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush");
      return;
    }
    // The file format of HDF5 1.8 on: its superblock, object headers and indexes carry checksums, so that
    // damaged metadata is refused on reading rather than read as data (or crash the reader).
    Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access properties");
    check(H5Pset_libver_bounds(access, H5F_LIBVER_V18, H5F_LIBVER_LATEST), "file format");
    file = H5Fcreate(writing.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access);
    if (file < 0) throw std::runtime_error("cannot be created");
    frames = 0;
    write_attribute(file, "schema", SCHEMA);
    write_attribute(file, "schema_version", SCHEMA_VERSION);
    write_attribute(file, "complete", 0.0);
    write_attribute(file, WRITTEN, 0.0);
    write_attribute(file, "units", update->unit_style);
    write_attribute(file, "axis", std::string(1, "xyz"[grid->layer_axis()]));
    write_attribute(file, "dimension", domain->dimension);
    for (const auto &[name, value] : identity) write_attribute(file, name, value);
    write_attribute(file, "run_id", run_id ? run_id : "");
    write_attribute(file, "code_version", std::string("SEDIMENT ") + sediment::version + ", LAMMPS " + lmp->version);
    write_attribute(file, "run_start", utils::current_date());
    std::string columns;
    for (const std::string &name : names) columns += (columns.empty() ? "" : ",") + name;
    write_attribute(file, "columns", columns);
    std::vector<double> centres(layers.count);
    for (int k = 0; k < layers.count; ++k) centres[k] = layers.lo + (k + 0.5) * layers.thickness;
    write_array(file, "layer_centre", centres);
    write_array(file, "class_edges", grid->class_diameters());
    create_frames(file, "time", H5T_NATIVE_DOUBLE, 1, nullptr);
    create_frames(file, "step", H5T_NATIVE_LLONG, 1, nullptr);
    create_frames(file, "fraction", H5T_NATIVE_DOUBLE, 3, shape);
    const hsize_t fluid_values[1] = {2};
    if (!fluid_id.empty()) create_frames(file, FRAME_SETS[FLUID_SET], H5T_NATIVE_DOUBLE, 2, fluid_values);
    open_frame_sets();
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush");
  });
  is_open = true;
}

void FixLayersHDF5::take_frame(bool write_now)
{
  if (grid->invoked_array != update->ntimestep) grid->compute_array();
  double **array = grid->array;
  const int rows = grid->size_array_rows, cols = grid->size_array_cols - 1;
  const bigint step = update->ntimestep;
  // Frames wait on rank 0 and go to the file together: writing and flushing one frame took some
  // 160 000 instructions and seven system calls, which rank 0 spent while the other ranks waited.
  // The file holds every frame before a restart file (a resumed run continues the frames before its
  // step), those up to the end of each run, and otherwise frames at most WRITE_INTERVAL seconds old.
  // (LAMMPS sets the next restart step after the fixes' setup: a run's first frame is written at once.)
  write_now = write_now || (output->restart_flag && output->next_restart < step + nevery);
  on_rank0([&] {
    for (int k = 0; k < rows; ++k)
      for (int c = 0; c < cols; ++c) pending_values.push_back(array[k][c + 1]);
    pending_time.push_back(sediment_time_now(update));
    pending_step.push_back(step);
    if (!fluid_id.empty()) pending_fluid.insert(pending_fluid.end(), fluid_now, fluid_now + 2);
    last_frame_step = step;
    ++frames;
    if (write_now || MPI_Wtime() - last_write >= WRITE_INTERVAL ||
        pending_values.size() * sizeof(double) >= PENDING_BYTES)
      write_pending();
  });
}

// Rank 0: the frames waiting, into the file, and the file flushed; then the count of frames written,
// flushed (the frames are the file's once both flushes are done). A killed run keeps every frame
// written so far, and a full disk shows here.
void FixLayersHDF5::write_pending()
{
  last_write = MPI_Wtime();
  const hsize_t count = pending_step.size();
  if (count == 0) return;
  put_frames(frame_sets[0], FRAME_SETS[0], H5T_NATIVE_DOUBLE, frames, count, pending_time.data());
  put_frames(frame_sets[1], FRAME_SETS[1], H5T_NATIVE_LLONG, frames, count, pending_step.data());
  put_frames(frame_sets[2], FRAME_SETS[2], H5T_NATIVE_DOUBLE, frames, count, pending_values.data());
  if (frame_sets[FLUID_SET] >= 0)
    put_frames(frame_sets[FLUID_SET], FRAME_SETS[FLUID_SET], H5T_NATIVE_DOUBLE, frames, count, pending_fluid.data());
  check(H5Fflush(file, H5F_SCOPE_GLOBAL), "writing the frames (disk full?)");
  set_attribute(file, WRITTEN, static_cast<double>(frames));
  check(H5Fflush(file, H5F_SCOPE_GLOBAL), "writing the frames (disk full?)");
  pending_fluid.clear();
  pending_time.clear();
  pending_step.clear();
  pending_values.clear();
}

std::vector<std::pair<const char *, double>> FixLayersHDF5::parameters(const sediment::Layers &layers) const
{
  // What the frames mean: a file continued by a run that differs in any of these would splice two
  // different experiments.
  std::vector<std::pair<const char *, double>> values = {{"layer_lo", layers.lo},
                                                        {"layer_thickness", layers.thickness},
                                                        {"cross_section", grid->cross_section()}};
  if (domain->dimension == 2) values.emplace_back("slab_thickness", grid->slab_thickness());
  if (particle_density > 0.0) values.emplace_back("particle_density", particle_density);
  values.insert(values.end(), water.begin(), water.end());
  return values;
}



std::string FixLayersHDF5::choose_file(bigint step_now, size_t layers, size_t columns,
                                       const std::vector<std::pair<const char *, double>> &identity,
                                       const std::string &run_id)
{
  // New frames go to PATH.partial, which replaces PATH when LAMMPS is done (destructor). A run that
  // continues one whose frames are under PATH.partial (killed, resumed) or PATH (finished, restarted
  // from a restart file) carries on from a copy; PATH itself is never modified, so an earlier result
  // survives a run that dies. A run resumed from a restart file of this fix continues the frames of
  // the run that wrote it, or none: 'overwrite' never applies to it.
  const std::string partial = path + ".partial";
  const bool resumed = resumed_frames >= 0;
  for (const std::string &candidate : {partial, path}) {
    if (!file_exists(candidate)) continue;
    const std::string what = candidate == partial ? "an unfinished run's frames" : "an earlier run's frames";
    if (candidate == path && H5Fis_hdf5(candidate.c_str()) <= 0)
      throw std::runtime_error("exists but is not an HDF5 file; not overwriting it");
    std::string differs;    // how the frames held there differ in what they mean
    std::string other_run;  // whose they are, if another run's
    long long before = 0;   // frames before this step
    try {
      Handle old(H5Fopen(candidate.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "the file cannot be opened");
      const std::string schema = read_string_attribute(old, "schema");
      if (schema != SCHEMA) {    // a file of someone else's under the name is never replaced (invalid_argument)
        if (candidate == path) throw std::invalid_argument(candidate + " is not a SEDIMENT layer file; not overwriting it");
        throw std::runtime_error("not a layer file");
      }
      Handle set(H5Dopen2(old, "fraction", H5P_DEFAULT), H5Dclose, "dataset fraction");
      Handle space(H5Dget_space(set), H5Sclose, "dataspace");
      hsize_t dims[3];
      H5Sget_simple_extent_dims(space, dims, nullptr);
      if (dims[1] != layers || dims[2] != columns)
        differs = fmt::format("{} layers x {} columns, the compute gives {} x {}", dims[1], dims[2], layers, columns);
      if (differs.empty() && has_dataset(old, FRAME_SETS[FLUID_SET]) != !fluid_id.empty())
        differs = fluid_id.empty() ? "the fluid of each frame, this run names no fluid"
                                   : "no fluid per frame (an earlier version's file), this run records it";
      for (const auto &[name, value] : identity) {
        const double held = H5Aexists(old, name) > 0 ? read_double_attribute(old, name) : 0.0;
        if (differs.empty() && held != value) differs = fmt::format("{} {}, this run has {}", name, held, value);
      }
      const std::string held_id = read_string_attribute(old, "run_id");
      if (!held_id.empty() && !run_id.empty() && held_id != run_id)
        other_run = fmt::format("run {}, this is run {}", held_id, run_id);
      read_back(old, false);    // frames that do not read back are never continued
      before = frames_before(old, step_now);
    } catch (const std::invalid_argument &e) {
      throw std::runtime_error(e.what());
    } catch (const std::exception &e) {
      // A damaged file of this fix (a run killed while it wrote, a truncated copy): what it holds
      // cannot be checked, so it is never continued; 'overwrite yes' may replace it on a fresh start.
      if (overwrite && !resumed) continue;
      throw std::runtime_error(fmt::format("{} is damaged ({}): its frames cannot be {}; remove it to start the run "
                                           "anew", candidate, e.what(), resumed ? "continued" : "checked"));
    }
    if (differs.empty()) differs = other_run;
    if (resumed) {
      if (!differs.empty() && candidate == path)
        throw std::runtime_error(fmt::format("the frames this run wrote before step {} ({}) are gone and {} holds {} "
                                             "with {}: start the run anew", step_now, partial, path, what, differs));
      if (!differs.empty())
        throw std::runtime_error(fmt::format("{} holds {} with {}: the restart file is not of the run that wrote "
                                             "them; start the run anew", candidate, what, differs));
      if (before != resumed_frames)
        throw std::runtime_error(fmt::format("{} holds {} frames before step {} and the restart file was written "
                                             "after {}: they are not the frames of one run; start the run anew",
                                             candidate, before, step_now, resumed_frames));
    } else {
      // A run continues the frames it finds when they are its own and it starts after the first of
      // them (read_restart of a restart file without this fix); an unfinished run's frames are
      // continued even with 'overwrite yes'.
      const bool continues = differs.empty() && step_now > 0 && before > 0;
      if (overwrite && !(continues && candidate == partial)) continue;
      if (step_now == 0 && differs == other_run) differs.clear();    // a fresh start: whose they are is moot
      if (!differs.empty())
        throw std::runtime_error(fmt::format("{} holds {} with {}: use another file or 'overwrite yes'", candidate,
                                             what, differs));
      if (!continues)
        throw std::runtime_error(fmt::format("{} holds {} and this run starts anew at step {}: remove it, use "
                                             "another file or 'overwrite yes'", candidate, what, step_now));
    }
    if (candidate == path) copy_file(path, partial);    // a finished file, continued: work on a copy
    return partial;
  }
  if (resumed)
    throw std::runtime_error(fmt::format("this run resumes at step {} from a restart file, but the {} frames before "
                                         "that step ({} or {}) are gone: start the run anew", step_now,
                                         resumed_frames, partial, path));
  if (file_exists(partial) && remove(partial.c_str()) != 0)
    throw std::runtime_error(partial + " cannot be replaced");
  return partial;
}

std::string FixLayersHDF5::incomplete_reason(long long file_id) const
{
  // The frames must follow each other every nevery steps (a gap means frames of two runs were
  // spliced, or lost) and, with end_time, reach it (a deck that stopped early is not the test).
  const std::vector<long long> steps = read_frames<long long>(file_id, "step", H5T_NATIVE_LLONG);
  if (steps.empty()) return "no frames";
  for (size_t k = 1; k < steps.size(); ++k)
    if (steps[k] <= steps[k - 1] || steps[k] - steps[k - 1] > nevery)
      return fmt::format("the frames jump from step {} to step {} (frames of two runs, or frames lost)", steps[k - 1],
                         steps[k]);
  if (end_time > 0.0) {
    const std::vector<double> time = read_frames<double>(file_id, "time", H5T_NATIVE_DOUBLE);
    if (time.size() != steps.size()) return "the frames' times and steps differ in number";
    if (!(time.back() >= end_time * (1.0 - 1e-9)))
      return fmt::format("the frames end at time {:.6g}, before end_time {:.6g} (the input stopped early)",
                         time.back(), end_time);
  }
  return "";
}


void FixLayersHDF5::open_frame_sets()
{
  for (int k = 0; k < 4; ++k) {
    if (k == FLUID_SET && fluid_id.empty()) continue;
    frame_sets[k] = H5Dopen2(file, FRAME_SETS[k], H5P_DEFAULT);
    if (frame_sets[k] < 0) throw std::runtime_error(std::string("dataset ") + FRAME_SETS[k] + " cannot be opened");
  }
}

void FixLayersHDF5::close_file()
{
  on_rank0([&] {
    // The frames waiting, then every handle closed once, even when the disk is full: closing
    // writes what HDF5 holds, so a full disk may show only here.
    std::string failed;
    try {
      if (file >= 0) write_pending();
    } catch (const std::exception &e) {
      failed = e.what();
    }
    bool closed = true;
    for (long long &set : frame_sets) {
      if (set >= 0) closed = H5Dclose(set) >= 0 && closed;
      set = -1;
    }
    const hid_t open = file;
    file = -1;
    if (open >= 0) closed = H5Fclose(open) >= 0 && closed;
    if (failed.empty() && !closed) failed = "closing (disk full?)";
    if (!failed.empty()) throw std::runtime_error(failed);
  });
  is_open = false;
}

// The state a restart file keeps: a marker (older files began with the time, never negative), the
// simulated time, the step, the frames taken before that step and the run identity.
namespace {
constexpr double RESTART_MARKER = -1.0;
constexpr size_t RESTART_NUMBERS = 4, RESTART_ID_BYTES = 64;
}    // namespace

void FixLayersHDF5::write_restart(FILE *fp)
{
  // The simulated time at this step: with time steps changed between runs it is not step x dt,
  // and LAMMPS 2021 restart files lose it (time would restart as step x the current dt).
  if (comm->me != 0) return;
  const bigint step = update->ntimestep;
  const double numbers[RESTART_NUMBERS] = {RESTART_MARKER, sediment_time_now(update),
                                           static_cast<double>(step),
                                           static_cast<double>(frames - (last_frame_step == step ? 1 : 0))};
  std::vector<char> state(sizeof(numbers) + RESTART_ID_BYTES, '\0');
  memcpy(state.data(), numbers, sizeof(numbers));
  const char *run_id = input->variable->retrieve("sediment_run_id");
  if (run_id) strncpy(state.data() + sizeof(numbers), run_id, RESTART_ID_BYTES - 1);
  const int size = static_cast<int>(state.size());
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(state.data(), 1, state.size(), fp);
}

void FixLayersHDF5::restart(char *buf)
{
  double numbers[RESTART_NUMBERS];
  memcpy(numbers, buf, 2 * sizeof(double));
  if (numbers[0] != RESTART_MARKER) {    // a restart of an earlier build: time and step only
    update->atime = numbers[0];
    update->atimestep = static_cast<bigint>(numbers[1]);
    return;
  }
  memcpy(numbers, buf, sizeof(numbers));
  update->atime = numbers[1];
  update->atimestep = static_cast<bigint>(numbers[2]);
  resumed_frames = static_cast<long long>(numbers[3]);
  const char *held = buf + sizeof(numbers);
  const std::string resumed_run_id(held, strnlen(held, RESTART_ID_BYTES - 1));
  const char *run_id = input->variable->retrieve("sediment_run_id");
  if (run_id && *run_id && !resumed_run_id.empty() && resumed_run_id != run_id)
    error->all(FLERR, "Fix layers/hdf5: the restart file was written by run {}, this is run {}: a run resumes "
               "from its own restart files only", resumed_run_id, run_id);
}

double FixLayersHDF5::compute_scalar()
{
  double count = static_cast<double>(frames);
  MPI_Bcast(&count, 1, MPI_DOUBLE, 0, world);
  return count;
}
