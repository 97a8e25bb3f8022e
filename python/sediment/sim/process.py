# SPDX-License-Identifier: GPL-2.0-or-later
"""LAMMPS as a process: its environment and command line, starting it in a session of its own with a
guard that stops its ranks if Python dies, stopping it with its ranks, and the signals that stop it
(`RunInterrupted`); `Runs`, the runs of one caller stopped together, and the main thread's wait for the
threads that run them (`finished_in_turn`, `results_of`)."""
from __future__ import annotations

import os
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, wait
from contextlib import contextmanager
from pathlib import Path
from typing import TypeVar

from .paths import lmp_executable, mpirun_prefix


def run_environment() -> dict[str, str]:
    """The environment LAMMPS runs in here: one thread per rank, Open MPI allowed as root, and Open
    MPI's ob1 messaging layer unless the user chose one (OMPI_MCA_pml). The runs are on one machine,
    where ob1's shared memory carries the ranks' messages; choosing it spares loading the fabrics'
    layers, one of which (Intel Omni-Path's libpsm2, a dependency of Debian's Open MPI) spends 0.1 s
    per core timing the clock whenever a process starts: 0.35 s -> 0.16 s per start of a serial run
    on 2 cores."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    env.setdefault("OMPI_MCA_pml", "ob1")
    return env


def launch_command(deck: str, log: str, ranks: int, variables: dict[str, object] | None) -> tuple[list[str], dict[str, str]]:
    """The command line and environment that run `deck` with lmp_sediment on `ranks` MPI ranks."""
    cmd = mpirun_prefix(ranks) + [lmp_executable(), "-in", deck, "-log", log, "-nocite"]
    for name, value in (variables or {}).items():
        cmd += ["-var", name, str(value)]
    return cmd, run_environment()


def start_process(cmd: list[str], env: dict[str, str], cwd: Path, **kwargs) -> subprocess.Popen:
    """Starts a run in its own session, tied to this process's life: util-linux's setpriv gives it
    SIGTERM when this process dies, and a guard (`_guard`) stops every process of the session (mpirun
    puts each rank in a process group of its own) even if mpirun ignores that or this process dies by
    SIGKILL. Output that is not UTF-8 (a binary deck echoed in an error) is replaced, not fatal."""
    proc = subprocess.Popen(["setpriv", "--pdeathsig", "TERM", "--", *cmd], cwd=cwd, env=env, text=True,
                            errors="replace", start_new_session=True, **kwargs)
    proc.guard = _guard(proc.pid)
    return proc


def _guard(session: int) -> subprocess.Popen:
    """A process outside the run that waits on a pipe only this process holds: when this process ends
    in any way, the pipe closes and the guard stops the run's session and the children its processes
    started in other sessions (SIGTERM, then SIGKILL)."""
    script = (f"read _; for p in $(pgrep -s {session}); do pkill -TERM -P $p; done; "
              f"pkill -TERM -s {session}; sleep 5; pkill -KILL -s {session}")
    return subprocess.Popen(["sh", "-c", script], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


def release(proc: subprocess.Popen) -> None:
    """The run is over: its guard goes without acting."""
    guard = getattr(proc, "guard", None)
    if guard is not None and guard.poll() is None:
        guard.kill()
        guard.wait()
        guard.stdin.close()


def _family(session: int) -> list[int]:
    """The live processes of the run: those of its session and their descendants in any session
    (zombies excluded). A one-rank run is an Open MPI singleton, whose daemon (orted) starts a session
    of its own yet holds the run's stdout and stderr: left running, it keeps the pipes open and the
    reader of the run's output waiting after the run was stopped."""
    parent, in_session = {}, set()
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            stat = Path(entry.path, "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()    # state, ppid, pgrp, session, ...
        if fields[0] == "Z":
            continue
        pid = int(entry.name)
        parent[pid] = int(fields[1])
        if int(fields[3]) == session:
            in_session.add(pid)
    family = set(in_session)
    grew = True
    while grew:
        children = {pid for pid, ppid in parent.items() if ppid in family} - family
        family |= children
        grew = bool(children)
    return sorted(family)


def stop_process(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """SIGTERM to every process of the run (`_family`: mpirun, every rank and the daemons they forked),
    SIGKILL to those left after `grace` seconds."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in _family(proc.pid):
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass
        end = time.monotonic() + grace
        try:
            proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            continue
        while _family(proc.pid) and time.monotonic() < end:
            time.sleep(0.05)
        if not _family(proc.pid):
            break
    release(proc)


START_WAIT = 120.0    # s: LAMMPS prints its banner within a second of its start, even on a loaded machine
START_TRIES = 2
T = TypeVar("T")


class StartWatch:
    """Stops a run that printed nothing `seconds` after its start (`stalled`). Open MPI 4.1's singleton
    start hangs at times in MPI_Init, waiting on the daemon it started with no CPU time (two serial runs
    of one `make test`, for 12 and 25 minutes); LAMMPS prints its banner right after MPI_Init, so a run
    silent that long has not begun: it wrote nothing, and starting it again is safe."""

    def __init__(self, proc: subprocess.Popen, seconds: float | None = None) -> None:
        self.stalled = False
        self._printed = threading.Event()
        self._timer = threading.Timer(START_WAIT if seconds is None else seconds, self._check, (proc,))
        self._timer.daemon = True
        self._timer.start()

    def printed(self) -> None:
        """The run printed a line: it has started."""
        self._printed.set()

    def _check(self, proc: subprocess.Popen) -> None:
        if not self._printed.is_set():
            self.stalled = True
            stop_process(proc)

    def cancel(self) -> None:
        """The run is over: the watch goes without acting."""
        self._timer.cancel()


def once_started(attempt: Callable[[], T | None], cmd: list[str]) -> T:
    """What `attempt()`, a start of the run `cmd`, returns once it starts: it returns None where the run
    printed nothing and was stopped (`StartWatch`), and is tried START_TRIES times at most."""
    for _ in range(START_TRIES):
        result = attempt()
        if result is not None:
            return result
    raise RuntimeError(f"LAMMPS printed nothing in {START_WAIT:g} s after each of {START_TRIES} starts "
                       f"({' '.join(cmd)}): MPI_Init did not return (an Open MPI start that hung); nothing was run or "
                       "written")


class RunInterrupted(RuntimeError):
    """The run was stopped by SIGINT or SIGTERM; every rank has been stopped."""


class _Launch:
    """The run a `signals_stop` block starts: `start` launches it and keeps its process for the stop."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None
        self.signal: int | None = None    # a signal that came before the process was known

    def start(self, cmd: list[str], env: dict[str, str], cwd: Path, **kwargs) -> subprocess.Popen:
        self.proc = start_process(cmd, env, cwd, **kwargs)
        if self.signal is not None:
            raise RunInterrupted(f"stopped by {signal.Signals(self.signal).name}")
        return self.proc


@contextmanager
def signals_stop():
    """From before the run is launched (`_Launch.start`) until it ends, SIGINT and SIGTERM stop it (every
    rank) and raise RunInterrupted. A signal that comes while it is being launched is kept until its
    process is known, so that the run is stopped all the same."""
    launch = _Launch()

    def handler(signum, _frame):
        if launch.proc is None:
            launch.signal = signum
            return
        raise RunInterrupted(f"stopped by {signal.Signals(signum).name}")

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield launch
    except BaseException:
        if launch.proc is not None:
            stop_process(launch.proc)
        raise
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)



class Runs:
    """The runs under way of a caller that runs several at once (threads), to be stopped together: once
    stopped, a run that a thread starts after it is stopped as soon as it is known (a thread may be
    between starting its LAMMPS and adding it here when the stop comes)."""

    def __init__(self) -> None:
        self._procs: set[subprocess.Popen] = set()
        self._lock = threading.Lock()
        self.stopped = False

    def add(self, proc: subprocess.Popen) -> None:
        """A run under way (stopped at once if the runs were stopped)."""
        with self._lock:
            self._procs.add(proc)
            late = self.stopped
        if late:
            stop_process(proc, grace=2.0)

    def discard(self, proc: subprocess.Popen) -> None:
        """A run that has ended."""
        with self._lock:
            self._procs.discard(proc)

    def stop(self) -> None:
        """Stops every run under way and every one added from now on, with their ranks."""
        with self._lock:
            self.stopped = True
            procs = list(self._procs)
        for proc in procs:
            stop_process(proc, grace=2.0)


def finished_in_turn(futures: Iterable[Future], poll: float = 0.2) -> Iterator[Future]:
    """The futures as they finish (as concurrent.futures.as_completed yields them), the waiting thread
    waking every `poll` seconds. A SIGINT or SIGTERM that the kernel hands to another thread (a worker
    blocked reading its run's output) only marks the signal for Python, whose handler runs in the main
    thread once that thread runs again: blocked on a lock without a timeout, it would not, and a plan
    whose runs were paused hung after Ctrl-C for as long as they stayed paused (1 time in 8 on a loaded
    machine)."""
    pending = set(futures)
    while pending:
        done, pending = wait(pending, timeout=poll, return_when=FIRST_COMPLETED)
        yield from done


def results_of(futures: list[Future], poll: float = 0.2) -> list:
    """The futures' results in their order, waited for as `finished_in_turn` waits: the first failure
    raises as soon as it comes."""
    for future in finished_in_turn(futures, poll):
        future.result()
    return [future.result() for future in futures]
