"""The Zhang chapter's networks, trained in one pool of parallel tasks, and their ensembles.

:func:`train_networks` trains every network of the chapter through
:func:`nctwin.runner.run_tasks` (one task per network, or per chain of networks that start from
one another; one torch thread each, so the weights do not depend on the worker or the order):

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


def _train_or_none(data, rows, model_config, train_config, name) -> Trained | None:
    try:
        return train(data, rows, model_config, train_config, name=name, progress=False)
    except TrainingDivergedError:
        return None


def _chain(d1, train_rows, d2, d3, shares, seed, train_seed):
    """The variant without dropout (seed ``train_seed``) and its fine-tuning chains."""
    n = d1.x.shape[1]
    model_cfg, train_cfg = variant_configs(n, dropout=0.0, seed=train_seed)
    name = f"zhang2023_variant_p0_seed{train_seed}"
    net1 = train(d1, train_rows, model_cfg, train_cfg, name=name, progress=False)
    _, ft = finetune_configs(n, seed=train_seed)
    runs2 = transfer(net1, d2, shares, ft, seed=seed, progress=False)
    runs3 = transfer(runs2[-1].trained, d3, shares, ft, seed=seed, progress=False)
    return net1, runs2, runs3


def _paper_chain(d1, train_rows, d2, d3, seed, train_seed):
    """The paper's settings (seed ``train_seed``) and their fine-tuning chain at 0 and 15 %,
    with the same settings; None and empty chains if surface 1's training diverged."""
    cfgs = paper_configs(d1.x.shape[1], seed=train_seed)
    net1 = _train_or_none(d1, train_rows, *cfgs, f"zhang2023_paper_seed{train_seed}")
    if net1 is None:
        return None, [], []
    shares, name = (0.0, 15.0), "zhang2023_paper"
    runs2 = transfer(net1, d2, shares, cfgs[1], seed=seed, progress=False, prefix=name)
    runs3 = transfer(runs2[-1].trained, d3, shares, cfgs[1], seed=seed, progress=False,
                     prefix=name)  # fmt: skip
    return net1, runs2, runs3


def _call(fn: Callable, args: tuple):
    return fn(*args)


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
    """Train every network of the chapter (see the module docstring), ``n_jobs`` at a time.

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
        Fine-tuning shares (%), increasing, the last 15.
    seed : int
        Seed of the data splits.
    n_jobs : int
        Parallel trainings.
    """
    d1, d2 = data[1], data[2]
    n = d1.x.shape[1]
    s0 = seeds[0]

    def task(fn, *args):
        return (fn, args)

    tasks = {}  # the slowest first: the runner hands tasks out in order
    for s in seeds:
        tasks["chain", s] = task(_chain, d1, train_rows, d2, data[3], shares, seed, s)
    for batch, p in BATCH_RUNS:  # at 32 rows, 78,000 updates: next to the chains
        if batch is not None:
            cfgs = paper_configs(n, seed=s0, dropout=p, batch_rows=batch,
                                 epochs=_batch_epochs(batch))  # fmt: skip
            tasks["batch", batch, p] = task(_train_or_none, d1, train_rows, *cfgs,
                                            f"zhang2023_batch{batch}_p{p:g}")  # fmt: skip
    cfgs = paper_configs(n, seed=s0, dropout=0.0)
    tasks["batch", None, 0.0] = task(_train_or_none, d1, train_rows, *cfgs, "zhang2023_batch0_p0")
    for s in seeds:
        tasks["paper", s] = task(_paper_chain, d1, train_rows, d2, data[3], seed, s)
    for s in seeds:
        cfgs = variant_configs(n, dropout=0.5, seed=s)
        tasks["dropout", s] = task(_train_or_none, d1, train_rows, *cfgs,
                                   f"zhang2023_variant_p0.5_seed{s}")  # fmt: skip
    for p in (p for p in probabilities if p not in (0.0, 0.5)):  # those: see ``same``
        cfgs = variant_configs(n, dropout=p, seed=s0)
        tasks["sweep", p] = task(_train_or_none, d1, train_rows, *cfgs, f"zhang2023_sweep_p{p:g}")
    picked2, _ = split(len(d2.x), 0.15, seed=seed)
    cfgs = variant_configs(n, seed=s0)
    tasks["scratch"] = task(_train_or_none, d2, picked2, *cfgs, "zhang2023_s2_scratch15")
    out = dict(zip(tasks, run_tasks(_call, tasks.values(), n_jobs=n_jobs), strict=True))
    chains = [out["chain", s] for s in seeds]
    papers = [out["paper", s] for s in seeds]
    same = {0.0: chains[0][0], 0.5: out["dropout", s0]}  # the sweep's runs trained already
    return Networks(
        seeds=tuple(seeds),
        paper=[c[0] for c in papers],
        dropout=[out["dropout", s] for s in seeds],
        variant=[c[0] for c in chains],
        paper_transfer2=[c[1] for c in papers],
        paper_transfer3=[c[2] for c in papers],
        transfer2=[c[1] for c in chains],
        transfer3=[c[2] for c in chains],
        sweep={p: same[p] if p in same else out["sweep", p] for p in probabilities},
        batches={
            (b, p): papers[0][0] if (b, p) == (None, 0.5) else out["batch", b, p]
            for b, p in BATCH_RUNS
        },
        scratch=out["scratch"],
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
