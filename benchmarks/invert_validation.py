#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""`sediment invert` against known answers (docs/inverse.md): for each PSD, a laboratory's sheets are
synthesised from a rich forward run (50 000 parcels in 200 size classes, so that its PSD is near continuous
at the scale of the inverse's bins; Courant 1; its own seed) with realistic noise (the
152H read to 0.5 g/L at the D7928 times, the water drifting from 19 to 23 C over the day and recorded to
0.1 C, pipette samples at 10 cm weighed to 0.1 mg, the buoyancy sphere's balance to 1 mg at Bravo et
al.'s times, in the water of the moment), inverted, and the recovered PSD compared with the run's at the
reported diameters: those the readings resolve and those between them, with how often the band holds
the truth; the standard reduction of the same sheets beside it.

With --fines-152h, the fines' 152H sheet alone (a D7928 laboratory's), inverted without a sieve sheet and
with the fact that all of it passes 75 um, against the truth at every reading's cut and reported diameter,
with the band's reach at 75 um (100 %: the answer with no sand is one the band allows).

With --soils, real soils instead (examples/inverse/soils: sand to 0.6-1 mm, clay to 50 %): 50 g, the 152H at
the D7928 times and the sieve sheet of the same sample (ASTM openings from 2 mm to 75 um, percent passing to
0.1), each inverted with and without the sieves; the table adds the sieves, the tails and the USDA
fractions against the truth's.

    /usr/bin/python3 benchmarks/invert_validation.py [--out out/invert-validation] [--reuse-truth]
        [--soils | --fines-152h] [PSD.csv ...]
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.constants import WATER_20C_DENSITY  # noqa: E402
from sediment.inverse import LabTest, invert  # noqa: E402
from sediment.lab import texture  # noqa: E402
from sediment.lab.psd import read_psd  # noqa: E402
from sediment.lab.readout import R_FACTOR, SCHEDULES, BuoyancySphere, Column, Hydrometer, Pipette, Suspension  # noqa: E402
from sediment.lab.sheet import read_sheet  # noqa: E402
from sediment.sim.layers import read_layers  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402
from sediment.sim.scene import plan  # noqa: E402
from sediment.sim.scenefiles import write  # noqa: E402

PSDS = [HERE.parent / "examples" / "granulometry" / "psd" / f"sample{k}.csv" for k in range(1, 6)] + \
       [HERE.parent / "examples" / "inverse" / "psd" / f"{name}.csv"
        for name in ("gap_graded", "bimodal", "narrow", "steep_top", "steep_bottom")]
SOILS = [HERE.parent / "examples" / "inverse" / "soils" / f"{name}.csv"
         for name in ("sandy_clay", "clay", "clay_loam", "silt_loam")]
SIEVES_MM = (2.0, 0.85, 0.425, 0.25, 0.15, 0.106, 0.075)
SOIL_MASS = 0.050
REFERENCE_TEMPERATURE = 20.0
DISPERSANT = 2.5      # g/L on the 152H's scale: the dispersant's share of the blank (5 g/L of sodium hexametaphosphate)
# the band "holds" the truth within 0.01 points: a tail's extreme placement reaches 100 % to 1e-4 points (its
# prior is soft), and no reading resolves 0.01 points
HELD_TOLERANCE = 0.01
TRUTH_CLASSES = 200    # size ratio 1.03 per class for the samples' spans: finer than the inverse's bins


def drift(time_s: np.ndarray) -> np.ndarray:
    """The day's water temperature [C]: 19 C at the start, 23 C after 24 h, linear."""
    return 19.0 + 4.0 * np.asarray(time_s) / 86400.0


