# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs a deck through lmp_sediment (serial or mpirun) with a progress bar in simulated time.

Decks written by `sediment sample` announce their plan ("SEDIMENT plan steps N t_end T") and print
thermo rows beginning with step and time; the bar advances in simulated time and its ETA follows
the steps, which cost alike whatever the time step."""
from __future__ import annotations

import hashlib
import json
import os
import re
import secrets
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

from ..folders import folder_lock
from ..progress import bar as progress_bar
from ..results import write_atomic, write_text
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


def _launch(deck: str, log: str, ranks: int, variables: dict[str, object] | None) -> tuple[list[str], dict[str, str]]:
    """The command line and environment that run `deck` with lmp_sediment on `ranks` MPI ranks."""
    cmd = mpirun_prefix(ranks) + [lmp_executable(), "-in", deck, "-log", log, "-nocite"]
    for name, value in (variables or {}).items():
        cmd += ["-var", name, str(value)]
    return cmd, run_environment()


def _start(cmd: list[str], env: dict[str, str], cwd: Path, **kwargs) -> subprocess.Popen:
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
    in any way, the pipe closes and the guard stops the run's session (SIGTERM, then SIGKILL)."""
    script = f"read _; pkill -TERM -s {session}; sleep 5; pkill -KILL -s {session}"
    return subprocess.Popen(["sh", "-c", script], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


def _release(proc: subprocess.Popen) -> None:
    """The run is over: its guard goes without acting."""
    guard = getattr(proc, "guard", None)
    if guard is not None and guard.poll() is None:
        guard.kill()
        guard.wait()
        guard.stdin.close()


def _session(session: int) -> list[int]:
    """The live processes of a session (zombies excluded)."""
    pids = []
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            stat = Path(entry.path, "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()    # state, ppid, pgrp, session, ...
        if int(fields[3]) == session and fields[0] != "Z":
            pids.append(int(entry.name))
    return pids


def _stop(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """SIGTERM to every process of the run's session (mpirun and every rank), SIGKILL to those left
    after `grace` seconds."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in _session(proc.pid):
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass
        end = time.monotonic() + grace
        try:
            proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            continue
        while _session(proc.pid) and time.monotonic() < end:
            time.sleep(0.05)
        if not _session(proc.pid):
            break
    _release(proc)


class RunInterrupted(RuntimeError):
    """The run was stopped by SIGINT or SIGTERM; every rank has been stopped."""


class _Launch:
    """The run a `_signals_stop` block starts: `start` launches it and keeps its process for the stop."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None
        self.signal: int | None = None    # a signal that came before the process was known

    def start(self, cmd: list[str], env: dict[str, str], cwd: Path, **kwargs) -> subprocess.Popen:
        self.proc = _start(cmd, env, cwd, **kwargs)
        if self.signal is not None:
            raise RunInterrupted(f"stopped by {signal.Signals(self.signal).name}")
        return self.proc


@contextmanager
def _signals_stop():
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
            _stop(launch.proc)
        raise
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


RECORD = ".sediment-run.json"    # the folder's latest run: its identity, deck, variables and state
RUN_OUTPUTS = ("restart.a.bin", "restart.b.bin", "restart.a.bin.crc32", "restart.b.bin.crc32", "log.lammps",
               "log.failed.lammps", RECORD)
# Tables beside a run that it does not read but that its readout compares its frames with.
COMPARED = ("input_psd.csv", "simulated_psd.csv")


# Commands whose first literal argument (after an ID for molecule) is a file the deck reads.
_READS = re.compile(r"^\s*(?:read_data|include|read_dump|molecule\s+\S+)\s+([^\s$\"']+)", re.MULTILINE)


def input_files(deck: Path) -> list[Path]:
    """The files a deck reads besides itself: the literal names after read_data, include, read_dump and
    molecule (also inside an if's quoted commands) that exist beside it. Names built from variables
    cannot be known before the run and are not covered."""
    text = Path(deck).read_text(errors="replace").replace('"', "\n")
    names = dict.fromkeys(m.group(1) for m in _READS.finditer(text))
    return [Path(deck).parent / n for n in names if (Path(deck).parent / n).is_file()]


def inputs_id(deck: Path) -> str:
    """A hash of what a deck reads: its text (without whole-line comments, which `sediment sample`
    dates) and every file of `input_files`, each with its name."""
    digest = hashlib.sha256()
    deck = Path(deck)
    for path in [deck, *input_files(deck)]:
        data = path.read_bytes()
        if path == deck:
            data = b"\n".join(line for line in data.splitlines() if not line.lstrip().startswith(b"#"))
        digest.update(f"{path.name}\0{len(data)}\0".encode() + data)
    return digest.hexdigest()[:12]


def layer_file_of(deck: Path, variables: dict[str, str]) -> Path | None:
    """The layer file a deck's fix layers/hdf5 writes (its name from -var or an index/string variable of
    the deck), or None if it has none or its name cannot be known before the run."""
    text = Path(deck).read_text(errors="replace")
    found = re.search(r"^\s*fix\s+\S+\s+\S+\s+layers/hdf5\s+\S+\s+(\S+)", text, re.MULTILINE)
    if found is None:
        return None
    name = found.group(1)
    reference = re.fullmatch(r"\$\{(\w+)\}|\$(\w)", name)
    if reference:
        key = reference.group(1) or reference.group(2)
        defined = re.search(rf"^\s*variable\s+{key}\s+(?:index|string)\s+(\S+)", text, re.MULTILINE)
        name = variables.get(key) or (defined.group(1) if defined else None)
    if not name or "$" in name:
        return None
    return Path(deck).parent / name


def _unresumable(deck: Path, variables: dict[str, str]) -> bool:
    """Whether the deck's folder holds the frames of an interrupted run that wrote no restart file: no
    --resume can continue them, so a new start replaces them without --force (and says so)."""
    layers = layer_file_of(deck, variables)
    partial = layers.with_name(layers.name + ".partial") if layers is not None else None
    if partial is None or not partial.exists() or any((deck.parent / n).exists() for n in RUN_OUTPUTS[:2]):
        return False
    print(f"{partial.name}: frames of an interrupted run that wrote no restart file, which no --resume can "
          "continue: starting anew over them", file=sys.stderr)
    return True


def _stamp(layers: Path | None) -> tuple:
    """What says whether a run touched its frames: the layer file's and its .partial's size and time."""
    if layers is None:
        return ()
    return tuple((p.stat().st_size, p.stat().st_mtime_ns) if p.exists() else None
                 for p in (layers, layers.with_name(layers.name + ".partial")))


def _finished(layers: Path, identity: str) -> bool:
    """Whether `layers` is complete and of the run `identity`, with no frames of it left partial."""
    import h5py

    if not identity or not layers.is_file() or layers.with_name(layers.name + ".partial").exists():
        return False
    try:
        with h5py.File(layers, "r") as f:
            held = f.attrs.get("run_id", b"")
            return f.attrs.get("complete", 0) == 1 and (held.decode() if isinstance(held, bytes) else held) == identity
    except OSError:
        return False


def file_digest(path: Path) -> str:
    """The SHA-256 of a file's bytes, in hexadecimal."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def restart_damage(restart: Path, identity: str) -> str | None:
    """Why a restart file does not match the checksum fix layers/hdf5 wrote beside it once LAMMPS had
    closed it (NAME.crc32), or None if it matches; one that does not name the run `identity` (which
    fix layers/hdf5 stores in it) is said to be another run's."""
    import zlib

    sums = restart.with_name(restart.name + ".crc32")
    if not sums.is_file():
        return f"no checksum beside it ({sums.name}): the run was stopped before it recorded one"
    try:
        words = sums.read_text().split()
        held = dict(zip(words[::2], words[1::2]))
        crc, size = int(held["crc32"], 16), int(held["size"])
    except (ValueError, KeyError, UnicodeDecodeError):
        return f"its checksum file {sums.name} is damaged"
    if restart.stat().st_size != size:
        return (f"{restart.stat().st_size} bytes, {size} when it was last written ({sums.name}): damaged, or being "
                "written when the run was stopped")
    found, named = 0, False
    with open(restart, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            found = zlib.crc32(block, found)
            named = named or identity.encode() in block    # in the fix's state, before the atoms
    if found != crc and not named:
        return f"it does not name the interrupted run {identity}: a restart file of another run, or damaged"
    if found != crc:
        return (f"its bytes differ from those it was last written with (CRC-32 {found:08x}, {sums.name} says "
                f"{crc:08x}): damaged, or being written when the run was stopped")
    return None


def run_id(deck: Path, variables: dict[str, object]) -> str:
    """A new run's identity, INPUTS-VARIABLES-START: the hash of what the deck reads (`inputs_id`), of
    its variables, and a token of this start. Stored in the layer file and in each restart file: a
    resumed run continues only the frames and restart files of the start it resumes."""
    digest = hashlib.sha256()
    for name, value in sorted(variables.items()):
        digest.update(f"\0{name}={value}".encode())
    return f"{inputs_id(deck)}-{digest.hexdigest()[:6]}-{secrets.token_hex(4)}"


def read_record(folder: Path) -> dict | None:
    """The folder's run record (None if there is none); ValueError if it is damaged."""
    path = Path(folder) / RECORD
    if not path.is_file():
        return None
    try:
        record = json.loads(path.read_text())
        if not isinstance(record, dict) or not {"run_id", "deck", "state"} <= record.keys():
            raise ValueError("fields missing")
        return record
    except (ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path} is damaged ({exc}); remove it, and run the deck anew with --force") from None


def _write_record(folder: Path, **record) -> None:
    write_text(folder / RECORD, json.dumps(record, indent=1) + "\n")


def _resume_id(deck: Path, variables: dict[str, str]) -> str:
    """The identity of the interrupted run in the deck's folder, after checking that it can be resumed:
    it did not finish, it ran this deck, and what the deck reads has not changed since."""
    folder = deck.parent
    record = read_record(folder)
    if record is None or record.get("deck") != deck.name:
        raise ValueError(f"nothing to resume in {folder}: no interrupted run of {deck.name} is recorded there "
                         f"({RECORD}); run it without --resume")
    if record["state"] == "finished":
        raise ValueError(f"the run of {deck.name} in {folder} finished: nothing to resume; run it again with --force")
    if record["run_id"].split("-")[0] != inputs_id(deck):
        raise ValueError(f"{_what_changed(deck, record.get('files', {}))} since the interrupted run started: its "
                         "restart files are of other inputs; put them back as they were, or start the run anew with "
                         "--force")
    if record.get("variables", {}) != variables:
        raise ValueError(f"the interrupted run had the variables {record.get('variables')}, this one {variables}: "
                         "resume it with the same --var options")
    return record["run_id"]


def _check_written(deck: Path) -> None:
    """Refuses a deck that reads a file `sediment sample` wrote beside it whose bytes have changed since
    (its size and SHA-256 in the folder's manifest): a damaged data file may read as no atoms at all."""
    from ..folders import read_manifest

    written = read_manifest(deck.parent)["sets"].get("sample", {}).get("files", {})
    for path in input_files(deck):
        held = written.get(path.name)
        if held is not None and [path.stat().st_size, file_digest(path)] != held:
            raise ValueError(f"{path} changed since sediment sample wrote it ({path.stat().st_size} bytes, "
                             f"{held[0]} then): damaged, or edited; write it again (sediment sample --force)")


def _what_changed(deck: Path, started: dict[str, str]) -> str:
    """Which of the files a run started with (the record's names and SHA-256) are gone or changed, and which
    the deck reads now that it did not, as a message's start."""
    if deck.name not in started:    # a record of another run, or damaged
        return (f"the run record ({RECORD}) names no start of {deck.name} (damaged, or of another run), and "
                f"{deck.name} or a file it reads changed")
    now = [deck, *input_files(deck)]
    gone = [n for n in started if n not in COMPARED and not (deck.parent / n).is_file()]
    changed = [p.name for p in now if p.name in started and file_digest(p) != started[p.name]]
    new = [p.name for p in now if p.name not in started]
    parts = ([f"{', '.join(changed)} changed"] if changed else []) + ([f"{', '.join(gone)} deleted"] if gone else []) \
        + ([f"{deck.name} now reads {', '.join(new)}"] if new else [])
    return "; ".join(parts) if parts else f"{deck.name} or a file it reads changed (the run record names no files)"


def _check_partial(deck: Path, variables: dict[str, str], identity: str) -> None:
    """Refuses to resume frames that do not read back whole (read by a child process: HDF5 may crash on
    a damaged file), or that another run wrote: the run would continue them into a result no one can
    read, or into a splice."""
    from .layers import LayerFileError, read_layers_guarded

    layers = layer_file_of(deck, variables)
    partial = layers.with_name(layers.name + ".partial") if layers is not None else None
    if partial is None or not partial.exists():
        return    # fix layers/hdf5 says which frames are gone
    try:
        held = read_layers_guarded(partial).identity.get("run_id", "")
    except LayerFileError as exc:
        raise ValueError(f"cannot resume: the interrupted run's frames are damaged: {exc}; start the run anew with "
                         "--force") from None
    if held and held != identity:
        raise ValueError(f"cannot resume: {partial} holds the frames of run {held}, not those of the interrupted run "
                         f"{identity} (put there since?); start the run anew with --force")


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
            _check_written(deck)
            launch = dict(variables, sediment_run_id=run_id(deck, variables))
            if force or _unresumable(deck, variables):
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
        identity = _resume_id(deck, variables)
        files = read_record(folder).get("files", {})    # those of the start it continues
        _check_partial(deck, variables, identity)
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
    frames = _stamp(layers)
    _write_record(deck.parent, **record, state="running")
    try:
        result = _run(deck, ranks, launch, progress)
    except BaseException as exc:
        if isinstance(exc, KeyboardInterrupt) and layers is not None and _finished(layers, record["run_id"]):
            # the stop came once LAMMPS had finished, before the run's bookkeeping: its results are whole
            _finish_record(deck, record, layers)
            raise RunInterrupted(f"stopped by {exc or 'SIGINT'} as the run finished: its results are complete "
                                 f"({layers.name} and the run record)") from None
        if earlier is not None and layers is not None and _stamp(layers) == frames:
            # refused before it wrote a frame (fix layers/hdf5 keeps an earlier run's frames): the
            # record still describes the run whose frames are there
            write_atomic(deck.parent / RECORD, lambda tmp: tmp.write_bytes(earlier))
        else:
            _write_record(deck.parent, **record, state="interrupted" if isinstance(exc, RunInterrupted) else "failed")
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
        if layers is not None and _finished(layers, record["run_id"]):
            record["layers"] = {"file": layers.name, "sha256": file_digest(layers)}
        _write_record(deck.parent, **record, state="finished")


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
    cmd, env = _launch(deck.name, partial_log.name, ranks, variables)
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
        elif line.startswith("SEDIMENT plan") and len(words) >= 6:
            total_steps, t_end = int(words[3]), float(words[5])
            if progress:
                bar = progress_bar(total=t_end, unit="s", desc="simulated", file=sys.stderr, dynamic_ncols=True,
                               mininterval=0.5, bar_format="{desc}: {percentage:3.0f}%|{bar}| "
                                                           "{n:.4g}/{total:.4g} s [{elapsed}{postfix}]")
        elif len(words) >= 2 and words[0].isdigit() and _is_float(words[1]):
            step, now = int(words[0]), float(words[1])
            if bar is not None and step:
                left = (time.monotonic() - start) * (total_steps - step) / step
                bar.set_postfix_str(f"ETA {_clock(left)}", refresh=False)
                bar.update(min(now, t_end) - bar.n)

    def keep_failed_log() -> None:
        if partial_log.exists():
            os.replace(partial_log, failed_log)

    proc = None
    try:
        with _signals_stop() as launch:
            proc = launch.start(cmd, env, folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
            assert proc.stdout is not None
            for line in proc.stdout:
                take(line)
            code = proc.wait()
    except RunInterrupted as exc:
        layers = layer_file_of(deck, variables)
        if layers is not None and _finished(layers, variables.get("sediment_run_id", "")):
            # The stop came as LAMMPS finished: the layer file is this run's and complete.
            print(f"({exc} as the run finished: its results are complete)", file=sys.stderr)
            code = 0
        else:
            keep_failed_log()
            left = "no layer file"
            if layers is not None:
                partial = layers.with_name(layers.name + ".partial")
                left = f"its frames so far are in {partial.name}" if partial.exists() else "it wrote no frames"
            raise RunInterrupted(f"{exc} at step {step} of {total_steps or '?'} (t = {now:.6g} s): every rank was "
                                 f"stopped; {left}, an earlier result is untouched; sediment run --resume continues "
                                 "it from its last restart file") from None
    except BaseException:
        keep_failed_log()
        raise
    finally:
        if proc is not None:
            _release(proc)
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
    cmd, env = _launch(str(deck), "none", ranks, variables)
    if getattr(running, "stopped", False):
        raise RunInterrupted("the runs were stopped before this one began")
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
        _release(proc)
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
            _stop(proc, grace=2.0)

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
