# SPDX-License-Identifier: GPL-2.0-or-later
"""From a laboratory's sheets to the sample's PSD (docs/inverse.md): `invert` and its result."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import figures
from ..constants import HYDROMETER_TYPES, LAB_TEMPERATURE
from ..lab import texture
from ..lab.instruments import HydrometerTest, hydrometer, instrument
from ..lab.psd import NOT_FITTING
from ..lab.readout import Suspension, gs_correction
from ..lab.sheet import Reduction, Sheet, SieveSheet, SheetError, check_sheet, standard_reduction
from ..results import Table, write_text
from ..sim.scene import COLUMN_DIAMETERS
from .breakdown import Breakdown, breakdown, breakdown_band
from .fit import ROUGHNESS_DECADES, draw_placement, end_placement, fit, penalty
from .grid import NEAR, TOP, SizeGrid, size_grid
from .model import LabTest, cut_diameters, effective_times, linearise, psd_of, run_forward, solids_signal, \
    whole_sample_reading

CONVERGED = 0.2           # points of percent finer between rounds
EXTREME_PLACEMENT = 100.0  # the tails' extreme placements: 0.01 point off costs a unit of chi-square


@dataclass
class Inversion:
    """The recovered PSD of the whole sample with its band and draws, the standard reduction, the fit
    and its verdict, and every value of the test it used."""

    diameter: np.ndarray         # [m] the reported diameters: the bins' edges (and sieves above a split)
    percent: np.ndarray          # recovered percent finer, of the whole dry sample
    low: np.ndarray
    high: np.ndarray
    basis: np.ndarray            # what pins each diameter (sediment.inverse.grid)
    draws: np.ndarray            # [draws, diameters] the PSDs the data allow, for the band and the texture
    reduction: list[Reduction]       # the standard reduction of each sheet (percent of the whole sample)
    fit_rows: list[tuple[str, float, float, float, float, float]]       # instrument, time, opening, data, model, sigma
    chi2: float
    rounds: int
    smoothness: float
    resolution: str
    inputs: dict
    sieve: tuple[np.ndarray, np.ndarray] | None = None                  # openings [m], percent passing
    notes: list[str] = field(default_factory=list)
    corrections: Breakdown | None = None    # what moves the answer from the standard reduction, effect by effect

    @property
    def measured(self) -> np.ndarray:
        """Whether a reading or a sieve pins each diameter."""
        return np.isin(self.basis, ("reading", "sieve"))

    @property
    def reduced_chi2(self) -> float:
        """Chi-square per reading or sieve."""
        return self.chi2 / max(len(self.fit_rows), 1)

    @property
    def consistent(self) -> bool:
        """Whether some PSD explains the sheets within their noise (chi-square per reading < 4)."""
        return self.reduced_chi2 < 4.0

    @property
    def verdict(self) -> str:
        """The console's last line: whether a PSD explains the sheets."""
        if self.consistent:
            return f"verdict: fits (chi-square per reading {self.reduced_chi2:.3g})"
        return (f"verdict: {NOT_FITTING}: chi-square per reading {self.reduced_chi2:.3g} (>= 4): no PSD of this sample "
                "under this physics gives these readings within their noise")

    def texture(self) -> texture.TextureReport:
        """Clay, silt, sand and gravel, the USDA class, D10-D60, Cu and Cc, with their bands from the draws."""
        return texture.texture_report(self.diameter, self.percent, self.draws)

    def table(self) -> Table:
        """Percent finer with its band at each reported diameter, and what pins it."""
        table = Table(["diameter_um", "percent_finer", "low", "high", "measured", "basis"], notes=self.notes)
        for d, p, low, high, measured, basis in zip(self.diameter * 1e6, self.percent, self.low, self.high,
                                                    self.measured, self.basis):
            table.add(float(d), float(p), float(low), float(high), int(measured), basis)
        return table

    def save(self, folder: Path) -> list[Path]:
        """psd.csv, reduction.csv, corrections.csv, fit.csv, texture.csv, gradation.csv, invert.json and the
        figures invert.png, corrections.png, gradation.png, texture.png. Where the fit fails, every table's
        first line says so."""
        folder = Path(folder)
        first = "" if self.consistent else f"# {NOT_FITTING}: these files come from a fit that does not explain the " \
                                           "sheets (invert.json, 'notes')\n"
        reduction = Table(["instrument", "time_min", "reading", "correction", "meniscus", "unit", "temperature_C",
                           "depth_cm", "diameter_um", "percent_finer"],
                          notes=["hydrometer: reading, correction (the composite correction at that reading: the blank) "
                                 "and meniscus as the instrument reads (152H g/L, 151H specific gravity, as 1000 (R - 1) "
                                 "/ 0.6226 g/L of a 152H); depth_cm is D7928's H_m at reading + meniscus (the surface's "
                                 "graduation, from the calibration, less V_B / 2A); percent_finer is 100 a (reading - "
                                 "correction) / c0 in g/L"])
        for r in self.reduction:
            kind = instrument(r.instrument, r.scale.name)
            reading = r.scale.as_read(r.reading) if kind.on_hydrometer_scale else r.reading
            unit = kind.sheet_unit()
            for row in zip(r.time / 60, reading, r.correction / r.scale.per_unit, r.temperature, r.depth * 100,
                           r.diameter * 1e6, r.percent):
                reduction.add(r.instrument, *map(float, row[:3]), r.meniscus / r.scale.per_unit, unit,
                              *map(float, row[3:]))
        fitted = Table(["instrument", "time_min", "opening_mm", "measured", "simulated", "residual_sigma"])
        for name, t, opening, measured, model, sigma in self.fit_rows:
            fitted.add(name, "" if math.isnan(t) else t / 60, "" if math.isnan(opening) else opening * 1e3,
                       measured, model, (model - measured) / sigma)
        report = self.texture()
        summary = {"consistent": self.consistent, "chi2_per_reading": self.reduced_chi2, "verdict": self.verdict,
                   "inputs": self.inputs,
                   "psd": {"diameter_um": (self.diameter * 1e6).tolist(), "percent_finer": self.percent.tolist(),
                           "low": self.low.tolist(), "high": self.high.tolist(), "basis": self.basis.tolist()},
                   "texture": report.summary(), "rounds": self.rounds, "smoothness": self.smoothness,
                   "resolution": self.resolution, "notes": self.notes,
                   "corrections": None if self.corrections is None else self.corrections.summary()}
        written = [write_text(folder / "psd.csv", first + self.table().csv()),
                   write_text(folder / "reduction.csv", first + reduction.csv()),
                   write_text(folder / "fit.csv", first + fitted.csv())]
        mark = "" if self.consistent else f" ({NOT_FITTING}: no PSD explains the sheets)"
        written += [write_text(path, first + path.read_text()) if first and path.suffix == ".csv" else path
                    for path in report.save(folder, mark)]
        if self.corrections is not None:
            written += [write_text(folder / "corrections.csv", first + self.corrections.table().csv()),
                        self.corrections.plot(folder / "corrections.png")]
        written += [write_text(folder / "invert.json", json.dumps(summary, indent=1) + "\n"), self.plot(folder / "invert.png")]
        points = [(f"standard reduction ({r.instrument})", r.diameter, r.percent) for r in self.reduction]
        written.append(texture.gradation_figure(folder / "gradation.png", self.diameter, self.percent, self.low,
                                                self.high, self.sieve, points, title="gradation" + mark))
        return written

    def plot(self, path: Path) -> Path:
        """The recovered PSD with its band and the standard reduction; the fit's residuals."""
        plt = figures.pyplot()
        fig, (ax, res) = plt.subplots(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [3, 2]})
        d = self.diameter * 1e6
        ax.fill_between(d, self.low, self.high, color="C0", alpha=0.25, label="band")
        ax.plot(d, self.percent, "C0-", label="recovered PSD")
        ax.plot(d[self.measured], self.percent[self.measured], "C0o", ms=4, label="at a reading's or a sieve's diameter")
        ax.plot(d[~self.measured], self.percent[~self.measured], "o", mec="C0", mfc="white", ms=4,
                label="between them, or in a tail")
        for k, r in enumerate(self.reduction):
            ax.plot(r.diameter * 1e6, r.percent, "s", ms=5, color=f"C{k + 1}", label=f"standard reduction ({r.instrument})")
        if self.sieve is not None:
            ax.plot(self.sieve[0] * 1e6, self.sieve[1], "kv", ms=6, label="sieves")
        ax.set(xscale="log", xlabel="diameter [um]", ylabel="percent finer [%]", ylim=(0, 100),
               title="the sample's PSD from the sheets" + ("" if self.consistent else f" ({NOT_FITTING})"))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        for name in dict.fromkeys(r[0] for r in self.fit_rows if r[0] != "sieve"):
            rows = [r for r in self.fit_rows if r[0] == name]
            res.plot([r[1] / 60 for r in rows], [(r[4] - r[3]) / r[5] for r in rows], "o-", ms=4, label=name)
        res.axhline(0, color="k", lw=0.8)
        res.set(xscale="log", xlabel="time [min]", ylabel="(simulated - measured) / noise",
                title=f"fit: chi2 per reading {self.reduced_chi2:.2g}")
        res.legend(fontsize=8)
        res.grid(alpha=0.3)
        return figures.save(fig, path)


