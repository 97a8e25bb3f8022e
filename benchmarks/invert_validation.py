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

    /usr/bin/python3 benchmarks/invert_validation.py [--out out/invert-validation] [--reuse-truth] [PSD.csv ...]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.lab.inverse import LabTest, invert  # noqa: E402
from sediment.lab.psd import read_psd  # noqa: E402
from sediment.lab.readout import SCHEDULES, BuoyancySphere, Column, Hydrometer, Pipette, Suspension  # noqa: E402
from sediment.lab.sheet import read_sheet  # noqa: E402
from sediment.sim.layers import read_layers  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402
from sediment.sim.scene import plan, write  # noqa: E402

PSDS = [HERE.parent / "examples" / "granulometry" / "psd" / f"sample{k}.csv" for k in range(1, 6)] + \
       [HERE.parent / "examples" / "inverse" / "psd" / f"{name}.csv" for name in ("gap_graded", "bimodal", "narrow")]
REFERENCE_TEMPERATURE = 20.0
TRUTH_CLASSES = 200    # size ratio 1.03 per class for the samples' spans: finer than the inverse's bins


def drift(time_s: np.ndarray) -> np.ndarray:
    """The day's water temperature [C]: 19 C at the start, 23 C after 24 h, linear."""
    return 19.0 + 4.0 * np.asarray(time_s) / 86400.0


def synthesise(psd_path: Path, folder: Path) -> list[Path]:
    """The truth run and its three sheets."""
    water = Suspension.at_temperature(REFERENCE_TEMPERATURE)
    scene = plan(read_psd(psd_path), particles=50000, classes=TRUTH_CLASSES, courant=1.0, seed=99, suspension=water,
                 t_end=1.05 * 86400)
    # the run's water drifts as the laboratory's does: the inverse's mapping of the temperature record onto
    # one water is checked against a run in which the viscosity and density change with time
    scene.water_record = tuple((t, float(drift(t))) for t in (0.0, 1.05 * 86400))
    write(scene, folder / "truth")
    run_batch(folder / "truth" / "in.sedimentation", {"overwrite": "yes"})
    column = Column.from_layers(read_layers(folder / "truth" / "layers.h5"))
    hydro = np.array(SCHEDULES["d7928"], float) * 60
    readings = Hydrometer.astm_152h().read(column, hydro).reading
    lines = ["time_min,reading,temperature_C"] + [
        f"{t / 60:g},{np.round(r / 0.5) * 0.5:g},{np.round(c, 1):g}" for t, r, c in zip(hydro, readings, drift(hydro))]
    (folder / "hydrometer.csv").write_text("\n".join(lines) + "\n")
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
    parser.add_argument("psds", type=Path, nargs="*", default=PSDS)
    parser.add_argument("--out", type=Path, default=Path("out/invert-validation"))
    parser.add_argument("--bins", type=int, default=24)
    parser.add_argument("--reuse-truth", action="store_true",
                        help="invert the sheets an earlier run of this script left in --out (no new truth runs)")
    args = parser.parse_args()
    print("| PSD | readings | at the readings' diameters: mean / worst error, band holds | between them: mean / worst, "
          "band holds | standard reduction: mean / worst | chi2 per reading | time |")
    print("|---|---|---|---|---|---|---|")
    for psd_path in args.psds:
        folder = args.out / psd_path.stem
        names = [folder / f"{name}.csv" for name in ("hydrometer", "pipette", "buoyancy")]
        sheets = [read_sheet(p) for p in (names if args.reuse_truth else synthesise(psd_path, folder))]
        start = time.perf_counter()
        result = invert(sheets, LabTest(), folder / "runs", bins=args.bins)
        seconds = time.perf_counter() - start
        result.save(folder / "invert")
        truth_psd = read_psd(folder / "truth" / "simulated_psd.csv")
        truth = truth_psd.at(result.edges)
        error = np.abs(result.percent - truth)
        held = (result.low <= truth) & (truth <= result.high)
        standard = np.abs(np.concatenate([p - truth_psd.at(d) for _, _, d, p in result.reduction]))
        cells = []
        for part in (result.measured, ~result.measured):
            cells.append(f"{error[part].mean():.2f} / {error[part].max():.2f}, {held[part].mean():.0%}" if part.any() else "-")
        print(f"| {psd_path.stem} | {len(result.fit_rows)} | {cells[0]} | {cells[1]} | {standard.mean():.2f} / "
              f"{standard.max():.2f} | {result.reduced_chi2:.2f} | {seconds:.0f} s |", flush=True)


if __name__ == "__main__":
    main()
