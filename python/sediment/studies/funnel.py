# SPDX-License-Identifier: GPL-2.0-or-later
"""68 steel balls poured from a funnel into paste backfill (Zhang & Li 2024, case E).

Each run places the balls at random in the funnel (random sequential addition, one seed per run),
runs examples/paste/in.funnel, and reads the final positions. A study of many runs gives the vertical
distribution of the balls and, on horizontal planes every centimetre, the probability that a point
of the plane lies inside a ball. Any variable of the deck can be set for a study (a variant: the
funnel's stem and fall, the paste's surface model, the contacts); `compare` sets variants side by side.
"""
from __future__ import annotations

import hashlib
import io
import json
import math
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import figures
from ..progress import bar as progress_bar
from ..results import Table, write_text
from ..sim.deck import index_variables
from ..sim.process import finished_in_turn
from ..sim.run import run_batch
from .paste import EXAMPLES, PASTE, PLASTIC_VISCOSITY

BALLS = 68
DIAMETER = 0.0126
MOULD_RADIUS = 0.0375
# The cone of in.funnel: radius 25 mm at its outlet, 60 mm at 60 mm higher.
OUTLET_RADIUS, CONE_HEIGHT, TOP_RADIUS = 0.025, 0.060, 0.060


@dataclass(frozen=True)
class Funnel:
    """Where in.funnel's funnel stands: a stem of length `stem` under the cone, its exit `fall` above
    the paste surface at height `surface` (the deck variables of the same names) [m]."""

    stem: float
    fall: float
    surface: float

    @classmethod
    def of(cls, settings: dict[str, str] | None = None) -> Funnel:
        """The funnel of a run of in.funnel with these deck variables (the deck's defaults otherwise)."""
        values = {**index_variables(EXAMPLES / "in.funnel"), **(settings or {})}
        try:
            funnel = cls(**{k: float(values[k]) for k in ("stem", "fall", "surface")})
        except ValueError as bad:
            raise ValueError(f"stem, fall and surface are lengths in metres: {bad}") from None
        if funnel.stem < 0 or funnel.fall <= 0 or not 0 < funnel.surface <= PASTE["surface"]:
            raise ValueError(f"the stem must be >= 0 m, the fall > 0 m and the paste surface in the mould (0 to "
                             f"{PASTE['surface']} m), got stem {funnel.stem}, fall {funnel.fall}, surface "
                             f"{funnel.surface}")
        return funnel

    @property
    def outlet_height(self) -> float:
        """Height of the cone's outlet (the top of the stem) [m]."""
        return self.surface + self.fall + self.stem


def random_packing(seed: int, balls: int = BALLS, diameter: float = DIAMETER, max_tries: int = 200_000,
                   funnel: Funnel | None = None) -> np.ndarray:
    """Centres of `balls` non-overlapping spheres at random inside the funnel's cone (random sequential
    addition: uniform candidates, kept when clear of the cone, its outlet and the balls kept so far)."""
    rng = np.random.default_rng(seed)
    r = diameter / 2
    slope = (TOP_RADIUS - OUTLET_RADIUS) / CONE_HEIGHT
    clearance = r * math.sqrt(1 + slope * slope)    # radial offset that keeps a ball clear of the cone
    outlet = (funnel or Funnel.of()).outlet_height
    centres = np.empty((0, 3))
    for _ in range(max_tries):
        z = rng.uniform(outlet + r, outlet + CONE_HEIGHT - r)
        reach = OUTLET_RADIUS + slope * (z - outlet) - clearance
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
    surface: float           # final paste level [m] (above the filling level if the balls displace paste)
    max_speed: float
    pour_time: float
    wall_seconds: float

    def depths(self) -> np.ndarray:
        """Depth of each ball's centre below the final paste level [m]."""
        return self.surface - self.positions[:, 2]


# Deck variables a study sets itself, and those its packing and readouts assume (case E's balls).
OWN_VARIABLES = ("packing", "out", "dt", "settle")
FIXED_VARIABLES = ("d", "balls")


def check_settings(settings: dict[str, str]) -> Funnel:
    """Refuses a variable in.funnel (and what it includes) does not declare, one the study sets itself,
    or a funnel that cannot stand; returns the funnel."""
    if clash := sorted(set(settings) & set(OWN_VARIABLES)):
        raise ValueError(f"the study sets {', '.join(clash)} itself")
    if fixed := sorted(set(settings) & set(FIXED_VARIABLES)):
        raise ValueError(f"the study is case E's {BALLS} balls of {DIAMETER * 1e3} mm: {', '.join(fixed)} cannot be set "
                         "(run examples/paste/in.funnel directly with a packing of your own)")
    if unknown := sorted(set(settings) - set(index_variables(EXAMPLES / "in.funnel"))):
        raise ValueError(f"in.funnel has no variable {', '.join(unknown)} (see its 'variable NAME index' lines and "
                         "those of steel.lmp and mould.lmp)")
    return Funnel.of(settings)