@dataclass(frozen=True)
class SieveData:
    """The sieve sheet as the fit takes it: the openings below the specimen's top, their percent of the
    specimen and its noise, and the specimen's share of the whole sample."""

    opening: np.ndarray
    percent: np.ndarray          # of the specimen
    top: float                   # the specimen's largest grain [m]
    share: float                 # of the whole sample in the specimen (1 without a split)
    whole: SieveSheet | None
    noise: float                 # of a sieve's percent passing [points of the whole sample]

    @property
    def sigma(self) -> np.ndarray:
        """Each sieve's noise in points of the specimen."""
        return np.full(len(self.opening), self.noise / self.share)


def sieve_data(sieve: SieveSheet | None, split: float | None, noise: float) -> SieveData:
    """What the sieve sheet says of the hydrometer's specimen. Without a split the specimen is the whole
    sample, so its coarsest grain is the finest sieve all of it passes; with one, the specimen is the
    part passing the split sieve, whose percent passing scales the rest."""
    if sieve is None:
        if split is not None:
            raise ValueError("--split needs the sieve sheet: the percent passing the split sieve sets the specimen's "
                             "share of the sample")
        return SieveData(np.empty(0), np.empty(0), TOP, 1.0, None, noise)
    if split is not None:
        at = np.flatnonzero(np.abs(np.log(sieve.opening / split)) < math.log(NEAR))
        if not len(at):
            raise SheetError(f"{sieve.label}: no sieve of {split * 1e3:g} mm, the split: the sheet must give the "
                             "percent passing it")
        share = sieve.passing[at[0]] / 100.0
        if share <= 0:
            raise SheetError(f"{sieve.label}: nothing passes the {split * 1e3:g} mm split: there is no specimen")
        top = sieve.opening[at[0]]
    else:
        whole = np.flatnonzero(sieve.passing >= 100.0)
        if not len(whole):
            raise SheetError(f"{sieve.label}: {sieve.passing[-1]:g} % passes the largest sieve "
                             f"({sieve.opening[-1] * 1e3:g} mm), so the sample has coarser grains: give the sieve "
                             "the whole sample passes, or --split OPENING_MM where the hydrometer's specimen is the "
                             "part passing one sieve")
        share, top = 1.0, sieve.opening[whole[0]]
    below = sieve.opening < top / NEAR
    return SieveData(sieve.opening[below], sieve.passing[below] / share, top, share, sieve, noise)


