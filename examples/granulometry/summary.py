# SPDX-License-Identifier: GPL-2.0-or-later
"""Mean |P - PSD| per instrument and size range over several runs of run.sh, as a Markdown table:
    python3 examples/granulometry/summary.py out/sample1 out/sample2 ... [--reference simulated|input]
        [--readout FOLDER]   (e.g. the output of sediment readout --schedule bravo --out RUN/FOLDER)"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="+", type=Path, help="output folders of run.sh (with readout/errors.csv)")
    parser.add_argument("--reference", default="simulated", choices=["simulated", "input"])
    parser.add_argument("--readout", default="readout", help="readout folder inside each run")
    args = parser.parse_args()
    table: dict[str, dict[tuple[str, str], str]] = {}
    columns: list[tuple[str, str]] = []
    for run in args.runs:
        path = run / args.readout / "errors.csv"
        if not path.is_file():
            raise SystemExit(f"{path}: missing (run run.sh first)")
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["reference"] != args.reference:
                    continue
                key = (row["instrument"], row["size_range"])
                if key not in columns:
                    columns.append(key)
                error = float(row["mean_abs_error_points"])
                table.setdefault(run.name, {})[key] = "-" if error != error else f"{error:.2f} ({row['readings']})"
    print(f"mean |P - {args.reference} PSD| in percentage points (readings)\n")
    print("| run | " + " | ".join(f"{i} {r}" for i, r in columns) + " |")
    print("|---|" + "---|" * len(columns))
    for run, cells in table.items():
        print(f"| {run} | " + " | ".join(cells.get(k, "") for k in columns) + " |")


if __name__ == "__main__":
    main()
