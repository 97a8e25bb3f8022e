# SPDX-License-Identifier: GPL-2.0-or-later
"""The granulometry report of a sedimentation test: each instrument's readings, its PSD next to the
input PSD, and the error per size range (docs/sedimentation-tests.md section 6)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import figures
from ..constants import D422_CYLINDER_AREA, PIPETTE_DEPTH, PIPETTE_VOLUME
from ..results import Table, write_atomic, write_text
from .instruments import ReadoutSetup, instrument
from .psd import PSD
from .readout import Column, Hydrometer, Readings

SIZE_RANGES_UM = [(0.0, 5.0), (5.0, 20.0), (20.0, 75.0)]


def read_all(column: Column, instruments: list[str], schedule: str = "d422", sphere_depth: float | None = None,
             pipette_depth: float = PIPETTE_DEPTH, pipette_volume: float = PIPETTE_VOLUME,
             cylinder_area: float = D422_CYLINDER_AREA, hydrometer: Hydrometer | None = None) -> tuple[list[Readings], list[str]]:
    """Readings of the chosen instruments at the schedule's times that the frames cover.

    Parameters
    ----------
    column : Column
        The simulated (or analytic) suspension at the frame times.
    instruments : list of str
        Names in ``sediment.lab.instruments.INSTRUMENTS`` (an unknown one is refused).
    schedule : str
        Reading times: ``"d422"``, ``"d7928"`` or ``"bravo"`` (the buoyancy sphere reads on Bravo et
        al.'s times with ``"d422"``).
    sphere_depth : float, optional
        Buoyancy sphere centre depth [m]; default 0.3 of the column height.
    pipette_depth, pipette_volume : float
        Pipette tip depth [m] and sample volume [m3].
    cylinder_area : float
        Cylinder cross-section [m2], for the hydrometer's level rise.
    hydrometer : Hydrometer, optional
        The instrument; default the nominal 152H.

    Returns
    -------
    readings : list of Readings
        One per instrument with at least one reading time inside the frames.
    notes : list of str
        The readout's inputs (Gs, water, viscosity, c0, height) and the times left out.
    """
    f = column.suspension
    notes = [f"readout inputs: Gs = {f.specific_gravity:.4g}, water {f.fluid_density:.6g} kg/m3, viscosity "
             f"{f.viscosity:.4g} Pa s, c0 = {column.initial_concentration():.4g} kg/m3, column {column.height:.4g} m"]
    if column.water_text():
        notes.append(column.water_text())
    # a reading time at the last frame's to the digits a sum of time steps keeps is read at that frame
    last = column.time[-1]
    setup = ReadoutSetup(schedule, sphere_depth, pipette_depth, pipette_volume, cylinder_area, hydrometer)
    chosen = [instrument(name) for name in instruments]    # every name checked before any reads
    results = []
    for name, reader in zip(instruments, chosen):
        read, times = reader.simulated(column, setup)
        times = np.where(np.abs(times - last) <= 1e-9 * last, last, times)
        early, late = int(np.sum(times <= column.time[0])), int(np.sum(times > column.time[-1]))
        covered = times[(times > column.time[0]) & (times <= column.time[-1])]
        if early:
            notes.append(f"{name}: {early} of {len(times)} reading times come before the first frame after the start "
                         f"(at {column.time[min(1, len(column.time) - 1)] / 60:.3g} min)")
        if late:
            notes.append(f"{name}: {late} of {len(times)} reading times come after the last frame (at "
                         f"{column.time[-1] / 60:.6g} min)")
        # A reading is interpolated between the frames around it: frames farther apart than the
        # reading's own time would make it a guess.
        index = np.clip(np.searchsorted(column.time, covered), 1, len(column.time) - 1)
        gaps = column.time[index] - column.time[index - 1]
        if np.any(gaps > covered):
            k = int(np.argmax(gaps > covered))
            raise ValueError(f"{name}: the frames around the reading at {covered[k] / 60:.3g} min are "
                             f"{gaps[k] / 60:.3g} min apart, longer than the reading's own time: it would be a guess "
                             "between them; write frames more often (a lower --courant, or a column nearer the "
                             "cylinder's height)")
        if len(covered):
            results.append(read(column, covered))
    return results, notes


def error_summary(readings: list[Readings], psd: PSD) -> list[tuple[str, str, int, float]]:
    """(instrument, size range, readings in it, mean |P - PSD| in percentage points)."""
    rows = []
    for r in readings:
        d_um = r.diameter * 1e6
        for lo, hi in SIZE_RANGES_UM:
            inside = (d_um >= lo) & (d_um < hi)
            error = float(np.mean(np.abs(r.percent_finer[inside] - psd.at(r.diameter[inside])))) if inside.any() else np.nan
            rows.append((r.instrument, f"{lo:g}-{hi:g} um", int(inside.sum()), error))
    return rows


@dataclass
class Granulometry:
    """A sedimentation test read out: the instruments' readings, notes on the inputs, and the PSDs
    (input and simulated) they are compared with."""

    readings: list[Readings]
    notes: list[str] = field(default_factory=list)
    psd: PSD | None = None
    simulated: PSD | None = None
    title: str = ""

    def references(self) -> list[tuple[str, PSD]]:
        """The PSDs given to compare with, by name ("input", "simulated")."""
        return [(name, curve) for name, curve in (("input", self.psd), ("simulated", self.simulated))
                if curve is not None]

    def table(self) -> Table:
        """Mean |P - PSD| per reference, instrument and size range; the notes give the inputs."""
        table = Table(["reference", "instrument", "size_range", "readings", "mean_abs_error_points"],
                      notes=list(self.notes))
        for name, curve in self.references():
            for reader, size_range, count, error in error_summary(self.readings, curve):
                table.add(name, reader, size_range, count, f"{error:.4g}")
        return table

    def save(self, folder: Path) -> list[Path]:
        """<instrument>.csv per instrument, errors.csv (with a reference PSD) and granulometry.png/.pdf."""
        folder = Path(folder)
        written = [path for r in self.readings for path in r.save(folder)]
        if self.references():
            written.append(write_text(folder / "errors.csv", self.table().csv()))
        return written + _plot(self, folder)


def granulometry(column: Column, instruments: list[str], psd: PSD | None = None, simulated: PSD | None = None,
                 title: str = "", **options) -> Granulometry:
    """`read_all` (same options) as a result to tabulate and save, compared with the PSDs given."""
    readings, notes = read_all(column, instruments, **options)
    return Granulometry(readings, notes, psd, simulated, title)


def _plot(report: Granulometry, folder: Path) -> list[Path]:
    plt = figures.pyplot()
    psd, simulated, readings, title = report.psd, report.simulated, report.readings, report.title
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for curve, style, label in ((psd, "k-", "input PSD"), (simulated, "k--", "simulated PSD")):
        if curve is not None:
            d = np.exp(np.linspace(np.log(curve.diameter[0]), np.log(curve.diameter[-1]), 300))
            ax.plot(d * 1e6, curve.at(d), style, lw=1.5, label=label)
    for r, marker in zip(readings, "osD"):
        ax.plot(r.diameter * 1e6, r.percent_finer, marker + "-", ms=5, lw=1, label=r.instrument)
    ax.set_xscale("log")
    ticks = [t for t in (1, 2, 5, 10, 20, 50, 100, 200) if ax.get_xlim()[0] <= t <= ax.get_xlim()[1]]
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax.set_xlabel("diameter [um]")
    ax.set_ylabel("percent finer by mass [%]")
    ax.set_ylim(0, 105)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    if title:
        ax.set_title(title)
    fig.tight_layout()
    written = [write_atomic(folder / f"granulometry.{ext}", lambda tmp, ext=ext: fig.savefig(tmp, dpi=150, format=ext))
               for ext in ("png", "pdf")]
    plt.close(fig)
    return written
