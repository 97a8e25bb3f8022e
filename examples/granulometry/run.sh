#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# A simulated sedimentation test of one of the five samples of Bravo et al. (2015), end to end:
#   examples/granulometry/run.sh SAMPLE [OUT] [sediment sample options...]
# e.g. run.sh sample5 out/sample5 --particles 50000      (or --geometry slab --cylinder bravo)
# Writes OUT/{sample.data,in.sedimentation,layers.h5,readout/granulometry.png,...}. A layer file of an
# earlier run in OUT is refused (nothing is lost) unless SEDIMENT_REPLACE=1 (make demo sets it).
set -eu
here=$(dirname "$(readlink -f "$0")")
sediment="$here/../../bin/sediment"
sample=${1:?usage: run.sh sample1..sample5 [OUT] [sediment sample options]}
out=${2:-out/$sample}
[ $# -ge 2 ] && shift 2 || shift 1
ranks=${SEDIMENT_RANKS:-2}
"$sediment" sample "$here/psd/$sample.csv" --out "$out" ${SEDIMENT_REPLACE:+--force} "$@"
"$sediment" run "$out/in.sedimentation" --np "$ranks" ${SEDIMENT_REPLACE:+--force}
"$sediment" readout "$out/layers.h5" --out "$out/readout"
echo "figure: $out/readout/granulometry.png"
