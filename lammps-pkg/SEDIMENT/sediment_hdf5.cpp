// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: the HDF5 and file helpers of fix layers/hdf5.
------------------------------------------------------------------------- */

#include "sediment_hdf5.h"

#include <cstdio>

namespace LAMMPS_NS {
namespace SedimentHDF5 {

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

double read_double_attribute(hid_t where, const char *name)
{
  double value = 0.0;
  Handle attr(H5Aopen(where, name, H5P_DEFAULT), H5Aclose, std::string("attribute ") + name);
  check(H5Aread(attr, H5T_NATIVE_DOUBLE, &value), std::string("attribute ") + name);
  return value;
}

void set_attribute(hid_t where, const char *name, double value)
{
  // written in place: a file flushed (or a process killed) between a delete and a create would hold
  // no such attribute
  if (H5Aexists(where, name) <= 0) return write_attribute(where, name, value);
  Handle attr(H5Aopen(where, name, H5P_DEFAULT), H5Aclose, std::string("attribute ") + name);
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

void write_array(hid_t where, const char *name, const std::vector<double> &values)
{
  const hsize_t dims[1] = {values.size()};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose, "dataspace");
  Handle props(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "properties");
  if (values.size() * sizeof(double) <= 60000) {
    check(H5Pset_layout(props, H5D_COMPACT), "compact layout");
  } else {
    check(H5Pset_chunk(props, 1, dims), "chunking");
    check(H5Pset_fletcher32(props), "checksums");
  }
  Handle set(H5Dcreate2(where, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, props, H5P_DEFAULT),
             H5Dclose, std::string("dataset ") + name);
  if (!values.empty()) check(H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name);
}

void create_frames(hid_t where, const char *name, hid_t type, int rank, const hsize_t *frame_dims)
{
  hsize_t dims[3] = {0, 0, 0}, maxdims[3] = {H5S_UNLIMITED, 0, 0}, chunk[3] = {1, 1, 1};
  for (int k = 1; k < rank; ++k) dims[k] = maxdims[k] = chunk[k] = frame_dims[k - 1];
  if (rank == 1) chunk[0] = 256;
  Handle space(H5Screate_simple(rank, dims, maxdims), H5Sclose, "dataspace");
  Handle props(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "properties");
  check(H5Pset_chunk(props, rank, chunk), "chunking");
  check(H5Pset_fletcher32(props), "checksums");    // a damaged frame is refused on reading, not read as data
  Handle set(H5Dcreate2(where, name, type, space, H5P_DEFAULT, props, H5P_DEFAULT), H5Dclose,
             std::string("dataset ") + name);
}

bool has_dataset(hid_t handle, const char *name)
{
  return H5Lexists(handle, name, H5P_DEFAULT) > 0;
}

void put_frames(hid_t set, const char *name, hid_t type, hsize_t frames, hsize_t count, const void *data)
{
  hsize_t dims[3] = {frames, 0, 0};
  {
    Handle space(H5Dget_space(set), H5Sclose, "dataspace");
    const int rank = H5Sget_simple_extent_ndims(space);
    hsize_t current[3];
    H5Sget_simple_extent_dims(space, current, nullptr);
    for (int k = 1; k < rank; ++k) dims[k] = current[k];
    check(H5Dset_extent(set, dims), std::string("resizing ") + name);
  }
  if (count == 0) return;
  Handle space(H5Dget_space(set), H5Sclose, "dataspace");
  const int rank = H5Sget_simple_extent_ndims(space);
  hsize_t start[3] = {frames - count, 0, 0}, block[3] = {count, dims[1], dims[2]};
  check(H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, block, nullptr), "selection");
  Handle memory(H5Screate_simple(rank, block, nullptr), H5Sclose, "dataspace");
  check(H5Dwrite(set, type, memory, space, H5P_DEFAULT, data), std::string("writing ") + name + " (disk full?)");
}

bool file_exists(const std::string &name)
{
  FILE *probe = fopen(name.c_str(), "rb");
  if (probe) fclose(probe);
  return probe != nullptr;
}

bool file_crc32(const std::string &name, uint32_t &crc, long long &size)
{
  static uint32_t table[256];
  if (table[1] == 0)
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      table[n] = c;
    }
  FILE *in = fopen(name.c_str(), "rb");
  if (!in) return false;
  std::vector<unsigned char> buffer(1 << 20);
  crc = 0xFFFFFFFFu;
  size = 0;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), in)) > 0) {
    for (size_t k = 0; k < n; ++k) crc = table[(crc ^ buffer[k]) & 0xFF] ^ (crc >> 8);
    size += static_cast<long long>(n);
  }
  const bool ok = !ferror(in);
  fclose(in);
  crc ^= 0xFFFFFFFFu;
  return ok;
}

void copy_file(const std::string &from, const std::string &to)
{
  FILE *in = fopen(from.c_str(), "rb");
  if (!in) throw std::runtime_error(from + " cannot be read");
  FILE *out = fopen(to.c_str(), "wb");
  if (!out) {
    fclose(in);
    throw std::runtime_error(to + " cannot be written");
  }
  std::vector<char> buffer(1 << 20);
  size_t n;
  bool ok = true;
  while (ok && (n = fread(buffer.data(), 1, buffer.size(), in)) > 0) ok = fwrite(buffer.data(), 1, n, out) == n;
  ok = ok && !ferror(in);
  fclose(in);
  ok = (fclose(out) == 0) && ok;
  if (!ok) throw std::runtime_error("copying to " + to + " failed (disk full?)");
}

}    // namespace SedimentHDF5
}    // namespace LAMMPS_NS
