# SPDX-License-Identifier: GPL-2.0-or-later
"""Texture and gradation of a grading curve, as soil and geotechnical reports give them: clay, silt,
sand and gravel (USDA, ISO 14688-1), the USDA texture class, D10-D60 with the coefficients of uniformity
and curvature, each with its band from draws of the curve; the texture triangle and the gradation
chart. Arithmetic only: no simulation.

A curve is percent finer [%] at increasing diameters [m], linear in log(diameter) between them. Every
function takes one curve, shape (n,), or draws of it on the same diameters, shape (draws, n).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import figures
from ..results import Table, write_text

# fraction -> (lower, upper) diameter [m]; the limits of each system
SYSTEMS = {
    "USDA": {"clay": (0.0, 2e-6), "silt": (2e-6, 50e-6), "sand": (50e-6, 2e-3)},
    "ISO 14688-1": {"clay": (0.0, 2e-6), "silt": (2e-6, 63e-6), "sand": (63e-6, 2e-3), "gravel": (2e-3, math.inf)},
}
LEVELS = (10, 30, 50, 60)
USDA_CLASSES = ("sand", "loamy sand", "sandy loam", "loam", "silt loam", "silt", "sandy clay loam", "clay loam",
                "silty clay loam", "sandy clay", "silty clay", "clay")


def percent_at(diameter: np.ndarray, percent: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The curve(s) at the diameters `at` (linear in log d). Below the curve's first diameter it is 0
    where the curve starts at 0, above its last 100 where it ends at 100; NaN elsewhere outside."""
    x, p = np.log(np.asarray(diameter, float)), np.atleast_2d(np.asarray(percent, float))
    t = np.log(np.asarray(at, float))
    k = np.clip(np.searchsorted(x, t, side="right"), 1, len(x) - 1)
    w = np.clip((t - x[k - 1]) / (x[k] - x[k - 1]), 0.0, 1.0)
    out = p[:, k - 1] * (1 - w) + p[:, k] * w
    below, above = t < x[0], t > x[-1]
    out[:, below] = np.where(p[:, :1] == 0.0, 0.0, np.nan)
    out[:, above] = np.where(p[:, -1:] >= 100.0, 100.0, np.nan)
    return out if np.ndim(percent) > 1 else out[0]


def fractions(diameter: np.ndarray, percent: np.ndarray, system: str) -> dict[str, np.ndarray]:
    """Percent of the sample in each fraction of `system` (SYSTEMS). USDA defines texture on the fine
    earth, the part finer than 2 mm: its clay, silt and sand are renormalised to sum to 100."""
    limits = SYSTEMS[system]
    edges = sorted({v for pair in limits.values() for v in pair if 0 < v < math.inf})
    at = dict(zip(edges, np.moveaxis(np.atleast_1d(percent_at(diameter, percent, np.array(edges))), -1, 0)))
    at[0.0], at[math.inf] = 0.0, 100.0
    out = {name: at[b] - at[a] for name, (a, b) in limits.items()}
    if system == "USDA":
        fine_earth = at[2e-3]
        out = {name: 100.0 * value / fine_earth for name, value in out.items()}
    # rounding leaves -1e-13 where a fraction is empty
    return {name: np.clip(np.asarray(value, float), 0.0, 100.0) for name, value in out.items()}


def usda_class(clay, silt, sand) -> np.ndarray:
    """The USDA texture class of each (clay, silt, sand) in percent (normalised to sum to 100; NaN: '').
    The triangle's rules, taken in order so that each point has exactly one class."""
    clay, silt, sand = (np.asarray(v, float) for v in np.broadcast_arrays(clay, silt, sand))
    total = clay + silt + sand
    clay, silt, sand = (100 * v / total for v in (clay, silt, sand))
    rules = [
        silt + 1.5 * clay < 15,
        silt + 2 * clay < 30,
        ((clay >= 7) & (clay < 20) & (sand > 52)) | ((clay < 7) & (silt < 50)),
        (clay >= 7) & (clay < 27) & (silt >= 28) & (silt < 50) & (sand <= 52),
        ((silt >= 50) & (clay >= 12) & (clay < 27)) | ((silt >= 50) & (silt < 80) & (clay < 12)),
        (silt >= 80) & (clay < 12),
        (clay >= 20) & (clay < 35) & (silt < 28) & (sand > 45),
        (clay >= 27) & (clay < 40) & (sand > 20) & (sand <= 45),
        (clay >= 27) & (clay < 40) & (sand <= 20),
        (clay >= 35) & (sand > 45),
        (clay >= 40) & (silt >= 40),
        (clay >= 40) & (sand <= 45) & (silt < 40),
    ]
    known = np.isfinite(total) & (total > 0)
    return np.where(known, np.select(rules, USDA_CLASSES, default=""), "")


