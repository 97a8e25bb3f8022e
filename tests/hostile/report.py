#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The Markdown of a hostile round's outcomes (round4.py --json FILE: rounds 3 and 4) for docs/hostile.md: the counts per
command and per outcome, then every case that is not ok, grouped by what is wrong.

    tests/hostile/report.py OUTCOMES.json > part.md
    tests/hostile/report.py OUTCOMES.json --known-bad      # the names for round3.KNOWN_BAD"""
from __future__ import annotations

import json
import re
import sys
from collections import Counter, defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import round4  # noqa: E402  (round 3's cases with round 4's added)

round3 = round4.round3

AREAS = [
    ("ownership", "One command's --out onto another's folder or onto an input"),
    ("rerun", "Reruns in the same folder"),
    ("concurrent", "Two commands in one folder at once"),
    ("signal", "Signals (SIGINT, SIGTERM, SIGKILL) at each phase"),
    ("full-disk", "A full disk"),
    ("damaged", "Damaged files"),
    ("unit", "Unit slips"),
    ("value", "Impossible or inconsistent option values"),
    ("input", "Input files: encodings, delimiters, columns and shapes"),
]


def markdown(outcomes: dict) -> str:
    cases = {n: round3.CASES[n] for n in outcomes if n in round3.CASES}
    lines = ["| command | cases | ok | wrong | crash | vague |", "|---|---|---|---|---|---|"]
    by = defaultdict(Counter)
    for name, (outcome, _, _) in outcomes.items():
        by[cases[name].command][outcome] += 1
    total = Counter()
    for cmd in sorted(by):
        k = by[cmd]
        total.update(k)
        lines.append(f"| {cmd} | {sum(k.values())} | {k['ok']} | {k['wrong']} | {k['crash']} | {k['vague']} |")
    lines.append(f"| **all** | **{sum(total.values())}** | **{total['ok']}** | **{total['wrong']}** | "
                 f"**{total['crash']}** | **{total['vague']}** |")
    lines += ["", "| area | cases | ok | wrong | crash | vague |", "|---|---|---|---|---|---|"]
    by_area = defaultdict(Counter)
    for name, (outcome, _, _) in outcomes.items():
        by_area[cases[name].kind][outcome] += 1
    for kind, title in AREAS:
        k = by_area.get(kind)
        if k:
            lines.append(f"| {title} | {sum(k.values())} | {k['ok']} | {k['wrong']} | {k['crash']} | {k['vague']} |")
    for kind, title in AREAS:
        bad = sorted((n for n, (o, _, _) in outcomes.items() if o != "ok" and cases[n].kind == kind),
                     key=lambda n: (outcomes[n][0], n))
        if not bad:
            continue
        lines += ["", f"### {title} ({len(bad)} not ok)", "", "| case | command | outcome | detail |",
                  "|---|---|---|---|"]
        for n in bad:
            outcome, detail, _ = outcomes[n]
            detail = detail.replace("|", "/").replace("\n", " ")
            detail = re.sub(r"/tmp/hostile3-[^/\s']+/(c-[^/\s']+/)?(fixtures/)?", "", detail)
            lines.append(f"| `{n}` | {cases[n].command} | {outcome} | {detail[:230]} |")
    return "\n".join(lines) + "\n"


def main() -> int:
    outcomes = json.loads(Path(sys.argv[1]).read_text())
    if "--known-bad" in sys.argv:
        for n in sorted(n for n, (o, _, _) in outcomes.items() if o != "ok"):
            print(f'    "{n}",')
        return 0
    sys.stdout.write(markdown(outcomes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
