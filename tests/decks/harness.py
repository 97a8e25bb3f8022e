"""Runs LAMMPS decks through lmp_sediment and reads what they print.

Decks print "SAMPLE v1 v2 ..." rows and "RESULT key value key value ..." lines; checks compare
them with analytic references from the physics core (sediment._core).
"""
from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "python"))
from sediment.paths import mpirun_prefix  # noqa: E402

LMP = os.environ.get("SEDIMENT_LMP", str(HERE.parents[1] / "build" / "lmp_sediment"))


@dataclass
class DeckOutput:
    text: str
    returncode: int
    samples: np.ndarray
    results: dict[str, float] = field(default_factory=dict)


def run_deck(deck: str | Path, variables: dict[str, object] | None = None, np_ranks: int = 1,
             expect_failure: bool = False, cwd: Path | None = None, timeout: float = 600) -> DeckOutput:
    deck = Path(deck)
    if not deck.is_absolute():
        deck = HERE / deck
    cmd = mpirun_prefix(np_ranks) + [LMP, "-in", str(deck), "-log", "none", "-nocite"]
    for name, value in (variables or {}).items():
        cmd += ["-var", name, str(value)]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd or HERE, timeout=timeout)
    text = proc.stdout + proc.stderr
    if (proc.returncode != 0) != expect_failure:
        sys.stderr.write(text[-4000:])
        raise AssertionError(f"{deck.name} exited with {proc.returncode}: {' '.join(cmd)}")
    rows, results = [], {}
    for line in text.splitlines():
        if line.startswith("SAMPLE "):
            rows.append([float(v) for v in line.split()[1:]])
        elif line.startswith("RESULT "):
            words = line.split()[1:]
            results.update({k: float(v) for k, v in zip(words[::2], words[1::2])})
    return DeckOutput(text, proc.returncode, np.array(rows), results)


def report(message: str) -> None:
    print(message, flush=True)
