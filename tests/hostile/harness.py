# SPDX-License-Identifier: GPL-2.0-or-later
"""The machinery of the hostile rounds (round3.py): running `bin/sediment` with a time limit, hashing
folders, judging an outcome, damaging files, the shared fixtures and a small full disk.

An outcome is exactly one of
    ok     the right result, or exit 2 with a message that names the cause and nothing on disk changed
    wrong  exit 0 with a wrong, mixed or lost result; another file deleted or overwritten; a damaged
           file read as whole; a bad input accepted (the command went to work on it)
    crash  a traceback, death by a signal, an exit code other than 0, 2 or 130
    vague  refused, but the message names the wrong cause or none
"""
from __future__ import annotations

import hashlib
import os
import random
import re
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Sequence

REPO = Path(__file__).resolve().parents[2]
SEDIMENT = [str(REPO / "bin" / "sediment")]
PSD = REPO / "examples" / "granulometry" / "psd" / "sample5.csv"
PSD1 = REPO / "examples" / "granulometry" / "psd" / "sample1.csv"
INV = REPO / "examples" / "inverse"
SPHERES_CSV = REPO / "tests" / "data" / "vw1965_dev.csv"
CASE_A = REPO / "examples" / "single_sphere" / "in.case_a"
TINY = ["--particles", "1000", "--t-end", "7200"]            # 725 steps, half a second
LONG = ["--particles", "2000", "--t-end", "7200", "--courant", "0.05"]   # some 58000 steps, a few seconds
OUTCOMES = ("ok", "wrong", "crash", "vague")
REFUSED = (2,)


@dataclass
class Done:
    rc: int | None
    out: str
    err: str
    timed_out: bool = False
    seconds: float = 0.0

    @property
    def message(self) -> str:
        """The lines of stderr that are the message: no progress bars, no argparse usage."""
        lines = []
        for raw in self.err.replace("\r", "\n").splitlines():
            line = raw.strip()
            if "%|" in line:        # a progress bar; a message may follow it on the same line
                line = re.sub(r"^.*%\|[^|]*\|[^\]]*\]", "", line).strip()
            if not line or line.startswith("usage:") or raw.startswith(" "):
                continue
            lines.append(line)
        return "\n".join(lines)

    @property
    def last(self) -> str:
        lines = self.message.splitlines()
        return lines[-1][:200] if lines else ""


def env() -> dict:
    e = dict(os.environ)
    e["PYTHONPATH"] = str(REPO / "python") + (":" + e["PYTHONPATH"] if e.get("PYTHONPATH") else "")
    e.setdefault("SEDIMENT_LMP", str(REPO / "build" / "lmp_sediment"))
    e.pop("PYTHONWARNINGS", None)
    return e


def stop(proc: subprocess.Popen, sig: int = signal.SIGTERM, grace: float = 8.0) -> None:
    """End a sediment we started: its clean-up first, then its whole session."""
    if proc.poll() is None:
        try:
            proc.send_signal(sig)
            proc.wait(grace)
        except subprocess.TimeoutExpired:
            pass
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()


def start(args: Sequence, cwd: Path | None = None, stdin=subprocess.DEVNULL) -> subprocess.Popen:
    return subprocess.Popen(SEDIMENT + [str(a) for a in args], cwd=cwd, stdin=stdin, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, errors="replace", env=env(),
                            start_new_session=True)


def finish(proc: subprocess.Popen, timeout: float, t0: float) -> Done:
    try:
        out, err = proc.communicate(timeout=timeout)
        return Done(proc.returncode, out, err, False, time.monotonic() - t0)
    except subprocess.TimeoutExpired:
        stop(proc)
        out, err = proc.communicate()
        return Done(proc.returncode, out, err, True, time.monotonic() - t0)


def sed(*args, timeout: float = 120, cwd: Path | None = None) -> Done:
    t0 = time.monotonic()
    return finish(start(args, cwd), timeout, t0)


def must(*args, timeout: float = 300) -> Done:
    done = sed(*args, timeout=timeout)
    if done.rc != 0:
        raise RuntimeError(f"sediment {' '.join(map(str, args))}: exit {done.rc}: {done.err[-500:]}")
    return done


# ---- folders ------------------------------------------------------------------------------------
STAGE = ".sediment-stage-"    # a killed command's stage: hidden, cleared by the next command in the folder
IGNORED = re.compile(r"\.lock$|^\.sediment-files\.json$")    # locks, and the manifest every publish updates


def tree(folder: Path) -> dict[str, str]:
    """Every file under folder (locks aside) with its hash; a missing folder is an empty tree."""
    folder = Path(folder)
    if folder.is_file():
        return {".": hashlib.sha256(folder.read_bytes()).hexdigest()}
    if not folder.exists():
        return {}
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not IGNORED.search(p.name)
            and not any(part.startswith(STAGE) for part in p.relative_to(folder).parts)}


TIMED = ("sweep.csv", "trials.csv", "effects.csv")   # tables with wall times in them: by name only


def csvs(folder: Path) -> dict[str, str]:
    """The deterministic part of a result: its CSV tables and data files by hash, other files by name."""
    return {k: (v if k.endswith((".csv", ".data")) and not k.endswith(TIMED) else "") for k, v in tree(folder).items()}


def diff(before: dict, after: dict) -> str:
    gone = sorted(set(before) - set(after))
    new = sorted(set(after) - set(before))
    changed = sorted(k for k in set(before) & set(after) if before[k] != after[k])
    parts = []
    if gone:
        parts.append("deleted " + ", ".join(gone[:4]) + ("..." if len(gone) > 4 else ""))
    if changed:
        parts.append("changed " + ", ".join(changed[:4]) + ("..." if len(changed) > 4 else ""))
    if new:
        parts.append("new " + ", ".join(new[:4]) + ("..." if len(new) > 4 else ""))
    return "; ".join(parts)


