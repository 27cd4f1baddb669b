r"""The experiment of Zhang et al. (2023): a BP network learns the exact step error of ball-end
CL segments on one free-form surface and is fine-tuned to two more.

Per surface (Sec. "Sample construction"): the stand-in of :mod:`nctwin.physics.surfaces`, its
iso-parametric path (the paper's lines, CC points and tool radius), the exact step error of every
segment (:func:`nctwin.physics.steperror.step_error_um`, the network's target) and the Table 1
samples (:func:`nctwin.physics.steperror.step_error_samples`, with the number of inner points
that makes the input width fit eq. 8 with the paper's first hidden layer).

Training runs through the shared loop of :mod:`nctwin.learn.train`, several networks of one
shape at a time (:func:`nctwin.learn.stack.fit_stack`); the loop learns on "programs" of
consecutive rows. Samples are independent, so the training rows are cut, in a seeded random
order, into chunks of ``window_lines`` rows; a batch is ``batch_size`` chunks, and the loop holds
out ``val_share`` of the chunks (10 %) to keep the weights of the best validation epoch. Inputs
and targets are Z-scored with the statistics of the training chunks (eq. 7; the loop divides by
the population standard deviation, :math:`n` rather than eq. 7's :math:`n - 1`: a relative
difference of 4e-5 at 12,000 rows). The tool radius column is constant, so its Z-score is 0.

Configurations
--------------
:func:`paper_configs`
    The paper's settings (read from ``data/papers/zhang2023_summary.csv``): weights N(0, 1),
    its dropout, SGD with its momentum and learning rate, :data:`PAPER_EPOCHS` epochs as the
    cap with early stopping after
    :data:`PAPER_PATIENCE` epochs without improvement, MSE. The paper gives no batch size (its
    SGD reads as one random sample per update); the default is the full batch, and
    :func:`batch_sweep` scores 1, 32, 256 rows and the full batch, with and without dropout.
:func:`variant_configs`
    The closest variant that converges here: PyTorch's default uniform weights, SGD with
    momentum 0.8, lr 1e-2, batches of 128 rows, MSE, dropout as given; the same early stopping
    and cap as the paper's settings.
:func:`finetune_configs`
    The variant's fine-tuning to a new surface (Tables 4-7): the variant without dropout at lr
    3e-3, capped at :data:`FINETUNE_EPOCHS`. The paper's settings fine-tune with
    :func:`paper_configs` themselves (the paper gives no others).

Every network stops once its validation loss has not improved for :data:`PAPER_PATIENCE`
epochs, or at its cap: the paper's :data:`PAPER_EPOCHS`, :data:`FINETUNE_EPOCHS` for
fine-tuning, :data:`BATCH_SWEEP_EPOCHS` for the batch sweep's runs at 32 and 256 rows;
:attr:`nctwin.learn.train.Trained.converged` says which ended it.

Every network of the chapter is trained by :func:`nctwin.chapters.zhang2023_seeds.train_networks`
(five seeds of those the claims judge, in parallel); this module scores them.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import partial

import numpy as np
import pandas as pd
import torch

from ..checks import best_time_s
from ..learn.models import BPConfig
from ..learn.stack import fit_stack
from ..learn.train import TrainConfig, Trained, TrainingDivergedError, load_checkpoint
from ..physics.steperror import step_error_iterative_um, step_error_samples, step_error_um
from ..report.papers import load_paper_table
from .zhang2023_surfaces import (
    SurfaceData,
    chord_check,
    paper_hidden,
    surface_data,
    surfaces_table,
)
from .zhang2023_tables import dropout_conventions, error_histogram, transfer_metrics

__all__ = [
    "BATCH_RUNS",
    "BATCH_SWEEP_EPOCHS",
    "FINETUNE_EPOCHS",
    "PAPER_EPOCHS",
    "PAPER_PATIENCE",
    "SurfaceData",
    "TransferRun",
    "batch_sweep",
    "best_time_s",
    "chord_check",
    "dropout_conventions",
    "dropout_sweep",
    "error_histogram",
    "finetune_configs",
    "paper_configs",
    "paper_hidden",
    "predict_um",
    "scaled_mse",
    "split",
    "surface_data",
    "surfaces_table",
    "timing_table",
    "train",
    "transfer",
    "transfer_metrics",
    "transfer_table",
    "variant_configs",
]


#: Early stopping of every training of the chapter (a choice; the paper gives none): epochs
#: without a lower validation loss before training stops.
PAPER_PATIENCE = 100

#: The paper's settings (``data/papers/zhang2023_summary.csv``).
_PAPER = load_paper_table("zhang2023_summary").set_index("quantity")["value"].astype(float)

#: The paper's epochs (Sec. "Training"): the cap of training on surface 1.
PAPER_EPOCHS = int(_PAPER["epochs"])

#: The cap of fine-tuning (the paper gives none), far above where early stopping ends it.
FINETUNE_EPOCHS = 10_000

#: The batch sweep's cap at 32 and 256 rows per update (a time budget: 78,000 and 8,800
#: updates, against the full batch's 2000; :func:`batch_sweep` says which runs reach it).
BATCH_SWEEP_EPOCHS = 200


def split(n: int, share: float, *, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Seeded random split of ``range(n)``: ``round(share * n)`` picked rows and the rest.

    Both index arrays are in the permutation's (random) order.

    Raises
    ------
    ValueError
        If ``share`` is not in [0, 1].
    """
    if not 0.0 <= share <= 1.0:
        raise ValueError(f"share = {share!r} is out of range: allowed [0, 1]")
    order = np.random.default_rng([seed, n]).permutation(n)
    k = round(share * n)
    return order[:k], order[k:]


