"""The one runner (nctwin.runner): in order, locally or on a Dask cluster, with the same bits."""

from __future__ import annotations

import os

import numpy as np
import pytest

from nctwin.chapters import chien2023 as ch
from nctwin.machine import load_profile
from nctwin.programs.training import global_program, mixed_program
from nctwin.runner import SCHEDULER_ENV, run_tasks


def _square(x: int) -> int:
    return x * x


def test_results_come_back_in_the_order_of_the_tasks():
    assert run_tasks(_square, [(k,) for k in range(7)], n_jobs=2) == [k * k for k in range(7)]
    assert run_tasks(_square, [(3,)], n_jobs=1, threads=True) == [9]


def _pid(_: int) -> int:
    return os.getpid()


def test_one_job_runs_here_whatever_the_environment_says(monkeypatch):
    # a task that runs tasks of its own inside a worker opens no pool and no cluster client
    monkeypatch.setenv(SCHEDULER_ENV, "tcp://192.0.2.1:8786")  # nothing listens there
    assert run_tasks(_pid, [(0,), (1,)], n_jobs=1) == [os.getpid()] * 2


@pytest.mark.parametrize("n_jobs", [0, -1, 1.5, True])
def test_bad_worker_counts_are_named(n_jobs):
    with pytest.raises(ValueError, match=rf"n_jobs = {n_jobs!r} is out of range"):
        run_tasks(_square, [(1,)], n_jobs=n_jobs)


@pytest.mark.slow
def test_a_dask_cluster_gives_the_local_bits(monkeypatch):
    # the chapter's simulations, as a sweep would send them: two programs on the FIR kernel
    distributed = pytest.importorskip("dask.distributed")
    machine = load_profile("paper1_sim")
    tasks = [
        (mixed_program(3, n_lines=60, feed_mm_s=80.0, tol_mm=0.3), machine, None, 0),
        (global_program(4, n_lines=60, feed_mm_s=70.0, tol_mm=0.4), machine, None, 1),
    ]
    monkeypatch.delenv(SCHEDULER_ENV, raising=False)
    local = run_tasks(ch.simulate_one, tasks, n_jobs=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                                  processes=True) as cluster:  # fmt: skip
        monkeypatch.setenv(SCHEDULER_ENV, cluster.scheduler_address)
        remote = run_tasks(ch.simulate_one, tasks, n_jobs=2)
    assert len(remote) == len(local) == 2
    for a, b in zip(local, remote, strict=True):
        for field in ("features", "targets", "block_time_s"):
            np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
        assert (a.measured_s, a.cam_s) == (b.measured_s, b.cam_s)
