"""The granulometry report of a sedimentation test: each instrument's readings, its PSD next to the
input PSD, and the error per size range (sedimentation-tests.md section 6)."""
from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from .psd import PSD
from .readout import SCHEDULES, BuoyancySphere, Column, Hydrometer, Pipette, Readings

SIZE_RANGES_UM = [(0.0, 5.0), (5.0, 20.0), (20.0, 75.0)]


def read_all(column: Column, instruments: list[str], schedule: str = "d422", sphere_depth: float | None = None,
             pipette_depth: float = 0.10, pipette_volume: float = 25e-6,
             cylinder_area: float = 27.8e-4, hydrometer: Hydrometer | None = None) -> tuple[list[Readings], list[str]]:
    """Readings of the chosen instruments at the schedule's times that the frames cover (the
    hydrometer: the nominal 152H unless another is given); returns them with notes on the inputs
    and the times left out."""
    f = column.fluid
    notes = [f"readout inputs: Gs = {f.specific_gravity:.4g}, water {f.density:.6g} kg/m3, viscosity "
             f"{f.viscosity:.4g} Pa s, c0 = {column.initial_concentration():.4g} kg/m3, column {column.height:.4g} m"]
    results = []
    for name in instruments:
        if name == "hydrometer":
            read = partial((hydrometer or Hydrometer.astm_152h()).read, cylinder_area=cylinder_area)
            times = np.array(SCHEDULES[schedule]) * 60.0
        elif name == "buoyancy":
            read = BuoyancySphere(0.3 * column.height if sphere_depth is None else sphere_depth).read
            times = np.array(SCHEDULES["bravo" if schedule == "d422" else schedule]) * 60.0
        else:
            pipette = Pipette(pipette_depth, pipette_volume)
            read, times = pipette.read, pipette.default_times(column.fluid)
        covered = times[(times > column.time[0]) & (times <= column.time[-1])]
        if len(covered) < len(times):
            notes.append(f"{name}: {len(times) - len(covered)} of {len(times)} reading times lie beyond the "
                         f"frames (last at {column.time[-1] / 60:.3g} min)")
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


def write_report(readings: list[Readings], out: Path, psd: PSD | None = None, simulated: PSD | None = None,
                 title: str = "") -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    written = []
    for r in readings:
        path = out / f"{r.instrument}.csv"
        path.write_text(r.table())
        written.append(path)
    references = [(name, curve) for name, curve in (("input", psd), ("simulated", simulated)) if curve is not None]
    if references:
        path = out / "errors.csv"
        path.write_text("reference,instrument,size_range,readings,mean_abs_error_points\n" + "".join(
            f"{name},{a},{b},{n},{e:.4g}\n" for name, curve in references for a, b, n, e in error_summary(readings, curve)))
        written.append(path)
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
    for ext in ("png", "pdf"):
        fig.savefig(out / f"granulometry.{ext}", dpi=150)
        written.append(out / f"granulometry.{ext}")
    plt.close(fig)
    return written
