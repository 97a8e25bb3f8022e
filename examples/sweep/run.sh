#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# What each time step buys, for the four examples of docs/sweep.md:
#   examples/sweep/run.sh [OUT] [case-a|sphere|paste|scene ...]       (default: out/sweep, all four)
# Each study is one `sediment sweep` (table, figure and the cheapest step within 1 % in OUT/NAME).
set -eu
here=$(dirname "$(readlink -f "$0")")
examples="$here/.."
sediment="$here/../../bin/sediment"
out=${1:-out/sweep}
[ $# -ge 1 ] && shift
studies=${*:-case-a sphere paste scene}
mkdir -p "$out"

field() {   # field() PATTERN N TERMINAL-OPTIONS: field N of the `sediment terminal` line matching PATTERN
    pattern=$1 n=$2
    shift 2
    "$sediment" terminal "$@" | awk -v p="$pattern" -v n="$n" '$0 ~ p {print $n}'
}

for study in $studies; do
    case $study in
    case-a)     # case A: 0.1 mm sphere in water, analytic velocity curve
        "$sediment" sweep "$examples/single_sphere/in.case_a" --out "$out/case-a" \
            --dt 1e-5,3e-5,1e-4,3e-4,1e-3,1.5e-3,2.5e-3,4e-3,1e-2 --integrator implicit,explicit \
            --observe velocity --reference "velocity=9.265e-3*(1-exp(-x/1.5e-3))" \
            --tau 1.5e-3 --rayleigh 8.12e-8 --title "Case A: 0.1 mm sphere in water" ;;
    sphere)     # case C: 19 mm sphere (6513 kg/m3) in suspension 1, zhang-li law
        sphere="--law zhang-li --diameter 0.019 --particle-density 6513 --fluid-density 1280 --viscosity 0.0131
                --yield-stress 30.5 --youngs-modulus 200e9"
        v_t=$(field "terminal velocity" 3 $sphere)
        t_r=$(field "Rayleigh time" 3 $sphere)
        "$sediment" sweep "$examples/valentik_whitmore/in.sphere" --out "$out/sphere" --var t_end 9 \
            --dt 1e-5,1e-4,1e-3,3e-3,1e-2,3e-2,0.1,0.2 --observe speed distance --reference "speed=$v_t" \
            --rayleigh "$t_r" --title "Case C: 19 mm sphere in clay suspension 1 (9 s)" ;;
    paste)      # case D: 12.6 mm steel ball from 255 mm into paste, settling distance
        t_r=$(field "Rayleigh time" 3 --diameter 0.0126 --particle-density 8135 --viscosity 0.7 --youngs-modulus 200e9)
        "$sediment" sweep "$examples/paste/in.ball_in_paste" --out "$out/paste" \
            --dt 1e-6,2e-6,5e-6,1e-5,2e-5,5e-5,1e-4,2e-4,5e-4,1e-3 --observe depth \
            --rayleigh "$t_r" --title "Case D: 12.6 mm ball from 255 mm into paste" ;;
    scene)      # sample 5, 20 000 parcels, 24 h: the readouts against the step of `sediment sample`
        "$sediment" sample "$examples/granulometry/psd/sample5.csv" --out "$out/scene/deck" --particles 20000 >/dev/null
        "$sediment" sweep "$out/scene/deck/in.sedimentation" --out "$out/scene" --parameter dt_scale \
            --dt 0.25,0.5,1,2,4,8,16,32 --observe hydrometer buoyancy pipette \
            --title "Sample 5, 20 000 parcels, 24 h: readouts vs step scale" ;;
    *)  echo "unknown study '$study' (expected case-a, sphere, paste or scene)" >&2; exit 2 ;;
    esac
done
