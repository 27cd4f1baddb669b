"""benchmarks/_targets.py: `make bench` fails on a record that misses a comparison target."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "_targets.py"
_spec = importlib.util.spec_from_file_location("bench_targets", SCRIPT)
targets = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(targets)


@pytest.mark.parametrize(
    ("value", "target", "missed"),
    [
        (0.05, "<= 0.1", False),
        (0.1, "<= 0.1", False),
        (0.11, "<= 0.1", True),
        (0.3, "< 0.3", True),
        (2e7, ">= 1e7", False),
        (9.9e6, ">= 1e7", True),
        (0.019, "< 0.020 s for 4999 G-lines", False),
        (0.021, "< 0.020 s for 4999 G-lines", True),
        (4682, "~5000", False),
        (1e9, "baseline", False),
        (1e9, "", False),
    ],
)
def test_a_comparison_target_is_checked_and_others_describe(value, target, missed):
    assert targets.missed({"value": value, "target": target}) is missed


def test_a_miss_fails_the_run_and_names_the_record():
    lines = [{"benchmark": "a", "value": 1.0, "unit": "s", "target": "<= 2"},
             {"benchmark": "b", "value": 3.0, "unit": "s", "target": "<= 2"}]  # fmt: skip
    text = "".join(json.dumps(r) + "\n" for r in lines)
    run = subprocess.run([sys.executable, str(SCRIPT)], input=text, capture_output=True,
                         text=True, check=False)  # fmt: skip
    assert run.returncode == 1
    assert run.stdout == text
    assert run.stderr == "bench: missed: b = 3.0 s (target <= 2)\n"
    ok = subprocess.run([sys.executable, str(SCRIPT)], input=text.splitlines(True)[0],
                        capture_output=True, text=True, check=False)  # fmt: skip
    assert ok.returncode == 0
