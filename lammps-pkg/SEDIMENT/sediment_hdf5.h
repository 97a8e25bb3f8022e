// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: the HDF5 and file helpers of fix layers/hdf5. Each
   throws std::runtime_error saying what failed.
------------------------------------------------------------------------- */

#ifndef LMP_SEDIMENT_HDF5_H
#define LMP_SEDIMENT_HDF5_H

#include <hdf5.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace LAMMPS_NS {
namespace SedimentHDF5 {

// Closes an HDF5 handle when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*closer)(hid_t), const std::string &what) : id_(id), closer_(closer), what_(what)
  {
    if (id_ < 0) throw std::runtime_error(what);
  }
  // Closing a dataset writes its cached chunks: a full disk shows here, so a close after writing is checked.
  void close()
  {
    const herr_t status = closer_(id_);
    id_ = -1;
    if (status < 0) throw std::runtime_error("writing " + what_ + " (disk full?)");
  }
  ~Handle()
  {
    if (id_ >= 0) closer_(id_);
  }
  Handle(const Handle &) = delete;
  Handle &operator=(const Handle &) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*closer_)(hid_t);
  std::string what_;
};

void check(herr_t status, const std::string &what);

void write_attribute(hid_t where, const char *name, double value);
void write_attribute(hid_t where, const char *name, const std::string &value);
// Sets (or overwrites in place) a scalar double attribute.
void set_attribute(hid_t where, const char *name, double value);
double read_double_attribute(hid_t where, const char *name);
// "" if there is none or it is not a string.
std::string read_string_attribute(hid_t where, const char *name);

// Fixed array (1d) of doubles, checksummed: in its object header (whose checksum covers it) if it fits there,
// else in one chunk with its own checksum.
void write_array(hid_t where, const char *name, const std::vector<double> &values);
// Extendable dataset whose first dimension counts frames.
void create_frames(hid_t where, const char *name, hid_t type, int rank, const hsize_t *frame_dims);
// Resizes an open frame dataset to `frames` and writes its last `count` frames from `data`.
void put_frames(hid_t set, const char *name, hid_t type, hsize_t frames, hsize_t count, const void *data);
bool has_dataset(hid_t handle, const char *name);
// A one-value-per-frame dataset (time or step) whole.
template <typename T> std::vector<T> read_frames(hid_t handle, const char *name, hid_t type)
{
  Handle set(H5Dopen2(handle, name, H5P_DEFAULT), H5Dclose, std::string("dataset ") + name);
  Handle space(H5Dget_space(set), H5Sclose, "dataspace");
  hsize_t count = 0;
  H5Sget_simple_extent_dims(space, &count, nullptr);
  std::vector<T> values(count);
  if (count > 0) check(H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name);
  return values;
}

bool file_exists(const std::string &name);
// CRC-32 (IEEE 802.3, as zlib's crc32 and Python's zlib.crc32) and size of a file; false if it cannot be read.
bool file_crc32(const std::string &name, uint32_t &crc, long long &size);
void copy_file(const std::string &from, const std::string &to);

}    // namespace SedimentHDF5
}    // namespace LAMMPS_NS

#endif