def characteristic_diameters(diameter: np.ndarray, percent: np.ndarray, levels=LEVELS) -> dict[str, np.ndarray]:
    """D10, D30, ... [m]: where the curve(s) first reach each level, in log d; NaN where one does not."""
    x, p = np.log(np.asarray(diameter, float)), np.atleast_2d(np.asarray(percent, float))
    out = {}
    for level in levels:
        values = np.full(len(p), np.nan)
        for r, row in enumerate(p):
            k = int(np.argmax(row >= level))
            if row[k] < level:
                continue
            if k == 0:
                values[r] = math.exp(x[0]) if row[0] == level else np.nan
                continue
            w = (level - row[k - 1]) / (row[k] - row[k - 1])
            values[r] = math.exp(x[k - 1] + w * (x[k] - x[k - 1]))
        out[f"D{level}"] = values if np.ndim(percent) > 1 else values[0]
    return out


def coefficients(d10, d30, d60) -> tuple[np.ndarray, np.ndarray]:
    """The coefficients of uniformity, Cu = D60 / D10, and curvature, Cc = D30^2 / (D10 D60)."""
    d10, d30, d60 = (np.asarray(v, float) for v in (d10, d30, d60))
    return d60 / d10, d30 ** 2 / (d10 * d60)


def _band(draws: np.ndarray) -> tuple[float, float]:
    """The central 95 % of the draws that are numbers (NaN, NaN with none)."""
    finite = draws[np.isfinite(draws)]
    return tuple(np.percentile(finite, [2.5, 97.5])) if len(finite) else (math.nan, math.nan)


