# SPDX-License-Identifier: GPL-2.0-or-later
"""A laboratory's batch of samples (docs/inverse.md): one sub-folder per sample with its sheets and its
`sample.json` (the sample's own options of `sediment invert`: masses, cylinder, stirring time), each
inverted in a process of its own, several at a time, into a result folder of its own; a sample whose
sheets and options are those of its finished result is not run again. One table and one figure of
every sample's texture and gradation."""
from __future__ import annotations

import hashlib
import json
import math
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import figures
from ..results import Table, write_text
from ..sim.process import finished_in_turn

OPTIONS_FILE = "sample.json"
FILE_OPTIONS = ("hydrometer-calibration", "budget")    # options whose value is a file of the sample's folder


@dataclass
class Sample:
    """One sample of a batch: its folder, its sheets and the options of its inversion."""

    name: str
    folder: Path
    sheets: list[Path]
    options: list[str]
    error: str = ""

    def key(self, common: list[str]) -> str:
        """The SHA-256 of what the inversion reads: the sheets' and option files' bytes and the options."""
        digest = hashlib.sha256()
        files = self.sheets + [Path(self.options[k + 1]) for k in range(len(self.options) - 1)
                               if self.options[k].lstrip("-") in FILE_OPTIONS]
        for path in files:
            digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
        digest.update("\0".join(common + self.options).encode())
        return digest.hexdigest()


def read_samples(folder: Path) -> list[Sample]:
    """The batch's samples: every sub-folder with CSV sheets, its options from its sample.json (a JSON object
    of option names without the dashes and their values; "sheets" lists the sheets where not every CSV of
    the folder is one). A sample that cannot be read keeps its error and is reported, not run."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"--batch {folder}: not a folder (one sub-folder per sample, with its sheets and {OPTIONS_FILE})")
    samples = []
    for sub in sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith(".")):
        sample = Sample(sub.name, sub, [], [])
        try:
            settings = _settings(sub)
            named = settings.pop("sheets", None)
            files = {sub / str(settings[k]) for k in FILE_OPTIONS if k in settings}
            sample.sheets = [sub / n for n in named] if named is not None else \
                sorted(p for p in sub.glob("*.csv") if p not in files)
            if not sample.sheets:
                raise ValueError("no sheet (CSV) in the folder")
            for name, value in settings.items():
                if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                    raise ValueError(f"{OPTIONS_FILE}: {name} must be a number or a string, got {value!r}")
                sample.options += [f"--{name}", str(sub / str(value)) if name in FILE_OPTIONS else str(value)]
        except (ValueError, OSError) as exc:
            sample.error = str(exc)
        samples.append(sample)
    if not samples:
        raise ValueError(f"--batch {folder}: no sub-folder: give one per sample, with its sheets and {OPTIONS_FILE}")
    return samples


def _settings(folder: Path) -> dict:
    """A sample's sample.json (an empty object where there is none)."""
    path = folder / OPTIONS_FILE
    if not path.exists():
        return {}
    try:
        settings = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: not JSON ({exc})") from None
    if not isinstance(settings, dict):
        raise ValueError(f"{path}: an object of options is expected, e.g. {{\"mass\": 0.05}}")
    for forbidden in ("out", "batch", "design", "jobs"):
        if forbidden in settings:
            raise ValueError(f"{path}: '{forbidden}' is the batch's to set, not a sample's")
    return settings