def synthesise(psd_path: Path, folder: Path, soil: bool = False) -> list[Path]:
    """The truth run and its sheets: the three instruments', or for a soil the 152H's and the sieves'."""
    water = Suspension.at_temperature(REFERENCE_TEMPERATURE)
    scene = plan(read_psd(psd_path), particles=50000, classes=TRUTH_CLASSES, courant=1.0, seed=99, suspension=water,
                 t_end=1.05 * 86400, mass=SOIL_MASS if soil else 0.060)
    # the run's water drifts as the laboratory's does: the inverse's mapping of the temperature record onto
    # one water is checked against a run in which the viscosity and density change with time
    scene.water_record = tuple((t, float(drift(t))) for t in (0.0, 1.05 * 86400))
    write(scene, folder / "truth", force=True)    # the script's own truth run: a new one replaces it
    run_batch(folder / "truth" / "in.sedimentation", {"overwrite": "yes"})
    column = Column.from_layers(read_layers(folder / "truth" / "layers.h5"))
    hydro = np.array(SCHEDULES["d7928"], float) * 60
    # the 152H floats in the run's water with a dispersant (DISPERSANT g/L on its scale), and the companion
    # cylinder of that liquid, read beside it, is the blank: both read to 0.5 g/L as a laboratory reads them
    hydrometer = Hydrometer.astm_152h()
    blank = (column.suspension.fluid_density - WATER_20C_DENSITY) / R_FACTOR + DISPERSANT
    liquid = replace(column.suspension, fluid_density=float(hydrometer.liquid_density(blank)))
    readings = hydrometer.read(replace(column, suspension=liquid), hydro).reading
    lines = ["time_min,reading,temperature_C,blank"] + [
        f"{t / 60:g},{np.round(r / 0.5) * 0.5:g},{np.round(c, 1):g},{np.round(blank / 0.5) * 0.5:g}"
        for t, r, c in zip(hydro, readings, drift(hydro))]
    (folder / "hydrometer.csv").write_text("\n".join(lines) + "\n")
    if soil:
        truth = read_psd(folder / "truth" / "simulated_psd.csv")
        passing = truth.at(np.array(SIEVES_MM) * 1e-3)
        lines = ["opening_mm,percent_passing"] + [f"{o:g},{np.round(p, 1):g}" for o, p in zip(SIEVES_MM, passing)]
        (folder / "sieve.csv").write_text("\n".join(lines) + "\n")
        return [folder / "hydrometer.csv", folder / "sieve.csv"]
    pipette_times = np.sort(Pipette(0.10).default_times(water))
    concentration = [Pipette(0.10).read(column, [t]).reading[0] for t in pipette_times]
    lines = ["time_min,depth_cm,mass_g,temperature_C"] + [
        f"{t / 60:.6g},10,{np.round(c * 0.025 * 1e4) / 1e4:.4f},{np.round(T, 1):g}"
        for t, c, T in zip(pipette_times, concentration, drift(pipette_times))]
    (folder / "pipette.csv").write_text("\n".join(lines) + "\n")
    sphere_times = np.array(SCHEDULES["bravo"], float) * 60
    # the balance reads the sphere in the water of the moment (its density at the drifted temperature; the
    # column's mixture is reckoned with the layer file's water, the run's first)
    from sediment import _core
    sphere = BuoyancySphere(0.3 * scene.height)
    shift = np.array([_core.water_density(t) - column.suspension.fluid_density for t in drift(sphere_times)]) \
        * sphere.volume * 1e3
    apparent = sphere.read(column, sphere_times).reading - shift
    lines = ["time_min,apparent_mass_g,temperature_C"] + [
        f"{t / 60:g},{np.round(a, 3):.3f},{np.round(T, 1):g}" for t, a, T in zip(sphere_times, apparent, drift(sphere_times))]
    (folder / "buoyancy.csv").write_text("\n".join(lines) + "\n")
    return [folder / name for name in ("hydrometer.csv", "pipette.csv", "buoyancy.csv")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("psds", type=Path, nargs="*")
    parser.add_argument("--out", type=Path, default=Path("out/invert-validation"))
    parser.add_argument("--bins", type=int, default=24)
    parser.add_argument("--soils", action="store_true", help="the soils with sand and clay, 152H and sieve sheets")
    parser.add_argument("--fines-152h", action="store_true",
                        help="the fines' 152H sheet alone, without and with '100 %% passes 75 um'")
    parser.add_argument("--reuse-truth", action="store_true",
                        help="invert the sheets an earlier run of this script left in --out (no new truth runs)")
    args = parser.parse_args()
    psds = args.psds or (SOILS if args.soils else PSDS)
    if args.soils:
        soils(psds, args)
        return
    if args.fines_152h:
        fines_152h(psds, args)
        return
    print("| PSD | readings | at the readings' diameters: mean / worst error, band holds | between them: mean / worst, "
          "band holds | all reported: band holds | standard reduction: mean / worst | chi2 per reading | time |")
    print("|---|---|---|---|---|---|---|---|")
    for psd_path in psds:
        folder = args.out / psd_path.stem
        names = [folder / f"{name}.csv" for name in ("hydrometer", "pipette", "buoyancy")]
        sheets, refused = [], []
        for path in (names if args.reuse_truth else synthesise(psd_path, folder)):
            try:
                sheets.append(read_sheet(path))
            except ValueError:    # a reading off the 152H's scale: no laboratory could read it, the others stand
                refused.append(path.stem)
        label = psd_path.stem + (f" (without the {', '.join(refused)}: off its scale)" if refused else "")
        start = time.perf_counter()
        result = invert(sheets, LabTest(0.060), folder / "runs", bins=args.bins)
        seconds = time.perf_counter() - start
        result.save(folder / "invert")
        truth_psd = read_psd(folder / "truth" / "simulated_psd.csv")
        truth = truth_psd.at(result.diameter)
        error = np.abs(result.percent - truth)
        held = (result.low - HELD_TOLERANCE <= truth) & (truth <= result.high + HELD_TOLERANCE)
        standard = np.abs(np.concatenate([r.percent - truth_psd.at(r.diameter) for r in result.reduction]))
        cells = []
        for part in (result.basis == "reading", result.basis == "between"):
            cells.append(f"{error[part].mean():.2f} / {error[part].max():.2f}, {held[part].mean():.0%}" if part.any() else "-")
        reported = ~np.isin(result.basis, ("floor", "top"))
        print(f"| {label} | {len(result.fit_rows)} | {cells[0]} | {cells[1]} | {held[reported].mean():.0%} of "
              f"{reported.sum()} | {standard.mean():.2f} / "
              f"{standard.max():.2f} | {result.reduced_chi2:.2f} | {seconds:.0f} s |", flush=True)


def fines_152h(psds: list[Path], args: argparse.Namespace) -> None:
    """The fines' 152H sheets alone: no sieve sheet, then a sieve sheet saying that 100 % passes 75 um."""
    print("| PSD | sheets | readings' cuts: mean / worst, held | all reported: held | coarsest cut: inverse [band] "
          "against truth | cuts whose band is under 3 points: worst error | band's top at 75 um | mean band width | "
          "chi2 | time |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for psd_path in psds:
        folder = args.out / psd_path.stem
        hydrometer = folder / "hydrometer.csv" if args.reuse_truth else synthesise(psd_path, folder)[0]
        passing = folder / "sieve_75um.csv"
        passing.write_text("opening_mm,percent_passing\n0.075,100\n")
        truth_psd = read_psd(folder / "truth" / "simulated_psd.csv")
        try:
            sheet = read_sheet(hydrometer)
        except ValueError as exc:    # a reading off the 152H's scale: no laboratory could read this test
            print(f"| {psd_path.stem} | 152H | refused: {exc} | | | | | | | |", flush=True)
            continue
        for label, sieve in (("152H", None), ("152H, 100 % passes 75 um", read_sheet(passing))):
            start = time.perf_counter()
            result = invert([sheet], LabTest(0.060), folder / "runs-152h", sieve=sieve, bins=args.bins)
            seconds = time.perf_counter() - start
            truth = truth_psd.at(result.diameter)
            error = np.abs(result.percent - truth)
            held = (result.low - HELD_TOLERANCE <= truth) & (truth <= result.high + HELD_TOLERANCE)
            cut, reported = result.basis == "reading", ~np.isin(result.basis, ("floor", "top"))
            k = np.flatnonzero(cut)[-1]
            top = np.interp(np.log(75e-6), np.log(result.diameter), result.high)
            narrow = cut & (result.high - result.low < 3.0)
            narrow_error = f"{error[narrow].max():.2f} of {narrow.sum()}" if narrow.any() else "none"
            print(f"| {psd_path.stem} | {label} | {error[cut].mean():.2f} / {error[cut].max():.2f}, {held[cut].mean():.0%} | "
                  f"{held[reported].mean():.0%} | {result.diameter[k] * 1e6:.1f} um: {result.percent[k]:.1f} "
                  f"[{result.low[k]:.1f}, {result.high[k]:.1f}] against {truth[k]:.1f} | {narrow_error} | {top:.1f} | "
                  f"{np.mean(result.high[reported] - result.low[reported]):.1f} | {result.reduced_chi2:.2f} | "
                  f"{seconds:.0f} s |", flush=True)


def soils(psds: list[Path], args: argparse.Namespace) -> None:
    """The soils' table: each with and without its sieve sheet."""
    print("| soil | sheets | readings' cuts: mean / worst, held | sieves: mean / worst, held | between: mean / worst, "
          "held | tails: held | coarsest cut: error, held | all reported: held | USDA clay / silt / sand error | "
          "class (draws) | chi2 | time |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for psd_path in psds:
        folder = args.out / psd_path.stem
        names = [folder / "hydrometer.csv", folder / "sieve.csv"]
        hydrometer, sieve = [read_sheet(p) for p in (names if args.reuse_truth else synthesise(psd_path, folder, True))]
        truth_psd = read_psd(folder / "truth" / "simulated_psd.csv")
        fine = np.geomspace(0.1e-6, 3e-3, 400)
        truth_fractions = texture.fractions(fine, truth_psd.at(fine), "USDA")
        for label, chosen in (("152H + sieves", sieve), ("152H", None)):
            start = time.perf_counter()
            result = invert([hydrometer], LabTest(SOIL_MASS), folder / "runs", sieve=chosen, bins=args.bins)
            seconds = time.perf_counter() - start
            result.save(folder / ("invert" if chosen is not None else "invert-no-sieve"))
            truth = truth_psd.at(result.diameter)
            error = np.abs(result.percent - truth)
            held = (result.low - HELD_TOLERANCE <= truth) & (truth <= result.high + HELD_TOLERANCE)
            reported = ~np.isin(result.basis, ("floor", "top"))
            cells = []
            for part in (result.basis == "reading", result.basis == "sieve", result.basis == "between"):
                cells.append(f"{error[part].mean():.2f} / {error[part].max():.2f}, {held[part].mean():.0%}"
                             if part.any() else "-")
            tails = np.isin(result.basis, ("coarse tail", "fine tail"))
            coarsest = np.flatnonzero(result.basis == "reading")[-1]
            got = texture.fractions(result.diameter, result.percent, "USDA")
            usda = " / ".join(f"{got[k] - truth_fractions[k]:+.2f}" for k in ("clay", "silt", "sand"))
            report = result.texture()
            print(f"| {psd_path.stem} | {label} | {cells[0]} | {cells[1]} | {cells[2]} | "
                  f"{held[tails].mean():.0%} of {tails.sum()} | {result.percent[coarsest] - truth[coarsest]:+.2f}, "
                  f"{'yes' if held[coarsest] else 'NO'} | {held[reported].mean():.0%} | {usda} | {report.usda_class_line()} | "
                  f"{result.reduced_chi2:.2f} | {seconds:.0f} s |", flush=True)


if __name__ == "__main__":
    main()
