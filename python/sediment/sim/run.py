# SPDX-License-Identifier: GPL-2.0-or-later
"""The two ways of running a deck through lmp_sediment (serial or mpirun): `run_deck`, a recorded run
in its folder with a progress bar in simulated time, resumable, and `run_batch`, a quiet run whose
printed lines are collected. Starting and stopping the process is sim/process.py's, the run's
identity and records sim/provenance.py's.

Decks written by `sediment sample` announce their plan ("SEDIMENT plan steps N t_end T") and print
thermo rows beginning with step and time; the bar advances in simulated time and its ETA follows
the steps, which cost alike whatever the time step."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..folders import folder_lock
from ..progress import bar as progress_bar
from ..results import write_atomic
from .printed import parse_printed
from .process import (RunInterrupted, Runs, StartWatch, launch_command, once_started, release, signals_stop,
                      start_process, stop_process)
from .provenance import (COMPARED, RECORD, already_finished, check_partial, check_written, file_digest, finished,
                         input_files, layer_file_of, read_record, restart_damage, resume_id, run_id, stamp,
                         unresumable, write_record)


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

    Each fresh start gets an identity (`run_id`) that the layer file and every restart file keep and
    that the folder's run record (.sediment-run.json) names; a resumed run takes the interrupted one's.

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
        Start anew, letting the layer file replace one of another run (``-var overwrite yes``).
    resume : bool
        Continue the folder's interrupted run (killed or failed) from its newest intact restart file
        (restart.a.bin or restart.b.bin, as decks of `sediment sample` write them), refused if the
        deck or a file it reads changed since; its layer file continues.

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
        More ranks than cores without `oversubscribe`; nothing to resume; --force with --resume.
    """
    deck = Path(deck).resolve()
    if deck.is_dir():
        raise ValueError(f"{deck} is a folder; give the deck file (e.g. {deck / 'in.sedimentation'})")
    if not deck.is_file():
        raise FileNotFoundError(f"{deck}: no such deck")
    if force and resume:
        raise ValueError("--resume continues the interrupted run and --force starts the deck anew: give one of them")
    cores = len(os.sched_getaffinity(0))
    if ranks > cores and not oversubscribe:
        raise ValueError(f"--np {ranks} asks for more ranks than the {cores} cores here, which runs far slower than "
                         f"--np {cores}; add --oversubscribe to run it anyway")
    variables = {k: str(v) for k, v in (variables or {}).items()}
    folder = deck.parent
    with folder_lock(folder, "run"):
        if not resume:    # (a resumed run names what changed since it started)
            check_written(deck)
            done = None if force else already_finished(deck, variables)
            if done is not None:
                raise ValueError(f"{deck.name} has already finished: {done.name} holds its complete frames (`sediment "
                                 f"readout {folder}` reads them); --force runs it again and replaces them")
            launch = dict(variables, sediment_run_id=run_id(deck, variables))
            if force or unresumable(deck, variables):
                launch["overwrite"] = "yes"
            files = {p.name: file_digest(p) for p in [deck, *input_files(deck), *(folder / n for n in COMPARED)]
                     if p.is_file()}
            return _run_recorded(deck, ranks, variables, launch, progress, files)
        if "${resume}" not in deck.read_text(errors="replace"):
            raise ValueError(f"{deck.name} cannot be resumed: it has no 'resume' variable (decks written by "
                             "`sediment sample` have one)")
        restarts = sorted((p for p in (folder / "restart.a.bin", folder / "restart.b.bin") if p.is_file()),
                          key=lambda p: p.stat().st_mtime, reverse=True)
        if not restarts:
            raise ValueError(f"nothing to resume in {folder}: no restart file (restart.a.bin, restart.b.bin); "
                             "run it without --resume, or start it anew with --force")
        identity = resume_id(deck, variables)
        files = read_record(folder).get("files", {})    # those of the start it continues
        check_partial(deck, variables, identity)
        # A restart file that does not match the checksum written beside it (damaged, or written as the run
        # was killed) is passed over for the older one. Restart files of an earlier version have no
        # checksums: they are tried as they are.
        failures = []
        if any(p.with_name(p.name + ".crc32").is_file() for p in restarts):
            damage = {p: restart_damage(p, identity) for p in restarts}
            restarts = [p for p in restarts if damage[p] is None]
            if not restarts:
                raise RuntimeError(f"cannot resume: the restart files in {folder} do not match their checksums ("
                                   + "; ".join(f"{p.name}: {why}" for p, why in damage.items())
                                   + "): start the run anew with --force")
            for p, why in damage.items():
                if why:
                    print(f"passing over {p.name} ({why}); resuming from {restarts[0].name}", file=sys.stderr)
        # The newest restart file may yet fail to load: then the older one, if the failed attempt wrote no
        # restart file of its own. A restart file of another run is refused by fix layers/hdf5 and passed
        # over likewise.
        failures = []
        for k, restart in enumerate(restarts):
            stamps = [p.stat().st_mtime_ns for p in restarts]
            launch = dict(variables, sediment_run_id=identity, resume="yes", restart_file=restart.name)
            try:
                return _run_recorded(deck, ranks, variables, launch, progress, files)
            except RunInterrupted:    # a stop asked for, not a restart file that failed
                raise
            except RuntimeError as exc:
                failures.append(f"{restart.name}: {exc}")
                if k + 1 == len(restarts) or [p.stat().st_mtime_ns for p in restarts] != stamps:
                    break
                print(f"resuming from {restart.name} failed ({str(exc).splitlines()[0]}); trying {restarts[k + 1].name}",
                      file=sys.stderr)
        if all("written by run" in f for f in failures):
            raise RuntimeError(f"the restart files in {folder} are of another run (an earlier one, or copied from "
                               f"elsewhere), not of the interrupted run {identity}: its own are gone (replaced since, or "
                               "it stopped before it wrote one); start it anew with --force")
        reasons = dict.fromkeys(f.split(": ", 1)[1] for f in failures)    # the same reason once
        raise RuntimeError(f"cannot resume from {' or '.join(f.split(':')[0] for f in failures)}: " + "; ".join(reasons))


