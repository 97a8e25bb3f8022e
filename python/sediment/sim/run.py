# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs a deck through lmp_sediment (serial or mpirun) with a progress bar in simulated time.

Decks written by `sediment sample` announce their plan ("SEDIMENT plan steps N t_end T") and print
thermo rows beginning with step and time; the bar advances in simulated time and its ETA follows
the steps, which cost alike whatever the time step."""
from __future__ import annotations

import fcntl
import hashlib
import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from .paths import lmp_executable, mpirun_prefix


def _launch(deck: str, log: str, ranks: int, variables: dict[str, object] | None) -> tuple[list[str], dict[str, str]]:
    """The command line and environment that run `deck` with lmp_sediment on `ranks` MPI ranks."""
    cmd = mpirun_prefix(ranks) + [lmp_executable(), "-in", deck, "-log", log, "-nocite"]
    for name, value in (variables or {}).items():
        cmd += ["-var", name, str(value)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return cmd, env


def _start(cmd: list[str], env: dict[str, str], cwd: Path, **kwargs) -> subprocess.Popen:
    """Starts a run in its own process group (stopped as a whole), tied to this process's life:
    util-linux's setpriv gives it SIGTERM when this process dies, even by SIGKILL, so neither mpirun
    (which passes the signal to its ranks) nor a serial LAMMPS outlives it. Output that is not UTF-8
    (a binary deck echoed in an error) is replaced, not fatal."""
    return subprocess.Popen(["setpriv", "--pdeathsig", "TERM", "--", *cmd], cwd=cwd, env=env, text=True,
                            errors="replace", start_new_session=True, **kwargs)


def _stop(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """SIGTERM to the run's process group (mpirun and every rank), SIGKILL after `grace` seconds."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=grace)
            return
        except subprocess.TimeoutExpired:
            continue


class RunInterrupted(RuntimeError):
    """The run was stopped by SIGINT or SIGTERM; every rank has been stopped."""


@contextmanager
def _signals_stop(proc: subprocess.Popen):
    """While the run goes on, SIGINT and SIGTERM stop it (every rank) and raise RunInterrupted."""
    def handler(signum, _frame):
        raise RunInterrupted(f"stopped by {signal.Signals(signum).name}")

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    except BaseException:
        _stop(proc)
        raise
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


@contextmanager
def _folder_lock(folder: Path):
    """One `sediment run` at a time per folder: a second one would write the same files."""
    path = folder / ".sediment-run.lock"
    with open(path, "a+") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            raise RuntimeError(f"another sediment run is using {folder} (pid {handle.read().strip() or '?'}); "
                               "wait for it, or run the deck from another folder") from None
        handle.seek(0)
        handle.truncate()
        handle.write(str(os.getpid()))
        handle.flush()
        yield


def run_id(deck: Path, variables: dict[str, object]) -> str:
    """The identity of a run: a hash of the deck's text and its variables (stored in the layer file,
    which refuses to be continued by another run)."""
    digest = hashlib.sha256(Path(deck).read_bytes())
    for name, value in sorted(variables.items()):
        digest.update(f"\0{name}={value}".encode())
    return digest.hexdigest()[:16]


@dataclass
class RunResult:
    """What a run of a deck did: steps, simulated and wall time, its log."""

    deck: Path
    log: Path
    wall_seconds: float
    steps: int
    simulated_time: float


