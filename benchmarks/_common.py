"""Helpers shared by the benchmark scripts: timing and the JSON-lines record format."""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

#: Public programs beside the clone (absent in a user's clone).
SHARED_PROGRAMS = Path(__file__).resolve().parents[2] / "shared" / "programs"


def best_time_s(fn: Callable[[], object], *, repeat: int = 15, warmup: int = 2) -> float:
    """Shortest wall time of ``fn()`` over ``repeat`` runs, after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def record(benchmark: str, value: float, unit: str, target: str) -> None:
    """Print one benchmark record as a JSON line."""
    print(json.dumps({"benchmark": benchmark, "value": value, "unit": unit, "target": target}))
