// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: fix layers/hdf5
------------------------------------------------------------------------- */

#include "fix_layers_hdf5.h"
#include "sediment_args.h"

#include "compute_concentration_grid.h"
#include "fix_fluid.h"

#include "comm.h"
#include "domain.h"
#include "error.h"
#include "modify.h"
#include "update.h"

#include <hdf5.h>

#include <cstring>
#include <mpi.h>
#include <stdexcept>
#include <vector>

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

constexpr const char *SCHEMA = "sediment-layers";
constexpr int SCHEMA_VERSION = 1;

// Closes an HDF5 handle when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*closer)(hid_t), const std::string &what) : id_(id), closer_(closer)
  {
    if (id_ < 0) throw std::runtime_error(what);
  }
  ~Handle() { closer_(id_); }
  Handle(const Handle &) = delete;
  Handle &operator=(const Handle &) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*closer_)(hid_t);
};

void check(herr_t status, const std::string &what)
{
  if (status < 0) throw std::runtime_error(what);
}

void write_attribute(hid_t where, const char *name, double value)
{
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "dataspace");
  Handle attr(H5Acreate2(where, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("attribute ") + name);
  check(H5Awrite(attr, H5T_NATIVE_DOUBLE, &value), std::string("attribute ") + name);
}

void write_attribute(hid_t where, const char *name, const std::string &value)
{
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
  check(H5Tset_size(type, value.empty() ? 1 : value.size()), "string size");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "dataspace");
  Handle attr(H5Acreate2(where, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              std::string("attribute ") + name);
  check(H5Awrite(attr, type, value.c_str()), std::string("attribute ") + name);
}

std::string read_string_attribute(hid_t where, const char *name)
{
  if (H5Aexists(where, name) <= 0) return "";
  Handle attr(H5Aopen(where, name, H5P_DEFAULT), H5Aclose, std::string("attribute ") + name);
  Handle type(H5Aget_type(attr), H5Tclose, "attribute type");
  if (H5Tget_class(type) != H5T_STRING) return "";
  std::vector<char> text(H5Tget_size(type) + 1, '\0');
  check(H5Aread(attr, type, text.data()), std::string("attribute ") + name);
  return text.data();
}

// Fixed array (1d) of doubles.
void write_array(hid_t where, const char *name, const std::vector<double> &values)
{
  const hsize_t dims[1] = {values.size()};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose, "dataspace");
  Handle set(H5Dcreate2(where, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose, std::string("dataset ") + name);
  if (!values.empty()) check(H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name);
}

// Extendable dataset whose first dimension counts frames.
void create_frames(hid_t where, const char *name, hid_t type, int rank, const hsize_t *frame_dims)
{
  hsize_t dims[3] = {0, 0, 0}, maxdims[3] = {H5S_UNLIMITED, 0, 0}, chunk[3] = {1, 1, 1};
  for (int k = 1; k < rank; ++k) dims[k] = maxdims[k] = chunk[k] = frame_dims[k - 1];
  if (rank == 1) chunk[0] = 256;
  Handle space(H5Screate_simple(rank, dims, maxdims), H5Sclose, "dataspace");
  Handle props(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "properties");
  check(H5Pset_chunk(props, rank, chunk), "chunking");
  Handle set(H5Dcreate2(where, name, type, space, H5P_DEFAULT, props, H5P_DEFAULT), H5Dclose,
             std::string("dataset ") + name);
}

// Resizes a frame dataset to `frames` and, if data is given, writes frame `frames - 1`.
void put_frame(hid_t file, const char *name, hid_t type, hsize_t frames, const void *data)
{
  Handle set(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, std::string("dataset ") + name);
  hsize_t dims[3] = {frames, 0, 0};
  {
    Handle space(H5Dget_space(set), H5Sclose, "dataspace");
    const int rank = H5Sget_simple_extent_ndims(space);
    hsize_t current[3];
    H5Sget_simple_extent_dims(space, current, nullptr);
    for (int k = 1; k < rank; ++k) dims[k] = current[k];
    check(H5Dset_extent(set, dims), std::string("resizing ") + name);
  }
  if (!data) return;
  Handle space(H5Dget_space(set), H5Sclose, "dataspace");
  const int rank = H5Sget_simple_extent_ndims(space);
  hsize_t start[3] = {frames - 1, 0, 0}, count[3] = {1, dims[1], dims[2]};
  check(H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr), "selection");
  Handle memory(H5Screate_simple(rank, count, nullptr), H5Sclose, "dataspace");
  check(H5Dwrite(set, type, memory, space, H5P_DEFAULT, data), std::string("writing ") + name);
}

}    // namespace

