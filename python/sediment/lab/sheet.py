# SPDX-License-Identifier: GPL-2.0-or-later
"""A laboratory's sheet of readings (docs/inverse.md): what `sediment invert` takes in, checked row by
row, and the standard ASTM reduction of it.

A sheet is a CSV a laboratory already keeps, one kind per file, told apart by its header:

- hydrometer: ``time_min,reading,temperature_C``, ``blank`` optional (the reading in the control cylinder
  beside each reading, its composite correction); a 152H's in g/L of soil, a 151H's in specific gravity
  (read as the 152H's g/L from then on)
- pipette: ``time_min,depth_cm,mass_g`` (the dry solids of one pipette sample), ``temperature_C`` optional
- buoyancy sphere: ``time_min,apparent_mass_g`` (what the balance shows), ``temperature_C`` optional
- sieves: ``opening_mm,percent_passing`` (percent of the whole dry sample passing each sieve)

A sheet that no sedimenting suspension can give is refused with the reason: times out of order,
missing temperatures, readings on the other hydrometer's scale, readings rising with time or above what the whole
sample in suspension reads.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..constants import LAB_TEMPERATURE, PIPETTE_VOLUME
from ..csvfile import CsvError, CsvFile, read_csv
from .instruments import INSTRUMENTS, Instrument, hydrometer, instrument
from .readout import GRAMS, BuoyancySphere, Hydrometer, Scale, Suspension
from .sheetcheck import SheetError, plausible

# The sheets' kinds by their columns: the instruments' and the sieves'
KINDS = {name: i.columns for name, i in INSTRUMENTS.items()} | {"sieve": ("opening_mm", "percent_passing")}
OPTIONAL = {name: i.optional for name, i in INSTRUMENTS.items()} | {"sieve": ()}


@dataclass(frozen=True)
class Sheet:
    """One instrument's readings: times [s], the readings in the instrument's unit (152H g/L, pipette
    g/L of the sample, sphere apparent mass g), the water temperature at each [C] (NaN: not recorded)
    and, for the pipette, the depth of each sample [m]."""

    instrument: str
    path: Path
    time: np.ndarray
    reading: np.ndarray
    temperature: np.ndarray
    depth: np.ndarray = field(default_factory=lambda: np.empty(0))
    blank: np.ndarray = field(default_factory=lambda: np.empty(0))    # 152H composite correction per reading
    lines: tuple[int, ...] = ()    # each reading's line in the file, for messages
    scale: Scale = GRAMS    # a hydrometer's scale as read (its readings and blank are the 152H's g/L)

    def where(self, k: int) -> str:
        """Reading k as a message names it: its line in the file, and its time."""
        line = f"line {self.lines[k]}, " if self.lines else ""
        return f"{self.label}, {line}{self.time[k] / 60:g} min"

    @property
    def label(self) -> str:
        """The sheet's file and instrument, as messages name it."""
        return f"{self.path.name} ({self.instrument})"

    @property
    def kind(self) -> Instrument:
        """The instrument that read it (a hydrometer of its scale's type)."""
        return instrument(self.instrument, self.scale.name)


@dataclass(frozen=True)
class SieveSheet:
    """A sieve analysis: openings [m], increasing, and the percent of the whole dry sample passing each."""

    path: Path
    opening: np.ndarray
    passing: np.ndarray

    instrument = "sieve"

    @property
    def label(self) -> str:
        """The sheet's file, as messages name it."""
        return f"{self.path.name} (sieve)"


