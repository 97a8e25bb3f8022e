# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs LAMMPS decks through lmp_sediment and reads what they print.

Decks print "SAMPLE v1 v2 ..." rows and "RESULT key value key value ..." lines; checks compare
them with analytic references from the physics core (sediment._core); `read_dump_frames` reads a
text dump's frames by step.

With SEDIMENT_PLUGIN naming a sedimentplugin.so, each deck runs on the lmp of SEDIMENT_LMP with that
plugin loaded first, as a user of the plugin route writes it: a wrapper deck holds `plugin load
PLUGIN` and then `include DECK`. The same on every release with the PLUGIN package (29 Sep 2021 loads
no plugin from LAMMPS_PLUGIN_PATH at start). The run must show that the plugin loaded: the route
tests' lmps have SEDIMENT in their trees too, which would otherwise run the decks all the same.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "python"))
from sediment.sim.run import DeckOutput, run_batch  # noqa: E402


def died(out: DeckOutput) -> str:
    """A run that died of a signal, as a report says it: whether LAMMPS had ended (a fault at exit, in
    MPI_Finalize or a destructor) or not, and the last lines, where Open MPI prints the faulting stack."""
    stage = "after LAMMPS ended (Total wall time printed)" if "Total wall time" in out.text else "during the run"
    tail = "\n      ".join(out.text.strip().splitlines()[-15:])
    return f"crash (exit {out.returncode}) {stage}; the deck's last lines:\n      {tail}"


def run_deck(deck: str | Path, variables: dict[str, object] | None = None, np_ranks: int = 1,
             expect_failure: bool = False, cwd: Path | None = None, timeout: float = 600) -> DeckOutput:
    deck = Path(deck)
    if not deck.is_absolute():
        deck = HERE / deck
    plugin = os.environ.get("SEDIMENT_PLUGIN")
    if plugin:
        out = _run_with_plugin(Path(plugin).resolve(), deck.resolve(), variables, np_ranks, cwd or HERE, timeout)
    else:
        out = run_batch(deck, variables, np_ranks, cwd=cwd or HERE, timeout=timeout, check=False)
    if (out.returncode != 0) != expect_failure:
        sys.stderr.write(out.text[-4000:])
        raise AssertionError(f"{deck.name} exited with {out.returncode} (variables {variables})")
    return out


def _run_with_plugin(plugin: Path, deck: Path, variables, np_ranks: int, cwd: Path, timeout: float):
    """The deck run through a wrapper that loads the plugin first. The wrapper sits in a folder of
    its own; the run's working folder, and so every relative name in the deck, stays the caller's.
    The -var variables are global and reach the included deck; a restart file the deck reads is read
    after the load, so the styles it names are the plugin's. Not for a deck that issues `clear`:
    29 Sep 2021 unloads every plugin there, and the rest of the deck would run the tree's styles."""
    if not plugin.is_file():
        raise FileNotFoundError(f"SEDIMENT_PLUGIN={plugin}: no such file")
    with tempfile.TemporaryDirectory(prefix="sediment-plugin-") as tmp:
        wrapper = Path(tmp) / f"plugin_{deck.name}"
        wrapper.write_text(f'plugin load "{plugin}"\ninclude "{deck}"\n')
        out = run_batch(wrapper, variables, np_ranks, cwd=cwd, timeout=timeout, check=False)
    # LAMMPS only logs a load that failed and goes on: with the tree's own SEDIMENT the deck would pass.
    if "Loading plugin: " not in out.text or "Open of file" in out.text:
        sys.stderr.write(out.text[-4000:])
        raise AssertionError(f"{plugin} did not load (see LAMMPS's output above)")
    return out


G = 9.81    # the decks' gravity [m/s2]
# name -> (function of the rank count, rank counts ctest runs it with: () once without --np; None:
# not in the standard list, registered by tests/decks/CMakeLists.txt for a LAMMPS with PLUGIN only)
CHECKS: dict = {}


def read_dump_frames(path: Path) -> dict[int, np.ndarray]:
    """The frames of a LAMMPS text dump (columns after the header) by step."""
    lines = path.read_text().splitlines()
    frames, k = {}, 0
    while k < len(lines):
        step = int(lines[k + 1])
        count = int(lines[k + 3])
        start = k + 9
        frames[step] = np.array([[float(v) for v in line.split()] for line in lines[start:start + count]])
        k = start + count
    return frames


def check(fn=None, *, ranks=(1, 2)):
    """Registers a check (of checks.py or the modules it imports); ctest asks `checks.py --list` for
    the names and their rank counts."""
    def register(fn):
        CHECKS[fn.__name__] = (fn, None if ranks is None else tuple(ranks))
        return fn
    return register(fn) if fn is not None else register


def report(message: str) -> None:
    print(message, flush=True)
