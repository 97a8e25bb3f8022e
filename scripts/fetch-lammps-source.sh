#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Downloads the original source tarball of Debian's lammps source package into DIR and prints its path:
#   scripts/fetch-lammps-source.sh SUITE VERSION|latest DIR
# (e.g. bookworm with the version of the installed liblammps-dev, or sid latest). The deb-src entry
# and its package lists are kept in DIR: the machine's apt configuration is not changed. apt checks
# the tarball against the signed index. Skipped when DIR already holds a tarball of that version.
# The Debian mirror is the machine's own (the archive apt installs Debian's main from; a proxy in
# apt's configuration applies too), SEDIMENT_DEBIAN_MIRROR if set, deb.debian.org otherwise.
set -euo pipefail
suite=${1:?usage: fetch-lammps-source.sh SUITE VERSION|latest DIR}
version=${2:?usage: fetch-lammps-source.sh SUITE VERSION|latest DIR}
dir=$(realpath -m "${3:?usage: fetch-lammps-source.sh SUITE VERSION|latest DIR}")
mkdir -p "$dir/apt-lists/partial"
sources="$dir/$suite-src.sources"
apt_opts=(-o Dir::Etc::sourcelist="$sources" -o Dir::Etc::sourceparts=- -o Dir::State::Lists="$dir/apt-lists"
          -o APT::Get::List-Cleanup=0)
upstream() { echo "${1%-*}" | sed 's/^[0-9]*://'; }    # 20220106.git7586adbb6a+ds1-2 -> 20220106.git7586adbb6a+ds1
if [ "$version" != latest ] && ls "$dir/lammps_$(upstream "$version").orig.tar."* >/dev/null 2>&1; then
    ls "$dir/lammps_$(upstream "$version").orig.tar."*
    exit 0
fi
mirror=${SEDIMENT_DEBIAN_MIRROR:-$(apt-get indextargets --format '$(REPO_URI) $(RELEASE) $(COMPONENT)' 2>/dev/null |
                                    awk '$3 == "main" && $2 !~ /-/ {print $1; exit}')}
mirror=${mirror:-http://deb.debian.org/debian/}
cat > "$sources" <<SRC
Types: deb-src
URIs: $mirror
Suites: $suite
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
apt-get update "${apt_opts[@]}" >/dev/null
[ "$version" = latest ] && version=$(apt-cache showsrc "${apt_opts[@]}" lammps | awk '/^Version:/ {print $2; exit}')
orig="$dir/lammps_$(upstream "$version").orig.tar"
if ! ls "$orig".* >/dev/null 2>&1; then
    echo "fetching the LAMMPS $version source package (Debian $suite)" >&2
    # The orig tarball is all we need; a mirror may lack the .dsc or the Debian diff.
    (cd "$dir" && apt-get source --download-only "${apt_opts[@]}" "lammps=$version" >/dev/null 2>&1 || true)
fi
ls "$orig".* 2>/dev/null || { echo "could not fetch the lammps $version source package ($suite)" >&2; exit 1; }