def paper_configs(
    n_inputs: int,
    *,
    seed: int = 0,
    dropout: float = float(_PAPER["dropout_p"]),
    batch_rows: int | None = None,
    epochs: int = PAPER_EPOCHS,
) -> tuple[BPConfig, TrainConfig]:
    """The paper's network and training settings (see the module docstring).

    Parameters
    ----------
    n_inputs : int
    seed : int
    dropout : float
        Probability of dropping a hidden unit (default: the paper's).
    batch_rows : int, optional
        Rows per update; None: all training rows (one update per epoch).
    epochs : int
        Default: the paper's, the cap; training stops earlier once the validation loss has not
        improved for :data:`PAPER_PATIENCE` epochs (the kept weights, those of the best validation
        epoch, are then the same as after all ``epochs``).

    Raises
    ------
    ValueError
        If ``batch_rows`` < 1 or ``epochs`` < 1.
    """
    if batch_rows is not None and batch_rows < 1:
        raise ValueError(f"batch_rows = {batch_rows!r} is out of range: allowed >= 1 or None")
    if epochs < 1:
        raise ValueError(f"epochs = {epochs!r} is out of range: allowed >= 1")
    model = BPConfig(
        n_inputs=n_inputs, hidden=paper_hidden(), dropout=dropout, weight_init="normal"
    )
    window, batch = (99, 1_000_000) if batch_rows is None else (batch_rows, 1)
    train_config = TrainConfig(
        seed=seed, max_epochs=epochs, patience=min(epochs, PAPER_PATIENCE), batch_size=batch,
        window_lines=window, learning_rate=float(_PAPER["learning_rate"]), val_share=0.1,
        loss="mse", optimiser="sgd", momentum=float(_PAPER["momentum"]),
    )  # fmt: skip
    return model, train_config


