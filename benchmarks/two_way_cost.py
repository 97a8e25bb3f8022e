# SPDX-License-Identifier: GPL-2.0-or-later
"""What the test's column under two-way coupling costs against its one-way twin, per grid and ranks.

    /usr/bin/python3 benchmarks/two_way_cost.py [--sample 2] [--steps 300] [--cells 8,12,16,24]
        [--ranks 1,2] [--repeat 2]

The column of `sediment sample PSD --two-way --flow-cells N` (seed 1), cut after the first `--steps`
steps of its first stage, when every parcel is still in suspension; the twin is the same deck with
`-var flow no`. Each configuration's loop time is the least of `--repeat` rounds taken in turn (a
machine's load slows a run, never speeds it), and each ratio is of runs of one invocation.
docs/effects.md section 3 quotes it.
"""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from sediment.cli.types import count  # noqa: E402
from sediment.lab.psd import read_psd  # noqa: E402
from sediment.sim.run import run_batch  # noqa: E402
from sediment.sim.scene import Effects, plan  # noqa: E402
from sediment.sim.scenefiles import write  # noqa: E402

PSDS = HERE.parent / "examples" / "granulometry" / "psd"


def first_steps(deck: Path, steps: int) -> Path:
    """The deck up to its first stage's run, which ends after `steps` steps; its layer file is complete
    at any time (end_time of a nanosecond)."""
    text = deck.read_text()
    head = text[:text.index("\n", text.index('"run ${stage_end}'))] + "\n"
    head, stages = re.subn(r"stage_end\+ceil\(ceil\(\d+/v_dt_scale\)/v_frame_every\)\*v_frame_every\)",
                           f"stage_end+{steps})", head, count=1)
    head, ends = re.subn(r"^variable\s+t_end equal", "variable        t_end equal 1e-9 #", head, count=1,
                         flags=re.MULTILINE)
    if (stages, ends) != (1, 1):
        raise ValueError(f"{deck}: not a deck of `sediment sample` as this benchmark knows it (its first stage or "
                         "t_end not found)")
    cut = deck.with_name("in.first_steps")
    cut.write_text(head)
    return cut


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sample", type=int, default=2, help="Bravo et al.'s sample (1-5)")
    parser.add_argument("--steps", type=count, default=300)
    parser.add_argument("--cells", default="8,12,16,24", help="cells across the column, comma-separated")
    parser.add_argument("--ranks", default="1,2", help="MPI ranks, comma-separated")
    parser.add_argument("--repeat", type=count, default=2)
    args = parser.parse_args()
    cells = [int(c) for c in args.cells.split(",")]
    ranks = [int(r) for r in args.ranks.split(",")]
    psd = read_psd(PSDS / f"sample{args.sample}.csv")
    with tempfile.TemporaryDirectory() as tmp:
        decks = {}
        for n in cells:
            folder = Path(tmp) / f"cells_{n}"
            write(plan(psd, effects=Effects(flow=True), flow_cells=n), folder)
            decks[n] = first_steps(folder / "in.sedimentation", args.steps)
        configs = [(n, r, flow) for n in cells for r in ranks for flow in ("yes", "no")]
        best: dict[tuple, float] = {}
        for _ in range(args.repeat):
            for n, r, flow in configs:
                out = run_batch(decks[n], {"flow": flow, "overwrite": "yes"}, ranks=r, cwd=decks[n].parent)
                loop = sum(seconds for seconds, _ in out.loops)
                best[n, r, flow] = min(best.get((n, r, flow), loop), loop)
    print(f"sample {args.sample}: the first {args.steps} steps, least of {args.repeat} rounds")
    print("cells across  ranks  two-way [s]  one-way [s]  ratio")
    for n in cells:
        for r in ranks:
            two, one = best[n, r, "yes"], best[n, r, "no"]
            print(f"{n:12d}  {r:5d}  {two:11.3f}  {one:11.3f}  {two / one:5.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