FixLayersHDF5::FixLayersHDF5(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), compute_id(nullptr), fluid_id(nullptr), particle_density(0.0), grid(nullptr),
    fluid(nullptr), file(-1), is_open(false), frames(0)
{
  if (narg < 6)
    error->all(FLERR, "Fix layers/hdf5: expected 'fix ID group layers/hdf5 N FILE.h5 c_ID [keyword value ...]'");
  nevery = utils::inumeric(FLERR, arg[3], false, lmp);
  if (nevery <= 0) error->all(FLERR, "Fix layers/hdf5: N must be > 0");
  path = arg[4];
  if (strncmp(arg[5], "c_", 2) != 0)
    error->all(FLERR, "Fix layers/hdf5: expected a compute reference c_ID, not '{}'", arg[5]);
  compute_id = utils::strdup(arg[5] + 2);
  StyleArgs args(lmp, FLERR, "Fix layers/hdf5", narg, arg, 6);
  while (args.more()) {
    args.need(1, "a value");
    if (args.is("fluid")) {
      delete[] fluid_id;
      fluid_id = utils::strdup(args.text(1));
    } else if (args.is("particle_density")) {
      particle_density = args.positive(1, "particle_density");
    } else {
      args.unknown("fluid or particle_density");
    }
    args.next(1);
  }
  scalar_flag = 1;
  global_freq = 1;
  extscalar = 0;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);    // errors are reported through LAMMPS
}

FixLayersHDF5::~FixLayersHDF5()
{
  if (file >= 0) H5Fclose(file);
  delete[] compute_id;
  delete[] fluid_id;
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
  Compute *compute = sediment_find_compute(lmp, compute_id, "Fix layers/hdf5");
  grid = dynamic_cast<ComputeConcentrationGrid *>(compute);
  if (!grid)
    error->all(FLERR, "Fix layers/hdf5: compute '{}' is a compute {}, not a compute concentration/grid",
               compute_id, compute->style);
  if (!grid->is_layers())
    error->all(FLERR, "Fix layers/hdf5: compute '{}' bins into 3d cells; layer files need 'layers AXIS N'", compute_id);
  fluid = fluid_id ? FixFluid::find(lmp, fluid_id, "Fix layers/hdf5") : nullptr;
}

void FixLayersHDF5::setup(int /*vflag*/)
{
  if (!is_open) open_file();
  if (update->ntimestep % nevery == 0) write_frame();
}

void FixLayersHDF5::end_of_step()
{
  write_frame();
}

void FixLayersHDF5::post_run()
{
  close_file();
}

