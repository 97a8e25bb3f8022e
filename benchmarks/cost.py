# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost per particle-step of the SEDIMENT effects, as ratios measured in one run on this machine.

    /usr/bin/python3 benchmarks/cost.py [--particles 20000] [--steps 2000] [--repeats 3] [--baseline LMP]
                                        [--scenes plain,drag,...] [--counts] [--sweep] [--jobs]

Each scene runs `repeats` times, the scenes taking turns (so that a drift of the machine's speed
during the run touches every scene alike); the best loop time is kept. LAMMPS reports the loop
time, which excludes start-up. The targets' ratios (the effects against fix nve/sphere and against
the peer) are printed from the best times and as the median and range of each round's ratios. With
--baseline (another lmp_sediment, e.g. a build of an earlier commit) every scene also runs with it,
the two taking turns scene by scene, and the table gains the ratio this build / baseline, as the
ratio of the best times and as the median of the ratios of back-to-back pairs (robust to the
machine's drift during the run): on a machine whose speed drifts by 10 % between runs, the way to
measure one change.

With --counts the scenes run under valgrind's callgrind instead of the clock, on a model of one
core of this machine (32 KiB L1 data cache, the 512 KiB L2 as the last level; what misses it comes
from the 32 MiB L3): instructions, L1 and L2 data misses per particle-step, from the difference of a
run of `steps` and one of 3 x `steps` (so the run's set-up cancels), and a rough estimate of cycles that
charges each L1 miss the L2's latency and each L2 miss the L3's (12 and 40 cycles; no overlap, no
prefetch). Only the time-step loop is counted (LAMMPS_NS::Verlet::run; callgrind's --toggle-collect):
outside it, MPI's start-up polls for as long as its daemon takes to answer, so a whole-program count
moved with the machine's load (cachegrind, plain scene: 214.8 and 215.2 per particle-step in two runs
beside a LAMMPS build, 215.9 and 211.0 on a busier machine). Inside it
the instruction counts are the same from run to run, to the instruction; the misses move by a few
per million particle-steps with where the heap lands. A change of 2 % shows where the clock's noise
on a shared machine hides it. Default 20 000 particles x 50 steps (about 10 minutes for all scenes).
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Callable

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment import _core  # noqa: E402
from sediment.cli.types import count  # noqa: E402
from sediment.sim.paths import lmp_executable  # noqa: E402
from sediment.sim.process import run_environment  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402

SCENES = {"plain": "nve/sphere + gravity (reference)",
          "peer": "nve/sphere + fix viscous + reduced gravity (LAMMPS's own fixes, same Stokes physics)",
          "explicit": "nve/sphere + buoyancy + stokes drag (explicit)",
          "bare": "nve/sphere/fluid + gravity, no fluid fixes (every effect off)",
          "drag": "nve/sphere/fluid + buoyancy + stokes drag",
          "nonlinear": "as drag with dallavalle (general Newton step)",
          "schiller": "as drag with schiller-naumann (a Cd jump, not reached)",
          "zhangli": "as drag with zhang-li in water (two Cd jumps, not reached)",
          "bingham": "as zhangli in a Bingham fluid (yield stress half the weight)",
          "binghamlaw": "as bingham with law bingham (the paste's law)",
          "standard": "as drag with the standard drag curve (the sedimentation test's law)",
          "hindered": "as nonlinear + concentration/grid (400 layers) + difelice",
          "richardson": "as standard + concentration/grid (400 layers) + hindrance richardson-zaki",
          "cells": "as hindered on 20 x 20 x 100 3d cells",
          "lubricated": "as drag + pair lubricate/fluid"}


def scene_run(scene: str, particles: int, steps: int, lmp: Path | None = None, dt: float = 1e-4,
              mu: float | None = None) -> tuple[float, int]:
    """Loop time of the scene and how many times LAMMPS rebuilt its neighbor lists in it ("Neighbor
    list builds": each one exchanges atoms, remaps them into the box and rebuilds the ghosts), with
    `lmp` instead of the lmp_sediment in use when given, in a fluid of viscosity `mu` (default water's)."""
    previous = os.environ.get("SEDIMENT_LMP")
    if lmp is not None:
        os.environ["SEDIMENT_LMP"] = str(lmp)
    try:
        out = run_batch(HERE / "in.cost", {"scene": scene, "n": particles, "steps": steps, "dt": dt,
                                           "mu": MU if mu is None else mu})
        builds = re.search(r"^Neighbor list builds = (\d+)", out.text, re.MULTILINE)
        return out.loops[0][0], int(builds.group(1)) if builds else -1
    finally:
        if previous is None:
            os.environ.pop("SEDIMENT_LMP", None)
        else:
            os.environ["SEDIMENT_LMP"] = previous


def loop_time(scene: str, particles: int, steps: int, lmp: Path | None = None, dt: float = 1e-4,
              mu: float | None = None) -> float:
    """Loop time of the scene (scene_run's)."""
    return scene_run(scene, particles, steps, lmp, dt, mu)[0]


# Cachegrind's model of one core: L1 data cache and, as the last level, the L2 (size, ways, line).
CACHE_MODEL = ["--cache-sim=yes", "--I1=32768,8,64", "--D1=32768,8,64", "--LL=524288,8,64"]
L2_LATENCY, L3_LATENCY = 12, 40    # cycles charged per L1 miss and per L2 miss in the estimate
EVENTS = ("Ir", "D1mr", "D1mw", "DLmr", "DLmw")


# The time-step loop, the only part of a run counted: the scenes' decks make one `run` each.
COUNTED = "LAMMPS_NS::Verlet::run(int)"


def valgrind_totals(text: str) -> dict[str, int]:
    """The totals of a callgrind (or cachegrind) output file (its "events:" and "summary:" lines)."""
    lines = dict(line.split(":", 1) for line in text.splitlines() if line.startswith(("events:", "summary:")))
    if "events" not in lines or "summary" not in lines:
        raise ValueError("not a callgrind or cachegrind output file (no events or summary line)")
    names, values = lines["events"].split(), lines["summary"].split()
    if len(names) != len(values):
        raise ValueError("valgrind output: the summary does not match the events")
    return dict(zip(names, map(int, values)))


def counts_per_step(scene: str, particles: int, steps: int, lmp: Path | None = None,
                    dt: float = 1e-4, mu: float | None = None) -> dict[str, float]:
    """Instructions, L1 and L2 data misses per particle-step in the time-step loop, and the estimate
    of cycles."""
    if shutil.which("valgrind") is None:
        sys.exit("cost.py --counts needs valgrind (Debian package valgrind)")
    totals = []
    with tempfile.TemporaryDirectory() as tmp:
        for run_steps in (steps, 3 * steps):
            out = Path(tmp) / f"{scene}.{run_steps}"
            cmd = ["valgrind", "--tool=callgrind", *CACHE_MODEL, "--collect-atstart=no", f"--toggle-collect={COUNTED}",
                   f"--callgrind-out-file={out}",
                   str(lmp or lmp_executable()), "-in", str(HERE / "in.cost"), "-log", "none", "-screen", "none",
                   "-var", "scene", scene, "-var", "n", str(particles), "-var", "steps", str(run_steps),
                   "-var", "dt", repr(dt), "-var", "mu", repr(MU if mu is None else mu)]
            done = subprocess.run(cmd, capture_output=True, text=True, env=run_environment())
            if done.returncode != 0:
                sys.exit(f"cost.py --counts: scene {scene} failed under callgrind:\n{done.stderr[-2000:]}")
            totals.append(valgrind_totals(out.read_text()))
            if totals[-1]["Ir"] == 0:
                sys.exit(f"cost.py --counts: no instruction counted in {COUNTED} (a LAMMPS without its symbols?)")
    per = {e: (totals[1][e] - totals[0][e]) / (particles * 2 * steps) for e in EVENTS}
    l1, l2 = per["D1mr"] + per["D1mw"], per["DLmr"] + per["DLmw"]
    return {"instructions": per["Ir"], "L1 misses": l1, "L2 misses": l2,
            "cycles (est.)": per["Ir"] + L2_LATENCY * l1 + L3_LATENCY * l2}


# The targets of the per-step cost: what is measured, from the scenes' loop times (or counts), and its limit.
TARGETS = [
    ("every effect off / fix nve/sphere", lambda t: t["bare"] / t["plain"], 1.02),
    ("explicit stokes + buoyancy / peer", lambda t: t["explicit"] / t["peer"], 1.2),
    ("implicit stokes + buoyancy / peer", lambda t: t["drag"] / t["peer"], 1.3),
    ("nonlinear implicit (dallavalle) / peer", lambda t: t["nonlinear"] / t["peer"], 2.0),
    ("nonlinear implicit (schiller-naumann) / peer", lambda t: t["schiller"] / t["peer"], 2.0),
    ("nonlinear implicit (zhang-li, water) / peer", lambda t: t["zhangli"] / t["peer"], 2.0),
    ("nonlinear implicit (zhang-li, Bingham) / peer", lambda t: t["bingham"] / t["peer"], 2.0),
    ("nonlinear implicit (bingham, Bingham) / peer", lambda t: t["binghamlaw"] / t["peer"], 2.0),
    ("nonlinear implicit (standard curve) / peer", lambda t: t["standard"] / t["peer"], 2.0),
    ("grid + Di Felice on top of nonlinear / peer", lambda t: (t["hindered"] - t["nonlinear"]) / t["peer"], 1.0),
    ("grid + Richardson-Zaki on top of standard / peer", lambda t: (t["richardson"] - t["standard"]) / t["peer"], 1.0),
    ("3d cells + Di Felice on top of nonlinear / peer", lambda t: (t["cells"] - t["nonlinear"]) / t["peer"], 2.0),
    ("lubrication on top of implicit stokes / plain", lambda t: (t["lubricated"] - t["drag"]) / t["plain"], None),
]


def measured(ratio: Callable[[dict[str, float]], float], values: dict[str, float]) -> float | None:
    """A target's ratio of these scenes' values; None when one of its scenes did not run."""
    try:
        return ratio(values)
    except KeyError:
        return None


def target_text(limit: float | None) -> str:
    return f"<= {limit:g}" if limit else ""


def report_counts(scenes: dict[str, str], args: argparse.Namespace) -> None:
    """The --counts table: this build, and the baseline when given (the counts need no turns)."""
    steps = args.steps if args.steps_given else 50
    columns = ("instructions", "L1 misses", "L2 misses", "cycles (est.)")
    print(f"{args.particles} particles x ({steps}, {3 * steps}) steps at dt {args.dt:g} s, viscosity {args.viscosity:g} "
          f"Pa s (dt/tau {args.dt / tau_at(args.viscosity):.3g}) "
          "in the time-step loop under callgrind, per particle-step")
    print(f"{'scene':10s} " + " ".join(f"{c:>13s}" for c in columns) + (f" {'this/baseline':>14s}" if args.baseline
                                                                         else "") + "  what")
    cycles = {}
    for s, what in scenes.items():
        mine = counts_per_step(s, args.particles, steps, dt=args.dt, mu=args.viscosity)
        cycles[s] = mine["cycles (est.)"]
        against = ""
        if args.baseline:
            theirs = counts_per_step(s, args.particles, steps, args.baseline, dt=args.dt, mu=args.viscosity)
            against = f" {mine['cycles (est.)'] / theirs['cycles (est.)']:14.3f}"
        print(f"{s:10s} " + " ".join(f"{mine[c]:13.2f}" for c in columns) + against + f"  {what}", flush=True)
    print()
    print(f"{'ratio (estimated cycles)':48s} {'value':>10s} {'target':>7s}")
    for label, ratio, limit in TARGETS:
        value = measured(ratio, cycles)
        if value is not None:
            print(f"{label:48s} {value:10.3f} {target_text(limit):>7s}")

def existing_file(text: str) -> Path:
    path = Path(text)
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"no such file: {text}")
    return path.resolve()


def scene_list(text: str) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in SCENES]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"unknown scene(s) {', '.join(unknown) or text!r}; expected some of "
                                         f"{', '.join(SCENES)}")
    return names


