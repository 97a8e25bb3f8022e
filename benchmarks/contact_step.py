# SPDX-License-Identifier: GPL-2.0-or-later
"""What the contact time step costs and changes: a small bed of 320 quartz grains settling in water
onto a floor with Hertz contacts (tests/decks/soft_bed.lmp), coarse (60-100 um) and scaled down
tenfold (6-10 um, where the drag overdamps a contact), at the contact modulus `sediment sample
--contacts` would choose, for several steps.

    /usr/bin/python3 benchmarks/contact_step.py [--jobs 2]

Steps: a tenth and a fifth (the rule of `sediment sample`) of the smallest grain's Rayleigh time,
and fractions of the bed's stability bound: the largest stable step of the drag-implicit step for
a grain pressed by a Hertz spring (sediment._core.spring_step_limit) whose stiffness is that of the
contact between two smallest grains at the tolerated overlap, times 12 (Gershgorin's bound on the
stiffness of a grain with 12 neighbours, each contact counted on both grains). Each bed is
compared with the one at a tenth of the Rayleigh time: mean height (volume-weighted centre height
over the mean diameter) and packing fraction below twice it, the largest overlap during the run and
at its end (the settled bed).
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment import _core  # noqa: E402
from sediment.cli.types import count  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402
from sediment.sim.scene import OVERLAP_TOLERANCE, POISSON_RATIO, contact_modulus  # noqa: E402

DECK = HERE.parent / "tests" / "decks" / "soft_bed.lmp"
RHO_P, RHO_F, MU, G = 2650.0, 1000.0, 1e-3, 9.81
BEDS = {"coarse": (1.0, 0.5), "fine": (0.1, 5.0)}    # length scale, simulated time [s] (settling takes 1/scale)
STEPS = ("rayleigh/10", "rayleigh/5", "0.5 bound", "bound")


def modulus(scale: float) -> float:
    """The contact modulus `sediment sample --contacts` would choose for this bed."""
    d_max, d_mean = 100e-6 * scale, 80e-6 * scale
    v = float(_core.terminal_velocity("dallavalle", RHO_F, MU, 0.0, d_max, RHO_P, G)[0])
    solid_height = 320 * math.pi / 6 * d_mean ** 3 / (1e-3 * scale) ** 2
    return contact_modulus(RHO_P, v, solid_height * (RHO_P - RHO_F) * G)


def time_step(step: str, scale: float, youngs: float) -> float:
    d = 60e-6 * scale
    if step.startswith("rayleigh"):
        return _core.rayleigh_time(d / 2, RHO_P, youngs, POISSON_RATIO) / int(step.split("/")[1])
    omega = math.sqrt(12) * _core.hertz_contact_frequency("pair", d, RHO_P, youngs, POISSON_RATIO, OVERLAP_TOLERANCE)
    rate = 1.0 / _core.relaxation_time("dallavalle", RHO_F, MU, d, RHO_P)
    return (0.5 if step == "0.5 bound" else 1.0) * _core.spring_step_limit(omega, rate)


def settle(bed: str, step: str, folder: Path) -> dict:
    scale, t_end = BEDS[bed]
    youngs = modulus(scale)
    dt = time_step(step, scale, youngs)
    final = folder / f"{bed}-{step.replace('/', '_').replace(' ', '_')}.txt"
    start = time.perf_counter()
    out = run_batch(DECK, {"E": youngs, "dt": dt, "t_end": t_end, "every": 100, "final": final, "scale": scale},
                    cwd=folder, check=False)
    wall = time.perf_counter() - start
    row = {"bed": bed, "step": step, "E": youngs, "dt": dt, "steps": round(t_end / dt), "wall": wall}
    if out.returncode != 0:
        return {**row, "failed": out.error or f"exit {out.returncode}"}
    grains = np.loadtxt(final, skiprows=9)
    volume = np.pi / 6 * grains[:, 4] ** 3
    height = float(np.sum(volume * grains[:, 3]) / volume.sum())
    return {**row, "overlap": float(out.samples[:, 1].max()), "settled": float(out.samples[-1, 1]),
            "height": height / (80e-6 * scale),
            "packing": float(volume.sum() / ((1e-3 * scale) ** 2 * 2 * height))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--jobs", type=count, default=2)
    args = parser.parse_args()
    runs = [(bed, step) for bed in BEDS for step in STEPS]
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(max_workers=args.jobs) as pool:
        rows = list(pool.map(lambda run: settle(*run, Path(tmp)), runs))
    print(f"{'bed':7s} {'step':12s} {'dt [s]':>9s} {'steps':>8s} {'wall [s]':>8s} {'overlap':>8s} {'settled':>8s} "
          f"{'height/d':>9s} {'packing':>8s}  against rayleigh/10")
    for row in rows:
        reference = next(r for r in rows if r["bed"] == row["bed"] and r["step"] == "rayleigh/10")
        head = f"{row['bed']:7s} {row['step']:12s} {row['dt']:9.3g} {row['steps']:8d} {row['wall']:8.1f}"
        if "failed" in row:
            print(f"{head}  failed: {row['failed']}")
            continue
        change = (f"height {row['height'] / reference['height'] - 1:+.1%}, packing "
                  f"{row['packing'] / reference['packing'] - 1:+.1%}") if "height" in reference else ""
        print(f"{head} {row['overlap']:8.2%} {row['settled']:8.2%} {row['height']:9.4f} {row['packing']:8.4f}  {change}")


if __name__ == "__main__":
    main()
