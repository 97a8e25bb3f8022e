# SPDX-License-Identifier: GPL-2.0-or-later
"""benchmarks/flow_drift.py: a short run of one scene prints the reference row and one per schedule, with
the solves each took (the setup's and at most one per step) and a change against every step."""
from __future__ import annotations

import pytest
from conftest import benchmark_script


@pytest.fixture(scope="module")
def flow_drift():
    return benchmark_script("flow_drift")


def test_a_short_column_prints_each_schedule(flow_drift, capsys):
    assert flow_drift.main(["--scenes", "column", "--fraction", "0.1", "--schedules", "drift 0.5,every 10"]) == 0
    rows = capsys.readouterr().out.splitlines()[1:]
    assert [row.split()[:3] for row in rows][0] == ["column", "every", "1"]
    assert [row.split()[:2] for row in rows[1:]] == [["drift", "0.5"], ["every", "10"]]
    solves = [float(row.split()[3 if i == 0 else 2]) for i, row in enumerate(rows)]
    assert solves[0] == 31 and 1 <= solves[1] <= 31 and solves[2] == 4    # 30 steps: the setup's solve and one a step
    changes = [float(row.split()[-1]) for row in rows[1:]]
    assert all(0 <= change < 0.1 for change in changes)


def test_an_unknown_scene_is_refused(flow_drift):
    with pytest.raises(SystemExit):
        flow_drift.main(["--scenes", "clod"])
