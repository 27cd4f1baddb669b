"""Small shared helpers: parameter range checks and wall-clock timing."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

__all__ = ["best_time_s", "check_range"]


def check_range(
    name: str, value: float, low: float, high: float = np.inf, *, low_open: bool = False
) -> None:
    """Raise ValueError naming ``name``, its value and the allowed interval unless
    ``low <= value <= high`` (``low < value`` with ``low_open``)."""
    ok = (value > low if low_open else value >= low) and value <= high
    if not ok:
        bracket = "(" if low_open else "["
        raise ValueError(f"{name} = {value!r} is out of range: allowed {bracket}{low}, {high}]")


def best_time_s(fn: Callable[[], object], *, repeat: int = 5, warmup: int = 1) -> float:
    """Shortest wall time of ``fn()`` over ``repeat`` runs, after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)
