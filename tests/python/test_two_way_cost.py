# SPDX-License-Identifier: GPL-2.0-or-later
"""benchmarks/two_way_cost.py: the column's first steps, two ways and one, on its grids and ranks."""
from __future__ import annotations

import pytest
from conftest import REPO, benchmark_script


@pytest.fixture(scope="module")
def two_way_cost():
    return benchmark_script("two_way_cost")


def test_a_small_run_times_both_ways_on_each_grid(two_way_cost, capsys, monkeypatch):
    """Five steps on 8 and 12 cells across, one rank: a row per grid with both loop times; the cut
    deck runs its first stage's first steps only (a whole day's deck would take minutes)."""
    monkeypatch.setattr("sys.argv", ["two_way_cost.py", "--steps", "5", "--cells", "8,12", "--ranks", "1",
                                     "--repeat", "1"])
    assert two_way_cost.main() == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[2:]]
    assert [(r[0], r[1]) for r in rows] == [("8", "1"), ("12", "1")]
    assert all(float(r[2]) > 0 and float(r[3]) > 0 for r in rows)


def test_the_cut_deck_ends_after_its_first_stages_first_steps(two_way_cost, tmp_path):
    from sediment.lab.psd import read_psd
    from sediment.sim.scene import Effects, plan
    from sediment.sim.scenefiles import write

    write(plan(read_psd(REPO / "examples" / "granulometry" / "psd" / "sample2.csv"), effects=Effects(flow=True),
               particles=2000), tmp_path)
    text = two_way_cost.first_steps(tmp_path / "in.sedimentation", 5).read_text()
    assert text.count("run ${stage_end}") == 1 and text.rstrip().endswith('"run ${stage_end} upto post ${timing}"')
    assert "$(v_stage_end+5)" in text and "t_end equal 1e-9 #" in text


def test_a_deck_it_does_not_know_is_refused(two_way_cost, tmp_path):
    deck = tmp_path / "in.sedimentation"
    deck.write_text('units si\nif "$(step) < 5" then "run ${stage_end} upto"\n')
    with pytest.raises(ValueError, match="not a deck of `sediment sample` as this benchmark knows it"):
        two_way_cost.first_steps(deck, 5)
