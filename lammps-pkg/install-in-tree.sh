#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs SEDIMENT as a package of a LAMMPS source tree (CMake build), so that
#   cmake -S LAMMPS/cmake -B build -D PKG_SEDIMENT=on -D PKG_GRANULAR=on -D PKG_KSPACE=on -D FFT=FFTW3 ...
# builds its styles into liblammps and lmp:
#   lammps-pkg/install-in-tree.sh /path/to/lammps        (the folder with src/ and cmake/)
# Copies the styles and the physics core to src/SEDIMENT, the CMake module to
# cmake/Modules/Packages/SEDIMENT.cmake, the doc pages to doc/src and the examples to
# examples/PACKAGES/sediment, and adds SEDIMENT to the package lists of cmake/CMakeLists.txt and to
# the doc's command tables and package lists. It checks every place first and changes nothing if one
# is missing. Running it again refreshes the files that changed and changes nothing else. Tested on
# the LAMMPS of Debian 12's source package (29 Sep 2021, Debian 20220106: built, and the style checks
# run, by make test-lammps-2022), of Debian 13's (4 Feb 2025: the lists and LAMMPS's check-packages.py,
# by hand) and of Debian sid's (4 Jul 2026: built, and every deck run, by make test-lammps-current).
set -eu
here=$(dirname "$(readlink -f "$0")")
repo=$(dirname "$here")
lammps=${1:?usage: install-in-tree.sh LAMMPS_DIR (with src/ and cmake/)}
[ -f "$lammps/src/lammps.h" ] && [ -f "$lammps/cmake/CMakeLists.txt" ] ||
    { echo "install-in-tree.sh: $lammps is not a LAMMPS source tree (no src/lammps.h, cmake/CMakeLists.txt)" >&2; exit 2; }

cmakelists="$lammps/cmake/CMakeLists.txt"
fail() { echo "install-in-tree.sh: $*; nothing was changed" >&2; exit 1; }

# Checks first: the tree is changed only if every place the package goes into exists.
[ -d "$lammps/cmake/Modules/Packages" ] || fail "no cmake/Modules/Packages in $lammps"
grep -q '^  SEDIMENT$' "$cmakelists" || grep -q '^  GRANULAR$' "$cmakelists" ||
    fail "no GRANULAR in $cmakelists's package list to place SEDIMENT beside"
grep -q '^foreach(PKG_WITH_INCL ' "$cmakelists" ||
    fail "no 'foreach(PKG_WITH_INCL' list in $cmakelists for the packages with a CMake module"
if [ -d "$lammps/doc/src" ]; then
    "$repo/lammps-pkg/doc-tables.py" --check "$lammps/doc/src" || fail "the doc pages do not have the lists above"
fi

pkg="$lammps/src/SEDIMENT"
# src/SEDIMENT gets exactly the files below. A file whose content is already there is left as it is
# (and its time stamp with it), so a build of the tree recompiles only what changed since.
staged=$(mktemp -d)
trap 'rm -rf "$staged"' EXIT
mkdir -p "$staged/sediment"
# The styles; not sediment_styles.*: run-time registration and the plugin entry are for the
# driver and the plugin, an in-tree build registers the styles from their headers.
for f in "$here"/SEDIMENT/*.cpp "$here"/SEDIMENT/*.h; do
    case $(basename "$f") in sediment_styles.*) ;; *) cp "$f" "$staged/" ;; esac
done
for f in "$repo"/core/src/*.cpp; do cp "$f" "$staged/sediment_core_$(basename "$f")"; done
cp "$repo"/core/include/sediment/*.hpp "$staged/sediment/"
update() {    # update FILE DEST: DEST becomes FILE, untouched if it is already
    cmp -s "$1" "$2" || cp "$1" "$2"
}
[ -d "$pkg" ] && find "$pkg" -type f | while read -r f; do
    [ -f "$staged/${f#"$pkg"/}" ] || rm -f "$f"
done
mkdir -p "$pkg/sediment"
(cd "$staged" && find . -type f) | while read -r f; do update "$staged/$f" "$pkg/$f"; done
update "$here/cmake/SEDIMENT.cmake" "$lammps/cmake/Modules/Packages/SEDIMENT.cmake"

# Package lists of the CMake build: the standard packages, and the first list of those with a
# Packages/*.cmake (it starts with GRAPHICS on recent releases, KSPACE on 2022's).
grep -q '^  SEDIMENT$' "$cmakelists" || sed -i 's/^  GRANULAR$/  GRANULAR\n  SEDIMENT/' "$cmakelists"
grep -q '^foreach(PKG_WITH_INCL SEDIMENT ' "$cmakelists" ||
    sed -i '0,/^foreach(PKG_WITH_INCL /s//foreach(PKG_WITH_INCL SEDIMENT /' "$cmakelists"

# Doc pages, the command tables and the package lists (doc/utils/check-styles.py and
# check-packages.py look for every style and package there).
if [ -d "$lammps/doc/src" ]; then
    for f in "$here"/SEDIMENT/doc/*.rst; do update "$f" "$lammps/doc/src/$(basename "$f")"; done
    "$repo/lammps-pkg/doc-tables.py" "$lammps/doc/src"
fi
if [ -d "$lammps/examples" ]; then
    mkdir -p "$lammps/examples/PACKAGES/sediment"
    for f in "$here"/examples/*; do update "$f" "$lammps/examples/PACKAGES/sediment/$(basename "$f")"; done
fi
echo "SEDIMENT installed in $lammps: configure with -D PKG_SEDIMENT=on -D PKG_GRANULAR=on -D PKG_KSPACE=on -D FFT=FFTW3"
