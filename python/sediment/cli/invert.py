# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment invert: a laboratory's sheet of readings in, the sample's PSD out (docs/inverse.md)."""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ..constants import (BALANCE_NOISE, D422_CYLINDER_AREA, HYDROMETER_NOISE, HYDROMETER_TYPES, NOMINAL_BULB_LENGTH,
                         NOMINAL_BULB_VOLUME, PIPETTE_NOISE, PIPETTE_VOLUME, SIEVE_NOISE, SOIL_PARTICLE_DENSITY,
                         SPECIMEN_MASS, SPHERE_DIAMETER, SPHERE_MASS, SUSPENSION_VOLUME, THERMOMETER_NOISE)
from ..results import write_text
from .types import count, finite, quantity, quantity_list


EXAMPLES = [
    'sediment invert examples/inverse/soil/hydrometer.csv examples/inverse/soil/sieve.csv --mass 0.05 --out out/soil',
    'sediment invert examples/inverse/hydrometer.csv examples/inverse/pipette.csv --mass 0.06 --out out/invert',
    'sediment invert --design examples/granulometry/psd/sample5.csv --out out/design',
    'sediment invert --batch examples/inverse/real-lab --hydrometer-calibration examples/inverse/real-lab/hydrometer_1.csv '
    '--bulb-volume 55e-6 --bulb-length 0.137 --particle-density 2700 --meniscus 1 --out out/real-lab',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser(
        "invert", help="a laboratory's sheets (hydrometer, pipette, buoyancy sphere, sieves) in, the sample's PSD, "
        "texture and gradation out, with bands, the standard reduction beside it and the fit's verdict",
        description="Fits the PSD whose simulated test (the best physics: standard drag curve, Richardson & Zaki's "
        "hindrance, the water at the sheet's temperatures) reads what the sheets read. Sheets are CSV: "
        "time_min,reading,temperature_C[,blank] (152H g/L, or 151H specific gravity); time_min,depth_cm,mass_g "
        "(pipette); "
        "time_min,apparent_mass_g (buoyancy sphere); opening_mm,percent_passing (sieves, of the whole sample). "
        "Writes OUT/psd.csv (diameter_um,percent_finer,low,high,measured,basis), texture.csv, gradation.csv, "
        "reduction.csv, fit.csv, invert.json and the figures invert.png, gradation.png, texture.png. Exit 3: no PSD "
        "explains the sheets. See docs/inverse.md. "
        "Example: sediment invert examples/inverse/soil/hydrometer.csv examples/inverse/soil/sieve.csv --mass 0.05 "
        "--out out/soil")
    parser.add_argument("sheets", type=Path, nargs="*", help="the sheets of one sample (CSV)")
    parser.add_argument("--batch", type=Path, metavar="FOLDER",
                        help="instead of sheets: a laboratory's batch, one sub-folder per sample with its sheets and a "
                        "sample.json of its own options ({\"mass\": 0.05, \"stirred\": \"09:00\"}); the options "
                        "given here hold for every sample. Each sample's results go to OUT/SAMPLE, and OUT/summary.csv "
                        "and summary.png show them all; a sample already inverted with the same sheets and options is "
                        "not run again")
    parser.add_argument("--jobs", type=count, default=os.cpu_count() or 1,
                        help="with --batch: samples inverted at a time (default: the machine's cores)")
    parser.add_argument("--batch-key", help=argparse.SUPPRESS)    # a batch's record of a sample's inputs
    parser.add_argument("--design", type=Path, metavar="PSD",
                        help="instead of sheets: the PSD a sample is expected to have; compares instruments, reading "
                        "times and sample masses by how well each recovers it (OUT/design.csv, design.png)")
    parser.add_argument("--masses", type=quantity_list("specimen_mass"), default=[0.030, 0.045, 0.060, 0.080],
                        help="with --design: sample masses to compare [kg] (default 0.03,0.045,0.06,0.08)")
    parser.add_argument("--mass", type=quantity("specimen_mass"),
                        help="oven-dry mass of the hydrometer's specimen [kg] (this or --air-dry-mass is required with "
                        "sheets; the part passing --split where one is given, the whole sample's with --washed)")
    parser.add_argument("--air-dry-mass", type=quantity("specimen_mass"), metavar="KG",
                        help="instead of --mass: the specimen's air-dry mass [kg], with --water-content")
    parser.add_argument("--water-content", type=quantity("water_content"), metavar="W",
                        help="hygroscopic water content of the air-dry specimen, a fraction (0.035 for 3.5 %%): the "
                        "oven-dry mass is the air-dry mass / (1 + W)")
    parser.add_argument("--split", type=quantity("split"), metavar="OPENING_MM",
                        help="the hydrometer's specimen is the part of the sample passing this sieve (D422: 2.0); the "
                        "sieve sheet gives the percent passing it, --mass is that part's")
    parser.add_argument("--washed", type=quantity("split"), metavar="OPENING_MM",
                        help="the specimen was washed through this sieve before the hydrometer (0.053, 0.075): only the "
                        "part passing it was in the cylinder; --mass is the whole specimen's dry mass, the sieve sheet "
                        "(of the whole specimen) gives the share passing")
    parser.add_argument("--particle-density", type=quantity("particle_density"),
                        default=SOIL_PARTICLE_DENSITY, help="[kg/m3] (default 2650)")
    parser.add_argument("--cylinder-area", type=quantity("cylinder_area"),
                        default=D422_CYLINDER_AREA, help="[m2] (default D422's)")
    parser.add_argument("--volume", type=quantity("suspension_volume_m3"),
                        help="volume of the suspension [m3] (default 1e-3, the 1000 mL mark); its height in the "
                        "cylinder is the volume / --cylinder-area")
    parser.add_argument("--height", type=quantity("suspension_height"),
                        help="instead of --volume: the suspension's height [m] (the volume is then --cylinder-area x "
                        "--height)")
    parser.add_argument("--hydrometer-type", choices=HYDROMETER_TYPES, default=HYDROMETER_TYPES[0],
                        help="the hydrometer's scale: 152H (g/L of soil, the default) or 151H (specific gravity, 0.995 "
                        "to 1.038); the two have the same dimensions. The sheets' readings and blanks, the "
                        "calibration's readings, --zero-correction, --meniscus and --hydrometer-noise are in its unit")
    parser.add_argument("--hydrometer-calibration", type=Path, metavar="CSV",
                        help="the laboratory's calibration of its hydrometer (D7928): reading,distance_cm, the distance from "
                        "the graduation of each reading to the bulb's centre, two rows or more (default: the nominal "
                        "152H of D422)")
    parser.add_argument("--bulb-volume", type=quantity("bulb_volume"), default=NOMINAL_BULB_VOLUME,
                        help="the hydrometer bulb's volume [m3], for V_B / 2A (default the nominal 152H's 6.7e-05)")
    parser.add_argument("--bulb-length", type=quantity("bulb_length"), default=NOMINAL_BULB_LENGTH,
                        help="the hydrometer bulb's length [m], over which it averages the suspension (default 0.14)")
    parser.add_argument("--stirred", metavar="HH:MM",
                        help="when the suspension was stirred, for sheets that give clock times (a clock column, "
                        "HH:MM, instead of time_min)")
    parser.add_argument("--zero-correction", type=finite, default=0.0,
                        help="composite correction (dispersant, zero), subtracted from each reading [152H g/L; 151H: "
                        "its reading in the control cylinder less 1]")
    parser.add_argument("--meniscus", type=finite, default=0.0,
                        help="meniscus correction, added to each reading for its depth [152H g/L, about 1; 151H: about "
                        "0.0006]")
    parser.add_argument("--sphere-depth", type=quantity("instrument_depth"),
                        help="buoyancy sphere centre depth [m] (default 0.3 H)")
    parser.add_argument("--sphere-diameter", type=quantity("sphere_diameter"), default=SPHERE_DIAMETER, help="[m]")
    parser.add_argument("--sphere-mass", type=quantity("sphere_mass"), default=SPHERE_MASS, help="[kg]")
    parser.add_argument("--pipette-volume", type=quantity("pipette_volume"), default=PIPETTE_VOLUME,
                        help="[m3] (default 25 mL)")
    parser.add_argument("--hydrometer-noise", type=finite,
                        help="standard uncertainty of a hydrometer reading [152H g/L, default 0.25: read to 0.5 g/L; "
                        "151H default 0.00016, the same]")
    parser.add_argument("--balance-noise", type=quantity("balance_noise"),
                        default=BALANCE_NOISE, help="of a sphere's apparent mass [g]")
    parser.add_argument("--pipette-noise", type=quantity("pipette_noise"),
                        default=PIPETTE_NOISE, help="of a pipette sample's mass [g]")
    parser.add_argument("--sieve-noise", type=quantity("sieve_noise"), default=SIEVE_NOISE,
                        help="standard uncertainty of a sieve's percent passing [points] (default 0.5)")
    parser.add_argument("--thermometer", type=quantity("thermometer"),
                        default=THERMOMETER_NOISE, help="of the temperature record [C]")
    parser.add_argument("--budget", type=Path, help="budget.json of `sediment budget` for this test: its physical "
                        "total widens the band")
    parser.add_argument("--budget-sample", metavar="NAME", help="the sample of a budget.json that holds several")
    parser.add_argument("--bins", type=count, default=24, help="size bins between the finest and coarsest "
                        "reading's diameters (default 24)")
    parser.add_argument("--particles", type=count, default=20000, help="parcels of the forward runs (default 20000)")
    parser.add_argument("--seed", type=int, default=1, help="placement seed of the forward runs")
    parser.add_argument("--out", type=Path, default=Path("out/invert"), help="output folder")
    return parser


def run(args: argparse.Namespace) -> int:
    """Reads the sheets, inverts, prints the PSD and the verdict, writes the report."""
    from ..inverse import LabTest
    from ..lab.sheet import read_sheet
    from ..plausible import check, sphere_density

    if sum([args.design is not None, bool(args.sheets), args.batch is not None]) != 1:
        raise ValueError("give the sheets of a sample, or --batch FOLDER of samples, or --design PSD to plan a test "
                         "(one of them)")
    if args.batch is not None:
        return _batch(args)
    mass = specimen_mass(args)
    if args.design is None and mass is None:
        raise ValueError("--mass is required: the oven-dry mass of the hydrometer's specimen [kg] (0.05 for 50 g), or "
                         "--air-dry-mass with --water-content")
    if args.split is not None and args.washed is not None:
        raise ValueError("--split and --washed: the specimen is either the part passing a sieve (--split, --mass of "
                         "that part) or washed through one (--washed, --mass of the whole specimen); give one")
    if args.volume is not None and args.height is not None:
        raise ValueError("--volume and --height both give the suspension's size: give one (the height is the volume / "
                         "--cylinder-area)")
    height = args.height if args.height is not None else (args.volume or SUSPENSION_VOLUME) / args.cylinder_area
    # each within its range, the two may still make a cylinder no laboratory has (27.8 cm2 typed as 0.0278)
    check(args.cylinder_area * height * 1e3, "suspension_volume",
          f"--cylinder-area {args.cylinder_area:g} m2 x height {height:g} m:")
    volume = args.cylinder_area * height
    check(height, "suspension_height", f"--cylinder-area {args.cylinder_area:g} m2 makes the {volume * 1e3:.4g} L "
          "suspension's height")
    sphere = sphere_density(args.sphere_mass, args.sphere_diameter)
    if sphere is not None:
        raise ValueError(sphere)
    hydrometer_noise, zero_correction, meniscus = (
        hydrometer_step(args, "hydrometer_noise", "hydrometer_noise", HYDROMETER_NOISE),
        hydrometer_step(args, "zero_correction"),
        hydrometer_step(args, "meniscus"))
    noise = {"hydrometer": hydrometer_noise, "buoyancy": args.balance_noise,
             "pipette": args.pipette_noise / (args.pipette_volume * 1e3), "sieve": args.sieve_noise}
    test = LabTest(SPECIMEN_MASS if mass is None else mass, args.particle_density, args.cylinder_area, height,
                   hydrometer=hydrometer(args), zero_correction=zero_correction, meniscus=meniscus,
                   sphere_depth=args.sphere_depth, sphere_diameter=args.sphere_diameter, sphere_mass=args.sphere_mass,
                   noise=noise, thermometer=args.thermometer)
    sheets = [read_sheet(p, args.pipette_volume, args.stirred, args.hydrometer_type) for p in args.sheets]
    _refuse_repeats(sheets)
    sieves = [s for s in sheets if s.instrument == "sieve"]
    if len(sieves) > 1:
        raise ValueError(f"two sieve sheets ({sieves[0].path}, {sieves[1].path}): give one sieve analysis per sample")
    if args.design is None and len(sieves) == len(sheets):
        raise ValueError("a sieve sheet alone: give the sedimentation sheet(s) of the same sample too")
    if args.zero_correction and any(len(getattr(s, "blank", ())) for s in sheets):
        raise ValueError("--zero-correction and a sheet with a blank column: the composite correction is given twice; "
                         "keep one")
    return _design(args, test) if args.design is not None else _invert(args, test, sheets)


def specimen_mass(args: argparse.Namespace) -> float | None:
    """The oven-dry mass [kg] the options give: --mass, or --air-dry-mass / (1 + --water-content)."""
    if args.air_dry_mass is None:
        if args.water_content is not None:
            raise ValueError("--water-content without --air-dry-mass: the water content turns an air-dry mass into an "
                             "oven-dry one; with --mass (oven-dry) leave it out")
        return args.mass
    if args.mass is not None:
        raise ValueError("--mass and --air-dry-mass: give the oven-dry mass, or the air-dry mass with its water content")
    if args.water_content is None:
        raise ValueError("--air-dry-mass needs --water-content (the hygroscopic water content, a fraction: 0.035 for "
                         "3.5 %): the oven-dry mass is the air-dry mass / (1 + w)")
    return args.air_dry_mass / (1 + args.water_content)


def hydrometer_step(args: argparse.Namespace, option: str, quantity: str = "", default: float = 0.0) -> float:
    """An option given in the hydrometer's unit (a correction, the meniscus, the reading error) as the
    152H's g/L, checked against what a 152H's can plausibly be; `default` [g/L] where it is not given."""
    from ..lab.instruments import hydrometer
    from ..plausible import check, refusal

    value = getattr(args, option)
    if value is None:
        return default
    scale = hydrometer(args.hydrometer_type).scale
    grams = value * scale.per_unit
    named = f"--{option.replace('_', '-')}" + ("" if scale.in_grams else f" {value:g} ({scale.name}) as a 152H's:")
    quantity = quantity or option.replace("zero_", "")
    reason = refusal(grams, quantity)
    if not scale.in_grams and reason is not None and refusal(value, quantity) is None:
        raise ValueError(f"{named} {reason}; written in a 152H's g/L? with --hydrometer-type 151H "
                         f"give it in specific gravity: {value / scale.per_unit:.3g}")
    return check(grams, quantity, named)


def hydrometer(args: argparse.Namespace):
    """The hydrometer the options describe: the laboratory's calibration, or the nominal one of D422 (the
    151H's dimensions are the 152H's)."""
    from ..lab.readout import Hydrometer
    from ..lab.sheet import read_hydrometer_calibration

    if args.hydrometer_calibration is None:
        return Hydrometer.astm_152h(bulb_length=args.bulb_length, bulb_volume=args.bulb_volume)
    readings, distances = read_hydrometer_calibration(args.hydrometer_calibration, args.hydrometer_type)
    try:
        return Hydrometer.calibrated(readings, distances, args.bulb_volume, args.bulb_length)
    except ValueError as exc:
        raise ValueError(f"{args.hydrometer_calibration}: {exc}") from None


def _refuse_repeats(sheets: list) -> None:
    """The same sheet given twice (however saved) would count its readings twice and narrow the band."""
    import numpy as np

    seen: dict[tuple, Path] = {}
    for sheet in sheets:
        arrays = (sheet.opening, sheet.passing) if sheet.instrument == "sieve" else (sheet.time, sheet.reading, sheet.depth)
        key = (sheet.instrument, *(tuple(np.round(a, 9)) for a in arrays))
        if key in seen and seen[key].resolve() == sheet.path.resolve():
            named = f" (as {seen[key]} and {sheet.path})" if seen[key] != sheet.path else ""
            raise ValueError(f"{sheet.path} is given twice{named}: give each sheet once")
        if key in seen:
            raise ValueError(f"{sheet.path} and {seen[key]} hold the same readings: give each sheet once")
        seen[key] = sheet.path


BUDGET_PSD_TOLERANCE = 15.0    # points of percent finer between the budget's PSD and the one recovered
BUDGET_MASS_TOLERANCE = 0.3    # and a specimen mass off the budget's by more than this share


def budget_note(entry: dict, path: Path, diameter, percent, mass: float) -> str | None:
    """A note where a budget's test is not this one: its PSD far from the recovered one, or another mass;
    or where it does not say (a budget of an earlier version)."""
    import numpy as np

    from ..studies.budget import made_for_psd

    made = made_for_psd(entry)
    name = f"--budget {path} (sample '{entry['sample']}')"
    if made is None:
        return (f"check: {name} records no test it was made for (a budget of an earlier version): that its band is "
                "this sample's is not checked")
    inside = (diameter >= made.diameter[0]) & (diameter <= made.diameter[-1])
    gap = np.abs(made.at(diameter[inside]) - percent[inside]) if inside.any() else np.zeros(1)
    budget_mass = float((entry.get("made_for") or {}).get("mass_kg", mass))
    differs = []
    if gap.max() > BUDGET_PSD_TOLERANCE:
        k = int(np.argmax(gap))
        differs.append(f"its PSD is {gap[k]:.3g} points off the one recovered here (at {diameter[inside][k] * 1e6:.3g} um)")
    if abs(budget_mass / mass - 1) > BUDGET_MASS_TOLERANCE:
        differs.append(f"its specimen was {budget_mass * 1e3:.4g} g, this one {mass * 1e3:.4g} g")
    if not differs:
        return None
    return (f"check: {name} was made for another test: {'; '.join(differs)}: its physical totals, which widen the "
            "band, may not be this sample's; make the budget of this PSD (sediment budget psd.csv)")


def _invert(args: argparse.Namespace, test, sheets) -> int:
    """Inverts the sheets; prints the PSD and the verdict, writes the report (exit 3: no PSD fits)."""
    from ..inverse import invert

    band, budget, entry = 0.0, None, None
    if args.budget is not None:
        from ..sim.provenance import file_digest
        from ..studies.budget import budget_entry

        entry = budget_entry(args.budget, args.budget_sample)
        totals = entry["physical_total_pp"]
        missing = sorted({s.instrument for s in sheets if s.instrument != "sieve"} - set(totals))
        if missing:
            raise ValueError(f"--budget {args.budget}: no physical total for the {' and '.join(missing)} (it has "
                             f"{', '.join(sorted(totals))}): give the budget of this test's instruments")
        band = max(totals[s.instrument] for s in sheets if s.instrument != "sieve")
        budget = {"file": str(args.budget), "sha256": file_digest(args.budget), "sample": entry["sample"],
                  "physical_total_pp": totals, "band_pp": band,
                  "made_for": {k: v for k, v in (entry.get("made_for") or {}).items() if k in ("mass_kg", "temperature_C")}}
    readings = [s for s in sheets if s.instrument != "sieve"]
    sieve = next((s for s in sheets if s.instrument == "sieve"), None)
    split = args.split
    if args.washed is not None:
        from dataclasses import replace

        from ..inverse.invert import sieve_data

        if sieve is None:
            raise ValueError("--washed needs the sieve sheet of the whole specimen: the percent passing the wash sieve "
                             "is the share of --mass that was in the cylinder")
        share = sieve_data(sieve, args.washed * 1e-3, args.sieve_noise).share
        whole, test, split = test.mass, replace(test, mass=test.mass * share), args.washed
    result = invert(readings, test, args.out / "runs", sieve=sieve, split=None if split is None else split * 1e-3,
                    bins=args.bins, particles=args.particles, seed=args.seed, budget_band=band)
    if args.batch_key is not None:
        result.inputs["batch_key"] = args.batch_key
    result.inputs["budget"] = budget
    if entry is not None:
        note = budget_note(entry, args.budget, result.diameter, result.percent, test.mass)
        if note:
            result.notes.insert(-1, note)
    if args.washed is not None:
        result.inputs |= {"washed_mm": args.washed, "whole_specimen_mass": whole}
        result.notes.insert(-1, f"washed through {args.washed:g} mm before the hydrometer: {test.mass * 1e3:.4g} g in "
                            f"the cylinder, the {share * 100:.4g} % of the {whole * 1e3:.4g} g specimen that passed it")
    result.save(args.out)
    args.publish()    # before the verdict, which comes last
    notes, result.notes = result.notes, []
    print(result.table().text(), end="")
    print(result.texture().table().text(), end="")
    print("\n".join(notes))           # the verdict last
    if result.consistent:
        return 0
    twice = sorted({s.instrument for s in readings if sum(r.instrument == s.instrument for r in readings) > 1})
    hint = f" (two {' and two '.join(twice)} sheets: of two samples?)" if twice else ""
    print(f"sediment invert: no PSD explains the sheets together{hint} (exit 3): {notes[-1]}", file=sys.stderr)
    return 3


def _batch(args: argparse.Namespace) -> int:
    """Inverts a batch's samples; prints each as it ends and the summary, writes summary.csv, summary.png and the
    samples' consoles (logs/). Exit 2 where a sample could not be inverted, 3 where one fits no PSD, else 0."""
    from ..inverse.batch import read_samples, run_batch, summary_figure, summary_table

    samples = read_samples(args.batch)
    rows = run_batch(samples, _common_options(args.argv), args.final_out, args.out / "logs", args.jobs)
    table = summary_table(rows)
    write_text(args.out / "summary.csv", table.csv())
    summary_figure(args.out / "summary.png", rows)
    args.publish()
    print(table.text(), end="")
    failed = [r["sample"] for r in rows if r["result"] is None]
    odd = [r["sample"] for r in rows if r["result"] is not None and not r["result"]["consistent"]]
    if failed:
        print(f"sediment invert: {len(failed)} of {len(rows)} samples could not be inverted ({', '.join(failed)}): "
              f"their reasons are in summary.csv and {args.final_out / 'logs'}; the others' results stand (exit 2)",
              file=sys.stderr)
        return 2
    if odd:
        print(f"sediment invert: no PSD explains the sheets of {', '.join(odd)} (exit 3)", file=sys.stderr)
        return 3
    return 0


def _common_options(argv: list[str]) -> list[str]:
    """The batch command's options that hold for every sample: its arguments less the command, the batch's own
    options (--batch, --jobs, --out) and their values."""
    own = ("--batch", "--jobs", "--out")
    out, skip = [], False
    for token in argv[1:]:    # after the command's name
        if skip:
            skip = False
        elif token in own:
            skip = True
        elif not token.startswith(tuple(f"{o}=" for o in own)):
            out.append(token)
    return out


def _design(args: argparse.Namespace, test) -> int:
    """Compares the designs of a test of the expected PSD; prints and writes the table and figure."""
    from .. import figures
    from ..inverse import clay_reading_time, design_test
    from ..lab.psd import read_psd
    from ..results import Table, write_text

    psd = read_psd(args.design)
    rows = design_test(psd, args.out / "runs", masses=tuple(args.masses), test=test, bins=args.bins,
                       particles=args.particles, seed=args.seed)
    clay = "; ".join(f"{celsius:g} C: {seconds / 3600:.3g} h" for celsius, seconds in clay_reading_time(psd, test))
    table = Table(["design", "mass_g", "readings", "mean_error_pp", "worst_error_pp"],
                  notes=[f"{args.design.name}: the recovered PSD's error at the bin edges, mean over noise draws; "
                         "the hindrance's own uncertainty, growing with the mass, is not in it",
                         f"the 152H's cut reaches 2 um (clay) after: {clay} (at {test.mass * 1e3:g} g); a sheet whose "
                         "last reading comes earlier bounds the clay fraction instead of measuring it"])
    for name, mass, n, mean, worst in rows:
        table.add(name, f"{mass * 1e3:g}", n, f"{mean:.3g}" if n else "cannot read", f"{worst:.3g}" if n else "")
    print(table.text(), end="")
    write_text(args.out / "design.csv", table.csv())
    figures.design_errors(rows, args.out / "design.png", f"designs of a test of {args.design.stem}")
    return 0
