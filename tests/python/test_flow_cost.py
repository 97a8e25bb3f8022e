# SPDX-License-Identifier: GPL-2.0-or-later
"""benchmarks/flow_cost.py: LAMMPS's timing breakdown read per step, and a small run of every mode of
its deck (one-way, the flow at each interval and only at the start, PPPM) to the end of both tables;
no time is asserted (the machine's load would decide it)."""
from __future__ import annotations

import pytest
from conftest import benchmark_script

BREAKDOWN = """Loop time of 0.5 on 2 procs for 100 steps with 20000 atoms
Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    | 0          | 0          | 0          |   0.0 |  0.00
Kspace  | 0.1        | 0.2        | 0.3        |   0.0 | 40.00
Modify  | 0.25       | 0.26       | 0.27       |   0.0 | 52.00
"""


@pytest.fixture(scope="module")
def flow_cost():
    return benchmark_script("flow_cost")


def test_the_breakdown_is_read_at_its_average(flow_cost):
    assert flow_cost.section(BREAKDOWN, "Kspace") == pytest.approx(0.2)
    assert flow_cost.section(BREAKDOWN, "Modify") == pytest.approx(0.26)
    assert flow_cost.section(BREAKDOWN, "Neigh") == 0.0


def test_a_small_run_prints_both_tables(flow_cost, capsys):
    assert flow_cost.main(["--particles", "600", "--steps", "4", "--repeat", "1", "--grid", "8", "--every", "1,0",
                           "--drift", "0.5", "--grids", "8", "--ranks", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("600 grains, 8^3 cells, 1 ranks: one-way step")
    rows = [line.split() for line in lines[2:5]]
    assert [row[0] for row in rows] == ["1", "once", "drift"] and all(float(row[-3]) > 0 for row in rows)
    # every step: the setup's solve and one per step of both runs (5 + 4); once: the setup's alone
    assert [float(row[-1]) for row in rows[:2]] == [10.0, 1.0] and 1 <= float(rows[2][-1]) <= 10
    last = lines[-1].split()
    assert last[:2] == ["8", "1"] and len(last) == 5 and float(last[3]) > 0    # PPPM's Kspace time
