#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Unpack the LAMMPS headers that exactly match Debian's liblammps (29 Sep 2021 update 2) into DEST.
# liblammps-dev ships only part of the headers and none of the embedded fmt 7 library, so we take them
# from the Debian source package of the same version. Nothing of LAMMPS is committed to the project.
set -euo pipefail
dest=${1:?usage: fetch-lammps-headers.sh DEST}
[ -f "$dest/.complete" ] && exit 0
mkdir -p "$dest"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

sources=/etc/apt/sources.list.d/sediment-deb-src.sources
if ! apt-get source --print-uris lammps >/dev/null 2>&1; then
    cat > "$sources" <<SRC
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
    apt-get update -o Dir::Etc::sourcelist="$sources" -o Dir::Etc::sourceparts="-" \
        -o APT::Get::List-Cleanup="0" >/dev/null
fi
version=$(dpkg-query -W -f='${source:Version}' liblammps-dev)
(cd "$work" && apt-get source --download-only "lammps=$version" >/dev/null)
orig=$(ls "$work"/lammps_*.orig.tar.*)
tar -xf "$orig" -C "$work" --wildcards '*/src/*.h' '*/src/fmt/*' '*/src/GRANULAR/*' '*/src/PLUGIN/*'
top=$(ls -d "$work"/*/src)
cp -r "$top"/. "$dest"/
touch "$dest/.complete"
echo "LAMMPS $version headers in $dest"