def invert(sheets: list[Sheet], test: LabTest, folder: Path, *, sieve: SieveSheet | None = None,
           split: float | None = None, bins: int = 24, particles: int = 20000, courant: float = 4.0, rounds: int = 4,
           draws: int = 64, seed: int = 1, budget_band: float = 0.0) -> Inversion:
    """Recovers a sample's particle-size distribution from a laboratory's sheets of readings.

    The readings are simulated: DEM runs of the test in its cylinder, with the instruments reading
    the simulated column at the sheets' times. The masses of size bins whose simulated readings (and
    the sieves' percent passing, when given) match the sheets' are found by a constrained least
    squares; further runs with the fitted PSD update the hindrance, and draws of the data's noise
    give the band. The method and its limits are described in docs/inverse.md.

    Parameters
    ----------
    sheets : list of Sheet
        The readings (any of hydrometer, pipette, buoyancy sphere, one sheet each or several).
    test : LabTest
        Specimen mass, particle density, cylinder and instruments.
    folder : Path
        Where the forward runs go.
    sieve : SieveSheet, optional
        The same sample's sieve analysis (percent of the whole sample passing each opening).
    split : float, optional
        [m] the sieve whose passing part is the hydrometer's specimen (D422's 2 mm); `test.mass` is then the
        specimen's mass.
    bins : int
        Size bins between the finest and the coarsest reading's cut.
    particles, courant : int, float
        Resolution of the forward runs: simulated parcels, and the Courant number of their time steps.
    rounds : int
        Forward runs at most.
    draws : int
        Draws of the PSDs the data allow, for the band (their central 95 %) and the texture.
    seed : int
        Seed of the draws.
    budget_band : float
        Points of percent finer the physics' uncertainty adds (an error budget's physical total).

    Returns
    -------
    Inversion
        The PSD of the whole sample with its band, what pins each diameter, the standard reduction,
        the fit and its verdict.
    """
    if not sheets:
        raise ValueError("no sheet of readings to invert (a sieve sheet alone gives no sedimentation data)")
    recorded = np.concatenate([s.temperature[np.isfinite(s.temperature)] for s in sheets])
    mean_temperature = float(recorded.mean()) if len(recorded) else LAB_TEMPERATURE
    water = Suspension.at_temperature(mean_temperature, test.particle_density)
    c0 = test.initial_concentration
    signals = [solids_signal(sheet, test, water) for sheet in sheets]
    corrected = [test.corrected(sheet) for sheet in sheets]
    for sheet, reading, signal in zip(sheets, corrected, signals):
        kind = sheet.kind
        below = np.flatnonzero(reading < -2 * test.noise[sheet.instrument]) if kind.on_hydrometer_scale else []
        if len(below):
            k = below[0]
            raise SheetError(f"{sheet.where(k)}: the reading ({sheet.scale.quoted(sheet.reading[k])} on the sheet) is "
                             f"{reading[k]:.3g} g/L "
                             "after its composite correction: the correction (blank or --zero-correction) is larger "
                             "than the reading; check both")
        # the tolerance: twice the reading's noise, and 2 % of the solids' signal for the sampling of a real
        # suspension (a pipette's first samples can draw a little more than the mean)
        noise = test.noise[sheet.instrument]
        tolerance = max(2 * noise, 0.02 * signal)
        stated = "" if not kind.noise_as_read else \
            f" (now {kind.noise_text(noise)}; the tolerance is twice it, or 2 % of the solids' signal)"
        check_sheet(sheet, whole_sample_reading(sheet, test, water), tolerance, reading, kind.noise_option + stated)
    sieves = sieve_data(sieve, split, test.noise["sieve"])
    if split is None and sieves.top > test.height / COLUMN_DIAMETERS:
        d422 = [p for o, p in zip(sieve.opening, sieve.passing) if abs(o - 2e-3) < 1e-5]
        raise SheetError(f"{sieve.label}: the whole sample passes only the {sieves.top * 1e3:g} mm sieve, and a column of "
                         f"{test.height:.3g} m settles grains up to {test.height / COLUMN_DIAMETERS * 1e3:.3g} mm ("
                         f"{COLUMN_DIAMETERS} diameters): the hydrometer's specimen is the part passing a sieve (D422's "
                         f"2 mm{f', which {d422[0]:g} % passes' if d422 else ''}); give --split 2.0 (or the opening it "
                         "was split at)")
    reduction = [standard_reduction(sheet, water, c0, test.hydrometer, test.cylinder_area, test.sphere, test.meniscus,
                                    test.correction(sheet)) for sheet in sheets]
    times = [effective_times(s, water) for s in sheets]
    grid = size_grid(cut_diameters(sheets, times, test, water), bins, sieves.opening, sieves.top)
    shares = first_guess(reduction, sieves, grid)
    sieve_rows = 100.0 * grid.cumulative(sieves.opening)
    data = np.concatenate(corrected + [sieves.percent])
    sigma = np.concatenate([np.full(len(s.time), test.noise[s.instrument]) for s in sheets] + [sieves.sigma])
    # each sheet's rows among the data (the sieves' after them)
    ends = np.cumsum([0] + [len(s.time) for s in sheets])
    rows_of = [slice(a, b) for a, b in zip(ends[:-1], ends[1:])]
    readings = int(ends[-1])
    # the readings' times in water 1 C warmer: the runs reach the latest, and the band's thermometer
    # offset (below) is linear in the readings there
    warmer = [effective_times(s, water, 1.0) for s in sheets]
    t_end = 1.02 * max(t[-1] for t in warmer)

    def model(run, x, at=times):
        base, jac = linearise(run, x, sheets, at)
        return np.concatenate([base, sieve_rows @ x]), np.vstack([jac, sieve_rows])

    previous, weight, reading_sigma, converged = None, None, sigma, False
    for round_number in range(1, rounds + 1):
        # every bin keeps some mass in the run, so that its columns can be scaled to any share
        spread = 0.8 * shares + 0.2 / len(shares)
        run = run_forward(psd_of(spread, grid), grid, test, water, t_end, folder / f"round{round_number}",
                          particles, courant, seed)
        if round_number == 1:
            # the forward model's own sampling error: the same PSD with another placement; its rms
            # difference per instrument (over sqrt 2) adds to each reading's noise
            other = run_forward(psd_of(spread, grid), grid, test, water, t_end, folder / "sampling", particles,
                                courant, seed + 1)
            gap = run.readings(shares, sheets, times) - other.readings(shares, sheets, times)
            model_sigma = np.zeros(len(data))
            for rows, signal in zip(rows_of, signals):
                # and at least the resolution's 0.2 points of percent finer (the time step's, error budget)
                model_sigma[rows] = max(math.sqrt(np.mean(gap[rows] ** 2) / 2), 0.002 * signal)
            sigma = np.sqrt(reading_sigma ** 2 + model_sigma ** 2)
        for _ in range(2):    # Gauss-Newton on this run's columns
            base, jac = model(run, shares)
            shares, chi2, weight = fit(jac, base, shares, data, sigma, grid)
        percent = 100 * np.cumsum(shares)[:-1]
        moved = math.inf if previous is None else float(np.max(np.abs(percent - previous)))
        if moved < CONVERGED:
            converged = True
            break
        previous = percent
    base, jac = model(run, shares)
    chi2 = float(np.sum(((base - data) / sigma) ** 2))
    # The band: draws of the PSDs the data allow, each fit again with the readings and sieves drawn from
    # their noise (and the forward model's), the thermometer's offset drawn, the smoothness penalty aiming
    # at a draw of its prior with a weight drawn below the chosen one, and each tail's mass placed as drawn
    # (randomise-then-optimise). An offset moves every reading's time alike; its effect on the readings is
    # taken as linear (the record 1 C warmer).
    per_degree = np.concatenate([run.readings(shares, sheets, warmer) - base[:readings], np.zeros(len(sieves.opening))])
    rng = np.random.default_rng(seed)
    penalty_rows = len(penalty(grid))
    specimen_draws = []
    # the composite correction is one reading of the blank cylinder, subtracted from every reading of the
    # sheet: its error, a reading's, is common to them (as the thermometer's offset is)
    blank_rows = [rows for sheet, rows in zip(sheets, rows_of) if sheet.kind.on_hydrometer_scale]
    for _ in range(draws):
        noisy = data + rng.normal(0.0, sigma) - rng.normal(0.0, test.thermometer) * per_degree
        for rows in blank_rows:
            noisy[rows] += rng.normal(0.0, test.noise[HydrometerTest.name])
        x, _, _ = fit(jac, base, shares, noisy, sigma, grid, weight * 10 ** -rng.uniform(0, ROUGHNESS_DECADES),
                      rng.normal(0.0, 1.0, penalty_rows),
                      draw_placement(grid, rng))
        drawn = 100 * np.cumsum(x) / x.sum()
        drawn[-1] = 100.0    # the top at 100 % exactly, as the sheet says (the sum leaves 99.99999999999999)
        specimen_draws.append(drawn)
    # the tails' extreme placements the data allow: each tail's mass in its finest bin, then in its coarsest;
    # the band in a tail covers both
    extremes = []
    for end in (0, -1):
        x, _, _ = fit(jac, base, shares, data, sigma, grid, weight, None, end_placement(grid, end), EXTREME_PLACEMENT)
        extremes.append(100 * np.cumsum(x) / x.sum())
    specimen = 100 * np.cumsum(shares)
    specimen[-1] = 100.0
    result = _whole_sample(grid, specimen, np.array(specimen_draws).reshape(-1, grid.bins), np.array(extremes), sieves,
                           budget_band, rng)
    rows = []
    for sheet, at in zip(sheets, rows_of):
        rows += [(sheet.instrument, float(t), math.nan, float(m), float(f), float(s))
                 for t, m, f, s in zip(sheet.time, data[at], base[at], sigma[at])]
    rows += [("sieve", math.nan, float(o), float(m), float(f), float(s))
             for o, m, f, s in zip(sieves.opening, data[readings:], base[readings:], sigma[readings:])]
    resolution = (f"{particles} parcels, Courant {courant:g}, standard drag curve + Richardson & Zaki, water at "
                  f"{mean_temperature:.3g} C")
    inputs = test.record() | {
        "sheets": [str(s.path) for s in sheets] + ([str(sieve.path)] if sieve is not None else []),
        "composite_correction": {str(s.path): ("blank column" if len(s.blank) else test.zero_correction)
                                 for s in sheets if s.kind.on_hydrometer_scale},
        "hydrometer_type": next((s.scale.name for s in sheets if s.kind.on_hydrometer_scale),
                                HYDROMETER_TYPES[0]),
        "temperatures_C": [float(recorded.min()), float(recorded.max())] if len(recorded) else None,
        "split_mm": None if split is None else split * 1e3, "specimen_share": sieves.share,
        "top_um": sieves.top * 1e6}
    whole = [r.scaled(sieves.share) for r in reduction]
    out = Inversion(*result, whole, rows, chi2, round_number, float(weight), resolution, inputs,
                    None if sieve is None else (sieve.opening, sieve.passing))
    out.corrections = breakdown(sheets, reduction, times, test, water, grid, data, sigma, sieve_rows, shares,
                                sieves.share, (out.diameter, out.low, out.high))
    # the hindrance is physical at its size, within the measured spread of its slope: that spread widens the band
    below, above = out.corrections.hindrance_band(water, out.diameter)
    measured = ~np.isin(out.basis, ("floor", "top"))
    out.low[measured] = np.clip(out.percent - np.hypot(out.percent - out.low, below), 0.0, 100.0)[measured]
    out.high[measured] = np.clip(out.percent + np.hypot(out.high - out.percent, above), 0.0, 100.0)[measured]
    out.corrections = breakdown_band(out.corrections, out.diameter, out.low, out.high)
    out.notes.append(out.corrections.line())
    out.notes.append(f"forward model: {resolution}; {round_number} round(s)" + (
        "" if converged else f", not converged: the last round still moved the PSD by up to {moved:.2g} points "
                             f"(more than {CONVERGED:g}), as the hindrance of each round's PSD moves the next; the answer "
                             "stands, but read differences smaller than that as the model's own spread, which the band "
                             "does not hold: more --particles steady the runs"))
    unread = [s for s in sheets
              if s.kind.on_hydrometer_scale and not len(s.blank) and test.zero_correction == 0]
    if unread:
        a = gs_correction(test.particle_density / 1000.0)
        out.notes.append(f"no composite correction for {', '.join(s.path.name for s in unread)}: its readings are "
                         "taken as corrected already; a typical blank of 2-7 g/L (dispersant, temperature, meniscus) "
                         f"would lower percent finer by {100 * a * 2 / c0:.2g}-{100 * a * 7 / c0:.2g} points: give the "
                         "blank column or --zero-correction")
    in_tails = [f"D{level}" for level in texture.LEVELS if _in_tail(out.diameter, out.percent, out.basis, level)]
    if in_tails:
        out.notes.append(f"{', '.join(in_tails)} lie(s) in a tail, where the data give the mass but not its placement: "
                         "read them with their band")
    step = _sieves_step(grid, shares, sieves) or _sieves_tension(rows)
    if step is not None:
        out.notes.append(step)
    out.notes.append(_inputs_line(test, inputs))
    out.notes.append("measured 1: a reading's cut or a sieve; 0: between them, where the value and its band are those of "
                     "the smoothest PSDs the data allow (a step there is not seen), or in a tail (basis), where the "
                     "band covers every placement of the tail's mass the data allow")
    if split is not None:
        out.notes.append(f"specimen: the {sieves.share * 100:.4g} % passing {split * 1e3:g} mm; the curve is of the whole "
                         "sample")
    flagged = [r for r in rows if abs(r[4] - r[3]) > 4 * r[5]]
    for name, t, opening, measured, modelled, s in flagged:
        where = f"{opening * 1e3:g} mm" if name == "sieve" else f"{t / 60:g} min"
        out.notes.append(f"{name} at {where} is {abs(modelled - measured) / s:.1f} noise units off the fit: check it")
    read = [r for r in rows if r[0] != "sieve"]
    if len(read) >= 5 and out.reduced_chi2 < TOO_GOOD:
        units = {s.instrument: instrument(s.instrument, s.scale.name).noise_text(test.noise[s.instrument]) for s in sheets}
        out.notes.append(f"note: the readings lie far closer to the fit than their stated errors say (chi-square per "
                         f"reading {out.reduced_chi2:.2g}, where about 1 is expected): the band, which those errors set "
                         f"({', '.join(f'{k} {v}' for k, v in units.items())}), is wider than the readings need; or the "
                         "readings are not in the instrument's unit (a 151H's 1000 (G - 1) is not a 152H's g/L: give "
                         "--hydrometer-type 151H and its specific gravities)")
    if not out.consistent:
        out.notes.append(f"{NOT_FITTING}: a misread, a flocculated sample, or a wrong specimen mass or particle density "
                         "(check the readings named above)")
    out.notes.append(out.verdict)
    return out