def read_sheet(path: str | Path, pipette_volume: float = PIPETTE_VOLUME, stirred: str | None = None,
               hydrometer_type: str = "152H") -> Sheet | SieveSheet:
    """Reads and checks one sheet (its kind from its header); a pipette's masses become g/L of the sample,
    a hydrometer's readings (of a 152H or 151H: `hydrometer_type`) the 152H's g/L. A `clock` column
    (HH:MM of each reading) stands for `time_min`, counted from `stirred` (HH:MM)."""
    table = _table(path)
    if "clock" in table.header:
        table = _clock_to_minutes(table, stirred)
    path, header = table.path, table.header
    kinds = [k for k, columns in KINDS.items() if set(columns) <= set(header)]
    if not kinds:
        expected = "; ".join(",".join(c) for c in KINDS.values())
        raise SheetError(f"{path}: header {','.join(header)} is none of the sheets (expected {expected})")
    if len(kinds) > 1:
        raise SheetError(f"{path}: the header has the columns of {' and '.join(kinds)} sheets: give each instrument "
                         "a sheet of its own")
    kind = kinds[0]
    unknown = [name for name in header if name not in KINDS[kind] + OPTIONAL[kind]]
    if unknown:
        known = ", ".join(KINDS[kind] + OPTIONAL[kind])
        raise SheetError(f"{path}: column(s) {', '.join(unknown)} are not of a {kind} sheet (its columns: {known}): "
                         "rename or remove them, as a misspelt column would be left out silently")
    if not table.rows:
        raise SheetError(f"{path}: no readings below the header")
    values = {name: np.array(_numbers(table, name, blank=name in ("temperature_C", "blank"))) for name in header}
    lines = [line for line, _ in table.rows]
    if kind == "sieve":
        return _sieve_sheet(path, values["opening_mm"], values["percent_passing"])
    reader = instrument(kind, hydrometer_type)
    plausible(path, lines, values, "time_min", "time_min")
    time = values["time_min"] * 60.0
    if time[0] <= 0 or np.any(np.diff(time) <= 0):
        raise SheetError(f"{path}: the times must be > 0 and increase from row to row")
    values.setdefault("temperature_C", np.full(len(time), math.nan))
    temperature = values["temperature_C"]
    recorded = np.isfinite(temperature)
    if reader.on_hydrometer_scale and not recorded.all():
        missing = ", ".join(str(lines[k]) for k in np.flatnonzero(~recorded))
        raise SheetError(f"{path}: no temperature on line(s) {missing}: a hydrometer's reading needs the temperature "
                         "it was taken at")
    plausible(path, lines, values, "temperature_C", "temperature")
    reading, depth, blank = reader.sheet_readings(path, lines, values, pipette_volume)
    return Sheet(kind, path, time, reading, temperature, depth, blank, tuple(lines),
                 reader.scale if reader.on_hydrometer_scale else GRAMS)


def clock_minutes(text: str, where: str) -> float:
    """Minutes after midnight of a clock time: HH:MM on 24 hours (or H:MM, HH:MM:SS to the minute's
    fraction), or on 12 hours with AM or PM after it (9:19 AM, 3:18 PM, 12:05 AM just after midnight)."""
    words = text.strip().upper().replace(".", "").split()
    half = words.pop() if len(words) == 2 and words[1] in ("AM", "PM") else None
    parts = words[0].split(":") if len(words) == 1 else []
    try:
        values = [int(p) for p in parts]
    except ValueError:
        values = []
    hours = range(1, 13) if half else range(24)
    if len(values) not in (2, 3) or values[0] not in hours or not all(0 <= v < 60 for v in values[1:]):
        raise SheetError(f"{where}: '{text.strip()}' is not a clock time: HH:MM on 24 hours (14:05) or H:MM AM/PM "
                         "(2:05 PM)")
    hour = values[0] % 12 + (12 if half == "PM" else 0) if half else values[0]
    return hour * 60 + values[1] + (values[2] / 60 if len(values) == 3 else 0)


NEXT_DAY_AFTER = 120.0    # min: a clock that falls later than this in a test is past midnight, earlier a slip