def machine_and_build(lmp: Path | None = None, under_valgrind: bool = False) -> str:
    """What a figure was measured on: the CPU and its vector extensions, the LAMMPS release and the
    compiler of the build (lmp -h), and the vector copy of the block step that ran (the fix's log line;
    under valgrind, whose CPU has no AVX-512, the copy valgrind's run takes)."""
    exe = str(lmp or lmp_executable())
    cpu, flags = "unknown CPU", set()
    with open("/proc/cpuinfo") as f:
        for line in f:
            key, _, value = line.partition(":")
            if key.strip() == "model name" and cpu == "unknown CPU":
                cpu = value.strip()
            elif key.strip() == "flags" and not flags:
                flags = set(value.split())
    extensions = ", ".join(x for x in ("avx2", "fma", "avx512f") if x in flags) or "none of avx2, fma, avx512f"
    about = subprocess.run([exe, "-h"], capture_output=True, text=True).stdout.splitlines()
    release = next((l.split(" - ", 1)[1].strip() for l in about if l.startswith("Large-scale")), "unknown release")
    compiler = next((l.split(":", 1)[1].strip() for l in about if l.startswith("Compiler:")), "unknown compiler")
    probe = ([exe] if not under_valgrind else ["valgrind", "--tool=none", exe]) + [
        "-in", str(HERE / "in.cost"), "-log", "none", "-var", "scene", "nonlinear", "-var", "n", "64", "-var",
        "steps", "2"]
    printed = subprocess.run(probe, capture_output=True, text=True).stdout
    copy = re.search(r"stepped in blocks, (\w+) vectors", printed)
    return (f"machine: {cpu} ({extensions}); build: {exe}, LAMMPS {release}, compiler (lmp -h) {compiler}; block step in "
            f"{copy.group(1) if copy else 'unknown'} vectors")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=count, default=20000)
    parser.add_argument("--steps", type=count, help="steps of each run (default 2000; with --counts 50)")
    parser.add_argument("--repeats", type=count, default=3)
    parser.add_argument("--baseline", type=existing_file, help="another lmp_sediment to take turns with")
    parser.add_argument("--scenes", type=scene_list, default=list(SCENES),
                        help="comma-separated scenes to run (default: all; plain and peer always run, the ratios need them)")
    parser.add_argument("--counts", action="store_true",
                        help="instructions and cache misses under callgrind instead of the clock (see above)")
    parser.add_argument("--dt", type=float, default=1e-4,
                        help="time step of the scenes [s] (default 1e-4: dt/tau = 0.76 for their 30 um grains in water)")
    parser.add_argument("--viscosity", type=float, default=MU,
                        help="the fluid's viscosity [Pa s] (default water's, 1.002e-3); the sweep's points above dt/tau = 1 "
                             "take it as sqrt(dt/tau) x water's (see sweep_point())")
    parser.add_argument("--sweep", action="store_true",
                        help="the cost at every dt/tau from 1e-4 to 1e4 against the peer at each (see sweep())")
    parser.add_argument("--sweep-by", choices=("viscosity", "dt"), default="viscosity",
                        help="how the sweep reaches dt/tau above 1: 'viscosity' (default) as a user's scene does, with faster "
                             "relaxing grains and the same displacement per step as at dt/tau = 1; 'dt', as before issue 60's "
                             "second round, with steps up to 1e4 tau on the same grains, which cross the neighbor skin every "
                             "step (see sweep_point())")
    parser.add_argument("--jobs", action="store_true",
                        help="after the ratios, the main job's commands (make demo's) and the example inversion timed")
    args = parser.parse_args()
    args.steps_given = args.steps is not None
    # The references run where they can (EXPLICIT_LIMIT; --sweep takes the peer's cost at dt/tau = 1 past it).
    references = (("plain", "peer") if args.counts or args.sweep or args.dt <= EXPLICIT_LIMIT * tau_at(args.viscosity)
                  else ())
    scenes = {s: SCENES[s] for s in SCENES if s in args.scenes or s in references}
    print(machine_and_build(under_valgrind=args.counts))
    if args.baseline:
        print("baseline " + machine_and_build(args.baseline, under_valgrind=args.counts).split("; ", 1)[1])
    if args.counts:
        report_counts(scenes, args)
        return
    if args.sweep:
        sweep([s for s in args.scenes if s in SWEPT] or list(SWEPT), args.particles, args.steps or 1000, args.repeats,
              args.sweep_by)
        if args.jobs:
            time_jobs()
        return
    args.steps = args.steps or 2000
    rounds: list[dict[str, float]] = []
    baseline = {s: float("inf") for s in scenes}
    pair_ratios: dict[str, list[float]] = {s: [] for s in scenes}
    for _ in range(args.repeats):
        rounds.append({})
        for s in scenes:
            mine = loop_time(s, args.particles, args.steps, dt=args.dt, mu=args.viscosity)
            rounds[-1][s] = mine
            if args.baseline:
                theirs = loop_time(s, args.particles, args.steps, args.baseline, dt=args.dt, mu=args.viscosity)
                baseline[s] = min(baseline[s], theirs)
                pair_ratios[s].append(mine / theirs)
    times = {s: min(r[s] for r in rounds) for s in scenes}
    per = {s: t / (args.particles * args.steps) * 1e9 for s, t in times.items()}
    print(f"{args.particles} particles x {args.steps} steps at dt {args.dt:g} s, viscosity {args.viscosity:g} Pa s "
          f"(dt/tau {args.dt / tau_at(args.viscosity):.3g}), best of "
          f"{args.repeats}, 1 rank")
    against = f" {'baseline ns':>12s} {'this/baseline':>14s} {'median of pairs':>16s}" if args.baseline else ""
    print(f"{'scene':10s} {'ns/particle-step':>17s} {'ratio to plain':>15s}{against}  what")
    for s, what in scenes.items():
        other = baseline[s] / (args.particles * args.steps) * 1e9
        against = (f" {other:12.2f} {times[s] / baseline[s]:14.3f} {statistics.median(pair_ratios[s]):16.3f}"
                   if args.baseline else "")
        to_plain = f"{per[s] / per['plain']:15.2f}" if "plain" in per else f"{'-':>15s}"
        print(f"{s:10s} {per[s]:17.2f} {to_plain}{against}  {what}")
    if not references:
        print(f"no plain or peer scene at dt/tau {args.dt / tau_at(args.viscosity):.3g} > {EXPLICIT_LIMIT:g} (explicit, they cannot run there); "
              "their cost per particle-step at dt/tau = 1, which does not depend on the step, is --sweep's reference")
    if args.baseline:
        print(f"baseline: {args.baseline}; the peer and plain scenes run the same code in both builds, so "
              "their ratios show this machine's noise")
    report_targets(times, rounds)
    if args.jobs:
        time_jobs()


