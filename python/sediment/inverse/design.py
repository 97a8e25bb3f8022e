# SPDX-License-Identifier: GPL-2.0-or-later
"""Designing a test (`sediment invert --design`, docs/inverse.md): which instrument, reading times and
sample mass recover an expected PSD best, and when the 152H's cut reaches the clay limit (2 um)."""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..constants import LAB_TEMPERATURE, PIPETTE_DEPTH, SCHEDULES, SPECIMEN_MASS
from ..lab.instruments import instrument
from ..lab.psd import PSD
from ..lab.readout import Pipette, Suspension, gs_correction
from ..lab.sheet import Sheet
from .fit import fit
from .grid import MIN_BINS, SizeGrid
from .model import LabTest, linearise, psd_of, run_forward

CLAY_LIMIT = 2e-6    # [m]

# The designs `design_test` compares: instruments and their reading times [min] (the pipette at
# PIPETTE_DEPTH, at its default times).
DESIGNS = {
    "152H, D422 times": [("hydrometer", tuple(SCHEDULES["d422"]))],
    "152H, D7928 times": [("hydrometer", tuple(SCHEDULES["d7928"]))],
    f"pipette at {PIPETTE_DEPTH * 100:g} cm": [("pipette", None)],
    "buoyancy sphere, Bravo et al.'s times": [("buoyancy", tuple(SCHEDULES["bravo"]))],
    "152H (D7928) + pipette": [("hydrometer", tuple(SCHEDULES["d7928"])), ("pipette", None)],
}


def design_test(psd: PSD, folder: Path, masses=(0.030, 0.045, 0.060, 0.080), designs: dict = DESIGNS,
                test: LabTest = LabTest(SPECIMEN_MASS), bins: int = 12, draws: int = 24, particles: int = 20000,
                seed: int = 1) -> list[tuple[str, float, int, float, float]]:
    """Which instrument, reading times and sample mass recover `psd` best: for each mass a forward run of
    the test, each design's readings of it with their noise drawn `draws` times and fitted as `invert`
    fits (linearised at the truth), and the error of the recovered PSD at the bin edges against the
    truth. Returns (design, mass, readings, mean error, worst error) [pp], the mean over the draws of each
    draw's mean and worst absolute error (NaN, with no readings, where the instrument cannot read that
    mass, e.g. a suspension beyond the 152H's scale). The hindrance's own uncertainty, which grows with the mass, is
    not in it (docs/error-budget.md: the exponent row)."""
    if bins < MIN_BINS:
        raise ValueError(f"--bins {bins}: give at least {MIN_BINS} size bins")
    water = Suspension.at_temperature(LAB_TEMPERATURE, test.particle_density)
    rng = np.random.default_rng(seed)
    results = []
    for mass in masses:
        trial = replace(test, mass=mass)
        # the edges from the Stokes diameters the designs' readings resolve, as `invert` takes them
        scales = [d for parts in designs.values() for d in _design_diameters(parts, trial, water)]
        # the designs' span as readings' cuts, the PSD's largest grain the top
        edges = np.geomspace(min(scales), max(scales), bins)
        top = max(psd.span()[1], edges[-1] * 1.5)
        grid = SizeGrid(np.append(edges, top), np.array(["reading"] * bins + ["top"]), edges[0] / 3)
        truth = np.diff(np.concatenate([[0.0], psd.at(edges), [100.0]])) / 100.0
        spread = 0.8 * truth + 0.2 / len(truth)
        run = run_forward(psd_of(spread, grid), grid, trial, water, 1.02 * 86400, folder / f"mass{mass * 1e3:g}g",
                          particles, 4.0, seed)
        for name, parts in designs.items():
            sheets = _design_sheets(parts, trial, water)
            times = [s.time for s in sheets]
            try:
                base, jac = linearise(run, truth, sheets, times)
            except ValueError:    # e.g. a suspension denser than the 152H's scale: it cannot read this mass
                results.append((name, mass, 0, math.nan, math.nan))
                continue
            sigma = np.concatenate([np.full(len(s.time), trial.noise[s.instrument]) for s in sheets])
            mean_errors, worst_errors = [], []
            for _ in range(draws):
                noisy = base + rng.normal(0.0, sigma)
                x, _, _ = fit(jac, base, truth, noisy, sigma, grid)
                error = np.abs(100 * (np.cumsum(x) - np.cumsum(truth))[:-1])
                mean_errors.append(error.mean())
                worst_errors.append(error.max())
            results.append((name, mass, len(base), float(np.mean(mean_errors)), float(np.mean(worst_errors))))
    return results


def _design_sheets(parts, test: LabTest, water: Suspension) -> list[Sheet]:
    """The sheets of a design (readings unset: the forward run reads them)."""
    sheets = []
    for name, minutes in parts:
        instrument(name)    # an unknown name is refused
        if minutes is None:    # the pipette's default times at its depth
            time = np.sort(Pipette(PIPETTE_DEPTH).default_times(water))
            depth = np.full(len(time), PIPETTE_DEPTH)
        else:
            time = np.array(minutes, float) * 60
            depth = np.empty(0)
        sheets.append(Sheet(name, Path(name), time, np.zeros(len(time)), np.full(len(time), LAB_TEMPERATURE), depth))
    return sheets


def _design_diameters(parts, test: LabTest, water: Suspension) -> list[float]:
    """The Stokes diameters a design's readings resolve, at the instruments' nominal depths."""
    out = []
    for sheet in _design_sheets(parts, test, water):
        depth = sheet.kind.nominal_depth(test)
        out += list(water.stokes_diameter(depth, sheet.time))
    return out


def clay_reading_time(psd: PSD, test: LabTest, temperatures=(18.0, 20.0, 23.0, 25.0)) -> list[tuple[float, float]]:
    """When the 152H's cut reaches the clay limit: the Stokes time of a 2 um grain to the bulb's depth at
    the reading the expected PSD gives there, for each water temperature; (temperature [C], time [s])."""
    water = Suspension.at_temperature(LAB_TEMPERATURE, test.particle_density)
    reading = psd.at([CLAY_LIMIT])[0] / 100 * test.initial_concentration / gs_correction(water.specific_gravity)
    hydrometer = test.hydrometer
    depth = hydrometer.effective_depth(reading, test.cylinder_area)
    return [(t, depth / Suspension.at_temperature(t, test.particle_density).stokes_speed(CLAY_LIMIT))
            for t in temperatures]