void FixLayersHDF5::open_file()
{
  // The grid is evaluated once so that its layer geometry is known.
  if (grid->invoked_array != update->ntimestep) grid->compute_array();
  const sediment::Layers layers = grid->layer_geometry();
  const std::vector<std::string> names = grid->column_names();
  const hsize_t shape[2] = {static_cast<hsize_t>(layers.count), names.size()};
  const bigint step_now = update->ntimestep;

  on_rank0([&] {
    const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
    FILE *probe = fopen(path.c_str(), "rb");
    const bool exists = probe != nullptr;
    if (probe) fclose(probe);
    if (exists && is_hdf5 <= 0)
      throw std::runtime_error("exists but is not an HDF5 file; not overwriting it");
    if (exists) {
      // Continue the file: keep the frames before this step, so that a restarted run neither
      // loses nor repeats frames.
      file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      if (file < 0) throw std::runtime_error("cannot be opened for writing");
      if (read_string_attribute(file, "schema") != SCHEMA)
        throw std::runtime_error("is not a SEDIMENT layer file; not overwriting it");
      Handle set(H5Dopen2(file, "fraction", H5P_DEFAULT), H5Dclose, "dataset fraction");
      Handle space(H5Dget_space(set), H5Sclose, "dataspace");
      hsize_t dims[3];
      H5Sget_simple_extent_dims(space, dims, nullptr);
      if (dims[1] != shape[0] || dims[2] != shape[1])
        throw std::runtime_error(fmt::format("holds {} layers x {} columns, the compute gives {} x {}; "
                                             "use another file", dims[1], dims[2], shape[0], shape[1]));
      std::vector<long long> steps(dims[0]);
      Handle step_set(H5Dopen2(file, "step", H5P_DEFAULT), H5Dclose, "dataset step");
      if (dims[0] > 0) check(H5Dread(step_set, H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, steps.data()), "step");
      frames = 0;
      while (frames < static_cast<long long>(steps.size()) && steps[frames] < step_now) ++frames;
      for (const char *name : {"time", "step", "fraction"}) put_frame(file, name, H5T_NATIVE_DOUBLE, frames, nullptr);
      return;
    }
    file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) throw std::runtime_error("cannot be created");
    frames = 0;
    write_attribute(file, "schema", SCHEMA);
    write_attribute(file, "schema_version", SCHEMA_VERSION);
    write_attribute(file, "units", update->unit_style);
    write_attribute(file, "axis", std::string(1, "xyz"[grid->layer_axis()]));
    write_attribute(file, "dimension", domain->dimension);
    write_attribute(file, "cross_section", grid->cross_section());
    if (domain->dimension == 2) write_attribute(file, "slab_thickness", grid->slab_thickness());
    if (particle_density > 0.0) write_attribute(file, "particle_density", particle_density);
    if (fluid) {
      write_attribute(file, "fluid_density", fluid->properties().density);
      write_attribute(file, "fluid_viscosity", fluid->properties().viscosity);
      write_attribute(file, "fluid_yield_stress", fluid->properties().yield_stress);
    }
    std::string columns;
    for (const std::string &name : names) columns += (columns.empty() ? "" : ",") + name;
    write_attribute(file, "columns", columns);
    write_attribute(file, "layer_lo", layers.lo);
    write_attribute(file, "layer_thickness", layers.thickness);
    std::vector<double> centres(layers.count);
    for (int k = 0; k < layers.count; ++k) centres[k] = layers.lo + (k + 0.5) * layers.thickness;
    write_array(file, "layer_centre", centres);
    write_array(file, "class_edges", grid->class_diameters());
    create_frames(file, "time", H5T_NATIVE_DOUBLE, 1, nullptr);
    create_frames(file, "step", H5T_NATIVE_LLONG, 1, nullptr);
    create_frames(file, "fraction", H5T_NATIVE_DOUBLE, 3, shape);
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush");
  });
  is_open = true;
}

void FixLayersHDF5::write_frame()
{
  if (grid->invoked_array != update->ntimestep) grid->compute_array();
  double **array = grid->array;
  const int rows = grid->size_array_rows, cols = grid->size_array_cols - 1;
  on_rank0([&] {
    std::vector<double> values(static_cast<size_t>(rows) * cols);
    for (int k = 0; k < rows; ++k)
      for (int c = 0; c < cols; ++c) values[static_cast<size_t>(k) * cols + c] = array[k][c + 1];
    const double time = update->atime + (update->ntimestep - update->atimestep) * update->dt;
    const long long step = update->ntimestep;
    ++frames;
    put_frame(file, "time", H5T_NATIVE_DOUBLE, frames, &time);
    put_frame(file, "step", H5T_NATIVE_LLONG, frames, &step);
    put_frame(file, "fraction", H5T_NATIVE_DOUBLE, frames, values.data());
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush");    // a killed run keeps every finished frame
  });
}

void FixLayersHDF5::close_file()
{
  on_rank0([&] {
    if (file >= 0) H5Fclose(file);
    file = -1;
  });
  is_open = false;
}

double FixLayersHDF5::compute_scalar()
{
  double count = static_cast<double>(frames);
  MPI_Bcast(&count, 1, MPI_DOUBLE, 0, world);
  return count;
}
