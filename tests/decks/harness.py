# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs LAMMPS decks through lmp_sediment and reads what they print.

Decks print "SAMPLE v1 v2 ..." rows and "RESULT key value key value ..." lines; checks compare
them with analytic references from the physics core (sediment._core).
"""
from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "python"))
from sediment.sim.run import DeckOutput, run_batch  # noqa: E402


def run_deck(deck: str | Path, variables: dict[str, object] | None = None, np_ranks: int = 1,
             expect_failure: bool = False, cwd: Path | None = None, timeout: float = 600) -> DeckOutput:
    deck = Path(deck)
    if not deck.is_absolute():
        deck = HERE / deck
    out = run_batch(deck, variables, np_ranks, cwd=cwd or HERE, timeout=timeout, check=False)
    if (out.returncode != 0) != expect_failure:
        sys.stderr.write(out.text[-4000:])
        raise AssertionError(f"{deck.name} exited with {out.returncode} (variables {variables})")
    return out


def report(message: str) -> None:
    print(message, flush=True)
