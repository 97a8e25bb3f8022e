// SPDX-License-Identifier: GPL-2.0-or-later
/* ----------------------------------------------------------------------
   SEDIMENT package: writes the layer profiles of compute concentration/grid
   to an HDF5 file every N steps (schema: doc/fix_layers_hdf5.rst).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(layers/hdf5,FixLayersHDF5);
// clang-format on
#else

#ifndef LMP_FIX_LAYERS_HDF5_H
#define LMP_FIX_LAYERS_HDF5_H

#include "fix.h"

#include "sediment/concentration.hpp"

#include <string>
#include <utility>
#include <vector>

namespace LAMMPS_NS {

class FixLayersHDF5 : public Fix {
 public:
  FixLayersHDF5(class LAMMPS *, int, char **);
  ~FixLayersHDF5() override;
  int setmask() override;
  void init() override;
  void setup(int) override;
  void end_of_step() override;
  void post_run() override;
  double compute_scalar() override;
  void write_restart(FILE *) override;
  void restart(char *) override;

 private:
  std::string path;
  char *compute_id;
  double particle_density;
  class ComputeConcentrationGrid *grid;
  // The fluid's properties when this fix was defined, stored with the frames: the deck's first water
  // (a deck may re-issue the fluid between runs as a temperature record goes), which a resumed run
  // must have too.
  std::vector<std::pair<const char *, double>> water;
  // The fluid fix (empty: none); the density and viscosity of the water the steps before the next
  // frame ran in, which each frame records (a reading of the frames then takes the water as it was),
  // and those of the current run (init).
  std::string fluid_id;
  double fluid_now[2], fluid_run[2];
  long long file;       // hid_t of the open file (rank 0), -1 when closed
  // hid_t of its frame datasets time, step, fraction and, with a fluid, fluid (rank 0; -1: absent),
  // open while the file is: opening and closing them for each frame was three quarters of the cost
  // of writing it.
  long long frame_sets[4];
  bool is_open;         // the same on every rank (file is only meaningful on rank 0)
  long long frames;     // frames taken: in the file and waiting to be written (rank 0)
  // Frames taken but not yet in the file (rank 0), row by row, and when the file was last written.
  std::vector<double> pending_time, pending_values, pending_fluid;
  std::vector<long long> pending_step;
  double last_write;
  static constexpr double WRITE_INTERVAL = 1.0;             // seconds a frame waits at most
  static constexpr size_t PENDING_BYTES = size_t(64) << 20;    // or until this many bytes wait
  bool overwrite;       // a new run may replace an earlier file of other parameters
  double end_time;      // the frames are complete once they reach this simulated time (< 0: at the end)
  // Set by restart(): the frames taken before the restart file's step (-1: not resumed from a
  // restart file of this fix).
  long long resumed_frames;
  bigint last_frame_step;    // step of the newest frame taken (rank 0)
  bigint summed_restart;     // step of the newest restart file whose checksum is written (rank 0)
  std::string writing;  // the file the frames go to (rank 0): PATH.partial until LAMMPS is done

  void open_file();
  std::vector<std::pair<const char *, double>> parameters(const sediment::Layers &layers) const;
  std::string choose_file(bigint step_now, size_t layers, size_t columns,
                          const std::vector<std::pair<const char *, double>> &identity, const std::string &run_id);
  std::string incomplete_reason(long long file_id) const;    // why finished frames are no complete result
  void take_frame(bool write_now);    // takes a frame; writes the waiting ones if due or write_now
  void write_pending();
  void open_frame_sets();    // rank 0, the file open
  void close_file();
  void sum_restart();    // rank 0: the checksum of a restart file written since the last call
  // Runs `action` on rank 0 and stops every rank with its message if it failed.
  template <typename Action> void on_rank0(Action action);
};

}    // namespace LAMMPS_NS

#endif
#endif
