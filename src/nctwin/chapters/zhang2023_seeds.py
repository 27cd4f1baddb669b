"""The Zhang chapter's networks, trained as stacks in parallel tasks, and their ensembles.

:func:`train_networks` trains every network of the chapter as stacks
(:func:`nctwin.learn.stack.fit_stack`: networks that differ in seed or dropout only, stepped
together; each trains as it would alone) through :func:`nctwin.runner.run_tasks`, in three
rounds: surface 1 (one stack per setting, with the paper's short fine-tuning chains), then the
variant's fine-tuning to surface 2 (one stack per share), then to surface 3. One torch thread
each, so the weights do not depend on the worker or the order. The networks:

* the networks the claims judge, once per seed: the paper's settings (full batch, dropout 0.5)
  and its fine-tuning chain to surfaces 2 and 3 at 15 % with the same settings (the paper gives
  no others; the claims judge 15 %), the converging variant with dropout 0.5 and without, and
  the fine-tuning chains of the variant without dropout to surfaces 2 and 3 at every share (each
  seed fine-tunes its own network);
* the sweeps and diagnostics, once (the chapter's seed): the batch sweep, the dropout sweep
  (Table 2) and the network trained from scratch on surface 2.

Every network trains until early stopping ends it, under a cap that it does not reach (the
paper's 2000 epochs on surface 1 and for the paper's settings' fine-tuning,
:data:`~nctwin.chapters.zhang2023.FINETUNE_EPOCHS` for the variant's fine-tuning), except the
batch sweep's runs at 32 and 256 rows, which have a budget
(:data:`~nctwin.chapters.zhang2023.BATCH_SWEEP_EPOCHS`), and the batch sweep's full batch without
dropout, which reaches the paper's 2000.

The data splits (70/30 on surface 1, the fine-tuning rows) are drawn from the chapter's seed and
are the same for every training seed. The claims judge the **mean of the seeds' predictions**
(:func:`ensemble_um`, :func:`ensemble_transfer`); :func:`seed_runs` and
:func:`nctwin.chapters.zhang2023_claims.judged_claims` give every seed's own numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..learn.train import Trained, TrainingDivergedError
from ..runner import run_tasks
from .zhang2023 import (
    BATCH_RUNS,
    SurfaceData,
    TransferRun,
    _batch_epochs,
    finetune_configs,
    paper_configs,
    predict_um,
    split,
    train,
    transfer,
    transfer_metrics,
    variant_configs,
)

__all__ = [
    "Networks",
    "ensemble_transfer",
    "ensemble_um",
    "seed_runs",
    "train_networks",
]


@dataclass(frozen=True, eq=False)
class Networks:
    """Every network of the chapter (:func:`train_networks`).

    Parameters
    ----------
    seeds : tuple of int
    paper, dropout, variant : list of Trained
        One per seed: the paper's settings (full batch, dropout 0.5), the variant with dropout
        0.5 and the variant without dropout (surface 1).
    paper_transfer2, paper_transfer3 : list of list of TransferRun
        One list per seed, at 0 and 15 %: the seed's paper-settings network fine-tuned to
        surface 2 with the paper's settings, and its 15 % surface-2 network fine-tuned to
        surface 3.
    transfer2, transfer3 : list of list of TransferRun
        One list per seed: the seed's variant fine-tuned to surface 2 at every share, and its
        15 % surface-2 network fine-tuned to surface 3.
    sweep : dict
        Dropout probability -> the variant with that dropout (None: diverged); at 0 and 0.5
        the first seed's ``variant[0]`` and ``dropout[0]``, the same networks.
    batches : dict
        ``(batch_rows, dropout_p)`` of :data:`~nctwin.chapters.zhang2023.BATCH_RUNS` -> the
        paper's settings at that batch (None: diverged); the full batch at dropout 0.5 is
        ``paper[0]``.
    scratch : Trained
        The variant trained from scratch on the same 15 % of surface 2.
    """

    seeds: tuple[int, ...]
    paper: list[Trained]
    dropout: list[Trained]
    variant: list[Trained]
    paper_transfer2: list[list[TransferRun]]
    paper_transfer3: list[list[TransferRun]]
    transfer2: list[list[TransferRun]]
    transfer3: list[list[TransferRun]]
    sweep: dict[float, Trained | None]
    batches: dict[tuple[int | None, float], Trained | None]
    scratch: Trained


def _stack(data, rows, cfgs, names) -> list[Trained | None]:
    """Train the networks of ``cfgs`` ((model, train) config pairs) as one stack."""
    return train(data, rows, [c[0] for c in cfgs], [c[1] for c in cfgs], names=names)


def _paper(d1, train_rows, d2, d3, seed, seeds):
    """The paper's settings, one per seed, with their fine-tuning chains at 0 and 15 % with the
    same settings (empty where surface 1's training diverged), and the paper's settings without
    dropout (the chapter's seed), trained in the same stack."""
    n = d1.x.shape[1]
    cfgs = [paper_configs(n, seed=s) for s in seeds] + [
        paper_configs(n, seed=seeds[0], dropout=0.0)
    ]
    names = [f"zhang2023_paper_seed{s}" for s in seeds] + ["zhang2023_batch0_p0"]
    *nets, no_dropout = _stack(d1, train_rows, cfgs, names)
    kept = [k for k, net in enumerate(nets) if net is not None]
    chains2, chains3 = [[] for _ in seeds], [[] for _ in seeds]
    if kept:
        ft, prefix = [cfgs[k][1] for k in kept], "zhang2023_paper"
        runs2 = transfer([nets[k] for k in kept], d2, (0.0, 15.0), ft, seed=seed, prefix=prefix)
        runs3 = transfer([r[-1].trained for r in runs2], d3, (0.0, 15.0), ft, seed=seed,
                         prefix=prefix)  # fmt: skip
        for k, r2, r3 in zip(kept, runs2, runs3, strict=True):
            chains2[k], chains3[k] = r2, r3
    return nets, no_dropout, chains2, chains3


def _transfer(starts, data, pct, train_configs, seed) -> list[TransferRun]:
    """Each of ``starts`` fine-tuned on ``pct`` % of ``data`` (one stack)."""
    return [chain[0] for chain in transfer(starts, data, (pct,), train_configs, seed=seed)]


def _chains(starts, data, shares, train_configs, seed, n_jobs) -> list[list[TransferRun]]:
    """:func:`transfer` of ``starts`` at every share, one stack per share in parallel (the
    largest share first); one list of runs per start, in the order of ``shares``."""
    tasks = {p: (_transfer, starts, data, p, train_configs, seed)
             for p in sorted(shares, reverse=True) if p > 0}  # fmt: skip
    runs = _run(tasks, n_jobs)
    runs.update({p: _transfer(starts, data, p, train_configs, seed) for p in shares if p == 0})
    return [list(chain) for chain in zip(*(runs[p] for p in shares), strict=True)]


def _call(fn: Callable, args: tuple):
    return fn(*args)


def _run(tasks: dict, n_jobs: int) -> dict:
    """Run ``tasks`` (key -> (function, *args)) in parallel, in their order (the runner hands
    them out in order: the slowest first)."""
    calls = [(t[0], t[1:]) for t in tasks.values()]
    return dict(zip(tasks, run_tasks(_call, calls, n_jobs=n_jobs), strict=True))


def train_networks(
    data: dict[int, SurfaceData],
    train_rows: np.ndarray,
    seeds: Sequence[int],
    *,
    probabilities: Sequence[float],
    shares: tuple[float, ...],
    seed: int,
    n_jobs: int = 2,
) -> Networks:
    """Train every network of the chapter (see the module docstring), ``n_jobs`` stacks at a
    time.

    Parameters
    ----------
    data : dict
        Surface index (1, 2, 3) -> :class:`SurfaceData`.
    train_rows : ndarray of int
        Surface 1's training rows (the 70 %).
    seeds : sequence of int
        Training seeds of the networks the claims judge; ``seeds[0]`` also trains the sweeps
        and diagnostics.
    probabilities : sequence of float
        The dropout sweep's drop probabilities.
    shares : tuple of float
        Fine-tuning shares (%), increasing, the first 0, the last 15.
    seed : int
        Seed of the data splits.
    n_jobs : int
        Parallel stacks.
    """
    d1, d2, d3 = data[1], data[2], data[3]
    n = d1.x.shape[1]
    seeds = list(seeds)
    s0 = seeds[0]
    sweep_ps = [p for p in probabilities if p not in (0.0, 0.5)]  # those: ``variant``, ``dropout``
    variant = [variant_configs(n, dropout=0.0, seed=s) for s in seeds]
    dropout = [variant_configs(n, dropout=p, seed=s) for p, s in
               [(0.5, s) for s in seeds] + [(p, s0) for p in sweep_ps]]  # fmt: skip
    picked2, _ = split(len(d2.x), 0.15, seed=seed)
    # surface 1, the slowest stacks first
    tasks = {
        "variant": (_stack, d1, train_rows, variant,
                    [f"zhang2023_variant_p0_seed{s}" for s in seeds]),
        "dropout": (_stack, d1, train_rows, dropout,
                    [f"zhang2023_variant_p0.5_seed{s}" for s in seeds]
                    + [f"zhang2023_sweep_p{p:g}" for p in sweep_ps]),
        "paper": (_paper, d1, train_rows, d2, d3, seed, seeds),
    }  # fmt: skip
    by_batch = {}  # rows per update -> dropout probabilities (the full batch: ``_paper``)
    for b, p in BATCH_RUNS:
        if b is not None:
            by_batch.setdefault(b, []).append(p)
    for batch, ps in by_batch.items():
        cfgs = [paper_configs(n, seed=s0, dropout=p, batch_rows=batch, epochs=_batch_epochs(batch))
                for p in ps]  # fmt: skip
        tasks["batch", batch] = (_stack, d1, train_rows, cfgs,
                                 [f"zhang2023_batch{batch}_p{p:g}" for p in ps])  # fmt: skip
    tasks["scratch"] = (_stack, d2, picked2, [variant_configs(n, seed=s0)],
                        ["zhang2023_s2_scratch15"])  # fmt: skip
    out = _run(tasks, n_jobs)
    # the variant's fine-tuning: surface 2 at each share, then surface 3 from its 15 % networks
    nets1 = out["variant"]
    if None in nets1:
        raise TrainingDivergedError("the variant without dropout diverged on surface 1")
    ft = [finetune_configs(n, seed=s)[1] for s in seeds]
    chains2 = _chains(nets1, d2, shares, ft, seed, n_jobs)
    chains3 = _chains([chain[-1].trained for chain in chains2], d3, shares, ft, seed, n_jobs)
    paper, batch0_p0, paper2, paper3 = out["paper"]
    n_seeds = len(seeds)
    same = {0.0: nets1[0], 0.5: out["dropout"][0]}  # the sweep's runs trained already
    sweep = dict(zip(sweep_ps, out["dropout"][n_seeds:], strict=True))
    batches = {(None, 0.5): paper[0], (None, 0.0): batch0_p0}
    for batch, ps in by_batch.items():
        batches.update(zip([(batch, p) for p in ps], out["batch", batch], strict=True))
    return Networks(
        seeds=tuple(seeds),
        paper=paper,
        dropout=out["dropout"][:n_seeds],
        variant=nets1,
        paper_transfer2=paper2,
        paper_transfer3=paper3,
        transfer2=chains2,
        transfer3=chains3,
        sweep={p: same[p] if p in same else sweep[p] for p in probabilities},
        batches={key: batches[key] for key in BATCH_RUNS},
        scratch=out["scratch"][0],
    )


def ensemble_um(nets: Sequence[Trained], x: np.ndarray) -> np.ndarray:
    """The mean of the networks' predicted step errors (um) of samples ``x``."""
    return np.mean([predict_um(net, x) for net in nets], axis=0)


def ensemble_transfer(chains: Sequence[Sequence[TransferRun]]) -> list[TransferRun]:
    """One :class:`TransferRun` per share whose prediction is the mean of the seeds'
    (``trained``: the first seed's network)."""
    return [
        TransferRun(r[0].surface, r[0].finetune_pct, r[0].trained, r[0].test_rows,
                    np.mean([m.predicted_um for m in r], axis=0))
        for r in zip(*chains, strict=True)
    ]  # fmt: skip


def seed_runs(
    nets: dict[str, Sequence[Trained]], x: np.ndarray, y_um: np.ndarray, y_std_um: float
) -> pd.DataFrame:
    """Every seed's network and the ensemble (``seed`` = -1) of each label on test samples.

    Parameters
    ----------
    nets : dict
        Label -> the networks of the seeds.
    x, y_um : ndarray
        Test samples and their exact step errors.
    y_std_um : float
        The Z-score's scale of ``test_mse`` (the standard deviation of the training rows'
        step errors, eq. 7), the same for every seed and the ensemble.

    Returns
    -------
    pandas.DataFrame
        ``network``, ``seed``, ``epochs``, ``best_epoch``, ``converged`` (the best epoch lies
        more than the patience below the cap; NaN for the ensemble), ``test_mse`` and
        :func:`transfer_metrics`.
    """
    rows = []
    for label, members in nets.items():
        preds = [predict_um(m, x) for m in members]
        for m, pred in [*zip(members, preds, strict=True), (None, np.mean(preds, axis=0))]:
            cfg = m.train_config if m is not None else None
            rows.append({"network": label, "seed": cfg.seed if cfg else -1,
                         "epochs": len(m.history["train"]) if m else np.nan,
                         "best_epoch": m.best_epoch if m else np.nan,
                         "converged": m.converged if m else np.nan,
                         "test_mse": float(np.mean(((pred - y_um) / y_std_um) ** 2)),
                         **transfer_metrics(pred, y_um)})  # fmt: skip
    return pd.DataFrame(rows)
