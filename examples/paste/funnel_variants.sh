#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# The funnel study (case E) for every variant of docs/paste.md's table, 15 pours each, then the table
# and figures side by side:  examples/paste/funnel_variants.sh [OUT]   (about 40 min on 2 cores)
# Rows 01-15 reproduce Zhang & Li's model, their law with their plastic viscosity (law zhang-li, whose
# eta_B 0.7 Pa s the study sets with it); row 16 is the default study, law bingham (eta_B 0.279 Pa s).
# Writes OUT/NN_label/ (one saved study each) and OUT/funnel_variants.{csv,png}, funnel_variants_presence.png.
set -eu
here=$(dirname "$(readlink -f "$0")")
sediment="$here/../../bin/sediment"
out=${1:-out/funnel}
study() {    # study LABEL [--dt DT] [--set NAME=VALUE ...]
    label=$1
    shift
    "$sediment" paste funnel --runs 15 --jobs 2 --set law=zhang-li "$@" --out "$out/$label"
}
study 01_cone --set stem=0
study 02_cone_centre --set stem=0 --set effect_submergence=no
study 03_cone_fall25_centre --set stem=0 --set fall=0.25 --set effect_submergence=no
study 04_stem5 --set stem=0.05
study 05_stem5_centre --set stem=0.05 --set effect_submergence=no
study 06_stem5_centre_smoothlaw --set stem=0.05 --set effect_submergence=no --set law=zhang-li/smooth
study 07_stem5_centre_fill140 --set stem=0.05 --set effect_submergence=no --set surface=0.140
study 08_stem5_e0.3 --set stem=0.05 --set tsuji=0.1588
study 09_stem5_fill134_rising --set stem=0.05 --set surface=0.134 --set effect_displacement=yes
study 10_stem10_default --set stem=0.10
study 11_stem10_centre --set stem=0.10 --set effect_submergence=no
study 12_stem10_fill134_rising --set stem=0.10 --set surface=0.134 --set effect_displacement=yes
study 13_stem10_e0.3 --set stem=0.10 --set tsuji=0.1588
study 14_stem10_friction0.1 --set stem=0.10 --set friction=0.1 --set rolling=0
study 15_stem10_dt3e-6 --dt 3e-6 --set stem=0.10
study 16_stem10_bingham --set stem=0.10 --set law=bingham
"$sediment" paste funnel-compare "$out"/[0-9][0-9]_*/ --out "$out"