def variant_configs(
    n_inputs: int,
    *,
    dropout: float = 0.0,
    seed: int = 0,
    patience: int = PAPER_PATIENCE,
    max_epochs: int = PAPER_EPOCHS,
) -> tuple[BPConfig, TrainConfig]:
    """The closest variant that converges (see the module docstring).

    Parameters
    ----------
    n_inputs : int
    dropout : float
        Probability of dropping a hidden unit (PyTorch's convention).
    seed : int
    patience : int
        Epochs without a lower validation loss before training stops (at most
        ``max_epochs``).
    max_epochs : int
        The cap (the paper's 2000).

    Raises
    ------
    ValueError
        If ``patience`` or ``max_epochs`` < 1, or ``dropout`` is outside [0, 1).
    """
    for name, value in (("patience", patience), ("max_epochs", max_epochs)):
        if value < 1:
            raise ValueError(f"{name} = {value!r} is out of range: allowed >= 1")
    model = BPConfig(
        n_inputs=n_inputs, hidden=paper_hidden(), dropout=dropout, weight_init="uniform"
    )
    train_config = TrainConfig(
        seed=seed, max_epochs=max_epochs, patience=min(patience, max_epochs), batch_size=16,
        window_lines=8, learning_rate=1e-2, val_share=0.1, loss="mse", optimiser="sgd",
        momentum=0.8,
    )  # fmt: skip
    return model, train_config


def finetune_configs(n_inputs: int, *, seed: int = 0) -> tuple[BPConfig, TrainConfig]:
    """Fine-tuning settings (the paper gives none): :func:`variant_configs` without dropout, at
    lr 3e-3 (at the variant's 1e-2 the surface-1 network's first steps on a new surface can
    diverge; at 1e-3 the validation loss creeps down for thousands of epochs), capped at
    :data:`FINETUNE_EPOCHS`."""
    model, train_config = variant_configs(
        n_inputs, dropout=0.0, seed=seed, max_epochs=FINETUNE_EPOCHS
    )
    return model, replace(train_config, learning_rate=3e-3)


