#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The vector copies of the step stay in their vectors: a check of the built library, not of the clock.

The block step runs in copies compiled for AVX2 and AVX-512 (functions named *_avx2, *_avx512). A call
from one of them into the project's code compiled for the default target (SSE) runs SSE code with the
vector registers' upper halves in use. GCC 12 left such a call (series_terms) in the stages, four per
block, and at dt/tau below 0.1 the Dallavalle step took 2.5x the peer instead of 1.5x on the driver
build (issue 60). Instruction counts do not see this (cachegrind runs the AVX2 copy and counts the
same instructions); the disassembly does: the stages' vector copies may call only the batch
functions (exp_many, log_many: entered with vzeroupper, they run vector copies of their own) and
phis() for the rare subnormal band; everything else they use must be inlined.

    tests/perf/vector_calls.py LIBRARY    (ctest: perf.vector_calls)
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

# The block step's vector copies, and what they may call: the batch functions (entered with vzeroupper,
# they run vector copies of their own) and phis() for the rare subnormal band.
STAGES = re.compile(r"^sediment::DragBlock::stages_avx(2|512)\(")
ALLOWED = ("sediment::exp_many(", "sediment::log_many(", "sediment::phis(double)",
           "sediment::(anonymous namespace)::with_avx512(", "sediment::(anonymous namespace)::with_avx2(")


def calls_from_stages(disassembly: str) -> dict[str, set[str]]:
    """For each vector copy of the block's stages, the project functions it calls."""
    calls: dict[str, set[str]] = {}
    function = None
    for line in disassembly.splitlines():
        header = re.match(r"^[0-9a-f]+ <(.*)>:$", line)
        if header:
            function = header.group(1) if STAGES.match(header.group(1)) else None
            if function:
                calls.setdefault(function, set())
            continue
        target = re.search(r"\scall\s+[0-9a-f]+ <(.*)>$", line)
        if function and target and not target.group(1).endswith("@plt"):
            calls[function].add(target.group(1))
    return calls


def main() -> int:
    if len(sys.argv) != 2 or not Path(sys.argv[1]).is_file():
        print("usage: vector_calls.py LIBRARY (the built libsediment_lammps.so)", file=sys.stderr)
        return 2
    if shutil.which("objdump") is None:
        print("vector_calls.py needs objdump (Debian package binutils)", file=sys.stderr)
        return 2
    text = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", sys.argv[1]], capture_output=True,
                          text=True, check=True).stdout
    calls = calls_from_stages(text)
    if len(calls) < 2:
        print(f"{sys.argv[1]}: the AVX2 and AVX-512 copies of the stages are missing", file=sys.stderr)
        return 1
    bad = {f: sorted(c for c in callees if not c.startswith(ALLOWED)) for f, callees in calls.items()}
    for function, callees in sorted(bad.items()):
        if callees:
            print(f"FAIL {function} calls default-target code: {', '.join(callees)} "
                  "(mark it [[gnu::always_inline]])")
    if any(bad.values()):
        return 1
    print(f"PASS vector_calls: the stages' {len(calls)} vector copies call only the batch functions")
    return 0


if __name__ == "__main__":
    sys.exit(main())