def _clock_to_minutes(table: CsvFile, stirred: str | None) -> CsvFile:
    """The sheet with its `clock` column turned into `time_min` after the stirring. A clock that falls
    is a reading past midnight (the next day) where it falls by more than 12 h (23:55 to 00:10), or
    where the reading before it came at least two hours into the test, as the long readings do
    (D7928's 4 and 24 h, Bouyoucos's 2 h); a smaller fall minutes into the test is refused as a slip."""
    if "time_min" in table.header:
        raise SheetError(f"{table.path}: both clock and time_min columns: give the readings' times once")
    if stirred is None:
        raise SheetError(f"{table.path}: the sheet gives clock times: say when the suspension was stirred with "
                         "--stirred HH:MM")
    start = clock_minutes(stirred, "--stirred")
    k = table.header.index("clock")
    rows, previous, day = [], 0.0, 0
    for line, row in table.rows:
        minutes = clock_minutes(row[k], table.where(line)) - start + 1440 * day
        if minutes <= previous and (rows or minutes + 1440 > 0):
            if rows and previous < NEXT_DAY_AFTER and previous - minutes < 720:
                raise SheetError(f"{table.where(line)}: the clock goes back to {row[k].strip()}, {previous:g} min after "
                                 f"the stirring at {stirred}: a slip (a reading past midnight comes after the long "
                                 "readings, not minutes into the test)")
            day += 1
            minutes += 1440
        if minutes <= previous:
            raise SheetError(f"{table.where(line)}: the reading at {row[k].strip()} is not after the one before it")
        rows.append((line, row[:k] + [f"{minutes:.6g}"] + row[k + 1:]))
        previous = minutes
    header = table.header[:k] + ["time_min"] + table.header[k + 1:]
    return replace(table, header=header, rows=rows)


def _sieve_sheet(path: Path, opening_mm: np.ndarray, passing: np.ndarray) -> SieveSheet:
    """Checks a sieve analysis: openings in mm, distinct; percents within 0-100 of the whole sample and
    cumulative (never more passing a finer sieve)."""
    if np.any(opening_mm <= 0):
        raise SheetError(f"{path}: sieve openings must be > 0 mm")
    if opening_mm.max() > 200:
        raise SheetError(f"{path}: a sieve opening of {opening_mm.max():g} mm: write the openings in millimetres "
                         "(0.075 for the 75 um sieve)")
    if opening_mm.min() >= 20:
        raise SheetError(f"{path}: the finest sieve is {opening_mm.min():g} mm: write the openings in millimetres (0.075 "
                         "for the 75 um sieve), not micrometres")
    values, counts = np.unique(opening_mm, return_counts=True)
    if np.any(counts > 1):
        raise SheetError(f"{path}: the sieve opening {values[counts > 1][0]:g} mm appears twice")
    if np.any((passing < 0) | (passing > 100)):
        raise SheetError(f"{path}: percent passing must be within 0-100 (of the whole dry sample)")
    if passing.max() <= 1.0:
        raise SheetError(f"{path}: percent passing tops out at {passing.max():g}: write percent (0-100), not fractions")
    order = np.argsort(opening_mm)
    opening, passing = opening_mm[order] * 1e-3, passing[order]
    rises = np.flatnonzero(np.diff(passing) < 0)
    if len(rises):
        k = rises[0]
        raise SheetError(f"{path}: more passes the {opening[k] * 1e3:g} mm sieve ({passing[k]:g} %) than the coarser "
                         f"{opening[k + 1] * 1e3:g} mm one ({passing[k + 1]:g} %): percent passing is cumulative")
    return SieveSheet(path, opening, passing)


def _table(path: str | Path) -> CsvFile:
    """A sheet's table (sediment.csvfile: one reader for every CSV given), its errors as SheetErrors."""
    try:
        return read_csv(path, "sheet")
    except CsvError as exc:
        raise SheetError(str(exc)) from None


def _numbers(table: CsvFile, name: str, blank: bool = False) -> list[float]:
    """A column's numbers, its errors as SheetErrors."""
    try:
        return table.numbers(name, blank)
    except CsvError as exc:
        raise SheetError(str(exc)) from None