def run_deck(deck: Path, ranks: int = 1, variables: dict[str, str] | None = None, progress: bool = True,
             oversubscribe: bool = False, force: bool = False, resume: bool = False) -> RunResult:
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
    oversubscribe : bool
        Allow more ranks than cores.
    force : bool
        Let the layer file replace one of another run (``-var overwrite yes``).
    resume : bool
        Continue a killed or failed run from the newest restart file beside the deck (restart.a.bin or
        restart.b.bin, as decks of `sediment sample` write them); its layer file continues.

    Returns
    -------
    RunResult
        Steps, simulated and wall time, the log's path (log.lammps, written only when the run succeeds).

    Raises
    ------
    RuntimeError
        The run failed (LAMMPS's error; its log is log.failed.lammps), or another run uses the folder.
    RunInterrupted
        SIGINT or SIGTERM stopped it; mpirun and every rank were stopped too.
    ValueError
        More ranks than cores without `oversubscribe`.
    """
    deck = Path(deck).resolve()
    if deck.is_dir():
        raise ValueError(f"{deck} is a folder; give the deck file (e.g. {deck / 'in.sedimentation'})")
    if not deck.is_file():
        raise FileNotFoundError(f"{deck}: no such deck")
    cores = len(os.sched_getaffinity(0))
    if ranks > cores and not oversubscribe:
        raise ValueError(f"--np {ranks} asks for more ranks than the {cores} cores here, which runs far slower than "
                         f"--np {cores}; add --oversubscribe to run it anyway")
    variables = dict(variables or {})
    variables.setdefault("sediment_run_id", run_id(deck, variables))    # a resumed run is the same run
    if force:
        variables["overwrite"] = "yes"
    folder = deck.parent
    if resume:
        if "${resume}" not in deck.read_text(errors="replace"):
            raise ValueError(f"{deck.name} cannot be resumed: it has no 'resume' variable (decks written by "
                             "`sediment sample` have one)")
        restarts = sorted((p for p in (folder / "restart.a.bin", folder / "restart.b.bin") if p.is_file()),
                          key=lambda p: p.stat().st_mtime, reverse=True)
        if not restarts:
            raise ValueError(f"nothing to resume in {folder}: no restart file (restart.a.bin, restart.b.bin); "
                             "run it without --resume")
        # The newest restart file may be the one a kill cut short: then the other, one interval older.
        for k, restart in enumerate(restarts):
            try:
                return run_deck(deck, ranks, {**variables, "resume": "yes", "restart_file": restart.name}, progress,
                                oversubscribe, force)
            except RuntimeError as exc:
                if k + 1 == len(restarts) or "restart" not in str(exc).lower():
                    raise
    log, failed_log = folder / "log.lammps", folder / "log.failed.lammps"
    with _folder_lock(folder):
        # The log is written under a temporary name: log.lammps is always a complete log of a run
        # that succeeded, log.failed.lammps that of the last one that did not.
        partial_log = folder / f".log.lammps.{os.getpid()}.partial"
        cmd, env = _launch(deck.name, partial_log.name, ranks, variables)
        start = time.monotonic()
        total_steps, t_end, step, now, errors, tail = 0, 0.0, 0, 0.0, [], deque(maxlen=5)
        bar = None
        proc = _start(cmd, env, folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        try:
            with _signals_stop(proc):
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
                                       mininterval=0.5, bar_format="{desc}: {percentage:3.0f}%|{bar}| "
                                                                   "{n:.4g}/{total:.4g} s [{elapsed}{postfix}]")
                    elif len(words) >= 2 and words[0].isdigit() and _is_float(words[1]):
                        step, now = int(words[0]), float(words[1])
                        if bar is not None and step:
                            left = (time.monotonic() - start) * (total_steps - step) / step
                            bar.set_postfix_str(f"ETA {_clock(left)}", refresh=False)
                            bar.update(min(now, t_end) - bar.n)
                code = proc.wait()
        except BaseException:
            if partial_log.exists():
                os.replace(partial_log, failed_log)
            raise
        finally:
            if bar is not None:
                bar.close()
        if code != 0 or errors:
            if partial_log.exists():
                os.replace(partial_log, failed_log)
            message = errors[0] if errors else "\n".join(tail)
            raise RuntimeError(f"{deck.name} failed (exit {code}): {message} (see {failed_log})")
        os.replace(partial_log, log)
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
              timeout: float | None = None, check: bool = True, running: set | None = None,
              on_line: Callable[[str], None] | None = None) -> DeckOutput:
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
    running : set, optional
        Holds the run's process while it runs, for a caller running several at once to stop them
        (`stop_all`).
    on_line : callable, optional
        Called with each line LAMMPS prints as it prints it (a progress bar follows the thermo rows).

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
    proc = _start(cmd, env, cwd or deck.parent, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if running is not None:
        running.add(proc)
    # Standard output is read line by line as it comes (standard error by a thread, so that neither
    # pipe can fill and stall the run); a timer stops a run that overstays its timeout.
    stderr_text: list[str] = []
    reader = threading.Thread(target=lambda: stderr_text.append(proc.stderr.read()), daemon=True)
    timed_out = threading.Event()

    def overstayed() -> None:
        timed_out.set()
        _stop(proc)

    timer = threading.Timer(timeout, overstayed) if timeout is not None else None
    lines = []
    try:
        reader.start()
        if timer is not None:
            timer.start()
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.append(line)
            if on_line is not None:
                on_line(line)
        proc.wait()
        reader.join()
    except BaseException:
        _stop(proc)
        raise
    finally:
        if timer is not None:
            timer.cancel()
        if running is not None:
            running.discard(proc)
    if timed_out.is_set():
        raise subprocess.TimeoutExpired(cmd, timeout)
    stdout, stderr = "".join(lines), "".join(stderr_text)
    wall = time.monotonic() - start
    rows, results = [], {}
    for line in stdout.splitlines():
        if line.startswith("SAMPLE "):
            rows.append([float(v) for v in line.split()[1:]])
        elif line.startswith("RESULT "):
            words = line.split()[1:]
            results.update({k: float(v) for k, v in zip(words[::2], words[1::2])})
    out = DeckOutput(stdout + stderr, proc.returncode, wall, np.array(rows), results)
    if check and out.error:
        raise RuntimeError(f"{deck.name} failed: {out.error}")
    return out


def stop_all(running: set) -> None:
    """Stops every run in `running` (see run_batch) and its ranks."""
    for proc in list(running):
        _stop(proc, grace=2.0)


def _is_float(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def _clock(seconds: float) -> str:
    minutes, secs = divmod(int(round(seconds)), 60)
    return f"{minutes // 60:d}:{minutes % 60:02d}:{secs:02d}" if minutes >= 60 else f"{minutes:d}:{secs:02d}"