# ---- judging ------------------------------------------------------------------------------------
Words = Sequence  # each item: a string, or a tuple of alternatives; every item must be in the message


def has(text: str, words: Words) -> bool:
    low = text.lower()
    for item in words:
        alts = (item,) if isinstance(item, str) else tuple(item)
        if not any(a.lower() in low for a in alts):
            return False
    return True


def show(words: Words) -> str:
    return " + ".join(w if isinstance(w, str) else "|".join(w) for w in words)


def crashed(done: Done, allowed: Iterable[int] = (0, 2, 130)) -> str | None:
    if "Traceback (most recent call last)" in done.err:
        tail = [line for line in done.err.strip().splitlines() if line.strip()]
        return "traceback: " + (tail[-1].strip()[:180] if tail else "?")
    if done.rc is not None and done.rc < 0 and not done.timed_out:
        try:
            name = signal.Signals(-done.rc).name
        except ValueError:
            name = str(-done.rc)
        return f"died of {name}: {done.last}"
    if done.rc not in allowed and not done.timed_out:
        return f"exit {done.rc}: {done.last}"
    return None


def refusal(done: Done, words: Words, before: dict | None = None, after: dict | None = None,
            accept: Callable[[], tuple[bool, str]] | None = None, refuse_codes: Sequence[int] = REFUSED
            ) -> tuple[str, str]:
    """The outcome of a case that must be refused (or, with accept, may also be done right)."""
    bad = crashed(done, (0, 130, *refuse_codes))
    if bad:
        return "crash", bad
    if done.timed_out:
        return "wrong", f"accepted: still at work after {done.seconds:.0f} s (no check refused it)"
    if done.rc == 0:
        if accept is None:
            return "wrong", "exit 0: accepted" + (f" ({done.out.strip().splitlines()[-1][:140]})"
                                                  if done.out.strip() else "")
        good, why = accept()
        return ("ok", why) if good else ("wrong", "exit 0: " + why)
    if done.rc == 130:
        return "crash", f"exit 130 with no signal: {done.last}"
    if before is not None and after is not None and before != after:
        return "wrong", f"refused ({done.last[:100]}) but the disk changed: {diff(before, after)}"
    if not done.message:
        return "vague", f"exit {done.rc} with nothing on stderr"
    if has(done.message, words):
        return "ok", done.last
    return "vague", f"'{done.last[:150]}' (wants {show(words)})"


# ---- damage -------------------------------------------------------------------------------------
def damage(path: Path, how: str, seed: int = 7) -> None:
    data = bytearray(path.read_bytes())
    n = len(data)
    rng = random.Random(seed)
    if how.startswith("cut"):                       # cut50: the first 50 %
        path.write_bytes(bytes(data[: n * int(how[3:]) // 100]))
    elif how == "empty":
        path.write_bytes(b"")
    elif how == "text":
        path.write_bytes(b"this is not what it says it is\n")
    elif how.startswith("zero"):                    # zero50: 4 KiB of zeros at 50 %
        at = min(n * int(how[4:]) // 100, max(0, n - 4096))
        data[at: at + 4096] = bytes(min(4096, n - at))
        path.write_bytes(bytes(data))
    elif how.startswith("bytes"):                   # bytes3: 3 random bytes changed
        for _ in range(int(how[5:])):
            at = rng.randrange(n)
            data[at] = (data[at] + 1 + rng.randrange(255)) % 256
        path.write_bytes(bytes(data))
    elif how.startswith("head"):                    # head: the first 512 bytes random
        data[:512] = bytes(rng.randrange(256) for _ in range(min(512, n)))
        path.write_bytes(bytes(data))
    elif how.startswith("tail"):                    # tail: the last 4 KiB random
        for at in range(max(0, n - 4096), n):
            data[at] = rng.randrange(256)
        path.write_bytes(bytes(data))
    elif how == "appended":
        path.write_bytes(bytes(data) + bytes(rng.randrange(256) for _ in range(3000)))
    else:
        raise ValueError(how)


# ---- a small full disk -------------------------------------------------------------------------
class FullDisk:
    """A tmpfs of `size` bytes under `where`, filled until `free` bytes are left (root only)."""

    def __init__(self, where: Path, size: int = 4 << 20):
        self.path = Path(where)
        self.path.mkdir(parents=True, exist_ok=True)
        subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(self.path)], check=True)

    def fill(self, free: int) -> None:
        filler = self.path / ".filler"
        st = os.statvfs(self.path)
        left = st.f_bavail * st.f_frsize
        with open(filler, "ab") as f:
            f.write(b"\0" * max(0, left - free))
        # tmpfs counts pages: take the last of them byte by byte
        try:
            with open(filler, "ab") as f:
                while os.statvfs(self.path).f_bavail * os.statvfs(self.path).f_frsize > free:
                    f.write(b"\0" * 4096)
                    f.flush()
        except OSError:
            pass

    def free(self) -> None:
        (self.path / ".filler").unlink(missing_ok=True)

    def close(self) -> None:
        subprocess.run(["umount", "-l", str(self.path)], check=False)


def can_mount() -> bool:
    return os.geteuid() == 0 and shutil.which("mount") is not None


def tmpdir(root: Path, name: str) -> Path:
    return Path(tempfile.mkdtemp(prefix=re.sub(r"[^A-Za-z0-9]+", "-", name)[:40] + "-", dir=root))