REPO = HERE.parent
# What a user runs, in order: make demo's two commands (the planner, then the test of sample 5 with
# its decision, on 2 ranks), and the inversions of the example sheets (the README's: the soil).
JOBS = [("the planner: sediment plan sample5 --jobs 2", ["bin/sediment", "plan", "examples/granulometry/psd/sample5.csv",
                                                         "--out", "{out}/plan", "--jobs", "2"]),
        ("the test: sample, run (2 ranks) and readout of sample 5 with the plan's decision",
         ["examples/granulometry/run.sh", "sample5", "{out}/sample5", "--plan", "{out}/plan/report.json"]),
        ("sediment invert of examples/inverse's three sheets",
         ["bin/sediment", "invert", "examples/inverse/hydrometer.csv", "examples/inverse/pipette.csv",
          "examples/inverse/buoyancy.csv", "--mass", "0.06", "--out", "{out}/invert"]),
        ("sediment invert of examples/inverse/soil's 152H and sieve sheets (the README's)",
         ["bin/sediment", "invert", "examples/inverse/soil/hydrometer.csv", "examples/inverse/soil/sieve.csv",
          "--mass", "0.05", "--out", "{out}/soil"])]


def time_jobs() -> None:
    """Wall time of each of JOBS, once, in a fresh folder."""
    import time

    with tempfile.TemporaryDirectory() as out:
        print("wall time of what users run, in this run (fresh folder, once):")
        for label, command in JOBS:
            start = time.perf_counter()
            done = subprocess.run([word.format(out=out) for word in command], cwd=REPO, capture_output=True, text=True,
                                  env=dict(os.environ, SEDIMENT_RANKS="2"))
            if done.returncode != 0:
                raise SystemExit(f"{label} failed: {done.stderr.strip().splitlines()[-1:]}")
            print(f"  {label:80s} {time.perf_counter() - start:7.1f} s")


