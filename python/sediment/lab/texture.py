# SPDX-License-Identifier: GPL-2.0-or-later
"""Soil texture and gradation from a grading curve: the arithmetic of a laboratory report, no simulation.

The clay, silt, sand and gravel fractions (USDA, ISO 14688-1), the USDA texture class, the characteristic
diameters D10-D60 with the coefficients of uniformity and curvature, each with a band from draws of the
curve; the USDA texture triangle and the gradation chart.

A curve is percent finer [%] at increasing diameters [m], linear in log(diameter) between them. Every
function takes one curve, shape (n,), or draws of it on the same diameters, shape (draws, n), and then
answers one value per draw.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import figures
from ..results import Table, write_text

# system -> fraction -> (lower, upper) diameter [m]
SYSTEMS: dict[str, dict[str, tuple[float, float]]] = {
    "USDA": {"clay": (0.0, 2e-6), "silt": (2e-6, 50e-6), "sand": (50e-6, 2e-3)},
    "ISO 14688-1": {"clay": (0.0, 2e-6), "silt": (2e-6, 63e-6), "sand": (63e-6, 2e-3), "gravel": (2e-3, math.inf)},
}
LEVELS = (10, 30, 50, 60)    # the percents finer of the characteristic diameters
USDA_CLASSES = ("sand", "loamy sand", "sandy loam", "loam", "silt loam", "silt", "sandy clay loam", "clay loam",
                "silty clay loam", "sandy clay", "silty clay", "clay")
# each class's outline on the triangle: its corners as (clay, silt) [%], from the rules of `usda_class`
USDA_POLYGONS: dict[str, tuple[tuple[float, float], ...]] = {
    "sand": ((0, 0), (0, 15), (10, 0)),
    "loamy sand": ((0, 15), (0, 30), (15, 0), (10, 0)),
    "sandy loam": ((0, 30), (0, 50), (7, 50), (7, 41), (20, 28), (20, 0), (15, 0)),
    "loam": ((7, 41), (7, 50), (27, 50), (27, 28), (20, 28)),
    "silt loam": ((0, 50), (0, 80), (12, 80), (12, 88), (27, 73), (27, 50)),
    "silt": ((0, 80), (0, 100), (12, 88), (12, 80)),
    "sandy clay loam": ((20, 0), (20, 28), (27, 28), (35, 20), (35, 0)),
    "clay loam": ((27, 28), (27, 53), (40, 40), (40, 15), (35, 20)),
    "silty clay loam": ((27, 53), (27, 73), (40, 60), (40, 40)),
    "sandy clay": ((35, 0), (35, 20), (40, 15), (55, 0)),
    "silty clay": ((40, 40), (40, 60), (60, 40)),
    "clay": ((40, 15), (40, 40), (60, 40), (100, 0), (55, 0)),
}
CLOSED = 1e-9                              # points: a curve's end within this of 0 or 100 % is closed
UNKNOWN = "unknown"                       # the class row of draws (or a curve) whose fractions are not known
CENTRAL_CLASS = "USDA class (central)"    # texture.csv: the system of the central curve's class row
DRAWS_CLASS = "USDA class"                # texture.csv: the system of the other classes the draws fall in
LIMITS_UM = ((2.0, "clay | silt"), (50.0, "USDA silt | sand"), (63.0, "ISO silt | sand"), (2000.0, "sand | gravel"))


def _curve(diameter, percent) -> tuple[np.ndarray, np.ndarray]:
    """log(diameter) and the curve(s) as floats, checked to fit each other."""
    d, p = np.asarray(diameter, float), np.asarray(percent, float)
    if d.ndim != 1 or d.size < 2 or not np.all(d > 0) or not np.all(np.diff(d) > 0):
        raise ValueError("a curve needs at least two increasing diameters > 0")
    if p.ndim not in (1, 2) or p.shape[-1] != d.size:
        raise ValueError(f"percent of shape {p.shape} for {d.size} diameters: give (n,) or (draws, n)")
    return np.log(d), p


def percent_at(diameter, percent, at) -> np.ndarray:
    """The curve(s) at the diameters `at` [m], linear in log(diameter).

    Beyond the curve only a closed end is known: below its first diameter it is 0 where it starts at
    0 % (nothing finer), above its last 100 where it ends at 100 % (nothing coarser); NaN otherwise.

    Parameters
    ----------
    diameter : array (n,)
        Increasing diameters [m].
    percent : array (n,) or (draws, n)
        Percent finer at `diameter`.
    at : float or array
        Diameters [m] to read the curve at.

    Returns
    -------
    ndarray
        Shape ``percent.shape[:-1] + np.shape(at)``.
    """
    x, p = _curve(diameter, percent)
    rows = np.atleast_2d(p)
    t = np.log(np.atleast_1d(np.asarray(at, float)))
    # each diameter's segment, those beyond the ends taking the end segments (then overwritten below)
    k = np.clip(np.searchsorted(x, t, side="right"), 1, x.size - 1)
    w = np.clip((t - x[k - 1]) / (x[k] - x[k - 1]), 0.0, 1.0)
    out = rows[:, k - 1] * (1 - w) + rows[:, k] * w
    # a closed end within rounding (a draw's 100 * cumsum / sum may end at 99.99999999999999)
    out[:, t < x[0]] = np.where(rows[:, :1] <= CLOSED, 0.0, np.nan)
    out[:, t > x[-1]] = np.where(rows[:, -1:] >= 100.0 - CLOSED, 100.0, np.nan)
    return out.reshape(p.shape[:-1] + np.shape(at))


def fractions(diameter, percent, system: str) -> dict[str, np.ndarray]:
    """Percent of the sample in each fraction of a classification system.

    A fraction is the difference of the curve at its limits (`percent_at`): NaN where a limit lies
    beyond the curve and the curve is not closed there (0 % at its fine end, 100 % at its coarse end).
    ISO 14688-1's gravel is everything coarser than 2 mm, 100 - P(2 mm). USDA defines texture on the fine
    earth, the part finer than 2 mm: its clay, silt and sand are percent of that part (divided by
    P(2 mm) / 100, so they sum to 100 whatever the gravel), NaN where P(2 mm) is not known or is 0.

    Parameters
    ----------
    diameter : array (n,)
        Increasing diameters [m].
    percent : array (n,) or (draws, n)
        Percent finer at `diameter`.
    system : str
        A key of `SYSTEMS`: ``"USDA"`` or ``"ISO 14688-1"``.

    Returns
    -------
    dict of str to ndarray
        Fraction name -> percent, shape ``percent.shape[:-1]``.
    """
    if system not in SYSTEMS:
        raise ValueError(f"unknown classification system {system!r}: one of {', '.join(SYSTEMS)}")
    limits = SYSTEMS[system]
    cuts = sorted({b for pair in limits.values() for b in pair if 0 < b < math.inf})
    finer = dict(zip(cuts, np.moveaxis(percent_at(diameter, percent, np.array(cuts)), -1, 0)))
    finer[0.0], finer[math.inf] = 0.0, 100.0
    out = {name: np.asarray(finer[hi] - finer[lo], float) for name, (lo, hi) in limits.items()}
    top = max(hi for _, hi in limits.values())
    if top < math.inf:    # a system that stops short of the coarsest grains speaks of the part finer than its top
        below = np.asarray(finer[top], float)
        scale = np.where(below > 0, 100.0 / np.where(below > 0, below, 1.0), np.nan)
        out = {name: value * scale for name, value in out.items()}
    # interpolation leaves -1e-14 in an empty fraction
    # rounding leaves 1e-14 where a fraction is empty: 0 there
    return {name: np.clip(np.where(np.abs(value) < 1e-9, 0.0, value), 0.0, 100.0) for name, value in out.items()}


def _usda_rules(clay, silt, sand) -> list[np.ndarray]:
    """The twelve classes' conditions in the order of USDA_CLASSES, each complete in itself (the Soil Survey
    Manual's triangle). On the triangle exactly one holds at every point, its edges included. The sand
    limits the manual also states (sand >= 85 for sand, 70-91 for loamy sand) follow from the others."""
    return [
        silt + 1.5 * clay < 15,
        (silt + 1.5 * clay >= 15) & (silt + 2 * clay < 30),
        (((clay >= 7) & (clay < 20) & (sand > 52)) | ((clay < 7) & (silt < 50))) & (silt + 2 * clay >= 30),
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


def usda_class(clay, silt, sand) -> np.ndarray:
    """The USDA texture class of (clay, silt, sand).

    Parameters
    ----------
    clay, silt, sand : float or array
        Percents (broadcast together). They are rescaled to sum to 100, so fractions of 1 or rounded
        percents work alike; a point with a value that is not a number, or below -0.5, is unknown.

    Returns
    -------
    ndarray of str
        One of `USDA_CLASSES` per point ('' where unknown), of the inputs' broadcast shape.
    """
    clay, silt, sand = (np.asarray(v, float) for v in np.broadcast_arrays(clay, silt, sand))
    with np.errstate(invalid="ignore"):
        known = np.isfinite(clay) & np.isfinite(silt) & np.isfinite(sand) & (np.minimum(np.minimum(
            clay, silt), sand) >= -0.5)
        clay, silt, sand = (np.clip(v, 0.0, None) for v in (clay, silt, sand))
        total = clay + silt + sand
        known &= total > 0
        scale = 100.0 / np.where(known, total, 1.0)
    names = np.select(_usda_rules(clay * scale, silt * scale, sand * scale), USDA_CLASSES, default="")
    return np.where(known, names, "")


def characteristic_diameters(diameter, percent, levels=LEVELS) -> dict[str, np.ndarray]:
    """The diameters at which the curve(s) first reach given percents finer.

    Parameters
    ----------
    diameter : array (n,)
        Increasing diameters [m].
    percent : array (n,) or (draws, n)
        Percent finer at `diameter`.
    levels : sequence of float
        Percents finer; the default gives D10, D30, D50 and D60.

    Returns
    -------
    dict of str to ndarray
        ``"D10"`` ... -> diameter [m] (linear in log d between the curve's points), shape
        ``percent.shape[:-1]``; NaN where the curve stays below the level, or starts above it (the
        crossing then lies below the curve's first diameter).
    """
    x, p = _curve(diameter, percent)
    rows = np.atleast_2d(p)
    r = np.arange(len(rows))
    out = {}
    for level in levels:
        reached = rows >= level
        k = np.argmax(reached, axis=1)        # the first point at or above the level
        j = np.maximum(k - 1, 0)              # the point before it
        with np.errstate(invalid="ignore", divide="ignore"):    # k = 0 divides by zero; that cell is not used
            w = (level - rows[r, j]) / (rows[r, k] - rows[r, j])
            log_d = np.where(k > 0, x[j] + w * (x[k] - x[j]), x[0])
        known = reached.any(axis=1) & ((k > 0) | (rows[:, 0] == level))
        out[f"D{level:g}"] = np.where(known, np.exp(log_d), np.nan).reshape(p.shape[:-1])
    return out


def coefficients(d10, d30, d60) -> tuple[np.ndarray, np.ndarray]:
    """The coefficients of uniformity and curvature.

    Parameters
    ----------
    d10, d30, d60 : float or array
        Characteristic diameters (any one unit).

    Returns
    -------
    tuple of ndarray
        Cu = D60 / D10 and Cc = D30^2 / (D10 D60); NaN where a diameter is NaN.
    """
    d10, d30, d60 = (np.asarray(v, float) for v in (d10, d30, d60))
    return d60 / d10, d30 ** 2 / (d10 * d60)


def _band(values: np.ndarray) -> tuple[float, float]:
    """The 2.5 and 97.5 percentiles of the values that are numbers (NaN, NaN with none)."""
    finite = np.asarray(values, float)[np.isfinite(values)]
    if not finite.size:
        return math.nan, math.nan
    low, high = np.percentile(finite, [2.5, 97.5])
    return float(low), float(high)


def _cell(value: float, scale: float = 1.0) -> float | str:
    """A number for Table.add, or an empty cell where there is none."""
    return float(value) * scale if np.isfinite(value) else ""


def _number(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


@dataclass
class TextureReport:
    """The texture and gradation of a curve, with bands from draws of it (`texture_report`).

    texture.csv, columns ``system,fraction,percent,low,high``:

    - ``USDA,clay|silt|sand,...`` and ``ISO 14688-1,clay|silt|sand|gravel,...``: the central curve's
      fraction [%] (USDA: of the fine earth, finer than 2 mm), with ``low``, ``high`` the 2.5 and 97.5
      percentiles of that fraction over the draws;
    - ``USDA class (central),<class>,<percent>,,``: the central curve's class, with the percent of the
      draws that fall in it (0 if none);
    - ``USDA class,<class>,<percent>,,``: every other class some draw falls in, most frequent first
      (``unknown`` for draws whose fractions are not known). The class rows' percents sum to 100.

    gradation.csv, columns ``quantity,value,low,high,unit,reached_percent``: D10, D30, D50, D60 [um],
    Cu and Cc [-] of the central curve, ``low``, ``high`` the 2.5 and 97.5 percentiles over the draws
    that reach the quantity, ``reached_percent`` the percent of draws that do (Cu, Cc: that reach
    D10, D30 and D60). A cell is empty where there is no value; lines starting with ``#`` under the
    table say which quantities the central curve does not reach and why, and which bands rest on only
    part of the draws.
    """

    fractions: dict[str, dict[str, float]]            # system -> fraction -> percent of the central curve
    fraction_draws: dict[str, dict[str, np.ndarray]]  # system -> fraction -> percent per draw
    usda: str                                          # the central curve's USDA class ('' unknown)
    class_share: dict[str, float]                      # class -> percent of the draws in it
    gradation: dict[str, float]                        # D10 ... [m], Cu, Cc of the central curve
    gradation_draws: dict[str, np.ndarray]             # the same per draw
    reasons: dict[str, str] = field(default_factory=dict)    # quantity -> why the central curve lacks it

    def texture_table(self) -> Table:
        """texture.csv's rows (layout in the class docstring)."""
        table = Table(["system", "fraction", "percent", "low", "high"])
        for system, values in self.fractions.items():
            for name, value in values.items():
                table.add(system, name, _cell(value), *map(_cell, _band(self.fraction_draws[system][name])), fmt=".4g")
        central = self.usda or UNKNOWN
        share = float(self.class_share.get(central, 0.0)) if self.class_share else ""    # no draws: no share
        table.add(CENTRAL_CLASS, central, share, "", "", fmt=".4g")
        for name, share in sorted(self.class_share.items(), key=lambda item: (-item[1], item[0])):
            if name != central:
                table.add(DRAWS_CLASS, name, float(share), "", "", fmt=".4g")
        return table

    def gradation_table(self) -> Table:
        """gradation.csv's rows (layout in the class docstring), the notes on what is not reached."""
        table = Table(["quantity", "value", "low", "high", "unit", "reached_percent"])
        draws = len(next(iter(self.gradation_draws.values()), []))
        for name, value in self.gradation.items():
            values = self.gradation_draws[name]
            scale, unit = (1e6, "um") if name.startswith("D") else (1.0, "-")
            reached = 100.0 * np.mean(np.isfinite(values)) if draws else math.nan
            cells = [_cell(v, scale) for v in (value, *_band(values))]
            table.add(name, *cells, unit, _cell(reached), fmt=".4g")
            if not np.isfinite(value):
                table.notes.append(f"{name} not reached by the curve: {self.reasons.get(name, 'no value')}")
            if draws and 0 < reached < 100:
                table.notes.append(f"{name}: the band is over the {reached:.3g} % of the draws that reach it")
        if not draws:
            table.notes.append("no draws of the curve: no bands")
        return table

    def usda_class_line(self) -> str:
        """The central curve's class and how often the draws fall in it."""
        name = self.usda or UNKNOWN
        if not self.class_share:
            return f"{name} (no draws)"
        unknown = self.class_share.get(UNKNOWN, 0.0)
        if not unknown or name == UNKNOWN:
            return f"{name} ({self.class_share.get(name, 0.0):.0f} % of the draws)"
        # the share among the draws that have a class, and why the others have none
        return (f"{name} ({100 * self.class_share.get(name, 0.0) / (100 - unknown):.0f} % of the draws with a class; "
                f"{unknown:.0f} % have none: their curve does not reach 2 mm, so their fine earth is not known)")

    def gravel_line(self) -> str | None:
        """Where the sample holds gravel: that USDA's class is of its fine earth, and the modifier's rule."""
        gravel = self.fractions["ISO 14688-1"].get("gravel", math.nan)
        if not gravel >= 1.0:    # NaN (the curve stops below 2 mm), or a trace
            return None
        return (f"the USDA class is of the fine earth (< 2 mm); {gravel:.3g} % of the sample's mass is gravel, which "
                "USDA names by volume (gravelly at 15-35 %, very gravelly 35-60 %, extremely gravelly above): "
                "convert with the gravel's and the fine earth's densities before naming the modifier")

    def table(self) -> Table:
        """texture.csv's table with the class and the gradation as notes, for a terminal."""
        table = self.texture_table()
        gradation = self.gradation_table()
        parts = [f"{row[0]} {row[1] or '-'}{'' if row[4] == '-' else ' ' + row[4]} [{row[2] or '-'}, {row[3] or '-'}]"
                 for row in gradation.rows]
        gravel = self.gravel_line()
        table.notes = [f"USDA texture class: {self.usda_class_line()}", *([gravel] if gravel else []),
                       "gradation: " + "; ".join(parts), *gradation.notes]
        return table

    def summary(self) -> dict:
        """The report as plain numbers and strings, for a JSON file (None where there is no value)."""
        return {"fractions": {system: {name: {"percent": _number(value),
                                              "band": [_number(b) for b in _band(self.fraction_draws[system][name])]}
                                       for name, value in values.items()}
                              for system, values in self.fractions.items()},
                "usda_class": self.usda, "usda_class_share_of_draws": dict(self.class_share),
                "gradation": {name: {"value": _number(value), "band": [_number(b) for b in
                                                                       _band(self.gradation_draws[name])]}
                              for name, value in self.gradation.items()},
                "gradation_notes": self.gradation_table().notes}

    def save(self, folder: Path, mark: str = "") -> list[Path]:
        """Writes texture.csv, gradation.csv (its notes as ``#`` lines at the end) and texture.png (the USDA
        triangle, `mark` added to its title) into `folder`; returns their paths."""
        folder = Path(folder)
        gradation = self.gradation_table()
        return [write_text(folder / "texture.csv", self.texture_table().csv()),
                write_text(folder / "gradation.csv", gradation.csv() + "".join(f"# {n}\n" for n in gradation.notes)),
                texture_triangle(folder / "texture.png", self, title="USDA texture" + mark)]


def _why_not_reached(diameter: np.ndarray, percent: np.ndarray, level: float) -> str:
    """Why a curve has no D at `level`."""
    p = np.asarray(percent, float)
    if not np.all(np.isfinite(p)):
        return "the curve has values that are not numbers"
    if p[0] > level:
        return (f"the curve starts at {p[0]:.3g} % at its finest diameter, {diameter[0] * 1e6:.3g} um: "
                f"it crosses {level:g} % below the measured range")
    return f"the curve tops out at {p.max():.3g} % (at {diameter[-1] * 1e6:.3g} um), below {level:g} %"


def texture_report(diameter, percent, draws=None) -> TextureReport:
    """The texture and gradation of a curve with their bands from draws of it.

    Parameters
    ----------
    diameter : array (n,)
        Increasing diameters [m].
    percent : array (n,)
        The central curve, percent finer at `diameter`.
    draws : array (draws, n), optional
        Draws of the curve on the same diameters (the PSDs the data allow); the bands are the 2.5 and
        97.5 percentiles of each quantity over them, not the envelope of the curves. None: no bands.

    Returns
    -------
    TextureReport
    """
    diameter, percent = np.asarray(diameter, float), np.asarray(percent, float)
    if percent.ndim != 1:
        raise ValueError("the central curve must be one curve, shape (n,)")
    draws = np.empty((0, diameter.size)) if draws is None else np.asarray(draws, float).reshape(-1, diameter.size)
    central = {s: {n: float(v) for n, v in fractions(diameter, percent, s).items()} for s in SYSTEMS}
    drawn = {s: fractions(diameter, draws, s) for s in SYSTEMS}
    usda = str(usda_class(*(central["USDA"][n] for n in ("clay", "silt", "sand"))))
    classes = usda_class(*(drawn["USDA"][n] for n in ("clay", "silt", "sand")))
    classes = np.where(classes == "", UNKNOWN, classes)
    names, counts = np.unique(classes, return_counts=True)
    share = {str(n): 100.0 * c / len(classes) for n, c in zip(names, counts)}

    def gradation_of(curves: np.ndarray) -> dict[str, np.ndarray]:
        d = characteristic_diameters(diameter, curves)
        cu, cc = coefficients(d["D10"], d["D30"], d["D60"])
        return {**d, "Cu": cu, "Cc": cc}

    gradation = {n: float(v) for n, v in gradation_of(percent).items()}
    reasons = {f"D{level:g}": _why_not_reached(diameter, percent, level)
               for level in LEVELS if not np.isfinite(gradation[f"D{level:g}"])}
    missing = [n for n in ("D10", "D30", "D60") if n in reasons]
    if missing:
        reasons["Cu"] = f"needs D10 and D60; the curve does not reach {', '.join(missing)}"
        reasons["Cc"] = f"needs D10, D30 and D60; the curve does not reach {', '.join(missing)}"
    return TextureReport(central, drawn, usda, share, gradation, gradation_of(draws), reasons)


def _ternary(clay, silt) -> tuple[np.ndarray, np.ndarray]:
    """Plot coordinates on the USDA triangle: sand at the bottom left, silt at the bottom right, clay at the top."""
    clay, silt = np.asarray(clay, float), np.asarray(silt, float)
    return silt + 0.5 * clay, clay * math.sqrt(3) / 2


def _centroid(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """The area centroid of a polygon (shoelace)."""
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    six_areas = 3 * cross.sum()
    return tuple(float(((v + np.roll(v, -1)) * cross).sum() / six_areas) for v in (x, y))


def texture_triangle(path: Path, report: TextureReport, title: str = "USDA texture") -> Path:
    """The USDA texture triangle with the draws as a cloud and the central curve's texture as a star.

    Parameters
    ----------
    path : Path
        The figure's file (format from its suffix).
    report : TextureReport
        Whose USDA fractions are drawn.
    title : str
        The figure's title.

    Returns
    -------
    Path
        `path`, written.
    """
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(7, 6.3))
    for name, corners in USDA_POLYGONS.items():
        x, y = _ternary(*np.array(corners, float).T)
        ax.fill(x, y, facecolor="0.96", edgecolor="0.35", lw=0.8)
        ax.text(*_centroid(x, y), name.replace(" ", "\n") if len(name) > 10 else name, ha="center", va="center",
                fontsize=6.5, color="0.25")
    usda = report.fraction_draws["USDA"]
    x, y = _ternary(usda["clay"], usda["silt"])
    shown = np.isfinite(x) & np.isfinite(y)
    if shown.any():
        ax.plot(x[shown], y[shown], ".", color="C0", ms=2.5, alpha=0.4, label=f"draws ({shown.sum()})")
    cx, cy = _ternary(report.fractions["USDA"]["clay"], report.fractions["USDA"]["silt"])
    if np.isfinite(cx) and np.isfinite(cy):
        ax.plot(cx, cy, "*", color="C3", mec="k", ms=14, label=f"central: {report.usda_class_line()}")
    height = 50 * math.sqrt(3)
    ax.plot([0, 100, 50, 0], [0, 0, height, 0], "k-", lw=1.2)
    for v in range(10, 100, 10):
        ax.text(*_ternary(v, 0), f"{v} ", fontsize=7, ha="right", va="center")                   # clay: left side
        ax.text(*_ternary(100 - v, v), f" {v}", fontsize=7, ha="left", va="center")             # silt: right side
        ax.text(100 - v, -2, f"{v}", fontsize=7, ha="center", va="top")                         # sand: bottom
    ax.text(14, 48, "clay [%]", rotation=60, fontsize=9, ha="center")
    ax.text(86, 48, "silt [%]", rotation=-60, fontsize=9, ha="center")
    ax.text(50, -9, "sand [%]", fontsize=9, ha="center")
    ax.set(aspect="equal", xlim=(-8, 108), ylim=(-12, height + 6), title=title)
    ax.axis("off")
    ax.legend(loc="upper right", fontsize=7.5, frameon=False)
    return figures.save(fig, path)


def gradation_figure(path: Path, diameter, percent, low=None, high=None,
                     sieve: tuple[np.ndarray, np.ndarray] | None = None,
                     points: list[tuple[str, np.ndarray, np.ndarray]] | None = None, title: str = "gradation") -> Path:
    """The gradation chart of a laboratory report: percent finer against diameter.

    Parameters
    ----------
    path : Path
        The figure's file (format from its suffix).
    diameter, percent : array (n,)
        The curve: diameters [m] and percent finer; its D10, D30 and D60 are marked where reached.
    low, high : array (n,), optional
        Its band, shaded.
    sieve : (openings [m], percent passing), optional
        The sieve points.
    points : list of (label, diameters [m], percent finer), optional
        Other points, such as each instrument's standard reduction.
    title : str
        The figure's title.

    Returns
    -------
    Path
        `path`, written. The diameter axis spans 0.5 um to 2 mm, or wider where the data lie beyond.
    """
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(9, 5))
    d = np.asarray(diameter, float) * 1e6
    percent = np.asarray(percent, float)
    shown = [d]
    if low is not None and high is not None:
        ax.fill_between(d, np.asarray(low, float), np.asarray(high, float), color="C0", alpha=0.25, lw=0,
                        label="band (95 %)")
    ax.plot(d, percent, "C0-", lw=1.6, label="PSD")
    for k, (label, dd, pp) in enumerate(points or []):
        dd = np.asarray(dd, float) * 1e6
        ax.plot(dd, np.asarray(pp, float), "s", ms=4.5, color=f"C{k + 1}", mec="k", mew=0.4, label=label,
                clip_on=False)
        shown.append(dd)
    if sieve is not None:
        opening = np.asarray(sieve[0], float) * 1e6
        # unclipped: the coarse sieves sit on the 100 % line
        ax.plot(opening, np.asarray(sieve[1], float), "v", color="k", mfc="0.85", ms=7, label="sieves", clip_on=False)
        shown.append(opening)
    every = np.concatenate(shown)
    every = every[np.isfinite(every) & (every > 0)]
    left = min(0.5, every.min() / 1.3) if every.size else 0.5
    right = max(2000.0, every.max() * 1.3) if every.size else 2000.0
    for limit, label in LIMITS_UM:
        ax.axvline(limit, color="0.5", ls=":", lw=1)
        ax.text(limit * 1.06, 0.98, label, rotation=90, fontsize=7, color="0.3", va="top",
                transform=ax.get_xaxis_transform())
    for name, value in characteristic_diameters(diameter, percent, (10, 30, 60)).items():
        if np.isfinite(value):
            level, at = float(name[1:]), float(value) * 1e6
            ax.plot([at, at], [0, level], color="0.3", lw=0.7, ls="--")
            ax.plot([at], [level], "o", mfc="white", mec="k", ms=6)
            ax.annotate(f"{name} = {at:.3g} um", (at, level), xytext=(6, -11), textcoords="offset points", fontsize=7)
    ax.set(xscale="log", xlim=(left, right), ylim=(0, 100), xlabel="diameter [um]",
           ylabel="percent finer / passing [%]", title=title)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower right")    # a grading curve leaves the lower right empty
    return figures.save(fig, path)
