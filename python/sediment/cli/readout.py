# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment readout: hydrometer, buoyancy-sphere and pipette readings of a simulated test."""
from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..constants import (D422_CYLINDER_AREA, D422_CYLINDER_HEIGHT, INSTRUMENTS, PIPETTE_DEPTH, PIPETTE_VOLUME,
                         SCHEDULES, SOIL_PARTICLE_DENSITY)
from .types import positive, quantity, temperature


EXAMPLES = [
    'sediment readout out/sample5/layers.h5 --out out/sample5/readout',
    'sediment readout --psd examples/granulometry/psd/sample5.csv --stokes-preview --out out/preview',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("readout", help="hydrometer, buoyancy-sphere and pipette readings from a layer "
                                 "file (fix layers/hdf5), with CSV tables, the granulometry figure and errors")
    parser.add_argument("layers", type=Path, nargs="?", help="layer file (HDF5)")
    parser.add_argument("--instrument", default="all", choices=[*INSTRUMENTS, "all"])
    parser.add_argument("--schedule", default="d422", choices=sorted(SCHEDULES),
                        help="reading times (the buoyancy sphere uses Bravo et al.'s unless another is given)")
    parser.add_argument("--psd", type=Path, help="input PSD (diameter_um,percent_finer) to compare with "
                        "(default: input_psd.csv beside the layer file)")
    parser.add_argument("--simulated", type=Path, help="PSD actually simulated (default: simulated_psd.csv "
                        "beside the layer file)")
    parser.add_argument("--stokes-preview", action="store_true",
                        help="without a layer file: read an analytic Stokes column of --psd")
    parser.add_argument("--height", type=quantity("suspension_height"),
                        default=D422_CYLINDER_HEIGHT, help="preview column height [m]")
    parser.add_argument("--concentration", type=quantity("concentration"), default=50.0, help="preview solids [g/L]")
    parser.add_argument("--particle-density", type=quantity("particle_density"),
                        default=SOIL_PARTICLE_DENSITY, help="preview [kg/m3]")
    parser.add_argument("--surface", type=quantity("surface"),
                        help="free-surface coordinate [m] (default: top of the layers)")
    parser.add_argument("--sphere-depth", type=quantity("instrument_depth"),
                        help="buoyancy sphere centre depth [m] (default 0.3 H)")
    parser.add_argument("--pipette-depth", type=quantity("instrument_depth"), default=PIPETTE_DEPTH, help="[m]")
    parser.add_argument("--pipette-volume", type=quantity("pipette_volume"), default=PIPETTE_VOLUME, help="[m3]")
    parser.add_argument("--hydrometer", type=positive, nargs=6,
                        metavar=("L2", "VB", "STEM_D", "MASS", "L1_R0", "L1_R50"),
                        help="a measured hydrometer instead of the nominal 152H: bulb length [m], bulb volume "
                        "[m3], stem diameter [m], mass [kg], bulb top to the R = 0 and R = 50 marks [m]")
    parser.add_argument("--temperature", type=temperature, help="the water temperature the laboratory recorded [C], "
                        "0-40: the reduction takes the water's viscosity and density at it (default: the layer "
                        "file's fluid)")
    parser.add_argument("--viscosity", type=quantity("water_viscosity"),
                        help="viscosity for Stokes' law [Pa s] (default: the "
                        "layer file's fluid)")
    parser.add_argument("--cylinder-area", type=quantity("cylinder_area"), default=D422_CYLINDER_AREA,
                        help="for the hydrometer's level rise [m2]")
    parser.add_argument("--band", type=Path, metavar="BUDGET",
                        help="budget.json of `sediment budget` for this test: each reading gets the band (low, high) "
                        "that the physics' uncertainty puts around it (the budget's physical total)")
    parser.add_argument("--band-sample", metavar="NAME", help="the sample of a budget.json that holds several")
    parser.add_argument("--allow-partial", action="store_true",
                        help="read a layer file whose run did not finish (its frames stop early)")
    parser.add_argument("--out", type=Path, default=Path("out/readout"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Reads the column, prints the inputs and the errors per size range, writes the report."""
    from ..lab.granulometry import granulometry
    from ..lab.psd import read_psd
    from ..lab.readout import Column, Hydrometer, Suspension
    from ..lab.synthetic import settling_column

    compared = []    # the tables beside the layer file that the frames are compared with
    if args.layers is not None:    # PSD tables that `sediment sample` wrote beside the run
        for option, name in (("psd", "input_psd.csv"), ("simulated", "simulated_psd.csv")):
            beside = args.layers.parent / name
            if getattr(args, option) is None and beside.is_file():
                setattr(args, option, beside)
                compared.append(beside)
                print(f"using {beside}")
    if args.layers is not None:    # the frames and what they are compared with checked before they are read
        from ..sim.layers import check_layer_file, read_layers_guarded
        from ..sim.provenance import check_digest, check_inputs
        check_layer_file(args.layers)
        check_digest(args.layers)
        layers = read_layers_guarded(args.layers)
        check_inputs(args.layers, layers.identity.get("run_id", ""), compared)
    psd = read_psd(args.psd) if args.psd else None
    simulated = read_psd(args.simulated) if args.simulated else None
    if args.layers is not None:
        if not layers.complete:
            message = (f"{args.layers} is partial: the run writing it did not finish ({len(layers.time)} frames, the "
                       f"last at {layers.time[-1] / 60:.4g} min)")
            if not args.allow_partial:
                raise ValueError(message + "; resume or rerun it (sediment run --resume), or pass --allow-partial")
            print("warning: " + message)
        column = Column.from_layers(layers, surface=args.surface)
        if args.temperature is not None and args.viscosity is not None:
            raise ValueError("--temperature sets the viscosity: give one of --temperature and --viscosity")
        if args.temperature is not None:    # the lab's record, which may differ from the simulation's water
            water = Suspension.at_temperature(args.temperature, column.suspension.particle_density)
            column = replace(column, suspension=water, water=None)
        if args.viscosity is not None:
            column = replace(column, suspension=replace(column.suspension, viscosity=args.viscosity, temperature=None),
                             water=None)
        title = f"{args.layers.parent.name}/{args.layers.name}: simulated sedimentation test"
        made_by = " by " + layers.identity["code_version"] if "code_version" in layers.identity else ""
        frames_of = f"frames of run {layers.identity.get('run_id') or '(unnamed)'}{made_by}: {args.layers}"
    else:
        if psd is None:
            raise ValueError("give a layer file, or --psd with --stokes-preview for an analytic column")
        suspension = (Suspension(particle_density=args.particle_density) if args.temperature is None
                      else Suspension.at_temperature(args.temperature, args.particle_density))
        times = np.concatenate([[0.0], np.geomspace(10.0, 1440 * 60.0, 400)])
        column = settling_column(psd, args.height, times, args.concentration, suspension)
        title = f"{args.psd.name}: Stokes settling preview (no DEM)"
    instruments = list(INSTRUMENTS) if args.instrument == "all" else [args.instrument]
    hydrometer = Hydrometer.measured(*_measured(args.hydrometer)) if args.hydrometer else None
    report = granulometry(column, instruments, psd, simulated, title, schedule=args.schedule,
                          sphere_depth=args.sphere_depth, pipette_depth=args.pipette_depth,
                          pipette_volume=args.pipette_volume, cylinder_area=args.cylinder_area,
                          hydrometer=hydrometer)
    if args.layers is not None:
        report.notes.append(frames_of)
    if args.band is not None:
        from ..studies.budget import band_of

        band = band_of(args.band, args.band_sample)
        report.readings = [replace(r, band=band[r.instrument]) for r in report.readings]
        report.notes.append("band from the physics' uncertainty (" + str(args.band) + "): " +
                            ", ".join(f"{r.instrument} +-{r.band:.3g} pp" for r in report.readings))
    elif args.band_sample is not None:
        raise ValueError("--band-sample names a sample of --band BUDGET: give both")
    report.save(args.out)
    print(report.table().text(), end="")
    return 0


def _measured(values: list[float]) -> list[float]:
    """The six values of --hydrometer, each within its quantity's plausible range."""
    from ..plausible import check

    quantities = ("bulb_length", "bulb_volume", "stem_diameter", "hydrometer_mass", "scale_mark", "scale_mark")
    names = ("L2", "VB", "STEM_D", "MASS", "L1_R0", "L1_R50")
    return [check(v, q, f"--hydrometer {n}") for v, q, n in zip(values, quantities, names)]
