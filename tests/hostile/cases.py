# SPDX-License-Identifier: GPL-2.0-or-later
"""The machinery every case of hostile round 3 shares: `Case`, the table `CASES` the case modules
register into with `add`, the context `Ctx` a case runs in, and the fixtures built once per round."""
from __future__ import annotations

import shutil
import signal
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from harness import INV, LONG, PSD, TINY, must, start


@dataclass
class Case:
    name: str
    command: str
    kind: str
    fn: Callable
    quick: bool = False
    needs: tuple = ()


CASES: dict[str, Case] = {}


def add(name: str, command: str, kind: str, fn: Callable, quick: bool = False, needs: tuple = ()) -> None:
    assert name not in CASES, name
    command = {"preview": "readout", "paste-energy": "paste", "calibrate-tilt": "calibrate",
               "invert-pipette": "invert", "invert-buoyancy": "invert", "readout-preview": "readout",
               "calibrate-slump": "calibrate", "paste-balls": "paste", "invert-plain": "invert"}.get(command, command)
    CASES[name] = Case(name, command, kind, fn, quick, tuple(needs))


class Ctx:
    def __init__(self, tmp: Path, fixtures: Path):
        self.tmp, self.fixtures = tmp, fixtures

    def fx(self, name: str) -> Path:
        return self.fixtures / name

    def copy(self, name: str, dest: str | None = None) -> Path:
        target = self.tmp / (dest or name)
        shutil.copytree(self.fx(name), target, symlinks=True)
        return target

    def file(self, name: str, data: bytes | str) -> Path:
        path = self.tmp / name
        path.write_bytes(data.encode() if isinstance(data, str) else data)
        return path


# ==== fixtures: built once per round, copied by the cases that need them ============================
def fx_run(dest: Path) -> None:
    must("sample", PSD, "--out", dest, *TINY)
    must("run", dest / "in.sedimentation", "--quiet")
    must("readout", dest / "layers.h5", "--out", dest / "r")


def fx_sample(dest: Path) -> None:
    must("sample", PSD, "--out", dest, *TINY)


def with_restarts(folder: Path) -> bool:
    return all((folder / n).is_file() and (folder / n).stat().st_size > 0 for n in ("restart.a.bin", "restart.b.bin"))


def fx_interrupted(dest: Path) -> None:
    """A run of LONG killed once both restart files and its partial frames are there."""
    must("sample", PSD, "--out", dest, *LONG)
    for _ in range(4):
        proc = start(["run", dest / "in.sedimentation", "--quiet", "--force"])
        end = time.monotonic() + 120
        while not with_restarts(dest) and time.monotonic() < end and proc.poll() is None:
            time.sleep(0.005)
        proc.send_signal(signal.SIGKILL)
        proc.communicate()
        time.sleep(1.5)
        if with_restarts(dest) and (dest / "layers.h5.partial").is_file() and not (dest / "layers.h5").exists():
            return
    raise RuntimeError("no interrupted run with restart files")


def fx_longref(dest: Path) -> None:
    must("sample", PSD, "--out", dest, *LONG)
    must("run", dest / "in.sedimentation", "--quiet")


def fx_invert(dest: Path) -> None:
    must("invert", INV / "soil" / "hydrometer.csv", INV / "soil" / "sieve.csv", "--mass", "0.05", *INVERT_SMALL,
         "--out", dest / "out", timeout=600)


def fx_plan(dest: Path) -> None:
    must("plan", PSD, "--out", dest, *PLAN_SMALL, timeout=600)


FIXTURES = {"run": fx_run, "sample": fx_sample, "interrupted": fx_interrupted, "longref": fx_longref,
            "invert": fx_invert, "plan": fx_plan}
INVERT_SMALL = ["--particles", "2000", "--bins", "8"]
PLAN_SMALL = ["--particles", "1000,500", "--courant", "4", "--t-end", "7200", "--replicas", "1", "--no-models",
              "--jobs", "1"]


def build_fixtures(names: set[str], root: Path) -> None:
    for name in sorted(names):
        dest = root / name
        if not dest.exists():
            t0 = time.monotonic()
            FIXTURES[name](dest)
            print(f"fixture {name}: {time.monotonic() - t0:.1f} s", flush=True)