@dataclass
class TextureReport:
    """The texture and gradation of a curve, with bands from its draws.

    texture.csv: ``system,fraction,percent,low,high``: the USDA and ISO 14688-1 fractions with the
    central 95 % of the draws' fractions; then ``USDA class,<class>,<percent of draws>,,``, the central
    curve's class first. gradation.csv: ``quantity,value,low,high,unit,reached``: D10-D60 [um], Cu, Cc,
    with the central 95 % of the draws that reach the level and the share of draws that do (empty cells
    where the curve does not reach it).
    """

    fractions: dict[str, dict[str, float]]           # system -> fraction -> central value
    fraction_draws: dict[str, dict[str, np.ndarray]]
    usda: str                                         # the central curve's class
    class_share: dict[str, float]                     # class -> share of the draws [%]
    gradation: dict[str, float]                       # D10.. [m], Cu, Cc
    gradation_draws: dict[str, np.ndarray]

    def texture_table(self) -> Table:
        table = Table(["system", "fraction", "percent", "low", "high"])
        for system, values in self.fractions.items():
            for name, value in values.items():
                low, high = _band(self.fraction_draws[system][name])
                table.add(system, name, float(value), float(low), float(high), fmt=".4g")
        for name, share in sorted(self.class_share.items(), key=lambda kv: (kv[0] != self.usda, -kv[1])):
            table.add("USDA class", name, float(share), "", "", fmt=".3g")
        return table

    def gradation_table(self) -> Table:
        table = Table(["quantity", "value", "low", "high", "unit", "reached"])
        for name, value in self.gradation.items():
            draws = self.gradation_draws[name]
            scale, unit = (1e6, "um") if name.startswith("D") else (1.0, "-")
            low, high = _band(draws)
            cells = ["" if not np.isfinite(v) else float(v * scale) for v in (value, low, high)]
            table.add(name, *cells, unit, float(100 * np.mean(np.isfinite(draws))), fmt=".4g")
        missing = [n for n, v in self.gradation.items() if not np.isfinite(v)]
        if missing:
            table.notes.append(f"not reached by the curve: {', '.join(missing)} (the curve stops short of that percent "
                               "finer, or a coefficient needs a diameter it does not reach)")
        return table

    def table(self) -> Table:
        """Both tables as one, for a terminal."""
        table = self.texture_table()
        table.notes = [f"USDA texture class: {self.usda_class_line()}", "gradation: " + "; ".join(
            f"{r[0]} {r[1]}{' ' + r[4] if r[4] != '-' else ''} [{r[2]}, {r[3]}]" for r in self.gradation_table().rows)]
        return table

    def usda_class_line(self) -> str:
        """The central class and how often the draws fall in it."""
        return f"{self.usda} ({self.class_share.get(self.usda, 0.0):.0f} % of the draws)"

    def summary(self) -> dict:
        """For a JSON report."""
        def number(v):
            return float(v) if np.isfinite(v) else None
        return {"fractions": {s: {n: {"percent": number(v), "band": [number(b) for b in _band(self.fraction_draws[s][n])]}
                                  for n, v in values.items()} for s, values in self.fractions.items()},
                "usda_class": self.usda, "usda_class_share_of_draws": self.class_share,
                "gradation": {n: {"value": number(v), "band": [number(b) for b in _band(self.gradation_draws[n])]}
                              for n, v in self.gradation.items()}}

    def save(self, folder: Path) -> list[Path]:
        """texture.csv, gradation.csv and texture.png (the USDA triangle)."""
        folder = Path(folder)
        return [write_text(folder / "texture.csv", self.texture_table().csv()),
                write_text(folder / "gradation.csv", self.gradation_table().csv()),
                texture_triangle(folder / "texture.png", self)]


def texture_report(diameter: np.ndarray, percent: np.ndarray, draws: np.ndarray) -> TextureReport:
    """Texture and gradation of the central curve `percent`, their bands from `draws` (draws, n)."""
    draws = np.atleast_2d(draws)
    central = {s: {n: float(v) for n, v in fractions(diameter, percent, s).items()} for s in SYSTEMS}
    drawn = {s: fractions(diameter, draws, s) for s in SYSTEMS}
    usda = str(usda_class(*(central["USDA"][n] for n in ("clay", "silt", "sand"))))
    classes = usda_class(*(drawn["USDA"][n] for n in ("clay", "silt", "sand")))
    names, counts = np.unique(classes[classes != ""], return_counts=True)
    share = {str(n): float(100 * c / len(classes)) for n, c in zip(names, counts)}
    share.setdefault(usda, 0.0)

    def gradation_of(curves):
        d = characteristic_diameters(diameter, curves)
        cu, cc = coefficients(d["D10"], d["D30"], d["D60"])
        return d | {"Cu": cu, "Cc": cc}
    gradation = {n: float(v) for n, v in gradation_of(percent).items()}
    return TextureReport(central, drawn, usda, share, gradation, gradation_of(draws))


def _ternary(clay, silt):
    """Triangle coordinates: sand at the bottom left, silt at the bottom right, clay at the top."""
    return np.asarray(silt) + 0.5 * np.asarray(clay), np.asarray(clay) * math.sqrt(3) / 2


