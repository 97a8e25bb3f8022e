# SPDX-License-Identifier: GPL-2.0-or-later
"""benchmarks/cost.py: valgrind's totals read right, a scene's counts per particle-step taken from
the time-step loop of two runs (set-up cancels), and the targets' ratios from the rounds' times."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import benchmark_script


@pytest.fixture(scope="module")
def cost():
    return benchmark_script("cost")


def test_the_totals_are_the_summary_line_named_by_the_events_line(cost):
    text = ("desc: I1 cache: 32768 B, 64 B, 8-way associative\ncmd: lmp_sediment\n"
            "events: Ir I1mr ILmr Dr D1mr DLmr Dw D1mw DLmw \nfl=x.cpp\nfn=f\n1 5 0 0 2 1 0 1 0 0\n"
            "summary: 783908481 155938 50669 237832565 30552875 26110653 224930158 3195509 2973816\n")
    totals = cost.valgrind_totals(text)
    assert totals["Ir"] == 783908481 and totals["D1mr"] == 30552875 and totals["DLmw"] == 2973816
    with pytest.raises(ValueError, match="not a callgrind or cachegrind output file"):
        cost.valgrind_totals("Loop time of 1.2 on 1 procs\n")
    with pytest.raises(ValueError, match="does not match"):
        cost.valgrind_totals("events: Ir D1mr\nsummary: 12\n")


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
def test_a_scene_costs_its_step_per_particle_not_its_start_up(cost):
    # fix nve/sphere + gravity: about 215 instructions per particle-step (a few hundred at most);
    # with the start-up of LAMMPS (about 10^8 instructions) left in it would be tens of thousands.
    # And the count is the same from run to run, which is what it is for (the clock's noise here is
    # 10-15 %). Only the time-step loop is counted: a count of the whole program took in MPI's
    # start-up, which polls for as long as the machine's load makes it wait (215.9 against 211.0 on
    # a busy machine, issue 59), while the loop on one rank runs the same instructions every time but
    # for a handful: two runs on a loaded machine differed by 5 of 1.7e7 (214.96526 against 214.96533
    # per particle-step; where, not traced: the loop also reads the clock), so
    # they must agree to 1e-5, 2000 times closer than the whole program's counts did. Misses of a
    # scene this small (it fits the caches) are near zero, of either sign.
    first, again = (cost.counts_per_step("plain", 2000, 20) for _ in range(2))
    assert 100 < first["instructions"] < 500
    assert again["instructions"] == pytest.approx(first["instructions"], rel=1e-5)
    assert abs(first["L2 misses"]) < 5 and first["cycles (est.)"] == pytest.approx(
        first["instructions"] + 12 * first["L1 misses"] + 40 * first["L2 misses"])


def test_the_targets_come_from_the_best_times_and_each_round(cost, capsys):
    # Two rounds: the best times mix them (plain from the first, bare from the second), the rounds'
    # ratios do not; a target whose scenes did not run is left out.
    rounds = [{"plain": 1.0, "peer": 1.1, "bare": 1.3}, {"plain": 2.0, "peer": 2.2, "bare": 1.2}]
    best = {s: min(r[s] for r in rounds) for s in rounds[0]}
    cost.report_targets(best, rounds)
    lines = capsys.readouterr().out.splitlines()
    off = next(line for line in lines if line.startswith("every effect off"))
    assert off.split()[-7:] == ["1.200", "0.950", "0.600", "-", "1.300", "<=", "1.02"]
    assert not any(line.startswith("explicit") for line in lines)


def test_the_counts_run_the_scene_at_the_step_asked_for(cost, monkeypatch):
    # --counts --dt: the deck takes the step (it ran every scene at the default 1e-4 s before).
    commands = []

    def run(cmd, **kwargs):
        commands.append(cmd)
        out = Path(next(a for a in cmd if a.startswith("--callgrind-out-file=")).split("=", 1)[1])
        steps = int(cmd[cmd.index("steps") + 1])
        out.write_text(f"events: Ir D1mr D1mw DLmr DLmw\nsummary: {1000 + 10 * steps} 0 0 0 0\n")
        return type("Done", (), {"returncode": 0, "stderr": ""})()

    monkeypatch.setattr(cost.shutil, "which", lambda name: "/usr/bin/" + name)
    monkeypatch.setattr(cost.subprocess, "run", run)
    per = cost.counts_per_step("nonlinear", 100, 5, dt=1.32e-8)
    assert [cmd[cmd.index("dt") + 1] for cmd in commands] == ["1.32e-08", "1.32e-08"]
    # only the time-step loop is counted, not the start-up a loaded machine stretches
    assert all("--collect-atstart=no" in cmd and f"--toggle-collect={cost.COUNTED}" in cmd for cmd in commands)
    assert per["instructions"] == pytest.approx(10 * 10 / (100 * 10))


def test_the_sweep_runs_the_peer_beside_the_scenes_at_every_point(cost, monkeypatch, capsys):
    # Above dt/tau = 2 the explicit peer runs at dt/tau = 1, in the same fluid and round as the scenes
    # there, and each round's ratio divides by that round's peer (a drift of the machine between the
    # points must not enter a point's ratio). Times here: the peer doubles from round to round, the
    # scene costs twice the peer of its round, so every ratio is 2 exactly.
    calls = []
    state = {"round": 0}

    def scene_run(scene, particles, steps, lmp=None, dt=1e-4, mu=None):
        calls.append((scene, dt, mu))
        if scene == "peer":
            state["round"] += 1
        return 2.0 ** state["round"] * (2.0 if scene == "drag" else 1.0), 0

    monkeypatch.setattr(cost, "scene_run", scene_run)
    cost.sweep(["drag"], 10, 10, 3)
    for ratio in cost.RATIOS:
        mu, dt, peer_dt = cost.sweep_point(ratio)
        assert dt / cost.tau_at(mu) == pytest.approx(ratio)
        assert peer_dt / cost.tau_at(mu) == pytest.approx(ratio if ratio <= cost.EXPLICIT_LIMIT else 1.0)
        assert calls.count(("peer", peer_dt, mu)) >= 3 and calls.count(("drag", dt, mu)) == 3
    assert len(calls) == 2 * 3 * len(cost.RATIOS)
    points = {f"{ratio:.0e}" for ratio in cost.RATIOS}
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line.split()[:1] and
            line.split()[0] in points]
    assert len(rows) == len(cost.RATIOS)
    assert all(row[-2:] == ["2.00x", "(2.00)"] and row[3] == "0/0" for row in rows)
    assert [row[4].endswith("*") for row in rows] == [r > cost.EXPLICIT_LIMIT for r in cost.RATIOS]


def test_the_sweep_keeps_the_displacement_per_step_of_a_users_scene(cost):
    # Above dt/tau = 1 the sweep makes the grains relax faster (the viscosity as sqrt(dt/tau)), so
    # that they fall per step what they fall at dt/tau = 1 (g' tau dt), far inside LAMMPS's neighbor
    # skin: the rows measure the step, not LAMMPS's rebuilds of its lists. With --sweep-by dt the
    # grains of dt/tau = 1e4 fall 36 diameters per step (the rows before issue 60's second round).
    def fall(mu, dt):
        return cost.tau_at(mu) * dt
    at_one = fall(*cost.sweep_point(1.0)[:2])
    for ratio in cost.RATIOS:
        mu, dt, _ = cost.sweep_point(ratio)
        assert fall(mu, dt) == pytest.approx(min(ratio, 1.0) * at_one)
    mu, dt, peer_dt = cost.sweep_point(1e4, "dt")
    assert mu == cost.MU and dt == pytest.approx(1e4 * cost.TAU) and peer_dt == cost.TAU
    assert fall(mu, dt) == pytest.approx(1e4 * at_one)
