"""loky's replaced workers, in a module of their own: a worker that starts again imports the
module of the function it runs, and this one imports nothing heavy."""

from __future__ import annotations

import time
import warnings

from nctwin.runner import run_tasks

_KEPT: list[bytearray] = []


def _grow(k: int) -> int:
    # keeps 350 MB per call in the worker and outlasts loky's 1 s between memory checks
    _KEPT.append(bytearray(350_000_000))
    time.sleep(1.2)
    return k


def test_a_replaced_worker_leaves_no_warning():
    # loky retires a worker grown by 300 MB since its first task and warns while tasks wait
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert run_tasks(_grow, [(k,) for k in range(6)], n_jobs=2) == list(range(6))
    assert not [w for w in seen if "worker stopped" in str(w.message)]
