# SPDX-License-Identifier: GPL-2.0-or-later
"""68 steel balls poured from a funnel into paste backfill (Zhang & Li 2024, case E).

Each run places the balls at random in the funnel (random sequential addition, one seed per run),
runs examples/paste/in.funnel, and reads the final positions. A study of many runs gives the vertical
distribution of the balls and, on horizontal planes every centimetre, the probability that a point
of the plane lies inside a ball.
"""
from __future__ import annotations

import math
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import figures
from ..results import Table, write_text
from ..sim.run import run_batch
from .paste import EXAMPLES, PASTE

BALLS = 68
DIAMETER = 0.0126
MOULD_RADIUS = 0.0375
# Funnel of in.funnel: a cone from radius 25 mm at the outlet (z = 0.300) to 60 mm at z = 0.360.
OUTLET_HEIGHT, OUTLET_RADIUS, CONE_HEIGHT, TOP_RADIUS = 0.300, 0.025, 0.060, 0.060


def random_packing(seed: int, balls: int = BALLS, diameter: float = DIAMETER, max_tries: int = 200_000) -> np.ndarray:
    """Centres of `balls` non-overlapping spheres at random inside the closed funnel (random sequential
    addition: uniform candidates, kept when clear of the cone, the plug and the balls kept so far)."""
    rng = np.random.default_rng(seed)
    r = diameter / 2
    slope = (TOP_RADIUS - OUTLET_RADIUS) / CONE_HEIGHT
    clearance = r * math.sqrt(1 + slope * slope)    # radial offset that keeps a ball clear of the cone
    centres = np.empty((0, 3))
    for _ in range(max_tries):
        z = rng.uniform(OUTLET_HEIGHT + r, OUTLET_HEIGHT + CONE_HEIGHT - r)
        reach = OUTLET_RADIUS + slope * (z - OUTLET_HEIGHT) - clearance
        if reach <= 0:
            continue
        rho, phi = reach * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
        candidate = np.array([rho * math.cos(phi), rho * math.sin(phi), z])
        if len(centres) and np.min(np.sum((centres - candidate) ** 2, axis=1)) < diameter**2:
            continue
        centres = np.vstack([centres, candidate])
        if len(centres) == balls:
            return centres
    raise RuntimeError(f"placed only {len(centres)} of {balls} balls in the funnel after {max_tries} tries")


def write_packing(centres: np.ndarray, path: Path) -> None:
    """Writes the ball centres as create_atoms commands for in.funnel."""
    lines = [f"# {len(centres)} balls at random in the funnel"]
    lines += [f"create_atoms 1 single {x:.9g} {y:.9g} {z:.9g}" for x, y, z in centres]
    path.write_text("\n".join(lines) + "\n")


@dataclass
class Pour:
    """One pour of the 68 balls and where they ended."""

    seed: int
    placed: int
    balls: int               # in the mould at the end
    spilled: int             # bounced over the brim (removed once below it, outside the mould)
    positions: np.ndarray    # final centres of the balls in the mould [m]
    max_speed: float
    pour_time: float
    wall_seconds: float


def pour(seed: int, dt: float = 1e-6, settle: float = 0.4) -> Pour:
    """One run of in.funnel from the random packing of `seed`."""
    with tempfile.TemporaryDirectory() as tmp:
        packing, dump = Path(tmp) / "packing.lmp", Path(tmp) / "final.dump"
        write_packing(random_packing(seed), packing)
        out = run_batch(EXAMPLES / "in.funnel", {"packing": packing, "out": dump, "dt": dt, "settle": settle})
        positions = np.loadtxt(dump, skiprows=9, ndmin=2)[:, 1:4]
    r = out.results
    return Pour(seed, int(r["placed"]), int(r["balls"]), int(r["spilled"]), positions, r["max_speed"],
                r["pour_time"], out.wall_seconds)


@dataclass
class FunnelStudy:
    """Several pours of case E, one per random packing in the funnel."""

    pours: list[Pour]

    def table(self) -> Table:
        """Per pour: balls in the mould, spilled, depth range of the centres, pour and wall time."""
        table = Table(["seed", "placed", "in mould", "spilled", "shallowest [mm]", "deepest [mm]", "pour [s]",
                       "wall [s]"])
        for p in self.pours:
            depth = PASTE["surface"] - p.positions[:, 2]
            table.add(p.seed, p.placed, p.balls, p.spilled, f"{depth.min() * 1e3:.1f}", f"{depth.max() * 1e3:.1f}",
                      f"{p.pour_time:.3f}", f"{p.wall_seconds:.1f}")
        depths = np.concatenate([PASTE["surface"] - p.positions[:, 2] for p in self.pours])
        table.notes.append(f"all runs: centres {depths.min() * 1e3:.1f} to {depths.max() * 1e3:.1f} mm below the "
                           f"surface, {sum(p.spilled for p in self.pours)} spilled")
        return table

    def save(self, folder: Path) -> list[Path]:
        """funnel_positions.csv (every ball of every pour), funnel_positions.png, funnel_presence.png."""
        folder = Path(folder)
        positions = Table(["seed", "ball", "x_m", "y_m", "z_m", "depth_below_surface_m"])
        for p in self.pours:
            for i, (x, y, z) in enumerate(p.positions, start=1):
                positions.add(p.seed, i, x, y, z, PASTE["surface"] - z)
        return [write_text(folder / "funnel_positions.csv", positions.csv()),
                plot_positions(self.pours, folder / "funnel_positions.png"),
                plot_presence(self.pours, folder / "funnel_presence.png")]


