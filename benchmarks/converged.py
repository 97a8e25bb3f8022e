#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Does a plan's decision hold against the converged answer? Runs the decided deck of a plan (its
report.json) and three independent runs of the reference physics at more parcels and Courant 1 (seeds
of their own), and prints the decision's largest difference of a reading from each, per instrument,
with the spread of the converged runs among themselves (docs/effects.md section 3).

    /usr/bin/python3 benchmarks/converged.py out/plan/sample2/report.json --particles 50000
"""
from __future__ import annotations

import argparse
import itertools
import json
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.lab.granulometry import read_all  # noqa: E402
from sediment.lab.psd import read_psd  # noqa: E402
from sediment.lab.readout import Column, Suspension  # noqa: E402
from sediment.planner.scenes import SampleScene  # noqa: E402
from sediment.sim.layers import read_layers  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402
from sediment.sim.scene import Cylinder, Effects, plan  # noqa: E402
from sediment.sim.scenefiles import write  # noqa: E402

INSTRUMENTS = ["hydrometer", "buoyancy", "pipette"]


def readings(folder: Path) -> dict:
    """Each instrument's (times, percent finer) of the run in `folder`."""
    found, _ = read_all(Column.from_layers(read_layers(folder / "layers.h5")), INSTRUMENTS)
    return {r.instrument: (r.time, r.percent_finer) for r in found}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("report", type=Path, help="report.json of `sediment plan` for a sedimentation test")
    parser.add_argument("psd", type=Path, help="the PSD the plan was made for")
    parser.add_argument("--particles", type=int, default=50000, help="parcels of the converged runs")
    parser.add_argument("--seeds", type=int, nargs="+", default=[7, 11, 13])
    args = parser.parse_args()
    report = json.loads(args.report.read_text())
    decided = args.report.parent / "decision"
    run_batch(decided / "in.sedimentation", {"overwrite": "yes"})
    decision = readings(decided)
    options = report["scene_options"]
    reference = report["reference"]["settings"]
    water = Suspension.at_temperature(options.get("temperature") or 20.0, options["particle_density"])
    with tempfile.TemporaryDirectory() as tmp:
        def converged(seed: int) -> dict:
            scene = plan(read_psd(args.psd), cylinder=Cylinder(options["cylinder_area"], options["height"]),
                         mass=options["mass"], suspension=water, particles=args.particles, courant=1.0, seed=seed,
                         effects=Effects(reference["drag"], hindrance=reference["hindrance"]),
                         **{k: options[k] for k in ("geometry", "width", "classes", "layers", "t_end")})
            folder = Path(tmp) / f"seed{seed}"
            write(scene, folder)
            run_batch(folder / "in.sedimentation")
            return readings(folder)
        with ThreadPoolExecutor(max_workers=2) as pool:
            runs = dict(zip(args.seeds, pool.map(converged, args.seeds)))
    print(f"decision: {report['command']} (plan's error {report['decision']['error']:.3g} pp, tolerance "
          f"{report['tolerance']:g})")
    for seed, run in runs.items():
        diff = SampleScene.error(decision, run)
        print(f"against {args.particles} parcels, Courant 1, seed {seed}: "
              + ", ".join(f"{n} {v:.3g}" for n, v in diff.items()) + f" pp (max {max(diff.values()):.3g})")
    for a, b in itertools.combinations(args.seeds, 2):
        diff = SampleScene.error(runs[a], runs[b])
        print(f"converged runs {a} against {b}: max {max(diff.values()):.3g} pp")


if __name__ == "__main__":
    main()
