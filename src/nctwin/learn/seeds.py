"""Networks trained once per seed, all in parallel: the seeds over which the book judges every
learned claim (five or more, with their spread)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from ..runner import run_tasks
from .models import ModelConfig
from .train import TrainConfig, Trained, fit

__all__ = ["fit_seeds"]


def _fit(model_config: ModelConfig, cfg: TrainConfig, xs, ys, name: str) -> Trained:
    return fit(model_config, cfg, xs, ys, name=name, progress=False)


def fit_seeds(
    jobs: dict[str, tuple[ModelConfig, TrainConfig, Sequence[np.ndarray], Sequence[np.ndarray]]],
    seeds: Sequence[int] | Mapping[str, Sequence[int]],
    *,
    n_jobs: int = 2,
) -> dict[str, list[Trained]]:
    """Train every network of ``jobs`` once per seed, all in parallel through
    :func:`nctwin.runner.run_tasks` (each run cached by :func:`nctwin.learn.train.fit` as
    ``<name>_seed<s>``).

    Parameters
    ----------
    jobs : dict
        ``name -> (model_config, train_config, xs, ys)``; the seed of ``train_config`` is
        replaced by each of the job's seeds. List the slowest first: the runner hands out tasks
        in order.
    seeds : sequence of int, or dict
        The seeds of every job, or ``name -> seeds`` of each (one call, so that no worker waits
        for another's last network between groups of jobs).
    n_jobs : int
        Parallel trainings (each on one thread).

    Returns
    -------
    dict
        ``name -> [Trained per seed]``, in the order of its seeds.
    """
    of = seeds if isinstance(seeds, Mapping) else dict.fromkeys(jobs, seeds)
    tasks = [(name, cfg_m, replace(cfg, seed=s), xs, ys)
             for name, (cfg_m, cfg, xs, ys) in jobs.items() for s in of[name]]  # fmt: skip
    out = run_tasks(_fit, ((m, c, x, y, f"{n}_seed{c.seed}") for n, m, c, x, y in tasks),
                    n_jobs=n_jobs, desc="networks")  # fmt: skip
    nets: dict[str, list[Trained]] = {name: [] for name in jobs}
    for (name, *_), net in zip(tasks, out, strict=True):
        nets[name].append(net)
    return nets
