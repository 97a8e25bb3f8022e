# SPDX-License-Identifier: GPL-2.0-or-later
"""Calibration of paste and contact parameters from simple laboratory tests (Zhang & Li 2024, appendices).

- yield stress from a cylindrical slump test (Pashias & Boger 1996):
  S' = 1 - 2 t (1 - ln 2 t), S' = S / H, t = tau_y / (rho g H), solved for t;
- coefficient of restitution from drop and rebound heights: e = sqrt(H_r / H_f);
- static friction from a tilt test: mu_s = H_l / L (lift height over plate length).

Each function takes one value per repetition and returns the per-test values and their mean.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from ..constants import GRAVITY
from ..results import Table, write_text



@dataclass(frozen=True)
class Calibration:
    """A parameter measured in repeated laboratory tests."""

    name: str
    unit: str
    values: np.ndarray    # one per repetition

    @property
    def mean(self) -> float:
        """Mean over the repetitions."""
        return float(np.mean(self.values))

    @property
    def spread(self) -> float:
        """Sample standard deviation (0 for a single test)."""
        return float(np.std(self.values, ddof=1)) if len(self.values) > 1 else 0.0

    def table(self) -> Table:
        """One row per repetition; the note gives the mean and the spread."""
        unit = f" {self.unit}" if self.unit else ""
        table = Table(["test", f"{self.name}{f' [{self.unit}]' if self.unit else ''}"])
        for k, value in enumerate(self.values, start=1):
            table.add(k, f"{value:.4g}")
        table.notes.append(f"{self.name}: mean {self.mean:.4g}{unit} (s.d. {self.spread:.2g}{unit}) over "
                           f"{len(self.values)} test(s)")
        return table

    def save(self, folder: Path) -> list[Path]:
        """calibration.csv."""
        return [write_text(Path(folder) / "calibration.csv", self.table().csv())]


def _positive(name: str, values) -> np.ndarray:
    array = np.atleast_1d(np.asarray(values, dtype=float))
    if array.size == 0:
        raise ValueError(f"{name}: no values given")
    if not np.all(np.isfinite(array)) or np.any(array <= 0):
        raise ValueError(f"{name} must be finite and > 0, got {array.tolist()}")
    return array


def dimensionless_slump(t: float) -> float:
    """Pashias & Boger's S' = S/H of a cylinder for the dimensionless yield stress t = tau_y / (rho g H)."""
    if not 0.0 < t <= 0.5:
        raise ValueError(f"dimensionless yield stress must lie in (0, 0.5], got {t}")
    return 1.0 - 2.0 * t * (1.0 - math.log(2.0 * t))


def yield_stress_from_slump(slump, height: float, density: float, gravity: float = GRAVITY) -> Calibration:
    """tau_y from slumps S of a cylinder of height H filled with paste of density rho (SI units).

    S'(t) falls monotonically from 1 (t -> 0) to 0 (t = 1/2), so each slump has one root."""
    height = float(_positive("height", height)[0])
    density = float(_positive("density", density)[0])
    slumps = _positive("slump", slump)
    if np.any(slumps >= height):
        raise ValueError(f"a slump must be smaller than the cylinder height {height}, got {slumps.tolist()}")
    t = np.array([brentq(lambda x, s=s: dimensionless_slump(x) - s / height, 1e-15, 0.5, xtol=1e-15)
                  for s in slumps])
    return Calibration("yield stress (slump test)", "Pa", t * density * gravity * height)


def restitution_from_drops(drop_heights, rebound_heights) -> Calibration:
    """e = sqrt(H_r / H_f) per drop (no air drag: the heights are those of free flight)."""
    drops = _positive("drop height", drop_heights)
    rebounds = _positive("rebound height", rebound_heights)
    if drops.shape != rebounds.shape:
        raise ValueError(f"{drops.size} drop heights but {rebounds.size} rebound heights")
    if np.any(rebounds > drops):
        raise ValueError("a rebound higher than its drop would need e > 1")
    return Calibration("coefficient of restitution (drop test)", "", np.sqrt(rebounds / drops))


def friction_from_tilt(lift_heights, length: float) -> Calibration:
    """mu_s = H_l / L: the raised end's height over the plate length when the ball starts to slide
    (the appendix's definition; tan of the angle would be H_l / sqrt(L^2 - H_l^2))."""
    length = float(_positive("plate length", length)[0])
    lifts = _positive("lift height", lift_heights)
    if np.any(lifts >= length):
        raise ValueError(f"a lift height must be smaller than the plate length {length}")
    return Calibration("static friction (tilt test)", "", lifts / length)
