# SPDX-License-Identifier: GPL-2.0-or-later
"""Wall time of the sedimentation test (sample 5, 24 h = 1440 min, parcels in the D422 column)
against the number of particles and MPI ranks, with LAMMPS's memory estimate.

    /usr/bin/python3 benchmarks/scaling.py [--particles 1e4,1e5,1e6] [--ranks 1,2] [--full-up-to 1e5]

Scenes up to --full-up-to particles run the whole test. Larger ones run the first --stages stages
of the planned steps and the 24 h wall time is extrapolated: start-up + the measured loop time
per step x all the planned steps (every particle is integrated at every step, so the cost per
step does not fall as the column clears; the extrapolation is marked in the table).
Memory: LAMMPS's own estimate summed over the ranks, and the measured peak resident size of the
process for 1-rank runs (scenes in increasing size, so each run's peak is the largest so far).
"""
from __future__ import annotations

import argparse
import re
import resource
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.lab.psd import read_psd  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402
from sediment.sim.scene import Effects, plan  # noqa: E402
from sediment.sim.scenefiles import write  # noqa: E402

PSD = HERE.parent / "examples" / "granulometry" / "psd" / "sample5.csv"


def truncated(deck: Path, stages: int) -> Path:
    """The deck with only its first `stages` timestep/run pairs."""
    lines = deck.read_text().splitlines()
    runs = [k for k, line in enumerate(lines) if line.startswith("run ")]
    if stages >= len(runs):
        return deck
    short = deck.with_name(f"in.first{stages}")
    short.write_text("\n".join(lines[:runs[stages - 1] + 1]) + "\n")
    return short


def measure(deck: Path, ranks: int, total_steps: int) -> dict[str, float]:
    peak_before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    out = run_batch(deck, ranks=ranks)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss    # kB, largest child so far
    loop, steps, wall = sum(t for t, _ in out.loops), sum(n for _, n in out.loops), out.wall_seconds
    memory = max(float(m) for m in re.findall(r"memory allocation \(min/avg/max\) = [0-9.]+ \| [0-9.]+ \| ([0-9.]+) Mbytes",
                                              out.text))
    setup = wall - loop
    return {"steps_run": steps, "wall_run": wall, "loop": loop, "memory_mb": memory * ranks,
            "peak_rss_mb": peak / 1024 if ranks == 1 and peak > peak_before else float("nan"),
            "wall_24h": setup + loop / steps * total_steps}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", default="1e4,1e5,1e6")
    parser.add_argument("--ranks", default="1,2")
    parser.add_argument("--full-up-to", type=float, default=1e5, help="larger scenes are extrapolated")
    parser.add_argument("--stages", type=int, default=2, help="stages run for an extrapolated scene")
    parser.add_argument("--work", type=Path, help="folder for the scenes (default: a temporary one)")
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="sediment-scaling-"))
    psd = read_psd(PSD)
    print("particles,ranks,simulated_s,steps_planned,steps_run,wall_run_s,loop_s,lammps_memory_mb,peak_rss_mb,"
          "wall_1440min_s,"
          "ns_per_particle_step,extrapolated", flush=True)
    for n in [int(float(p)) for p in args.particles.split(",")]:
        scene = plan(psd, particles=n, effects=Effects("dallavalle"), courant=1.0)    # the scene of the README's table
        deck = write(scene, work / f"n{n}")[1]
        total = sum(steps for _, steps in scene.stages())
        full = n <= args.full_up_to
        run_deck = deck if full else truncated(deck, args.stages)
        for ranks in [int(r) for r in args.ranks.split(",")]:
            m = measure(run_deck, ranks, total)
            per = m["loop"] / m["steps_run"] / len(scene.diameter) * 1e9 * ranks
            print(f"{len(scene.diameter)},{ranks},{scene.t_end:g},{total},{m['steps_run']},{m['wall_run']:.1f},"
                  f"{m['loop']:.1f},{m['memory_mb']:.0f},{m['peak_rss_mb']:.0f},{m['wall_24h']:.1f},{per:.1f},{'no' if full else 'yes'}",
                  flush=True)


if __name__ == "__main__":
    main()