def _run_recorded(deck: Path, ranks: int, variables: dict[str, str], launch: dict[str, str],
                  progress: bool, files: dict[str, str]) -> RunResult:
    """Runs the deck with the `launch` variables (the folder locked), keeping the folder's run record:
    running, then finished, failed or interrupted. It names the SHA-256 of the files the run started
    with (`files`: the deck, what it reads and the tables compared with its frames) and, once finished,
    of its layer file: what a readout checks."""
    record = dict(run_id=launch["sediment_run_id"], deck=deck.name, variables=variables, files=files)
    earlier = (deck.parent / RECORD).read_bytes() if (deck.parent / RECORD).is_file() else None
    layers = layer_file_of(deck, variables)
    frames = stamp(layers)
    write_record(deck.parent, **record, state="running")
    try:
        result = _run(deck, ranks, launch, progress)
    except BaseException as exc:
        if isinstance(exc, KeyboardInterrupt) and layers is not None and finished(layers, record["run_id"]):
            # the stop came once LAMMPS had finished, before the run's bookkeeping: its results are whole
            _finish_record(deck, record, layers)
            raise RunInterrupted(f"stopped by {exc or 'SIGINT'} as the run finished: its results are complete "
                                 f"({layers.name} and the run record)") from None
        if earlier is not None and layers is not None and stamp(layers) == frames:
            # refused before it wrote a frame (fix layers/hdf5 keeps an earlier run's frames): the
            # record still describes the run whose frames are there
            write_atomic(deck.parent / RECORD, lambda tmp: tmp.write_bytes(earlier))
        else:
            write_record(deck.parent, **record, state="interrupted" if isinstance(exc, RunInterrupted) else "failed")
        raise
    try:
        _finish_record(deck, record, layers)
    except KeyboardInterrupt as exc:    # held while the record was written, raised after it
        raise RunInterrupted(f"stopped by {exc or 'SIGINT'} after the run finished: its results are complete"
                             + (f" ({layers.name} and the run record)" if layers is not None else "")) from None
    return result


