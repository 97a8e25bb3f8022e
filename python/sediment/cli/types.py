# SPDX-License-Identifier: GPL-2.0-or-later
"""Argument types of the command line: each refuses what its name excludes, with the reason."""
from __future__ import annotations

import argparse
import math
from typing import Callable


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


def quantity(name: str) -> Callable[[str], float]:
    """A finite number within the plausible range of a quantity of `sediment.plausible` (the type of
    the option that takes it), refused with the unit slip that most likely explains it."""
    from ..plausible import refusal

    def parse(text: str) -> float:
        value = finite(text)
        reason = refusal(value, name)
        if reason is not None:
            raise argparse.ArgumentTypeError(reason)
        return value

    parse.__name__ = name    # argparse names the type in its messages
    return parse


def quantity_list(name: str) -> Callable[[str], list[float]]:
    """Comma-separated numbers, each within the plausible range of the quantity `name`."""
    one = quantity(name)

    def parse(text: str) -> list[float]:
        return [one(word) for word in text.split(",")]

    parse.__name__ = name
    return parse


temperature = quantity("temperature")    # water, 0-40 C: the range of the water correlations


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