def pour(seed: int, dt: float = 1e-6, settle: float = 0.4, settings: dict[str, str] | None = None) -> Pour:
    """One run of in.funnel from the random packing of `seed`, with deck variables `settings`."""
    settings = dict(settings or {})
    funnel = check_settings(settings)
    with tempfile.TemporaryDirectory() as tmp:
        packing, dump = Path(tmp) / "packing.lmp", Path(tmp) / "final.dump"
        write_packing(random_packing(seed, funnel=funnel), packing)
        out = run_batch(EXAMPLES / "in.funnel", {**settings, "packing": packing, "out": dump, "dt": dt,
                                                 "settle": settle})
        positions = np.loadtxt(dump, skiprows=9, ndmin=2)[:, 1:4]
    r = out.results
    return Pour(seed, int(r["placed"]), int(r["balls"]), int(r["spilled"]), positions, r["level"], r["max_speed"],
                r["pour_time"], out.wall_seconds)


@dataclass
class Summary:
    """What the paper reports of a set of pours: every ball inside the paste, none at the surface, none
    lost, and the band of depths."""

    runs: int
    balls: int               # in the mould at the end, over every run
    spilled: int             # bounced over the brim, over every run
    centre_above: int        # balls whose centre is above the paste surface
    top_above: int           # balls not wholly inside the paste (their top above the surface)
    depth_mm: dict[str, float]    # of the centres below the surface: min, p10, median, p90, max

    def row(self) -> list[str]:
        """The summary as the cells of SUMMARY_COLUMNS."""
        d = self.depth_mm
        return [str(self.runs), str(self.spilled), str(self.centre_above), str(self.top_above),
                f"{d['min']:.1f}", f"{d['p10']:.1f}", f"{d['median']:.1f}", f"{d['p90']:.1f}", f"{d['max']:.1f}"]


SUMMARY_COLUMNS = ["runs", "spilled", "centre above surface", "top above surface", "shallowest [mm]", "p10 [mm]",
                   "median [mm]", "p90 [mm]", "deepest [mm]"]


