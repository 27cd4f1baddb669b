"""Helpers shared by the benchmark scripts: timing and the JSON-lines record format."""

from __future__ import annotations

import json
from functools import partial
from pathlib import Path

from nctwin.checks import best_time_s as _best_time_s

#: Benchmarks repeat more than the package's default: shortest of 15 runs after 2 warm-ups.
best_time_s = partial(_best_time_s, repeat=15, warmup=2)

#: Public programs beside the clone (absent in a user's clone).
SHARED_PROGRAMS = Path(__file__).resolve().parents[2] / "shared" / "programs"


def record(benchmark: str, value: float, unit: str, target: str) -> None:
    """Print one benchmark record as a JSON line."""
    print(json.dumps({"benchmark": benchmark, "value": value, "unit": unit, "target": target}))