def read_temperature_record(path: str | Path, t_end: float | None = None) -> tuple[tuple[float, float], ...]:
    """The water's temperature over a test, (time [s], temperature [C]) pairs, from any CSV with the
    columns time_min and temperature_C (a sheet of readings serves; rows without a temperature are
    left out). With the test's end `t_end` [s], a record that ends before a tenth of it is refused:
    its times are hours or seconds, not minutes, or it is another test's."""
    table = _table(path)
    path = table.path
    if not {"time_min", "temperature_C"} <= set(table.header):
        raise SheetError(f"{path}: a temperature record needs the columns time_min and temperature_C (header: "
                         f"{','.join(table.header)})")
    lines = [line for line, _ in table.rows]
    values = {"time_min": np.array(_numbers(table, "time_min")),
              "temperature_C": np.array(_numbers(table, "temperature_C", blank=True))}
    plausible(path, lines, values, "time_min", "record_time_min")
    plausible(path, lines, values, "temperature_C", "temperature")
    record = tuple((float(t) * 60.0, float(c)) for t, c in zip(values["time_min"], values["temperature_C"])
                   if math.isfinite(c))
    if not record:
        raise SheetError(f"{path}: no temperatures recorded")
    if record[0][0] < 0 or any(b[0] <= a[0] for a, b in zip(record[:-1], record[1:])):
        raise SheetError(f"{path}: the times must be >= 0 and increase from row to row")
    if t_end is not None and record[-1][0] < 0.1 * t_end:
        raise SheetError(f"{path}: the record ends at {record[-1][0] / 60:g} min, before a tenth of the test's "
                         f"{t_end / 60:g} min: time_min is in minutes (times in hours?), or the record is another "
                         "test's")
    return record


def check_sheet(sheet: Sheet, whole: float, resolution: float, corrected: np.ndarray | None = None,
                noise_option: str = "") -> None:
    """Refuses what no sedimenting suspension reads: a reading beyond `whole` (what the whole sample in
    suspension reads, in the instrument's unit) or one that moves back towards it with time by more than
    the reading's `resolution` (the solids at a depth only fall as the test goes on; a pipette is held
    to this between samples at one depth). `corrected`: the readings after their composite correction
    (the sheet's own are named beside them); `noise_option`: the option that states the reading error."""
    values = sheet.reading if corrected is None else corrected

    def named(k: int) -> str:
        after = "" if corrected is None or corrected[k] == sheet.reading[k] else \
            f", {values[k]:g}{'' if sheet.scale.in_grams else ' g/L'} after its correction"
        return f"{sheet.scale.quoted(sheet.reading[k])} on the sheet{after}"
    # the solids signal, falling with time: the sphere's apparent mass rises as the suspension thins
    kind = sheet.kind
    signal, top = (-values, -whole) if kind.reading_falls_with_solids else (values, whole)
    over = np.flatnonzero(signal > top + resolution)
    if len(over):
        k = over[0]
        raise SheetError(f"{sheet.where(k)}: the reading ({named(k)}) is beyond what the whole sample in suspension "
                         f"reads ({whole:.4g}): check the sample mass{kind.beyond_whole_hint}, the units or the sheet")
    same_depth = kind.check_sheet(sheet, values, whole)
    rises = np.flatnonzero((np.diff(signal) > resolution) & same_depth[1:])
    if len(rises):
        k = rises[0] + 1
        larger = (f"; if the laboratory reads less finely, state its reading error with {noise_option}"
                  if noise_option else "")
        raise SheetError(f"{sheet.where(k)}: the reading ({named(k)}) goes back towards the initial one from the "
                         f"reading before it ({sheet.where(k - 1).split(', ')[-1]}: {named(k - 1)}) by "
                         f"{abs(values[k] - values[k - 1]):.3g}, more than the tolerance ({resolution:.3g}): the solids "
                         "at a depth only fall as the test goes on, so one of the two is misread (or the sample "
                         f"flocculates){larger}")


