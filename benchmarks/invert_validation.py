#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""`sediment invert` against known answers (docs/inverse.md): for each PSD, a laboratory's sheets are
synthesised from a rich forward run (50 000 parcels, Courant 1, its own seed) with realistic noise (the
152H read to 0.5 g/L at the D7928 times, the water drifting from 19 to 23 C over the day and recorded to
0.1 C, pipette samples at 10 cm weighed to 0.1 mg, the buoyancy sphere's balance to 1 mg at Bravo et
al.'s times, in the water of the moment), inverted, and the recovered PSD compared with the run's at the bin edges; the standard
reduction of the same sheets beside it.

    /usr/bin/python3 benchmarks/invert_validation.py [--out out/invert-validation] [PSD.csv ...]
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


def drift(time_s: np.ndarray) -> np.ndarray:
    """The day's water temperature [C]: 19 C at the start, 23 C after 24 h, linear."""
    return 19.0 + 4.0 * np.asarray(time_s) / 86400.0


def lab_to_run(times: np.ndarray) -> np.ndarray:
    """The time in the run's water (20 C) of the same fall as `times` under the drift."""
    from sediment import _core

    grid = np.linspace(0.0, float(np.max(times)), 4000)
    rate = _core.water_viscosity(REFERENCE_TEMPERATURE) / np.array([_core.water_viscosity(t) for t in drift(grid)])
    elapsed = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(grid))])
    return np.interp(times, grid, elapsed)


def synthesise(psd_path: Path, folder: Path) -> list[Path]:
    """The truth run and its three sheets."""
    water = Suspension.at_temperature(REFERENCE_TEMPERATURE)
    scene = plan(read_psd(psd_path), particles=50000, courant=1.0, seed=99, suspension=water, t_end=1.05 * 86400)
    write(scene, folder / "truth")
    run_batch(folder / "truth" / "in.sedimentation", {"overwrite": "yes"})
    column = Column.from_layers(read_layers(folder / "truth" / "layers.h5"))
    hydro = np.array(SCHEDULES["d7928"], float) * 60
    readings = Hydrometer.astm_152h().read(column, lab_to_run(hydro)).reading
    lines = ["time_min,reading,temperature_C"] + [
        f"{t / 60:g},{np.round(r / 0.5) * 0.5:g},{np.round(c, 1):g}" for t, r, c in zip(hydro, readings, drift(hydro))]
    (folder / "hydrometer.csv").write_text("\n".join(lines) + "\n")
    pipette_times = np.sort(Pipette(0.10).default_times(water))
    concentration = [Pipette(0.10).read(column, [t]).reading[0] for t in lab_to_run(pipette_times)]
    lines = ["time_min,depth_cm,mass_g,temperature_C"] + [
        f"{t / 60:.6g},10,{np.round(c * 0.025 * 1e4) / 1e4:.4f},{np.round(T, 1):g}"
        for t, c, T in zip(pipette_times, concentration, drift(pipette_times))]
    (folder / "pipette.csv").write_text("\n".join(lines) + "\n")
    sphere_times = np.array(SCHEDULES["bravo"], float) * 60
    # the balance reads the sphere in the water of the moment (its density at the drifted temperature)
    from sediment import _core
    sphere = BuoyancySphere(0.3 * scene.height)
    shift = np.array([_core.water_density(t) - water.fluid_density for t in drift(sphere_times)]) * sphere.volume * 1e3
    apparent = sphere.read(column, lab_to_run(sphere_times)).reading - shift
    lines = ["time_min,apparent_mass_g,temperature_C"] + [
        f"{t / 60:g},{np.round(a, 3):.3f},{np.round(T, 1):g}" for t, a, T in zip(sphere_times, apparent, drift(sphere_times))]
    (folder / "buoyancy.csv").write_text("\n".join(lines) + "\n")
    return [folder / name for name in ("hydrometer.csv", "pipette.csv", "buoyancy.csv")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("psds", type=Path, nargs="*", default=PSDS)
    parser.add_argument("--out", type=Path, default=Path("out/invert-validation"))
    parser.add_argument("--bins", type=int, default=24)
    args = parser.parse_args()
    print("| PSD | readings | inverse: mean / worst error | standard reduction: mean / worst error | chi2 per reading | time |")
    print("|---|---|---|---|---|---|")
    for psd_path in args.psds:
        folder = args.out / psd_path.stem
        sheets = [read_sheet(p) for p in synthesise(psd_path, folder)]
        start = time.perf_counter()
        result = invert(sheets, LabTest(), folder / "runs", bins=args.bins)
        seconds = time.perf_counter() - start
        result.save(folder / "invert")
        truth = read_psd(folder / "truth" / "simulated_psd.csv")
        error = np.abs(result.percent - truth.at(result.edges))
        standard = np.abs(np.concatenate([p - truth.at(d) for _, _, d, p in result.reduction]))
        print(f"| {psd_path.stem} | {len(result.fit_rows)} | {error.mean():.2f} / {error.max():.2f} | "
              f"{standard.mean():.2f} / {standard.max():.2f} | {result.reduced_chi2:.2f} | {seconds:.0f} s |", flush=True)


if __name__ == "__main__":
    main()
