# SPDX-License-Identifier: GPL-2.0-or-later
"""benchmarks/final_states.py: a scene's final state read back from its dump, and two states told
apart (byte for byte, or by their largest differences) without mistaking different atoms for a
difference of the step."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import benchmark_script

from sediment.sim.paths import lmp_executable


@pytest.fixture(scope="module")
def final_states():
    return benchmark_script("final_states")


HEADER = ("ITEM: TIMESTEP\n3\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
          "ITEM: ATOMS id x y z vx vy vz omegax omegay omegaz\n")


def dump(path: Path, rows: list[list[float]]) -> np.ndarray:
    path.write_text(HEADER + "".join(" ".join(f"{v:.17g}" for v in row) + "\n" for row in rows))
    return np.loadtxt(path, skiprows=9, ndmin=2)


def test_states_are_the_same_byte_for_byte_or_differ_by_their_largest_change(final_states, tmp_path, capsys):
    rows = [[1, 0.1, 0.2, 0.3, 0.0, 0.0, -2e-3, 0, 0, 0], [2, 0.4, 0.5, 0.6, 0.0, 0.0, -1e-3, 0, 0, 0]]
    a = dump(tmp_path / "a", rows)
    b = dump(tmp_path / "b", rows)
    assert final_states.compare("same", tmp_path / "a", tmp_path / "b", a, b)
    rows[1][6] = -1e-3 * (1 + 2**-40)    # one sphere's speed changed by 2^-40 of itself
    rows[0][3] = 0.3 + 1e-12
    c = dump(tmp_path / "c", rows)
    assert not final_states.compare("changed", tmp_path / "c", tmp_path / "a", c, a)
    line = capsys.readouterr().out
    assert "changed" in line
    velocity = float(line.split("velocity")[1].split()[0])
    position = float(line.split("position")[1].split()[0])
    assert velocity == pytest.approx(1e-3 * 2**-40 / 2e-3, rel=1e-3) and position == pytest.approx(1e-12, rel=1e-3)
    other = dump(tmp_path / "d", [rows[0]])
    with pytest.raises(SystemExit, match="different atoms"):
        final_states.compare("lost an atom", tmp_path / "d", tmp_path / "a", other, a)


def test_a_scene_dumps_its_final_state_with_the_options_asked_for(final_states, tmp_path):
    # With the floor at z = 6 mm every sphere ends on or above it, those on it at rest; without it
    # the spheres (created all over the 20 mm periodic box) stay spread below it too.
    lmp = str(lmp_executable())
    settle = {"scene": "drag", "n": "200", "steps": "200", "dt": "0.01"}
    free = final_states.final_state(lmp, final_states.HERE / "in.cost", settle, tmp_path / "free", 1)
    floor = final_states.final_state(lmp, final_states.HERE / "in.cost", {**settle, "step_options": final_states.FLOOR},
                                     tmp_path / "floor", 1)
    assert free.shape == floor.shape == (200, 10)
    assert np.array_equal(free[:, 0], np.arange(1, 201)) and np.array_equal(floor[:, 0], free[:, 0])
    rest = 0.006 + 1.5e-5
    assert (free[:, 3] < 0.006).any()
    assert floor[:, 3].min() == pytest.approx(rest, rel=1e-12)
    on_floor = np.abs(floor[:, 3] - rest) < 1e-12
    assert on_floor.sum() > 10 and np.all(floor[on_floor, 4:10] == 0.0)


def test_a_missing_baseline_or_mpirun_is_refused_before_any_run(final_states, monkeypatch):
    for argv, message in ((["--baseline", "/no/such/lmp"], "no such executable"),
                          (["--baseline", "/bin/true", "--ranks", "2"], "needs mpirun")):
        monkeypatch.setattr(sys, "argv", ["final_states.py", *argv])
        monkeypatch.setattr(final_states.shutil, "which",
                            lambda name: None if name in ("mpirun", "/no/such/lmp") else "/bin/" + name)
        with pytest.raises(SystemExit, match=message):
            final_states.main()
