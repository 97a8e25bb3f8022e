# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment invert: a laboratory's sheet of readings in, the sample's PSD out (docs/inverse.md)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..constants import D422_CYLINDER_AREA, D422_CYLINDER_HEIGHT, SOIL_PARTICLE_DENSITY
from .types import count, finite, positive


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser(
        "invert", help="a laboratory's readings (hydrometer, pipette, buoyancy sphere) in, the sample's PSD out, "
        "with a band, the standard reduction beside it and the fit's verdict",
        description="Fits the PSD whose simulated test (the best physics: standard drag curve, Richardson & Zaki's "
        "hindrance, the water at the sheet's temperatures) reads what the sheets read. Sheets are CSV: "
        "time_min,reading,temperature_C (152H, g/L); time_min,depth_cm,mass_g (pipette); "
        "time_min,apparent_mass_g (buoyancy sphere). Writes OUT/psd.csv (diameter_um,percent_finer,low,high), "
        "reduction.csv, fit.csv, invert.json, invert.png. See docs/inverse.md. "
        "Example: sediment invert examples/inverse/hydrometer.csv examples/inverse/pipette.csv --mass 0.06 "
        "--out out/invert")
    parser.add_argument("sheets", type=Path, nargs="+", help="the sheets of one sample (CSV)")
    parser.add_argument("--mass", type=positive, default=0.060, help="dry sample mass [kg] (default 0.06)")
    parser.add_argument("--particle-density", type=positive, default=SOIL_PARTICLE_DENSITY, help="[kg/m3] (default 2650)")
    parser.add_argument("--cylinder-area", type=positive, default=D422_CYLINDER_AREA, help="[m2] (default D422's)")
    parser.add_argument("--height", type=positive, default=D422_CYLINDER_HEIGHT, help="suspension height [m]")
    parser.add_argument("--zero-correction", type=finite, default=0.0,
                        help="152H composite correction [g/L], subtracted from each reading (dispersant, zero)")
    parser.add_argument("--meniscus", type=finite, default=0.0, help="152H meniscus correction [g/L], for the depth")
    parser.add_argument("--sphere-depth", type=positive, help="buoyancy sphere centre depth [m] (default 0.3 H)")
    parser.add_argument("--sphere-diameter", type=positive, default=0.025, help="[m]")
    parser.add_argument("--sphere-mass", type=positive, default=0.020, help="[kg]")
    parser.add_argument("--pipette-volume", type=positive, default=25e-6, help="[m3] (default 25 mL)")
    parser.add_argument("--hydrometer-noise", type=positive, default=0.25,
                        help="standard uncertainty of a 152H reading [g/L] (default 0.25: read to 0.5 g/L)")
    parser.add_argument("--balance-noise", type=positive, default=1e-3, help="of a sphere's apparent mass [g]")
    parser.add_argument("--pipette-noise", type=positive, default=1e-4, help="of a pipette sample's mass [g]")
    parser.add_argument("--thermometer", type=positive, default=0.5, help="of the temperature record [C]")
    parser.add_argument("--budget", type=Path, help="budget.json of `sediment budget` for this test: its physical "
                        "total widens the band")
    parser.add_argument("--budget-sample", metavar="NAME", help="the sample of a budget.json that holds several")
    parser.add_argument("--bins", type=count, default=12, help="size bins between the finest and coarsest "
                        "reading's diameters (default 12)")
    parser.add_argument("--particles", type=count, default=20000, help="parcels of the forward runs (default 20000)")
    parser.add_argument("--seed", type=int, default=1, help="placement seed of the forward runs")
    parser.add_argument("--out", type=Path, default=Path("out/invert"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Reads the sheets, inverts, prints the PSD and the verdict, writes the report."""
    from ..lab.inverse import LabTest, invert
    from ..lab.sheet import read_sheet

    sheets = [read_sheet(p, args.pipette_volume) for p in args.sheets]
    noise = {"hydrometer": args.hydrometer_noise, "buoyancy": args.balance_noise,
             "pipette": args.pipette_noise / (args.pipette_volume * 1e3)}
    test = LabTest(args.mass, args.particle_density, args.cylinder_area, args.height, zero_correction=args.zero_correction,
                   meniscus=args.meniscus, sphere_depth=args.sphere_depth, sphere_diameter=args.sphere_diameter,
                   sphere_mass=args.sphere_mass, noise=noise, thermometer=args.thermometer)
    band = 0.0
    if args.budget is not None:
        from ..studies.budget import band_of

        band = max(band_of(args.budget, args.budget_sample)[s.instrument] for s in sheets)
    result = invert(sheets, test, args.out / "runs", bins=args.bins, particles=args.particles, seed=args.seed,
                    budget_band=band)
    print(result.table().text(), end="")
    for path in result.save(args.out):
        print(f"wrote {path}")
    return 0 if result.consistent else 3
