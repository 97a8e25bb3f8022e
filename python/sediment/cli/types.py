# SPDX-License-Identifier: GPL-2.0-or-later
"""Argument types of the command line: each refuses what its name excludes, with the reason."""
from __future__ import annotations

import argparse
import math


def finite(text: str) -> float:
    """A finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got '{text}'") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    return value


def positive(text: str) -> float:
    """A finite number > 0."""
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def nonnegative(text: str) -> float:
    """A finite number >= 0."""
    value = finite(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


def temperature(text: str) -> float:
    """A water temperature within the range of the water correlations, 0-40 C."""
    value = finite(text)
    if not 0.0 <= value <= 40.0:
        raise argparse.ArgumentTypeError(f"must be within 0-40 C (the range of the water correlations), got {text}")
    return value


MAX_COUNT = 10**9    # particles, ranks, layers, runs: beyond this no run fits this machine's memory


def count(text: str) -> int:
    """A whole number from 1 to 1e9 (written 20000 or 2e4)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got '{text}'") from None
    if not (math.isfinite(value) and value.is_integer()):
        raise argparse.ArgumentTypeError(f"must be a whole number, got '{text}'")
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text}")
    if value > MAX_COUNT:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_COUNT:.0e}, got {text}")
    return int(value)


def positive_list(text: str) -> list[float]:
    """Comma-separated numbers > 0."""
    return [positive(word) for word in text.split(",")]


def setting(text: str, what: str = "a setting is NAME=VALUE") -> tuple[str, str]:
    """NAME=VALUE, both non-empty (a deck variable and its value)."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise argparse.ArgumentTypeError(f"{what}, got '{text}'")
    return name.strip(), value.strip()