# The water's viscosity, and the relaxation time of the scene's grains (30 um quartz, Stokes) in a fluid
# of the water's density and viscosity mu: the step's regime is dt/tau.
MU = 1.002e-3


def tau_at(mu: float) -> float:
    return _core.relaxation_time("stokes", 998.2, mu, 3e-5, 2650)


TAU = tau_at(MU)
# Past this dt/tau the explicit references cannot run: the peer's explicit drag is unstable, and the
# plain scene's free fall crosses the box in a step.
EXPLICIT_LIMIT = 2.0
SWEPT = ("drag", "nonlinear", "standard", "richardson", "hindered")
RATIOS = (1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1e3, 1e4)


def sweep_point(ratio: float, by: str = "viscosity") -> tuple[float, float, float]:
    """The viscosity, the scenes' step and the peer's step of the sweep's point at dt/tau = `ratio`.

    Up to dt/tau = 1 the 30 um grains settle in water at dt = ratio x tau: they move at most 0.0036
    of their diameter per step (1.1e-7 m at dt/tau = 1, against LAMMPS's neighbor skin of 1 mm in SI
    units), and LAMMPS never rebuilds its neighbor lists in the run.

    Above, by 'viscosity' (the default), the grains relax faster, as a user's grains at such dt/tau
    do (a 1 um clay grain in water, tau ~1e-7 s, at dt ~1e-3 s): the viscosity is sqrt(ratio) x the
    water's, so tau falls by sqrt(ratio) and dt = ratio x tau rises by sqrt(ratio), and the terminal
    displacement per step, g' tau dt, stays the one at dt/tau = 1. The particle Reynolds number falls
    as 1/ratio (2.4e-6 at 1e4; the clay grain's is ~1e-6). The peer, whose explicit drag is unstable
    past dt/tau = 2, runs in the same fluid at dt = its tau.

    By 'dt' (the sweep before issue 60's second round) the same grains in water take dt = ratio x
    tau: at 1e4 they fall 1.1 mm (36 diameters) per step, more than half the skin, and LAMMPS
    rebuilds its lists, exchanges the atoms and remaps them into the box every step (every 10th on
    LAMMPS 29 Sep 2021, whose neigh_modify delay is 10), which the peer at dt/tau = 1 does not: a
    cost of the benchmark's scene, not of a user's."""
    if ratio <= 1.0 or by == "dt":
        dt = ratio * TAU
        return MU, dt, dt if ratio <= EXPLICIT_LIMIT else TAU
    mu = MU * ratio ** 0.5
    return mu, ratio * tau_at(mu), tau_at(mu)