def _in_tail(diameter: np.ndarray, percent: np.ndarray, basis: np.ndarray, level: float) -> bool:
    """Whether the curve reaches `level` percent finer within a tail (or below the floor's edge)."""
    k = int(np.argmax(percent >= level))
    return percent[k] >= level and basis[k] in ("fine tail", "coarse tail", "floor")


STEP_WARNING = 15.0        # points between the coarsest cut and the next sieve that deserve a second look
STEP_STEEPNESS = 50.0      # and per decade of diameter: a soil's silt rises by 20-40 points a decade


def _sieves_step(grid: SizeGrid, shares: np.ndarray, sieves: SieveData) -> str | None:
    """A note where the readings and the sieves meet with a step: a real gap in the grading, or a wrong
    --mass or another sample's sieve sheet, which such a step can absorb and still fit."""
    cut = np.flatnonzero(grid.basis == "reading")[-1]
    # the top is a sieve too where a sieve sheet says so (the split's, or the largest the specimen passes)
    sieved = (grid.basis == "sieve") | ((grid.basis == "top") & (sieves.whole is not None))
    above = np.flatnonzero(sieved & (np.arange(grid.bins) > cut))
    if not len(above):
        return None
    cumulative = 100 * np.cumsum(shares)
    rise = cumulative[above[0]] - cumulative[cut]
    # per decade of diameter: a protocol whose last cut is far below the sieves (4 h and 21 h readings, cuts
    # near 5 um, the 53 um sieve) spans a decade of silt, which rises there by itself
    steepness = rise / math.log10(grid.edges[above[0]] / grid.edges[cut])
    if rise < STEP_WARNING or steepness < STEP_STEEPNESS:
        return None
    return (f"check: the curve rises by {rise:.3g} points between the coarsest reading's cut ({grid.edges[cut] * 1e6:.3g} "
            f"um) and the {grid.edges[above[0]] * 1e3:g} mm sieve ({steepness:.3g} points per decade of diameter): a "
            "gap in the grading, or a wrong --mass, a sieve sheet of another sample or readings in another unit (a "
            "151H's as a 152H's: --hydrometer-type), which a step there absorbs")