def texture_triangle(path: Path, report: TextureReport) -> Path:
    """The USDA texture triangle with its classes, the draws' cloud and the central answer."""
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(7, 6.2))
    step = 0.5
    clay, silt = np.meshgrid(np.arange(0, 100 + step, step), np.arange(0, 100 + step, step))
    inside = clay + silt <= 100
    clay, silt = clay[inside], silt[inside]
    names = usda_class(clay, silt, 100 - clay - silt)
    index = np.array([USDA_CLASSES.index(n) for n in names])
    x, y = _ternary(clay, silt)
    ax.tricontourf(x, y, index, levels=np.arange(-0.5, 12), cmap="Pastel1", alpha=0.6)
    ax.tricontour(x, y, index, levels=np.arange(-0.5, 12), colors="0.4", linewidths=0.6)
    for k, name in enumerate(USDA_CLASSES):
        where = index == k
        ax.text(x[where].mean(), y[where].mean(), name, ha="center", va="center", fontsize=7, color="0.2")
    usda = report.fraction_draws["USDA"]
    dx, dy = _ternary(usda["clay"], usda["silt"])
    ax.plot(dx, dy, ".", color="C0", ms=3, alpha=0.5, label="draws")
    cx, cy = _ternary(report.fractions["USDA"]["clay"], report.fractions["USDA"]["silt"])
    ax.plot(cx, cy, "*", color="C3", ms=14, mec="k", label=f"answer: {report.usda_class_line()}")
    ax.plot([0, 100, 50, 0], [0, 0, 50 * math.sqrt(3), 0], "k-", lw=1)
    for v in range(0, 101, 20):
        ax.text(*_ternary(v, 0), f"{v}", fontsize=7, ha="right")                    # clay, on the left side
        ax.text(*_ternary(100 - v, v), f"{v}", fontsize=7, ha="left")               # silt, on the right side
        ax.text(100 - v, -3, f"{v}", fontsize=7, ha="center")                        # sand, on the bottom
    ax.text(12, 50, "clay [%]", rotation=60, fontsize=9)
    ax.text(80, 50, "silt [%]", rotation=-60, fontsize=9)
    ax.text(50, -8, "sand [%]", ha="center", fontsize=9)
    ax.set(aspect="equal", xlim=(-8, 108), ylim=(-11, 92), title="USDA texture")
    ax.axis("off")
    ax.legend(loc="upper right", fontsize=8)
    return figures.save(fig, path)


def gradation_figure(path: Path, diameter: np.ndarray, percent: np.ndarray, low: np.ndarray, high: np.ndarray,
                     sieve: tuple[np.ndarray, np.ndarray] | None = None,
                     points: list[tuple[str, np.ndarray, np.ndarray]] | None = None) -> Path:
    """The gradation chart of a laboratory report: percent finer from 0.5 um to 2 mm (wider where the data
    are), the sieve points, the standard reduction's points, the curve with its band, the class limits
    and D10, D30, D60 marked."""
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(9, 5))
    d = np.asarray(diameter) * 1e6
    ax.fill_between(d, low, high, color="C0", alpha=0.25, label="band (95 %)")
    ax.plot(d, percent, "C0-", lw=1.5, label="recovered PSD")
    shown = [d]
    for k, (label, dd, pp) in enumerate(points or []):
        ax.plot(np.asarray(dd) * 1e6, pp, "s", ms=5, color=f"C{k + 1}", label=label)
        shown.append(np.asarray(dd) * 1e6)
    if sieve is not None:
        ax.plot(sieve[0] * 1e6, sieve[1], "kv", ms=7, label="sieves")
        shown.append(sieve[0] * 1e6)
    everything = np.concatenate(shown)
    left, right = min(0.5, everything[everything > 0].min()), max(2000.0, everything.max())
    for limit, text in ((2, "clay | silt"), (50, "USDA silt | sand"), (63, "ISO silt | sand"), (2000, "sand | gravel")):
        ax.axvline(limit, color="0.5", ls=":", lw=1)
        ax.text(limit * 1.05, 2, text, rotation=90, fontsize=7, color="0.3", va="bottom")
    for name, value in characteristic_diameters(diameter, percent, (10, 30, 60)).items():
        if np.isfinite(value):
            level = float(name[1:])
            ax.plot([value * 1e6], [level], "o", mfc="white", mec="k", ms=6)
            ax.annotate(f"{name} {value * 1e6:.3g} um", (value * 1e6, level), xytext=(6, -10),
                        textcoords="offset points", fontsize=7)
    ax.set(xscale="log", xlim=(left, right), ylim=(0, 100), xlabel="diameter [um]",
           ylabel="percent finer / passing [%]", title="gradation")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="upper left")
    return figures.save(fig, path)