def train(
    data: SurfaceData,
    rows: np.ndarray,
    model_configs: Sequence[BPConfig],
    train_configs: Sequence[TrainConfig],
    *,
    names: Sequence[str],
    init: Sequence[Trained] | None = None,
) -> list[Trained | None]:
    """Train (or fine-tune from ``init``) one network per config on the rows ``rows`` of
    ``data``, as one stack (:func:`nctwin.learn.stack.fit_stack`: the configs may differ in the
    seed and the dropout only).

    The rows, in the given order, are cut into chunks of ``window_lines``.

    Returns
    -------
    list of Trained or None
        One per config; None where the training diverged.

    Raises
    ------
    ValueError
        If fewer than two chunks result (the loop needs one to validate on).
    """
    window = train_configs[0].window_lines
    x, y = data.x[rows], data.y_um[rows]
    n_chunks = -(-len(rows) // window)
    if n_chunks < 2:
        raise ValueError(
            f"rows = {len(rows)} is out of range: allowed at least {window + 1} (two chunks)"
        )
    if n_chunks < 20:  # small fine-tuning sets: smaller chunks, so that 10 % can validate
        window = max(1, len(rows) // 20)
        train_configs = [replace(c, window_lines=window) for c in train_configs]
    xs = np.array_split(x, -(-len(rows) // window))
    ys = np.array_split(y, len(xs))
    return fit_stack(model_configs, train_configs, xs, ys, names=names, init=init)


def predict_um(trained: Trained, x: np.ndarray) -> np.ndarray:
    r"""Predicted step errors in um, shape (n,), of samples ``x`` (n, n_inputs), in evaluation
    mode.

    The Z-score of the inputs (eq. 7) is folded into the first linear layer, which runs in
    float64 on the unscaled inputs: :math:`W' = W / \sigma` (per input column),
    :math:`b' = b - W' \mu`, so that :math:`W' x + b' = W (x - \mu) / \sigma + b`. The other
    layers run in float32, as in training, and the output is scaled back. This is the network
    :meth:`nctwin.learn.train.Trained.predict` runs, rounded differently: it skips the float64
    (n, n_inputs) array of scaled inputs, which took about three quarters of the prediction
    time. On this chapter's networks the two differ by at most 3e-5 um, and this one is three
    to four times closer to the network evaluated wholly in float64.

    Raises
    ------
    ValueError
        If ``x`` is not (n, n_inputs) or the input scaler has logarithmic columns.
    """
    first, rest = trained.model.layers[0], trained.model.layers[1:]
    if x.ndim != 2 or x.shape[1] != first.in_features:
        raise ValueError(f"x has shape {x.shape}: allowed (n, {first.in_features})")
    if trained.x_scaler.log_columns:
        raise ValueError(
            f"x_scaler.log_columns = {trained.x_scaler.log_columns!r}: allowed none (a BP "
            "network of this chapter)"
        )
    mean = torch.from_numpy(trained.x_scaler.mean)
    std = torch.from_numpy(trained.x_scaler.std)
    with torch.no_grad():
        weight = first.weight.double() / std
        bias = first.bias.double() - weight @ mean
        hidden = torch.addmm(bias, torch.from_numpy(np.asarray(x, dtype=np.float64)), weight.T)
        z = rest(hidden.float()).numpy()
    return trained.y_scaler.inverse(z)[:, 0]


def scaled_mse(trained: Trained, x: np.ndarray, y_um: np.ndarray) -> float:
    """MSE of the predictions of ``x`` in the Z-scored target units the network trains in
    (eq. 4 and 7; what Table 2 and Fig. 5 report), evaluation mode (no dropout)."""
    z = (predict_um(trained, x) - y_um) / trained.y_scaler.std[0]
    return float(np.mean(z * z))


def dropout_sweep(
    data: SurfaceData, test_rows: np.ndarray, nets: dict[float, Trained | None]
) -> pd.DataFrame:
    """Table 2: the variant trained with each dropout probability (:func:`train_networks`).

    Returns
    -------
    DataFrame
        ``dropout_p``, ``final_train_mse`` (last epoch, dropout active), ``test_mse`` (dropout
        off; both Z-scored), ``share_below_1um_pct`` and ``diverged`` (the training loss became
        NaN in every epoch, ``nets[p]`` is None; the numbers are then NaN).
    """
    rows = []
    y = data.exact.error_um[test_rows]
    for p, net in nets.items():
        row = {"dropout_p": p, "final_train_mse": np.nan, "test_mse": np.nan,
               "share_below_1um_pct": np.nan, "diverged": net is None}  # fmt: skip
        if net is not None:
            row.update(
                final_train_mse=net.history["train"][-1],
                test_mse=scaled_mse(net, data.x[test_rows], y),
                share_below_1um_pct=transfer_metrics(predict_um(net, data.x[test_rows]), y)[
                    "share_below_1um_pct"
                ],
            )
        rows.append(row)
    return pd.DataFrame(rows)


#: The batch sweep's runs: rows per update (None: the full batch) and dropout probability.
BATCH_RUNS = tuple((b, p) for b in (1, 32, 256, None) for p in (0.5, 0.0))


def _batch_epochs(batch: int | None) -> int:
    return {1: 1, None: PAPER_EPOCHS}.get(batch, BATCH_SWEEP_EPOCHS)


def batch_sweep(
    data: SurfaceData,
    train_rows: np.ndarray,
    test_rows: np.ndarray,
    nets: dict[tuple[int | None, float], Trained | None],
) -> pd.DataFrame:
    """The paper's settings at batches of 1, 32, 256 rows and the full batch, with dropout
    0.5 and without (:data:`BATCH_RUNS`, trained by :func:`train_networks`).

    Every run stops early after :data:`PAPER_PATIENCE` epochs without improvement. Batch 1
    runs one epoch (12,474 updates, already more than the full batch's 2000); 32 and 256 rows
    run up to :data:`BATCH_SWEEP_EPOCHS`; the full batch up to the paper's 2000 epochs.
    ``epochs`` and ``updates`` count what ran (for a diverged run, what was to run: its
    training stops at the first update that leaves a weight NaN); ``converged`` says whether
    early stopping ended the run (False: the cap did, and the run was still learning).

    Returns
    -------
    pandas.DataFrame
        ``batch_rows`` (0 = full), ``dropout_p``, ``updates``, ``epochs``, ``best_epoch``,
        ``converged``, ``final_train_mse``, ``test_mse``, ``pred_std_um`` (spread of the
        predictions; the exact step errors' is ``exact_std_um``), ``share_below_1um_pct``,
        ``diverged``.
    """
    y = data.exact.error_um[test_rows]
    n_train = len(train_rows) - round(0.1 * len(train_rows))
    rows = []
    for batch, p in BATCH_RUNS:
        net = nets[(batch, p)]
        n_epochs = _batch_epochs(batch) if net is None else len(net.history["train"])
        row = {"batch_rows": batch or 0, "dropout_p": p,
               "updates": n_epochs * (1 if batch is None else -(-n_train // batch)),
               "epochs": n_epochs, "best_epoch": np.nan, "converged": np.nan,
               "final_train_mse": np.nan,
               "test_mse": np.nan, "pred_std_um": np.nan, "exact_std_um": float(y.std()),
               "share_below_1um_pct": np.nan, "diverged": True}  # fmt: skip
        if net is not None:
            pred = predict_um(net, data.x[test_rows])
            row.update(best_epoch=net.best_epoch, converged=net.converged,
                       final_train_mse=net.history["train"][-1],
                       test_mse=scaled_mse(net, data.x[test_rows], y),
                       pred_std_um=float(pred.std()),
                       share_below_1um_pct=transfer_metrics(pred, y)["share_below_1um_pct"],
                       diverged=not np.isfinite(net.history["train"][-1]))  # fmt: skip
        rows.append(row)
    return pd.DataFrame(rows)


@dataclass(frozen=True, eq=False)
class TransferRun:
    """One fine-tuning of the transfer study.

    Parameters
    ----------
    surface, finetune_pct : int, float
    trained : Trained
        The fine-tuned network (the start network itself at 0 %).
    test_rows : ndarray of int
        Rows predicted (all rows not used for fine-tuning).
    predicted_um : ndarray
        Predictions of ``test_rows``.
    """

    surface: int
    finetune_pct: float
    trained: Trained
    test_rows: np.ndarray
    predicted_um: np.ndarray


def transfer(
    starts: Sequence[Trained],
    data: SurfaceData,
    shares_pct: tuple[float, ...],
    train_configs: Sequence[TrainConfig],
    *,
    seed: int,
    prefix: str = "zhang2023",
) -> list[list[TransferRun]]:
    """Fine-tune each of ``starts`` on ``shares_pct`` % of the samples of ``data`` and predict
    the rest (Tables 4-7); 0 % predicts every sample with the start network unchanged.

    Each share draws its rows with :func:`split` (seed ``seed``, the same rows for every start)
    and fine-tunes the starts as one stack (:func:`train`; ``train_configs``: one per start);
    each keeps its start network's scalers. ``prefix`` begins the checkpoints' names.

    Returns
    -------
    list of list of TransferRun
        One list per start, one run per share.

    Raises
    ------
    TrainingDivergedError
        If a fine-tuning diverged.
    """
    runs: list[list[TransferRun]] = [[] for _ in starts]
    for pct in shares_pct:
        picked, rest = split(len(data.x), pct / 100.0, seed=seed)
        tuned: list[Trained | None] = list(starts)
        if len(picked):
            names = [f"{prefix}_s{data.index}_ft{pct:g}_seed{c.seed}" for c in train_configs]
            tuned = train(data, picked, [s.model.config for s in starts], train_configs,
                          names=names, init=starts)  # fmt: skip
        for chain, net, name in zip(runs, tuned, [s.path.stem for s in starts], strict=True):
            if net is None:
                raise TrainingDivergedError(
                    f"fine-tuning {name} on {pct:g} % of surface {data.index} diverged"
                )
            chain.append(TransferRun(data.index, pct, net, rest, predict_um(net, data.x[rest])))
    return runs


def transfer_table(runs: list[TransferRun], data: dict[int, SurfaceData], paper: pd.DataFrame):
    """One row per surface x fine-tune share: :func:`transfer_metrics` beside the paper's
    maximum absolute error and share below 1 um (``zhang2023_transfer``; NaN where the paper
    gives none)."""
    ref = paper.set_index(["surface", "extract_pct"])
    rows = []
    for run in runs:
        key = (run.surface, run.finetune_pct)
        exact = data[run.surface].exact.error_um[run.test_rows]
        rows.append(
            {
                "surface": run.surface,
                "finetune_pct": run.finetune_pct,
                **transfer_metrics(run.predicted_um, exact),
                "paper_max_abs_err_um": ref["max_abs_err_um"].get(key, np.nan),
                "paper_share_below_1um_pct": ref["abs_err_lt_1um_pct"].get(key, np.nan),
            }
        )
    return pd.DataFrame(rows)


def timing_table(
    data: SurfaceData, trained: Trained, k_inner: int, paper_t8: pd.DataFrame
) -> pd.DataFrame:
    """Table 8: the time to get the step errors of one surface, by method.

    Every time is the shortest of 15 runs after 2 warm-ups (:func:`~nctwin.checks.best_time_s`),
    but two: building the Table 1 inputs (0.5 s a run) is the shortest of 3 after 1, and the
    iterative method runs on every 20th segment and is scaled to all of them, and its result is
    checked against the exact one (within 1e-6 um).

    Parameters
    ----------
    data : SurfaceData
        The surface (paper: surface 2), with its samples ``x`` of shape (n, 3 k + 13).
    trained : Trained
        The network (its checkpoint is loaded for the "with model import" time).
    k_inner : int
        Inner CC points per sample (for building the samples).
    paper_t8 : pandas.DataFrame
        The paper table ``zhang2023_table8``.

    Returns
    -------
    pandas.DataFrame
        Columns ``method, seconds, samples, paper_seconds``; methods ``nn_prediction``,
        ``nn_prediction_with_model_import``, ``nn_table1_samples``, ``geometric_iterative``,
        ``exact_vectorised``.

    Raises
    ------
    RuntimeError
        If the iterative and the exact step errors differ by 1e-6 um or more.
    """
    d2 = data
    net_s2 = trained
    best_s = partial(best_time_s, repeat=15, warmup=2)  # shortest of 15, as the benchmark
    t_predict = best_s(lambda: predict_um(net_s2, d2.x))
    t_import = best_s(lambda: predict_um(load_checkpoint(net_s2.path), d2.x))
    t_samples = best_time_s(lambda: step_error_samples(d2.path, k_inner), repeat=3, warmup=1)
    t_exact = best_s(lambda: step_error_um(d2.path))
    every = np.arange(0, d2.path.n_segments, 20)
    t0 = time.perf_counter()
    iterative = step_error_iterative_um(d2.path, segments=every)
    t_iter = (time.perf_counter() - t0) * d2.path.n_segments / len(every)
    if not np.max(np.abs(iterative - d2.exact.error_um[every])) < 1e-6:
        raise RuntimeError("the iterative step errors differ from the exact ones")
    paper_s = paper_t8.set_index(["method", "surface"])["time_s"]
    timing = pd.DataFrame(
        [
            ("nn_prediction", t_predict, np.nan),
            ("nn_prediction_with_model_import", t_import, paper_s[("proposed", 2)]),
            ("nn_table1_samples", t_samples, np.nan),
            ("geometric_iterative", t_iter, paper_s[("geometric", 2)]),
            ("exact_vectorised", t_exact, np.nan),
        ],
        columns=["method", "seconds", "paper_seconds"],
    )
    timing.insert(2, "samples", d2.path.n_segments)
    return timing