# chi-square per reading under which the readings fit too well for their stated errors: a real laboratory's
# sheets fit at 0.4-0.7, synthetic sheets read to 0.5 g/L at 0.004-0.09 (many bins fitted to few readings);
# a 151H's 1000 (G - 1) read as g/L shrinks the scatter by 0.62^2
TOO_GOOD = 0.03
TENSION = 2.0    # noise units each way: by chance both at once about once in a thousand fits


def _sieves_tension(rows: list[tuple[str, float, float, float, float, float]]) -> str | None:
    """A note where the fit is pulled apart at the sieves' join: the first reading of an instrument (its
    coarsest cut) and the finest sieve off the fit by TENSION noise units or more, the other way each. A
    step between them has absorbed what they disagree on; the step note sees it only when it is steep."""
    sieves = [r for r in rows if r[0] == "sieve"]
    if not sieves:
        return None
    finest = min(sieves, key=lambda r: r[2])
    pull = (finest[4] - finest[3]) / finest[5]
    for name in dict.fromkeys(r[0] for r in rows if r[0] != SieveSheet.instrument):
        first = min((r for r in rows if r[0] == name), key=lambda r: r[1])
        against = (first[4] - first[3]) / first[5]
        if abs(pull) >= TENSION and abs(against) >= TENSION and pull * against < 0:
            return (f"check: the {name}'s first reading ({first[1] / 60:g} min, {against:+.1f} noise units off the "
                    f"fit) and the {finest[2] * 1e3:g} mm sieve ({pull:+.1f}) pull the curve apart where they meet: a "
                    "sieve sheet of another sample, a wrong --mass, a first reading taken before the suspension stilled, "
                    "or a gap in the grading, which a step there absorbs")
    return None


