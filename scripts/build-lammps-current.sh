#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# A minimal current LAMMPS (Debian sid's source package) with SEDIMENT installed in its tree, for
# testing the package on a current release as well as on Debian 12's 2021 one:
#   scripts/build-lammps-current.sh DEST
# DEST/lammps: the source tree (src, cmake, doc) with SEDIMENT installed (lammps-pkg/install-in-tree.sh);
# DEST/build: liblammps.so and lmp with GRANULAR, PLUGIN and SEDIMENT, MPI, no FFT library.
# Each step is skipped when done (the tarball, the unpacked tree); the build is incremental, so a
# rerun recompiles only what changed. Nothing of LAMMPS is committed to the project.
set -euo pipefail
dest=$(realpath -m "${1:?usage: build-lammps-current.sh DEST}")
repo=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$dest"
# One build at a time in the cache (clones on one machine share it).
exec 9>"$dest/.lock"
flock 9

orig=$("$repo/scripts/fetch-lammps-source.sh" sid latest "$dest")

tree="$dest/lammps"
if [ ! -f "$tree/.complete" ]; then
    rm -rf "$tree" && mkdir -p "$tree"
    tar -xf "$orig" -C "$tree" cmake src doc/src doc/utils examples/plugins
    touch "$tree/.complete"
fi
"$repo/lammps-pkg/install-in-tree.sh" "$tree" >/dev/null

build="$dest/build"
# Configured every time (seconds): LAMMPS's CMake lists a package's sources when it configures, so a
# style added to or removed from SEDIMENT since the last run is picked up.
cmake -S "$tree/cmake" -B "$build" -D CMAKE_BUILD_TYPE=Release -D BUILD_SHARED_LIBS=on -D BUILD_MPI=on \
    -D BUILD_OMP=off -D BUILD_TOOLS=off -D FFT=KISS -D WITH_JPEG=off -D WITH_PNG=off -D WITH_GZIP=off \
    -D WITH_FFMPEG=off -D WITH_CURL=off -D PKG_GRANULAR=on -D PKG_PLUGIN=on -D PKG_SEDIMENT=on >/dev/null
cmake --build "$build" -j "${JOBS:-2}" >/dev/null
echo "LAMMPS $(basename "$orig" | sed 's/lammps_\(.*\)\.orig.*/\1/') with SEDIMENT: $build/lmp"