def sweep(scenes: list[str], particles: int, steps: int, repeats: int, by: str = "viscosity") -> None:
    """The step's cost at each dt/tau against the peer's at the same dt: in each of `repeats` rounds
    the peer and the scenes of a ratio run one after the other, so that a drift of the machine's
    speed touches them alike; printed as the ratio of the best times and as the median of the rounds'
    ratios, with the neighbor list builds of the run (the most of the scenes', and the peer's).
    Above dt/tau = 2 the explicit peer is unstable: there it runs at dt/tau = 1 in the same fluid
    and rounds and stands in, as its cost per particle-step does not depend on the step. How each
    point is reached: sweep_point()."""
    rows = []
    for ratio in RATIOS:
        mu, dt, peer_dt = sweep_point(ratio, by)
        rounds, builds = [], {}
        for _ in range(repeats):
            times = {}
            for s in ("peer", *scenes):
                times[s], builds[s] = scene_run(s, particles, steps, dt=peer_dt if s == "peer" else dt, mu=mu)
            rounds.append({s: t / (particles * steps) * 1e9 for s, t in times.items()})
        rows.append((ratio, mu, dt, {s: min(r[s] for r in rounds) for s in rounds[0]}, rounds, builds))
    print(f"{particles} particles x {steps} steps, {repeats} rounds, 1 rank; 30 um grains, tau = {TAU:.3g} s in water; "
          f"above dt/tau = 1 {'by the step on the same grains in water' if by == 'dt' else 'by the viscosity'} "
          "(sweep_point()); ratios to the peer at the same dt (at dt/tau = 1 above 2, where it is unstable): of the "
          "best times, and in brackets the median of the rounds' ratios; lists: neighbor list builds in the run, "
          "the most of the scenes' / the peer's")
    print(f"{'dt/tau':>8s} {'mu Pa s':>9s} {'dt s':>9s} {'lists':>9s} {'peer ns':>9s} " + " ".join(f"{s:>17s}" for s in scenes))
    for ratio, mu, dt, best, rounds, builds in rows:
        mark = "*" if ratio > EXPLICIT_LIMIT else " "
        medians = {s: statistics.median(r[s] / r["peer"] for r in rounds) for s in scenes}
        lists = f"{max(builds[s] for s in scenes)}/{builds['peer']}"
        print(f"{ratio:8.0e} {mu:9.3g} {dt:9.3g} {lists:>9s} {best['peer']:8.2f}{mark} "
              + " ".join(f"{best[s] / best['peer']:9.2f}x ({medians[s]:.2f})" for s in scenes))
    print("* the peer at dt/tau = 1 in the same fluid, run in the same rounds")


def report_targets(times: dict[str, float], rounds: list[dict[str, float]]) -> None:
    """Each target's ratio from the best loop times, and its median and range over the rounds (the
    scenes of a round run one after the other, so a drift of the machine's speed between rounds
    cancels in a round's ratio)."""
    print(f"{'ratio':48s} {'best times':>10s} {'median of rounds':>17s} {'range of rounds':>16s} {'target':>7s}")
    for label, ratio, limit in TARGETS:
        best = measured(ratio, times)
        if best is None:
            continue
        each = [ratio(r) for r in rounds]
        print(f"{label:48s} {best:10.3f} {statistics.median(each):17.3f} {min(each):7.3f} - {max(each):6.3f} "
              f"{target_text(limit):>7s}")

if __name__ == "__main__":
    main()