def _noise_text(name: str, noise: float, hydrometer_type: str) -> str:
    """A reading error as its option states it: an instrument's, or the sieves' in points."""
    return f"{noise:g} points" if name == SieveSheet.instrument else instrument(name, hydrometer_type).noise_text(noise)


def _inputs_line(test: LabTest, inputs: dict) -> str:
    """The test's values as the inverse used them, for the console."""
    scale = hydrometer(inputs["hydrometer_type"]).scale
    correction = "; ".join(f"{Path(k).name}: {v if isinstance(v, str) else scale.quoted_step(v)}"
                           for k, v in inputs["composite_correction"].items()) or "none"
    read = "" if scale.in_grams else " (its specific gravity R read as 1000 (R - 1) / 0.6226 g/L of a 152H)"
    temperatures = inputs["temperatures_C"]
    return (f"inputs: specimen {test.mass * 1e3:.5g} g (oven-dry), particle density {test.particle_density:g} kg/m3, "
            f"suspension {test.cylinder_area * test.height * 1e6:.4g} mL in a cylinder of {test.cylinder_area * 1e4:.4g} "
            f"cm2 ({test.height * 100:.4g} cm high), hydrometer {scale.name}{read}: {test.hydrometer.describe(scale)}, "
            f"composite correction {correction}, meniscus {scale.quoted_step(test.meniscus)}, water " + (f"{temperatures[0]:g}-{temperatures[1]:g} C" if temperatures else
                                               "20 C (no temperature recorded)")
            + f", the specimen's largest grain {inputs['top_um']:g} um"
            + (f" (the part passing {inputs['split_mm']:g} mm, {100 * inputs['specimen_share']:.4g} % of the sample)"
               if inputs["split_mm"] else "")
            + "; noise: " + ", ".join(f"{k} {_noise_text(k, v, scale.name)}" for k, v in test.noise.items())
            + f", thermometer {test.thermometer:g} C"
            + "; sheets: " + ", ".join(Path(s).name for s in inputs["sheets"]))


