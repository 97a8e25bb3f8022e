#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Hostile round 3 (issue 58): every command of `sediment` against faults (a full disk, SIGINT, SIGTERM
and SIGKILL at each phase, damaged files of each kind, two commands in one folder, reruns, one
command's --out onto another's folder or onto an input) and bad input (unit slips, encodings,
delimiters, duplicated columns, empty, unsorted, NaN, negative and huge values).

Each case sets up its own temporary folder, runs the command(s) and says exactly one of ok, wrong,
crash or vague (tests/hostile/harness.py says what each means). Run it as

    PYTHONPATH=python SEDIMENT_LMP=build/lmp_sediment tests/hostile/round3.py [--quick] [--only PATTERN]
        [--jobs 2] [--json OUTCOMES.json] [--list]      (tests/hostile/report.py OUTCOMES.json: the doc's tables)

`--quick` runs the cases that take seconds and no LAMMPS run of their own (they share one small
finished run, built once); tests/python/test_hostile_quick.py runs those under pytest, with the cases
in KNOWN_BAD expected to fail. The exit status is 1 when a case outside KNOWN_BAD is not ok."""
from __future__ import annotations

import argparse
import fnmatch
import json
import multiprocessing
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
# The cases, by theme; each module registers its cases into CASES as it is imported, in this order
import case_inputs  # noqa: E402, F401
import case_damaged  # noqa: E402, F401
import case_folders  # noqa: E402, F401
import case_signals  # noqa: E402, F401
from case_inputs import PATIENCE  # noqa: E402
from cases import CASES, INVERT_SMALL, Ctx, add, build_fixtures  # noqa: E402, F401  (round4.py adds its cases)


# ==== runner ================================================================================================
OUTCOME_NAMES = ("ok", "wrong", "crash", "vague")
KNOWN_BAD: set[str] = {   # not ok in the round of docs/hostile.md; take a case off when it is fixed
}


def run_case(item: tuple) -> tuple[str, str, str, float]:
    name, root, fixtures = item[:3]
    if len(item) > 3 and item[3] is not None and time.monotonic() > item[3]:
        return name, "not run", "past the --deadline", 0.0
    case = CASES[name]
    tmp = Path(tempfile.mkdtemp(prefix="c-", dir=root))
    t0 = time.monotonic()
    try:
        outcome, detail = case.fn(Ctx(tmp, Path(fixtures)))
    except Exception as e:  # noqa: BLE001 - a fault of the round itself, reported as such
        outcome, detail = "crash", f"ROUND ERROR {type(e).__name__}: {str(e).strip().splitlines()[-1][:160] if str(e).strip() else ''}"
    finally:
        subprocess.run(["umount", "-l", str(tmp / "disk")], stderr=subprocess.DEVNULL, check=False)
        shutil.rmtree(tmp, ignore_errors=True)
    assert outcome in OUTCOME_NAMES, outcome
    return name, outcome, " ".join(str(detail).split())[:300], time.monotonic() - t0


def select(only: str | None, quick: bool) -> list[str]:
    names = [n for n, c in CASES.items() if (not quick or c.quick)]
    if only:
        names = [n for n in names if fnmatch.fnmatch(n, only) or only in n]
    return names


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="only the cases that take seconds (no LAMMPS run of their own)")
    ap.add_argument("--only", help="cases whose name matches this glob or contains this text")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", type=Path, help="write the outcomes as JSON here")
    ap.add_argument("--list", action="store_true", help="list the cases and stop")
    ap.add_argument("--names", type=Path, help="run the cases named in this file (one a line)")
    ap.add_argument("--deadline", type=float, help="start no case after this many seconds (the rest: not run)")
    ap.add_argument("--patience", type=float, help="seconds a command that must refuse may work before it counts as "
                    "accepting (default 45)")
    args = ap.parse_args(argv)
    PATIENCE["value"] = args.patience or 45.0
    names = select(args.only, args.quick)
    if args.names:
        chosen = set(names)
        names = [n for n in args.names.read_text().split() if n in chosen]   # in the file's order
    if args.list:
        for n in names:
            c = CASES[n]
            print(f"{n}\t{c.command}\t{c.kind}\t{'quick' if c.quick else ''}")
        print(f"{len(names)} cases", file=sys.stderr)
        return 0
    root = Path(tempfile.mkdtemp(prefix="hostile3-"))
    fixtures = root / "fixtures"
    fixtures.mkdir()
    build_fixtures({f for n in names for f in CASES[n].needs}, fixtures)
    results = []
    t0 = time.monotonic()
    items = [(n, str(root), str(fixtures), t0 + args.deadline if args.deadline else None) for n in names]
    with multiprocessing.get_context("fork").Pool(max(1, args.jobs)) as pool:
        for name, outcome, detail, secs in pool.imap_unordered(run_case, items):
            results.append((name, outcome, detail, secs))
            mark = "ok " if outcome == "ok" else outcome.upper()
            print(f"{mark:5} {name} ({secs:.1f} s): {detail[:200]}", flush=True)
    counts = Counter(o for _, o, _, _ in results)
    print(f"{len(results)} cases in {time.monotonic() - t0:.0f} s: " +
          ", ".join(f"{counts[o]} {o}" for o in ("ok", "wrong", "crash", "vague")))
    if args.json:
        args.json.write_text(json.dumps({n: [o, d, round(s, 1)] for n, o, d, s in sorted(results)}, indent=1))
    shutil.rmtree(root, ignore_errors=True)
    unexpected = [n for n, o, _, _ in results if o not in ("ok", "not run") and n not in KNOWN_BAD]
    return 1 if unexpected else 0


if __name__ == "__main__":
    sys.exit(main())