@dataclass(frozen=True)
class Reduction:
    """The standard reduction of one sheet, with every correction it applied: per reading the
    composite correction subtracted from it (152H: the blank or the zero correction), the meniscus
    added to it for the depth, the water's temperature, the depth Stokes' law took (152H: D7928's
    H_m at the reading plus the meniscus), the diameter and the percent finer."""

    instrument: str
    time: np.ndarray            # s
    reading: np.ndarray         # as on the sheet (152H g/L, pipette g/L of the sample, sphere apparent mass g)
    correction: np.ndarray      # subtracted from the reading for the percent (152H), else 0
    meniscus: float             # g/L added to a 152H's reading for its depth
    temperature: np.ndarray     # C
    depth: np.ndarray           # m
    diameter: np.ndarray        # m
    percent: np.ndarray         # of the specimen (the inverse scales it to the whole sample)
    scale: Scale = GRAMS    # a hydrometer's scale as read (reading, correction and meniscus are in g/L)

    def scaled(self, share: float) -> "Reduction":
        """The same reduction with its percent finer of a sample of which the specimen is `share`."""
        return replace(self, percent=self.percent * share)


def standard_reduction(sheet: Sheet, suspension: Suspension, initial_concentration: float,
                       hydrometer: Hydrometer, cylinder_area: float, sphere: BuoyancySphere,
                       meniscus: float = 0.0, correction: float | np.ndarray = 0.0) -> Reduction:
    """The ASTM reduction of each reading: Stokes' diameter at the instrument's depth with the water at
    the reading's temperature (the test's where none was recorded), and percent finer from the reading.
    152H (D7928): the depth H_m at the reading as read plus the `meniscus` (the surface's graduation),
    the percent 100 a (R - `correction`) / c0, the composite correction measured at the same time."""
    temperature = np.where(np.isfinite(sheet.temperature), sheet.temperature,
                           suspension.temperature if suspension.temperature is not None else LAB_TEMPERATURE)
    waters = [Suspension.at_temperature(t, suspension.particle_density) for t in temperature]
    gs = suspension.specific_gravity
    kind = sheet.kind
    applied = np.zeros(len(sheet.time))
    if kind.on_hydrometer_scale:
        applied = applied + correction
    depth, percent = kind.reduce(sheet, waters, gs, initial_concentration, hydrometer, cylinder_area, sphere,
                                 meniscus, applied)
    diameter = np.array([w.stokes_diameter(z, time) for w, z, time in zip(waters, depth, sheet.time)], float)
    return Reduction(sheet.instrument, sheet.time, sheet.reading, applied,
                     meniscus if kind.on_hydrometer_scale else 0.0, temperature, np.asarray(depth, float),
                     diameter, percent, sheet.scale)


def read_hydrometer_calibration(path: str | Path, hydrometer_type: str = "152H") -> tuple[np.ndarray, np.ndarray]:
    """A hydrometer's calibration (D7928's H_r): CSV ``reading,distance_cm``, the distance from the
    graduation of each reading (on the scale of `hydrometer_type`) to the bulb's centre. Returns the
    readings [152H g/L] and the distances [m]."""
    scale = hydrometer(hydrometer_type).scale
    table = _table(path)
    path = table.path
    if not {"reading", "distance_cm"} <= set(table.header):
        raise SheetError(f"{path}: a hydrometer calibration needs the columns reading,distance_cm (the distance from "
                         f"the graduation of each reading to the bulb's centre; header: {','.join(table.header)})")
    lines = [line for line, _ in table.rows]
    values = {name: np.array(_numbers(table, name)) for name in ("reading", "distance_cm")}
    if len(lines) < 2:
        raise SheetError(f"{path}: a calibration needs at least two readings with their distances")
    plausible(path, lines, values, "reading", scale.reading_range)
    plausible(path, lines, values, "distance_cm", "calibration_cm")
    readings, distances = values["reading"], values["distance_cm"]
    order = np.argsort(readings, kind="stable")
    for a, b in zip(order[:-1], order[1:]):
        if readings[a] == readings[b]:
            raise SheetError(f"{path}, lines {lines[a]} and {lines[b]}: the reading {readings[a]:g} is calibrated twice")
        if distances[b] >= distances[a]:
            raise SheetError(f"{path}, lines {lines[a]} and {lines[b]}: the distance to the bulb's centre does not fall "
                             f"from reading {readings[a]:g} ({distances[a]:g} cm) to {readings[b]:g} ({distances[b]:g} "
                             "cm): a higher reading is a graduation lower on the stem, nearer the bulb")
    return scale.grams(readings[order]), distances[order] / 100.0