def _whole_sample(grid: SizeGrid, specimen: np.ndarray, draws: np.ndarray, extremes: np.ndarray, sieves: SieveData,
                  budget_band: float, rng: np.random.Generator):
    """The curve of the whole sample from the floor (the finest bin's lower end, 0 % by assumption) up: the
    specimen's scaled by its share, the sieves above the split; the band the draws' central 95 % and the
    tails' extreme placements, widened by the physics' budget."""
    diameter, basis = np.concatenate([[grid.floor], grid.edges]), np.concatenate([["floor"], grid.basis])
    percent = np.concatenate([[0.0], specimen]) * sieves.share
    # each draw's share of the specimen in the sample, from the split sieve's own noise
    shares = np.clip(sieves.share + rng.normal(0.0, sieves.noise / 100, len(draws)), 0.0, 1.0) \
        if sieves.share < 1.0 else np.ones(len(draws))
    draws = np.concatenate([np.zeros((len(draws), 1)), draws], axis=1) * shares[:, None]
    extremes = np.concatenate([np.zeros((len(extremes), 1)), extremes], axis=1) * sieves.share
    whole = sieves.whole
    if whole is not None and sieves.share < 1.0:
        above = whole.opening > sieves.top * NEAR
        diameter = np.concatenate([diameter, whole.opening[above]])
        basis = np.concatenate([basis[:-1], ["sieve"], ["sieve"] * above.sum()])
        percent = np.concatenate([percent, whole.passing[above]])
        drawn = whole.passing[above] + rng.normal(0.0, sieves.noise, (len(draws), above.sum()))
        draws = np.concatenate([draws, np.clip(np.maximum(drawn, draws[:, -1:]), 0.0, 100.0)], axis=1)
    low, high = np.percentile(draws, [2.5, 97.5], axis=0) if len(draws) > 1 else (percent.copy(), percent.copy())
    # the tails' extreme placements are PSDs the data allow: where a tail's mass lies moves the readings
    # next to it, so they bound the band at the cuts as well as in the tails
    spanned = np.arange(extremes.shape[1])
    low[spanned] = np.minimum(low[spanned], extremes.min(axis=0))
    high[spanned] = np.maximum(high[spanned], extremes.max(axis=0))
    below = np.sqrt(np.maximum(percent - low, 0.0) ** 2 + budget_band ** 2)
    above_band = np.sqrt(np.maximum(high - percent, 0.0) ** 2 + budget_band ** 2)
    low, high = np.clip(percent - below, 0, 100), np.clip(percent + above_band, 0, 100)
    top = basis == "top"      # 100 % by the sheet's own statement
    low[top], high[top] = percent[top], percent[top]
    # 0 % at the floor is the forward model's assumption: the data allow anything up to the first edge's
    low[0], high[0] = 0.0, high[1]
    return diameter, percent, low, high, basis, draws


def first_guess(reduction: list[Reduction], sieves: SieveData, grid: SizeGrid) -> np.ndarray:
    """Bin shares from the standard reduction's points and the sieves (of the specimen), 100 % at the top,
    interpolated in log d and made non-decreasing, mixed with a tenth of an even split so that every bin
    has mass for the run to scale."""
    d = np.concatenate([r.diameter for r in reduction] + [sieves.opening, [sieves.top]])
    p = np.concatenate([r.percent for r in reduction] + [sieves.percent, [100.0]])
    order = np.argsort(d)
    d, p = d[order], np.maximum.accumulate(np.clip(p[order], 0, 100))
    at_edges = np.interp(np.log(grid.edges), np.log(d), p, left=p[0], right=100.0)
    shares = np.maximum(np.diff(np.concatenate([[0.0], at_edges])) / 100.0, 0.0)
    shares[-1] += max(1.0 - shares.sum(), 0.0)
    return 0.9 * shares / shares.sum() + 0.1 / len(shares)
