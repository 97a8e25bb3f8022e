#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# A minimal LAMMPS of a given release, from Debian's source package, with SEDIMENT installed in its
# tree (the in-tree route), for testing the package on the releases the README names:
#   scripts/build-lammps.sh RELEASE DEST
# RELEASE: current   the current release (Debian sid's source package; 4 Jul 2026 when written)
#          2022      29 Sep 2021 (Debian 12, 20220106): the source package of the
#                    installed liblammps-dev (bookworm's newest without it), whose tree sets C++11
# DEST/lammps: the source tree (src, cmake, doc) with SEDIMENT installed (lammps-pkg/install-in-tree.sh);
# DEST/build: liblammps.so and lmp with GRANULAR, KSPACE (FFTW3: fix fluid/flow's FFTs), PLUGIN and
# SEDIMENT, MPI.
# Each step is skipped when done (the tarball, the unpacked tree); the build is incremental, so a
# rerun recompiles only what changed. Nothing of LAMMPS is committed to the project.
set -euo pipefail
usage="usage: build-lammps.sh current|2022 DEST"
release=${1:?$usage}
dest=$(realpath -m "${2:?$usage}")
repo=$(cd "$(dirname "$0")/.." && pwd)
case $release in
    current) suite=sid version=latest ;;
    2022) suite=bookworm version=$(dpkg-query -W -f='${source:Version}' liblammps-dev 2>/dev/null || echo latest) ;;
    *) echo "$usage" >&2; exit 2 ;;
esac
mkdir -p "$dest"
# One build at a time in the cache (clones on one machine share it).
exec 9>"$dest/.lock"
flock 9

orig=$("$repo/scripts/fetch-lammps-source.sh" "$suite" "$version" "$dest")

tree="$dest/lammps"
if [ ! -f "$tree/.complete" ]; then
    rm -rf "$tree" && mkdir -p "$tree"
    # sid's tarball holds the tree at its top, bookworm's in one folder (lammps-0~20220106.git...)
    first=$(tar -tf "$orig" | head -1 || true)
    case $first in
        */*) top=${first%%/*}/ strip=1 ;;
        *) top= strip=0 ;;
    esac
    tar -xf "$orig" -C "$tree" --strip-components=$strip \
        "${top}cmake" "${top}src" "${top}doc/src" "${top}doc/utils" "${top}examples/plugins"
    touch "$tree/.complete"
fi
"$repo/lammps-pkg/install-in-tree.sh" "$tree" >/dev/null

build="$dest/build"
# Configured every time (seconds): LAMMPS's CMake lists a package's sources when it configures, so a
# style added to or removed from SEDIMENT since the last run is picked up.
cmake -S "$tree/cmake" -B "$build" -D CMAKE_BUILD_TYPE=Release -D BUILD_SHARED_LIBS=on -D BUILD_MPI=on \
    -D BUILD_OMP=off -D BUILD_TOOLS=off -D FFT=FFTW3 -D FFT_SINGLE=off -D WITH_JPEG=off -D WITH_PNG=off \
    -D WITH_GZIP=off -D WITH_FFMPEG=off -D WITH_CURL=off -D PKG_GRANULAR=on -D PKG_KSPACE=on -D PKG_PLUGIN=on \
    -D PKG_SEDIMENT=on >/dev/null
cmake --build "$build" -j "${JOBS:-2}" >/dev/null
echo "LAMMPS $(basename "$orig" | sed 's/lammps_\(.*\)\.orig.*/\1/') with SEDIMENT: $build/lmp"
