#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The step at small dt/tau costs no more instructions than at dt/tau = 1: a check of counts, not of the clock.

Below dt/tau of about 0.1 every rate of the block step takes the Taylor series of the phi functions,
and the block takes only what its rates need (no exponential; where every rate of a block takes the
same number of terms, one sum without a count per rate). That path once took 420 instructions per
particle-step of the Dallavalle scene at dt/tau 1e-4 against 367 at 0.76 (8e0a59a); since, it takes
fewer than at dt/tau 1 (352 against 366; docs/performance.md). Callgrind counts the time-step loop's
instructions (benchmarks/cost.py --counts), the same to the instruction from run to run whatever
the machine's load, so the bounds below are ratios of counts of one build:

- the Dallavalle scene at dt/tau 1e-4 against itself at dt/tau 1: at most 1.03 (0.96 now; a loss
  of the path's shortcuts, as before 8e0a59a, gives 1.14);
- the same against the peer (fix nve/sphere + fix viscous) at the same dt: at most 1.8 (1.47 now;
  the project's target for the laws is 2 on the clock).

What counts cannot see, a vector copy that calls default-target code (issue 60, GCC 12's out-of-line
series_terms), perf.vector_calls checks in the disassembly.

    tests/perf/small_dt_counts.py LMP    (ctest: perf.small_dt_counts; about 30 s of CPU under valgrind, most of
                                          it the six runs' start-up)
"""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "benchmarks"))

PARTICLES, STEPS = 2000, 20           # counted: 3 x STEPS - STEPS steps of PARTICLES spheres
SMALL, ONE = 1e-4, 1.0                # dt/tau of the small-step path and of the reference point
OVER_ONE, OVER_PEER = 1.03, 1.8       # the bounds (see above)


def main() -> int:
    if len(sys.argv) != 2 or not Path(sys.argv[1]).is_file():
        print("usage: small_dt_counts.py LMP (an lmp with the SEDIMENT styles, e.g. build/lmp_sediment)", file=sys.stderr)
        return 2
    if shutil.which("valgrind") is None:
        print("small_dt_counts.py needs valgrind (Debian package valgrind)", file=sys.stderr)
        return 2
    import cost    # benchmarks/cost.py (imports the project's Python module)

    lmp = Path(sys.argv[1]).resolve()

    def instructions(scene: str, ratio: float) -> float:
        return cost.counts_per_step(scene, PARTICLES, STEPS, lmp, dt=ratio * cost.TAU)["instructions"]

    small, one, peer = instructions("nonlinear", SMALL), instructions("nonlinear", ONE), instructions("peer", SMALL)
    print(f"instructions per particle-step: Dallavalle at dt/tau {SMALL:g} {small:.1f}, at dt/tau {ONE:g} {one:.1f}; "
          f"the peer at dt/tau {SMALL:g} {peer:.1f}")
    failed = False
    if small > OVER_ONE * one:
        print(f"FAIL the small-dt/tau step takes {small / one:.3f}x its instructions at dt/tau {ONE:g} (at most {OVER_ONE})")
        failed = True
    if small > OVER_PEER * peer:
        print(f"FAIL the small-dt/tau step takes {small / peer:.3f}x the peer's instructions (at most {OVER_PEER})")
        failed = True
    if failed:
        return 1
    print(f"PASS small_dt_counts: {small / one:.3f}x the step at dt/tau {ONE:g} (<= {OVER_ONE}), {small / peer:.3f}x "
          f"the peer (<= {OVER_PEER})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