@dataclass
class FunnelStudy:
    """Several pours of case E, one per random packing in the funnel, with the same deck variables."""

    pours: list[Pour]
    settings: dict[str, str]
    dt: float

    def depths(self) -> np.ndarray:
        """Depth of every ball's centre below the final paste level of its pour, over every pour [m]."""
        return np.concatenate([p.depths() for p in self.pours])

    def summary(self) -> Summary:
        """Spills, balls at the surface and the band of depths over every pour."""
        depth = self.depths()
        if depth.size == 0:    # every ball spilled: no depths to report
            depth = np.array([math.nan])
        p10, median, p90 = np.percentile(depth, [10, 50, 90]) * 1e3
        return Summary(len(self.pours), sum(p.balls for p in self.pours), sum(p.spilled for p in self.pours),
                       int(np.sum(depth < 0)),
                       int(np.sum(depth < DIAMETER / 2)),
                       {"min": depth.min() * 1e3, "p10": p10, "median": median, "p90": p90, "max": depth.max() * 1e3})

    def table(self) -> Table:
        """Per pour: balls in the mould, spilled, depth range of the centres, pour and wall time."""
        table = Table(["seed", "placed", "in mould", "spilled", "shallowest [mm]", "deepest [mm]", "pour [s]",
                       "wall [s]"])
        for p in self.pours:
            depth = p.depths()
            table.add(p.seed, p.placed, p.balls, p.spilled, f"{depth.min() * 1e3:.1f}", f"{depth.max() * 1e3:.1f}",
                      f"{p.pour_time:.3f}", f"{p.wall_seconds:.1f}")
        s = self.summary()
        table.notes.append(f"time step {self.dt:g} s; deck variables: " + self.settings_text())
        table.notes.append(f"all runs: {s.balls} balls in the mould, {s.spilled} spilled; {s.centre_above} with the "
                           f"centre and {s.top_above} with the top above the surface; centres {s.depth_mm['min']:.1f} "
                           f"to {s.depth_mm['max']:.1f} mm below the surface (median {s.depth_mm['median']:.1f})")
        return table

    def settings_text(self) -> str:
        """The deck variables as NAME=VALUE words."""
        return " ".join(f"{k}={v}" for k, v in self.settings.items()) or "(the deck's defaults)"

    def save(self, folder: Path) -> list[Path]:
        """funnel_positions.csv (every ball of every pour), funnel_summary.json, funnel_positions.png,
        funnel_presence.png."""
        folder = Path(folder)
        positions = Table(["seed", "ball", "x_m", "y_m", "z_m", "depth_below_surface_m"])
        for p in self.pours:
            for i, (x, y, z) in enumerate(p.positions, start=1):
                positions.add(p.seed, i, x, y, z, p.surface - z)
        text = positions.csv()
        # The positions' digest ties the two files together: a study killed between them is refused later.
        summary = {"settings": self.settings, "dt": self.dt, "seeds": [p.seed for p in self.pours],
                   "spilled_per_run": [p.spilled for p in self.pours], "positions_sha256": _digest(text),
                   **self.summary().__dict__}
        return [write_text(folder / "funnel_positions.csv", text),
                write_text(folder / "funnel_summary.json", json.dumps(summary, indent=1) + "\n"),
                plot_positions(self.pours, folder / "funnel_positions.png"),
                plot_presence(self.pours, folder / "funnel_presence.png")]

    @classmethod
    def load(cls, folder: Path) -> FunnelStudy:
        """The study saved in `folder` (its summary and positions; loop times are not kept)."""
        folder = Path(folder)
        try:
            meta = json.loads((folder / "funnel_summary.json").read_text())
            settings, dt, seeds, spills = meta["settings"], float(meta["dt"]), meta["seeds"], meta["spilled_per_run"]
            text = (folder / "funnel_positions.csv").read_text()
            rows = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1, ndmin=2)
            digest = meta["positions_sha256"]
        except (OSError, ValueError, KeyError, TypeError) as bad:
            raise ValueError(f"{folder}: not a saved funnel study ({bad})") from None
        if _digest(text) != digest:
            raise ValueError(f"{folder}: funnel_positions.csv is not the one funnel_summary.json was saved with "
                             "(an interrupted or mixed save); run the study again")
        pours = []
        for seed, spilled in zip(seeds, spills):
            mine = rows[rows[:, 0] == seed]
            surface = float(np.mean(mine[:, 4] + mine[:, 5])) if len(mine) else math.nan
            pours.append(Pour(seed, BALLS, len(mine), spilled, mine[:, 2:5], surface, math.nan, math.nan, math.nan))
        return cls(pours, settings, dt)


def funnel_study(runs: int = 15, jobs: int = 2, dt: float = 1e-6, settings: dict[str, str] | None = None,
                 progress: bool = True) -> FunnelStudy:
    """`runs` pours with seeds 1..runs, `jobs` at a time, with deck variables `settings`."""

    settings = dict(settings or {})
    check_settings(settings)    # before any run
    if settings.get("law") in PLASTIC_VISCOSITY and "eta_B" not in settings:    # the viscosity goes with the law
        settings["eta_B"] = f"{PLASTIC_VISCOSITY[settings['law']]:g}"
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(pour, seed, dt, settings=settings) for seed in range(1, runs + 1)]
        for _ in progress_bar(finished_in_turn(futures), total=runs, desc="pours", unit="run", disable=not progress):
            pass
        return FunnelStudy([future.result() for future in futures], settings, dt)


@dataclass
class Comparison:
    """Funnel studies of several variants side by side."""

    studies: dict[str, FunnelStudy]    # label -> study

    def table(self) -> Table:
        """One row per variant: its deck variables, time step and summary."""
        table = Table(["variant", "deck variables", "dt [s]", *SUMMARY_COLUMNS])
        for label, study in self.studies.items():
            table.add(label, study.settings_text(), f"{study.dt:g}", *study.summary().row())
        return table

    def save(self, folder: Path) -> list[Path]:
        """funnel_variants.csv, funnel_variants.png (distributions), funnel_variants_presence.png."""
        folder = Path(folder)
        return [write_text(folder / "funnel_variants.csv", self.table().csv()),
                plot_variants(self.studies, folder / "funnel_variants.png"),
                plot_occupancy(self.studies, folder / "funnel_variants_presence.png")]


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def compare(folders: list[Path]) -> Comparison:
    """The saved studies in `folders`, each labelled by its folder's name."""
    return Comparison({Path(f).name: FunnelStudy.load(f) for f in folders})


