"""One runner for independent tasks: programs, seeds, recordings.

:func:`run_tasks` calls one function on a list of argument tuples and returns the results in
order. By default the tasks run in joblib's worker processes on the local cores. When the
environment variable ``NCTWIN_DASK_SCHEDULER`` names a scheduler address (for example
``tcp://10.0.0.5:8786``), the same calls run on that Dask cluster instead, through
:mod:`dask.distributed` and joblib's ``dask`` backend, for sweeps that outgrow one machine.
Every task is a pure function of its arguments (each one seeds its own random draws), so where it
runs does not change its result: the results are bit-identical either way (a test checks this
against a ``LocalCluster``).

Tasks that drive local processes (LinuxCNC recordings) ask for ``threads=True``: they run in
threads on this machine, whatever the environment says. ``n_jobs=1`` runs the tasks one after the
other in the calling process, whatever the environment says: a task that runs tasks of its own
(a calibration fold inside a worker) asks for that, and never opens a second pool or a client.

Local workers are joblib's reused loky processes. loky retires a worker whose memory has grown by
300 MB since its first task and starts another in its place (a network's training grows a worker
that first ran a simulation by about that much: freed memory stays with the process), with a
``UserWarning`` that it "stopped while some jobs were given to the executor". The tasks keep no
state between calls, so nothing but the new worker's start is lost; :func:`run_tasks` keeps that
one warning out of its caller's output.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from joblib import Parallel, delayed, parallel_config
from tqdm import tqdm

from .checks import check_int

__all__ = ["SCHEDULER_ENV", "run_tasks", "scheduler_address"]

#: Environment variable naming a Dask scheduler to run tasks on.
SCHEDULER_ENV = "NCTWIN_DASK_SCHEDULER"


#: The start of loky's warning when it replaces a worker (see the module docstring).
_WORKER_REPLACED = "A worker stopped while some jobs were given to the executor"


def scheduler_address() -> str | None:
    """The Dask scheduler named by :data:`SCHEDULER_ENV`, or None (run locally)."""
    return os.environ.get(SCHEDULER_ENV) or None


def run_tasks(
    fn: Callable[..., Any],
    tasks: Iterable[Sequence[Any]],
    *,
    n_jobs: int = 2,
    threads: bool = False,
    desc: str | None = None,
) -> list[Any]:
    """``[fn(*args) for args in tasks]``, run in parallel, in the order of ``tasks``.

    Parameters
    ----------
    fn : callable
        A module-level function (workers import it by name).
    tasks : iterable of tuples
        The positional arguments of each call.
    n_jobs : int
        Local workers, at least 1; 1 runs the tasks here, in order (on a Dask cluster any larger
        number is ignored: the cluster uses its own workers).
    threads : bool
        Run in local threads (tasks that drive local processes), never on a cluster.
    desc : str, optional
        Label of a progress bar (shown on a terminal, every 5 s at most).

    Returns
    -------
    list
        One result per task.

    Raises
    ------
    ValueError
        If ``n_jobs`` is not an integer >= 1.
    """
    check_int("n_jobs", n_jobs, 1)
    tasks = list(tasks)
    if n_jobs == 1:
        return _collect((fn(*args) for args in tasks), len(tasks), desc)
    jobs = (delayed(fn)(*args) for args in tasks)
    address = None if threads else scheduler_address()
    if address is None:
        backend = "threading" if threads else "loky"
        parallel = Parallel(n_jobs=n_jobs, backend=backend, return_as="generator")
        with warnings.catch_warnings():  # loky's manager thread warns through the same filters
            warnings.filterwarnings("ignore", _WORKER_REPLACED, UserWarning)
            return _collect(parallel(jobs), len(tasks), desc)
    try:  # only where a cluster is asked for: a slow import, and an optional extra
        from dask.distributed import Client
    except ImportError:
        raise ValueError(
            f"{SCHEDULER_ENV} = {address!r} needs Dask: pip install 'nctwin[dask]'"
        ) from None

    with Client(address), parallel_config(backend="dask"):
        return _collect(Parallel(return_as="generator")(jobs), len(tasks), desc)


def _collect(results: Iterable[Any], total: int, desc: str | None) -> list[Any]:
    if desc is None:
        return list(results)
    return list(tqdm(results, total=total, desc=desc, leave=False, mininterval=5.0))
