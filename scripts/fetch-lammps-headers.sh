#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Unpack the LAMMPS headers that exactly match Debian's liblammps, 29 Sep 2021 (Debian 12, 20220106), into DEST.
# liblammps-dev ships only part of the headers and none of the embedded fmt 7 library, so we take them
# from the Debian source package of the same version. Nothing of LAMMPS is committed to the project.
set -euo pipefail
dest=${1:?usage: fetch-lammps-headers.sh DEST}
[ -f "$dest/.complete" ] && exit 0
mkdir -p "$dest"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
version=$(dpkg-query -W -f='${source:Version}' liblammps-dev)
# The source package (80 MB) is downloaded once per machine, beside the LAMMPS builds of make test,
# and shared by every clone (one download at a time).
downloads="${XDG_CACHE_HOME:-$HOME/.cache}/sediment/lammps-source-bookworm"
mkdir -p "$downloads"
exec 9>"$downloads/.lock"
flock 9
orig=$("$(dirname "$0")/fetch-lammps-source.sh" bookworm "$version" "$downloads")
# The headers of src/ and of every package ('*/src/*.h' reaches into every package folder: KSPACE's
# fft3d_wrap.h, fft3d.h and kissfft.h, which fix fluid/flow solves its flow with, among them; a pattern
# naming them again matches no member of its own, and tar fails on it), the fmt they include, and in
# full the packages the styles build on: GRANULAR, PLUGIN.
tar -xf "$orig" -C "$work" --wildcards '*/src/*.h' '*/src/fmt/*' '*/src/GRANULAR/*' '*/src/PLUGIN/*'
top=$(ls -d "$work"/*/src)
cp -r "$top"/. "$dest"/
touch "$dest/.complete"
echo "LAMMPS $version headers in $dest"