def _finish_record(deck: Path, record: dict, layers: Path | None) -> None:
    """The run record of a finished run, with its layer file's SHA-256 and its log in place; signals wait
    until it is written."""
    from ..folders import signals_held

    with signals_held():
        partial = _partial_log(deck.parent)
        if partial.exists():    # a stop before the log's move
            os.replace(partial, deck.parent / "log.lammps")
        if layers is not None and finished(layers, record["run_id"]):
            record["layers"] = {"file": layers.name, "sha256": file_digest(layers)}
        write_record(deck.parent, **record, state="finished")


def _partial_log(folder: Path) -> Path:
    """The log of this process's run while LAMMPS writes it."""
    return folder / f".log.lammps.{os.getpid()}.partial"


def _run(deck: Path, ranks: int, variables: dict[str, str], progress: bool) -> RunResult:
    """One launch of the deck in its folder with a progress bar; see `run_deck`."""
    folder = deck.parent
    log, failed_log = folder / "log.lammps", folder / "log.failed.lammps"
    # The log is written under a temporary name: log.lammps is always a complete log of a run
    # that succeeded, log.failed.lammps that of the last one that did not.
    partial_log = _partial_log(folder)
    for stale in folder.glob(".log.lammps.*.partial"):    # of a sediment killed outright (the folder is locked)
        stale.unlink(missing_ok=True)
    cmd, env = launch_command(deck.name, partial_log.name, ranks, variables)
    start = time.monotonic()
    errors: list[str] = []
    tail: deque = deque(maxlen=5)
    bar = None
    total_steps, t_end, step, now, loops = 0, 0.0, 0, 0.0, 0

    def take(line: str) -> None:
        nonlocal bar, total_steps, t_end, step, now, loops
        tail.append(line.rstrip())
        words = line.split()
        loops += line.startswith("Loop time of ")
        if line.startswith("ERROR"):
            errors.append(line.strip())
        elif line.startswith("SEDIMENT end") and len(words) >= 6:    # where a run halted on time ended
            step, now = int(words[3]), float(words[5])
            if bar is not None:
                bar.update(min(now, t_end) - bar.n)
        elif line.startswith("SEDIMENT plan") and len(words) >= 6:
            total_steps, t_end = int(words[3]), float(words[5])
            if progress:
                bar = progress_bar(total=t_end, unit="s", desc="simulated", file=sys.stderr, dynamic_ncols=True,
                               mininterval=0.5, bar_format="{desc}: {percentage:3.0f}%|{bar}| "
                                                           "{n:.4g}/{total:.4g} s [{elapsed}{postfix}]")
        elif len(words) >= 2 and words[0].isdigit() and _is_float(words[1]):
            step, now = int(words[0]), float(words[1])
            if bar is not None and step:
                if step < total_steps:
                    left = (time.monotonic() - start) * (total_steps - step) / step
                    bar.set_postfix_str(f"ETA {_clock(left)}", refresh=False)
                else:    # a two-way deck whose flow shortened its steps runs on to t_end
                    bar.set_postfix_str(f"past the {total_steps} planned steps, ETA unknown", refresh=False)
                bar.update(min(now, t_end) - bar.n)

    def keep_failed_log() -> None:
        if partial_log.exists():
            os.replace(partial_log, failed_log)

    proc = None
    try:
        with signals_stop() as launch:
            def attempt() -> int | None:
                nonlocal proc
                proc = launch.start(cmd, env, folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
                watch = StartWatch(proc)
                assert proc.stdout is not None
                for line in proc.stdout:
                    watch.printed()
                    take(line)
                code = proc.wait()
                watch.cancel()
                if watch.stalled:
                    release(proc)
                    return None
                return code

            code = once_started(attempt, cmd)
    except RunInterrupted as exc:
        layers = layer_file_of(deck, variables)
        if layers is not None and finished(layers, variables.get("sediment_run_id", "")):
            # The stop came as LAMMPS finished: the layer file is this run's and complete.
            print(f"({exc} as the run finished: its results are complete)", file=sys.stderr)
            code = 0
        else:
            keep_failed_log()
            left = "no layer file"
            if layers is not None:
                partial = layers.with_name(layers.name + ".partial")
                left = f"its frames so far are in {partial.name}" if partial.exists() else "it wrote no frames"
            # a two-way deck may take more steps than it planned (the flow shortens them)
            of = "of ?" if not total_steps else f"of {total_steps}" if step <= total_steps else f"({total_steps} planned)"
            raise RunInterrupted(f"{exc} at step {step} {of} (t = {now:.6g} s): every rank was "
                                 f"stopped; {left}, an earlier result is untouched; sediment run --resume continues "
                                 "it from its last restart file") from None
    except BaseException:
        keep_failed_log()
        raise
    finally:
        if proc is not None:
            release(proc)
        if bar is not None:
            bar.close()
    if code != 0 or errors:
        keep_failed_log()
        message = errors[0] if errors else "\n".join(tail)
        raise RuntimeError(f"{deck.name} failed (exit {code}): {message} (see {failed_log})")
    if not loops:
        keep_failed_log()
        raise RuntimeError(f"{deck.name} ran no run (LAMMPS printed no 'Loop time'): an empty or cut deck, or one "
                           f"without a run command (see {failed_log})")
    if total_steps and step < total_steps:
        keep_failed_log()
        raise RuntimeError(f"{deck.name} ended at step {step} of the {total_steps} it announced (t = {now:.6g} s): "
                           f"the deck is cut short or stops early (see {failed_log})")
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
              timeout: float | None = None, check: bool = True, running: Runs | None = None,
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
    running : Runs, optional
        Holds the run's process while it runs, for a caller running several at once to stop them
        (`Runs.stop`); a run started after they were stopped is refused (RunInterrupted).
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
    cmd, env = launch_command(str(deck), "none", ranks, variables)
    start = time.monotonic()

    def attempt() -> tuple[str, str, int] | None:
        if getattr(running, "stopped", False):
            raise RunInterrupted("the runs were stopped before this one began")
        return _collect(cmd, env, cwd or deck.parent, timeout, running, on_line)

    stdout, stderr, returncode = once_started(attempt, cmd)
    wall = time.monotonic() - start
    parsed = parse_printed(stdout)
    out = DeckOutput(stdout + stderr, returncode, wall, parsed.samples, parsed.results)
    if check and out.error:
        raise RuntimeError(f"{deck.name} failed: {out.error}")
    return out


def _collect(cmd: list[str], env: dict[str, str], cwd: Path, timeout: float | None, running: Runs | None,
             on_line: Callable[[str], None] | None) -> tuple[str, str, int] | None:
    """One start of a `run_batch` run: its standard output, standard error and exit status, or None if
    it printed nothing (`StartWatch`) and was stopped."""
    proc = start_process(cmd, env, cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if running is not None:
        running.add(proc)
    # Standard output is read line by line as it comes (standard error by a thread, so that neither
    # pipe can fill and stall the run); a timer stops a run that overstays its timeout.
    stderr_text: list[str] = []
    reader = threading.Thread(target=lambda: stderr_text.append(proc.stderr.read()), daemon=True)
    timed_out = threading.Event()

    def overstayed() -> None:
        timed_out.set()
        stop_process(proc)

    timer = threading.Timer(timeout, overstayed) if timeout is not None else None
    watch = StartWatch(proc)
    lines = []
    try:
        reader.start()
        if timer is not None:
            timer.start()
        assert proc.stdout is not None
        for line in proc.stdout:
            watch.printed()
            lines.append(line)
            if on_line is not None:
                on_line(line)
        proc.wait()
        reader.join()
    except BaseException:
        stop_process(proc)
        raise
    finally:
        watch.cancel()
        release(proc)
        if timer is not None:
            timer.cancel()
        if running is not None:
            running.discard(proc)
    if watch.stalled:
        return None
    if timed_out.is_set():
        raise subprocess.TimeoutExpired(cmd, timeout)
    return "".join(lines), "".join(stderr_text), proc.returncode


def _is_float(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def _clock(seconds: float) -> str:
    minutes, secs = divmod(int(round(seconds)), 60)
    return f"{minutes // 60:d}:{minutes % 60:02d}:{secs:02d}" if minutes >= 60 else f"{minutes:d}:{secs:02d}"