def funnel_study(runs: int = 15, jobs: int = 2, dt: float = 1e-6, progress: bool = True) -> FunnelStudy:
    """`runs` pours with seeds 1..runs, `jobs` at a time."""
    from tqdm import tqdm

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return FunnelStudy(list(tqdm(pool.map(lambda s: pour(s, dt), range(1, runs + 1)), total=runs, desc="pours",
                                     unit="run", disable=not progress)))


def presence_probability(pours: list[Pour], plane: float, cell: float = 0.0025) -> tuple[np.ndarray, np.ndarray]:
    """Probability, over the runs, that the point of cell centre (x, y) on the plane z = `plane` lies
    inside a ball; cells outside the mould are NaN. Returns (cell centres along x and y, probability)."""
    edges = np.arange(-MOULD_RADIUS, MOULD_RADIUS + cell / 2, cell)
    centres = 0.5 * (edges[1:] + edges[:-1])
    gx, gy = np.meshgrid(centres, centres, indexing="ij")
    hits = np.zeros(gx.shape)
    r = DIAMETER / 2
    for p in pours:
        inside = np.zeros(gx.shape, dtype=bool)
        for x, y, z in p.positions:
            if abs(z - plane) < r:
                section = r * r - (z - plane) ** 2    # squared radius of the ball's cut by the plane
                inside |= (gx - x) ** 2 + (gy - y) ** 2 <= section
        hits += inside
    probability = hits / len(pours)
    probability[gx**2 + gy**2 > MOULD_RADIUS**2] = np.nan
    return centres, probability


def plot_positions(pours: list[Pour], path: Path) -> Path:
    """Vertical distribution of the final centres over every pour."""
    plt = figures.pyplot()

    depth = np.concatenate([PASTE["surface"] - p.positions[:, 2] for p in pours]) * 1e3
    fig, (side, hist) = plt.subplots(1, 2, figsize=(10, 4.5), gridspec_kw={"width_ratios": [1, 1.2]})
    for p in pours:
        side.scatter(p.positions[:, 0] * 1e3, (PASTE["surface"] - p.positions[:, 2]) * 1e3, s=6, alpha=0.5)
    side.axvline(-MOULD_RADIUS * 1e3, color="k")
    side.axvline(MOULD_RADIUS * 1e3, color="k")
    side.set(xlabel="x [mm]", ylabel="depth of the centre below the paste surface [mm]",
             title=f"Final positions, {len(pours)} runs", xlim=(-45, 45))
    side.invert_yaxis()
    bins = np.arange(np.floor(depth.min() / 5) * 5, depth.max() + 5, 5)
    hist.hist(depth, bins=bins, weights=np.full(depth.size, 1 / len(pours)), orientation="horizontal",
              color="C1", edgecolor="k")
    hist.set(xlabel="balls per run", ylabel="depth of the centre [mm]",
             title=f"Vertical distribution: {depth.min():.0f} to {depth.max():.0f} mm")
    hist.invert_yaxis()
    return figures.save(fig, path)


def plot_presence(pours: list[Pour], path: Path, spacing: float = 0.01) -> Path:
    """Probability of presence per cell on horizontal planes `spacing` apart (the paper's figure 22)."""
    plt = figures.pyplot()

    tops = [PASTE["surface"] - p.positions[:, 2].max() for p in pours]
    bottoms = [PASTE["surface"] - p.positions[:, 2].min() for p in pours]
    depths = np.arange(max(0.0, np.floor(min(tops) / spacing) * spacing),
                       max(bottoms) + DIAMETER / 2, spacing)
    cols = min(4, len(depths))
    rows = math.ceil(len(depths) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3 * cols, 2.9 * rows), squeeze=False)
    for ax, depth in zip(axes.flat, depths):
        centres, prob = presence_probability(pours, PASTE["surface"] - depth)
        extent = np.array([centres[0], centres[-1], centres[0], centres[-1]]) * 1e3
        image = ax.imshow(prob.T, origin="lower", extent=extent, vmin=0, vmax=1, cmap="viridis")
        ax.set_title(f"{depth * 1e3:.0f} mm below the surface", fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes.flat[len(depths):]:
        ax.axis("off")
    fig.colorbar(image, ax=axes, shrink=0.6, label="probability of presence")
    fig.suptitle(f"Balls on horizontal planes every {spacing * 1e3:.0f} mm ({len(pours)} runs)")
    return figures.save(fig, path, dpi=110, tight=False)