def presence_probability(pours: list[Pour], depth: float, cell: float = 0.0025) -> tuple[np.ndarray, np.ndarray]:
    """Probability, over the runs, that the point of cell centre (x, y) on the plane `depth` below the
    pour's final paste level lies inside a ball; cells outside the mould are NaN. Returns (cell centres
    along x and y, probability)."""
    edges = np.arange(-MOULD_RADIUS, MOULD_RADIUS + cell / 2, cell)
    centres = 0.5 * (edges[1:] + edges[:-1])
    gx, gy = np.meshgrid(centres, centres, indexing="ij")
    hits = np.zeros(gx.shape)
    r = DIAMETER / 2
    for p in pours:
        plane = p.surface - depth
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

    depth = np.concatenate([p.depths() for p in pours]) * 1e3
    fig, (side, hist) = plt.subplots(1, 2, figsize=(10, 4.5), gridspec_kw={"width_ratios": [1, 1.2]})
    for p in pours:
        side.scatter(p.positions[:, 0] * 1e3, p.depths() * 1e3, s=6, alpha=0.5)
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


def plot_variants(studies: dict[str, FunnelStudy], path: Path, per_row: int = 8) -> Path:
    """Vertical distribution of the centres for each variant, `per_row` to a row, the surface marked."""
    plt = figures.pyplot()

    cols = min(per_row, len(studies))
    rows = math.ceil(len(studies) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.1 * cols + 1, 4 * rows), sharey=True, squeeze=False)
    depths = [study.depths() * 1e3 for study in studies.values()]
    bins = np.arange(np.floor(min(d.min() for d in depths) / 5) * 5, max(d.max() for d in depths) + 5, 5)
    for ax, (label, study), depth in zip(axes.flat, studies.items(), depths):
        s = study.summary()
        ax.hist(depth, bins=bins, weights=np.full(depth.size, 1 / s.runs), orientation="horizontal", color="C1",
                edgecolor="k")
        ax.axhline(0, color="C0", lw=1.5)
        ax.axhline(DIAMETER / 2 * 1e3, color="C0", lw=0.8, ls="--")
        ax.set_title(f"{label}\nspilled {s.spilled}, top above {s.top_above}", fontsize=8)
        ax.set_xlabel("balls per run")
    for ax in axes.flat[len(studies):]:
        ax.axis("off")
    for row in axes:
        row[0].set_ylabel("depth of the centre [mm]\n(solid: surface; dashed: top at it)")
    axes[0, 0].invert_yaxis()
    return figures.save(fig, path)


def occupancy(pours: list[Pour], depth: float) -> float:
    """Mean over the mould's cross-section of the probability of presence on the plane `depth` below
    the level: the fraction of that plane inside balls, on average over the runs."""
    return float(np.nanmean(presence_probability(pours, depth)[1]))


def plot_occupancy(studies: dict[str, FunnelStudy], path: Path, step: float = 0.0025) -> Path:
    """The presence per plane of every variant in one panel: the occupied fraction of horizontal planes
    against their depth (the planes of the paper's figure 22 every 10 mm are marked)."""
    plt = figures.pyplot()

    deepest = max(study.depths().max() for study in studies.values()) + DIAMETER / 2
    depths = np.arange(-DIAMETER / 2, deepest + step / 2, step)
    fig, ax = plt.subplots(figsize=(9, 5.5))
    colours = plt.get_cmap("tab20")(np.linspace(0, 1, max(2, len(studies))))
    for k, (label, study) in enumerate(studies.items()):
        ax.plot([occupancy(study.pours, d) for d in depths], depths * 1e3, label=label, color=colours[k],
                ls=("-", "--", ":", "-.")[k % 4], lw=1.4)
    for plane in np.arange(0, deepest, 0.01):
        ax.axhline(plane * 1e3, color="0.85", lw=0.6, zorder=0)
    ax.axhline(0, color="C0", lw=1.2)
    ax.set(xlabel="fraction of the plane inside a ball (mean probability of presence)",
           ylabel="depth of the plane below the paste surface [mm]", title="Presence per plane, every variant")
    ax.invert_yaxis()
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    return figures.save(fig, path)


def plot_presence(pours: list[Pour], path: Path, spacing: float = 0.01) -> Path:
    """Probability of presence per cell on horizontal planes `spacing` apart (the paper's figure 22)."""
    plt = figures.pyplot()

    tops = [p.depths().min() for p in pours]
    bottoms = [p.depths().max() for p in pours]
    depths = np.arange(max(0.0, np.floor(min(tops) / spacing) * spacing),
                       max(bottoms) + DIAMETER / 2, spacing)
    cols = min(4, len(depths))
    rows = math.ceil(len(depths) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3 * cols, 2.9 * rows), squeeze=False)
    for ax, depth in zip(axes.flat, depths):
        centres, prob = presence_probability(pours, depth)
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
