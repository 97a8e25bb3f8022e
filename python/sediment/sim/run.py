# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs a deck through lmp_sediment (serial or mpirun) with a progress bar in simulated time.

Decks written by `sediment sample` announce their plan ("SEDIMENT plan steps N t_end T") and print
thermo rows beginning with step and time; the bar advances in simulated time and its ETA follows
the steps, which cost alike whatever the time step."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .paths import lmp_executable, mpirun_prefix


def _launch(deck: str, log: str, ranks: int, variables: dict[str, object] | None) -> tuple[list[str], dict[str, str]]:
    """The command line and environment that run `deck` with lmp_sediment on `ranks` MPI ranks."""
    cmd = mpirun_prefix(ranks) + [lmp_executable(), "-in", deck, "-log", log, "-nocite"]
    for name, value in (variables or {}).items():
        cmd += ["-var", name, str(value)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return cmd, env


@dataclass
class RunResult:
    """What a run of a deck did: steps, simulated and wall time, its log."""

    deck: Path
    log: Path
    wall_seconds: float
    steps: int
    simulated_time: float


def run_deck(deck: Path, ranks: int = 1, variables: dict[str, str] | None = None, progress: bool = True) -> RunResult:
    """Runs a deck in its folder with a progress bar in simulated time, writing log.lammps there.

    Parameters
    ----------
    deck : Path
        LAMMPS input deck.
    ranks : int
        MPI ranks (mpirun above 1).
    variables : dict, optional
        LAMMPS ``-var NAME VALUE`` pairs.
    progress : bool
        Show the progress bar.

    Returns
    -------
    RunResult
        Steps, simulated and wall time, the log's path.

    Raises
    ------
    RuntimeError
        The run failed; the message is LAMMPS's error.
    """
    deck = Path(deck).resolve()
    if not deck.is_file():
        raise FileNotFoundError(f"{deck}: no such deck")
    log = deck.parent / "log.lammps"
    cmd, env = _launch(deck.name, log.name, ranks, variables)
    start = time.monotonic()
    total_steps, t_end, step, now, errors, tail = 0, 0.0, 0, 0.0, [], deque(maxlen=5)
    bar = None
    with subprocess.Popen(cmd, cwd=deck.parent, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env=env) as proc:
        assert proc.stdout is not None
        for line in proc.stdout:
            tail.append(line.rstrip())
            words = line.split()
            if line.startswith("ERROR"):
                errors.append(line.strip())
            elif line.startswith("SEDIMENT plan") and len(words) >= 6:
                total_steps, t_end = int(words[3]), float(words[5])
                if progress:
                    from tqdm import tqdm
                    bar = tqdm(total=t_end, unit="s", desc="simulated", file=sys.stderr, dynamic_ncols=True,
                               mininterval=0.5, bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s "
                                                           "[{elapsed}{postfix}]")
            elif len(words) >= 2 and words[0].isdigit() and _is_float(words[1]):
                step, now = int(words[0]), float(words[1])
                if bar is not None and step:
                    left = (time.monotonic() - start) * (total_steps - step) / step
                    bar.set_postfix_str(f"ETA {_clock(left)}", refresh=False)
                    bar.update(min(now, t_end) - bar.n)
        code = proc.wait()
    if bar is not None:
        bar.close()
    if code != 0 or errors:
        message = errors[0] if errors else "\n".join(tail)
        raise RuntimeError(f"{deck.name} failed (exit {code}): {message} (see {log})")
    return RunResult(deck, log, time.monotonic() - start, step, now)


@dataclass
class DeckOutput:
    """What a deck printed: "SAMPLE v1 v2 ..." rows and "RESULT key value key value ..." lines."""
    text: str
    returncode: int
    wall_seconds: float
    samples: np.ndarray
    results: dict[str, float] = field(default_factory=dict)

    @property
    def loops(self) -> list[tuple[float, int]]:
        """(seconds, steps) of each run command, from LAMMPS's "Loop time of" lines (start-up excluded)."""
        return [(float(t), int(n)) for t, n in re.findall(r"^Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps",
                                                          self.text, re.MULTILINE)]

    @property
    def error(self) -> str | None:
        """LAMMPS's first ERROR line, or the exit code if it died without one."""
        for line in self.text.splitlines():
            if line.startswith("ERROR"):
                return line.strip()
        return None if self.returncode == 0 else f"exit code {self.returncode}"


def run_batch(deck: Path, variables: dict[str, object] | None = None, ranks: int = 1, cwd: Path | None = None,
              timeout: float | None = None, check: bool = True) -> DeckOutput:
    """Runs a deck quietly (no log file) and collects what it prints.

    Parameters
    ----------
    deck : Path
        LAMMPS input deck.
    variables : dict, optional
        LAMMPS ``-var NAME VALUE`` pairs.
    ranks : int
        MPI ranks.
    cwd : Path, optional
        Working folder; default the deck's.
    timeout : float, optional
        Seconds before the run is killed.
    check : bool
        Raise RuntimeError with LAMMPS's message if the run fails.

    Returns
    -------
    DeckOutput
        The text, the ``RESULT`` values and ``SAMPLE`` rows, loop times and the exit status.
    """
    deck = Path(deck).resolve()
    if not deck.is_file():
        raise FileNotFoundError(f"{deck}: no such deck")
    cmd, env = _launch(str(deck), "none", ranks, variables)
    start = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd or deck.parent, timeout=timeout, env=env)
    wall = time.monotonic() - start
    rows, results = [], {}
    for line in proc.stdout.splitlines():
        if line.startswith("SAMPLE "):
            rows.append([float(v) for v in line.split()[1:]])
        elif line.startswith("RESULT "):
            words = line.split()[1:]
            results.update({k: float(v) for k, v in zip(words[::2], words[1::2])})
    out = DeckOutput(proc.stdout + proc.stderr, proc.returncode, wall, np.array(rows), results)
    if check and out.error:
        raise RuntimeError(f"{deck.name} failed: {out.error}")
    return out


def _is_float(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def _clock(seconds: float) -> str:
    minutes, secs = divmod(int(round(seconds)), 60)
    return f"{minutes // 60:d}:{minutes % 60:02d}:{secs:02d}" if minutes >= 60 else f"{minutes:d}:{secs:02d}"