def run_batch(samples: list[Sample], common: list[str], out: Path, logs: Path, jobs: int) -> list[dict]:
    """Inverts every sample (those already done with the same inputs aside), `jobs` at a time, each by
    `sediment invert` in a process of its own into OUT/<sample>; its console into LOGS/<sample>.txt.
    Returns per sample its name, status and invert.json (None where it has none)."""
    logs.mkdir(parents=True, exist_ok=True)
    rows: dict[str, dict] = {}
    todo = []
    for sample in samples:
        if sample.error:
            rows[sample.name] = {"sample": sample.name, "status": f"error: {sample.error}", "result": None}
            continue
        key = sample.key(common)
        done = _result(out / sample.name)
        if done is not None and done.get("inputs", {}).get("batch_key") == key:
            rows[sample.name] = {"sample": sample.name, "status": _status(done, 0), "result": done, "reused": True}
            continue
        todo.append((sample, key))
    total = len(samples)
    for k, (name, row) in enumerate(rows.items(), 1):
        print(f"[{k}/{total}] {name}: {row['status']}" + (" (done before with the same inputs)" if
                                                           row.get("reused") else ""), flush=True)

    def invert_one(sample: Sample, key: str) -> dict:
        command = [sys.executable, "-m", "sediment", "invert", *map(str, sample.sheets), *common, *sample.options,
                   "--batch-key", key, "--out", str(out / sample.name)]
        done = subprocess.run(command, capture_output=True, text=True)
        write_text(logs / f"{sample.name}.txt", f"$ {' '.join(command)}\n{done.stdout}{done.stderr}")
        result = _result(out / sample.name) if done.returncode in (0, 3) else None
        if result is None:
            message = (done.stderr.strip().splitlines() or [f"exit {done.returncode}"])[-1]
            return {"sample": sample.name, "status": f"error: {message}", "result": None}
        return {"sample": sample.name, "status": _status(result, done.returncode), "result": result}

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = [pool.submit(invert_one, sample, key) for sample, key in todo]
        for future in finished_in_turn(futures):
            row = future.result()
            rows[row["sample"]] = row
            print(f"[{len(rows)}/{total}] {row['sample']}: {row['status']}", flush=True)
    return [rows[s.name] for s in samples]


def _result(folder: Path) -> dict | None:
    """A sample's invert.json, None where it has none (or an unreadable one)."""
    try:
        return json.loads((folder / "invert.json").read_text())
    except (OSError, json.JSONDecodeError, UnicodeDecodeError):
        return None


def _status(result: dict, code: int) -> str:
    """fits / NOT CONSISTENT, with the chi-square per reading."""
    word = "fits" if result.get("consistent") else "NOT CONSISTENT"
    return f"{word} (chi-square per reading {result.get('chi2_per_reading', math.nan):.3g})"


FRACTIONS = ("clay", "silt", "sand")
DIAMETERS = ("D10", "D30", "D50", "D60")


def summary_table(rows: list[dict]) -> Table:
    """One row per sample: status, USDA class with its share of the draws, clay/silt/sand and D10-D60
    with their bands."""
    columns = ["sample", "status", "usda_class", "class_share_percent"]
    for name in FRACTIONS:
        columns += [f"{name}_percent", f"{name}_low", f"{name}_high"]
    for name in DIAMETERS:
        columns += [f"{name}_um", f"{name}_low", f"{name}_high"]
    table = Table(columns, notes=["USDA fractions of the fine earth (< 2 mm); bands: the central 95 % of the draws; "
                                  "a sample's files are in its folder, its console in logs/"])
    for row in rows:
        result = row["result"]
        if result is None:
            table.add(row["sample"], row["status"], *[""] * (len(columns) - 2))
            continue
        texture = result["texture"]
        cells = [texture["usda_class"] or "unknown",
                 _cell(texture["usda_class_share_of_draws"].get(texture["usda_class"] or "unknown"))]
        for name in FRACTIONS:
            value = texture["fractions"]["USDA"][name]
            cells += [_cell(value["percent"]), *map(_cell, value["band"])]
        for name in DIAMETERS:
            value = texture["gradation"][name]
            cells += [_cell(value["value"], 1e6), *(_cell(v, 1e6) for v in value["band"])]
        table.add(row["sample"], row["status"], *cells)
    return table


def _cell(value, scale: float = 1.0) -> str:
    return "" if value is None or not math.isfinite(value) else f"{value * scale:.4g}"


def summary_figure(path: Path, rows: list[dict]) -> Path:
    """Every sample's curve with its band on one gradation chart."""
    plt = figures.pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    for k, row in enumerate(r for r in rows if r["result"] is not None):
        psd = row["result"]["psd"]
        d = np.asarray(psd["diameter_um"], float)
        colour = f"C{k % 10}"
        ax.fill_between(d, psd["low"], psd["high"], color=colour, alpha=0.12, lw=0)
        ax.plot(d, psd["percent_finer"], "-", color=colour, label=f"{row['sample']} ({row['result']['texture']['usda_class']})")
    for limit in (2.0, 50.0, 2000.0):
        ax.axvline(limit, color="0.6", lw=0.8, ls=":")
    ax.set(xscale="log", xlabel="diameter [um]", ylabel="percent finer [%]", ylim=(0, 100),
           title=f"the batch's samples ({len(rows)}): recovered PSDs with their bands")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    return figures.save(fig, path)
