#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs the Debian packages SEDIMENT needs, if any is missing (idempotent, quiet when done).
set -euo pipefail
packages=(
  cmake g++ make ccache dpkg-dev xz-utils util-linux procps
  lammps liblammps-dev python3-lammps openmpi-bin libopenmpi-dev libfftw3-dev
  pybind11-dev python3-pybind11 libgtest-dev libbenchmark-dev libhdf5-dev
  python3-numpy python3-scipy python3-matplotlib python3-h5py python3-pytest python3-pytest-xdist python3-tqdm
  python3-nbclient python3-nbformat python3-nbconvert python3-ipykernel python3-sphinx python3-myst-parser python3-numpydoc
  python3-pip python3-venv python3-setuptools python3-wheel
)
missing=()
for pkg in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "installing Debian packages: ${missing[*]}"
sudo_cmd=""
[ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
$sudo_cmd apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${missing[@]}" >/dev/null
