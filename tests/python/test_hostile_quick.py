# SPDX-License-Identifier: GPL-2.0-or-later
"""The quick cases of the hostile rounds (tests/hostile/round4.py --quick: rounds 3 and 4), one test each: a case passes
when its outcome is `ok`. The cases the last full round found bad are listed in round3.KNOWN_BAD and
expected to fail (strict): fixing one makes its test an XPASS failure, the reminder to take it off the
list. The cases share the round's fixtures (one small finished run, a tiny plan and an inversion),
built once per session."""
from __future__ import annotations

import importlib.util
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

HOSTILE = Path(__file__).resolve().parents[1] / "hostile"


def _round():
    """Round 3's module, with round 4's cases added to it."""
    sys.path.insert(0, str(HOSTILE))
    spec = importlib.util.spec_from_file_location("hostile_round4", HOSTILE / "round4.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["hostile_round4"] = module
    spec.loader.exec_module(module)
    return module.round3


round3 = _round()
QUICK = round3.select(None, quick=True)


@pytest.fixture(scope="session")
def hostile_root():
    root = Path(tempfile.mkdtemp(prefix="hostile3-pytest-"))
    (root / "fixtures").mkdir()
    yield root
    shutil.rmtree(root, ignore_errors=True)


def _param(name: str):
    marks = [pytest.mark.xfail(strict=True, reason="known bad in docs/hostile.md")] if name in round3.KNOWN_BAD else []
    return pytest.param(name, id=name, marks=marks)


@pytest.mark.parametrize("name", [_param(n) for n in QUICK])
def test_hostile_quick(name: str, hostile_root: Path) -> None:
    case = round3.CASES[name]
    round3.build_fixtures(set(case.needs), hostile_root / "fixtures")
    _, outcome, detail, _ = round3.run_case((name, str(hostile_root), str(hostile_root / "fixtures")))
    assert outcome == "ok", f"{outcome}: {detail}"


def test_known_bad_are_cases() -> None:
    """Every name in KNOWN_BAD is a case of the round (a renamed case must not hide a failure)."""
    assert not set(round3.KNOWN_BAD) - set(round3.CASES)
