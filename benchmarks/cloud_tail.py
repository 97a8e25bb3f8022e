# SPDX-License-Identifier: GPL-2.0-or-later
"""A falling cloud's long fall under fix fluid/flow, against what Nitsche & Batchelor (1997) and Metzger,
Nicolas & Guazzelli (2007) describe: the cloud keeps its shape for a while, then leaks spheres from its
rear into a vertical tail on its axis, and flattens as it empties its centre on the way to a torus.

    /usr/bin/python3 benchmarks/cloud_tail.py [--cells 32,48] [--steps 2400] [--every 50]

examples/falling_cloud (1000 spheres, N a / R = 10, R = 6 mm, box 8 R across and 48 R tall, drift 0.1),
on a grid of N cells across (R / sigma = N / 8). Per dump: the fall in R, the spheres lost (further than
1.5 R from the cloud's centre), the share of the cloud's spheres within 0.35 R of its vertical axis (a
uniform sphere: 0.178; a torus: less), the rms height over the rms horizontal spread per axis (a sphere:
1; flattened: less); at the end, where the lost spheres are. The cloud starts 4 R under the box's top
and the table stops before it reaches its own tail through the periodic bottom.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
sys.path.insert(0, str(HERE.parent / "tests" / "decks"))
from harness import read_dump_frames  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402

CLOUD = HERE.parent / "examples" / "falling_cloud" / "in.falling_cloud"
R, BOX_R, TALL = 6e-3, 8, 6
LOST = 1.5    # R: further than this from the cloud's centre, a sphere has left it
UNIFORM_CORE = 1.0 - (1.0 - 0.35 ** 2) ** 1.5


def offsets(x: np.ndarray, centre: np.ndarray, period: np.ndarray) -> np.ndarray:
    d = x - centre
    return d - period * np.round(d / period)


def measure(path: Path, every: int) -> list[tuple]:
    period = np.array([BOX_R * R, BOX_R * R, TALL * BOX_R * R])
    rows, centre, fallen = [], None, 0.0
    for step, frame in sorted(read_dump_frames(path).items()):
        x = frame[np.argsort(frame[:, 0]), 1:]    # positions by id
        guess = np.array([period[0] / 2, period[1] / 2, period[2] - BOX_R * R / 2]) if centre is None else centre
        for _ in range(30):    # the centre of the spheres within LOST R of it
            d = offsets(x, guess, period)
            guess = guess + d[np.linalg.norm(d, axis=1) < LOST * R].mean(axis=0)
        if centre is not None:
            fallen -= offsets(guess[2:], centre[2:], period[2:])[0]
        centre = guess
        d = offsets(x, centre, period)
        inside = np.linalg.norm(d, axis=1) < LOST * R
        across = np.hypot(d[inside, 0], d[inside, 1])
        shape = np.sqrt(np.mean(d[inside, 2] ** 2) / (np.mean(across ** 2) / 2))
        rows.append((step, fallen / R, 1 - inside.mean(), np.mean(across < 0.35 * R), shape, d[~inside]))
        if fallen > (TALL - 1) * BOX_R * R - 2 * R:    # its own tail ahead, through the periodic bottom
            break
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cells", default="32,48", help="grid cells across the box (multiples of 8)")
    parser.add_argument("--steps", type=int, default=2400)
    parser.add_argument("--every", type=int, default=50, help="steps between dumps")
    args = parser.parse_args(argv)
    for cells in [int(c) for c in args.cells.split(",")]:
        with tempfile.TemporaryDirectory() as tmp:
            run_batch(CLOUD, {"cells": cells, "tall": TALL, "steps": args.steps, "solve": "drift 0.1",
                              "dump": args.every}, ranks=1, cwd=Path(tmp))
            rows = measure(Path(tmp) / "cloud.dump", args.every)
        print(f"\n{cells} cells across (R / sigma = {cells / BOX_R:g})")
        print("  step  fallen/R  lost  within 0.35 R of the axis (sphere %.3f)  height/spread" % UNIFORM_CORE)
        for step, fallen, lost, core, shape, _ in rows[::4] + ([rows[-1]] if (len(rows) - 1) % 4 else []):
            print(f"{step:6d} {fallen:8.2f} {lost:6.3f} {core:8.3f} {shape:8.3f}")
        tail = rows[-1][5]
        if len(tail):
            across = np.hypot(tail[:, 0], tail[:, 1]) / R
            print(f"  the {len(tail)} lost: {np.mean(across < 0.5):.0%} within 0.5 R of the axis, "
                  f"{np.mean(tail[:, 2] > 0):.0%} above the cloud, median {np.median(tail[:, 2]) / R:.1f} R above")
    return 0


if __name__ == "__main__":
    sys.exit(main())
