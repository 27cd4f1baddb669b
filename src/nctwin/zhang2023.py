r"""The experiment of Zhang et al. (2023): a BP network learns the exact step error of ball-end
CL segments on one free-form surface and is fine-tuned to two more.

Per surface (Sec. "Sample construction"): the stand-in of :mod:`nctwin.surfaces`, its
iso-parametric path (200 lines x 100 CC points, R = 5 mm, 19,800 segments), the exact step
error of every segment (:func:`nctwin.steperror.step_error_um`, the network's target) and the
Table 1 samples (:func:`nctwin.steperror.step_error_samples`, with the number of inner points
that makes the input width fit eq. 8 with a first hidden layer of 28).

Training runs through the shared loop :func:`nctwin.train.fit`, which learns on "programs" of
consecutive rows. Samples are independent, so the training rows are cut, in a seeded random
order, into chunks of ``window_lines`` rows; a batch is ``batch_size`` chunks, and the loop holds
out ``val_share`` of the chunks (10 %) to keep the weights of the best validation epoch. Inputs
and targets are Z-scored with the statistics of the training chunks (eq. 7; the loop divides by
the population standard deviation, :math:`n` rather than eq. 7's :math:`n - 1`: a relative
difference of 4e-5 at 12,000 rows). The tool radius column is constant, so its Z-score is 0.

Configurations
--------------
:func:`paper_configs`
    The paper's settings: weights N(0, 1), dropout 0.5, SGD with momentum 0.8, lr 1e-5,
    2000 epochs, MSE; full batch (the paper names SGD but gives no batch size; one step per epoch
    over all training rows is what "2000 epochs" buys at lr 1e-5 at the least).
:func:`variant_configs`
    The closest variant that converges here: PyTorch's default uniform weights, SGD with
    momentum 0.8, lr 1e-2, batches of 128 rows, ``epochs`` epochs, MSE, dropout as given.
:func:`finetune_configs`
    Fine-tuning to a new surface (Tables 4-7): the variant without dropout at lr 1e-3.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
import torch

from .checks import best_time_s
from .models import BPConfig
from .steperror import (
    StepError,
    inner_points_for_hidden_width,
    step_error_samples,
    step_error_um,
)
from .surfaces import ToolPath, iso_parametric_path, paper_surface
from .train import TrainConfig, Trained, TrainingDivergedError, fit

__all__ = [
    "HIDDEN",
    "SurfaceData",
    "TransferRun",
    "best_time_s",
    "dropout_sweep",
    "error_histogram",
    "finetune_configs",
    "paper_configs",
    "predict_um",
    "scaled_mse",
    "split",
    "surface_data",
    "train",
    "transfer",
    "transfer_metrics",
    "transfer_table",
    "variant_configs",
]

#: Hidden layer widths of the paper (Sec. "Network parameter determination").
HIDDEN = (28, 20)


@dataclass(frozen=True, eq=False)
class SurfaceData:
    """One surface's path, exact step errors and network samples.

    Parameters
    ----------
    index : int
        Surface 1, 2 or 3.
    path : ToolPath
    exact : StepError
        Exact step errors, shape (19,800,).
    x : ndarray, shape (19,800, 3 k + 13)
        Table 1 samples.
    """

    index: int
    path: ToolPath
    exact: StepError
    x: np.ndarray

    @property
    def y_um(self) -> np.ndarray:
        """Targets, the exact step errors in um, shape (n, 1)."""
        return self.exact.error_um[:, None]


def surface_data(index: int, *, n_inner: int | None = None) -> SurfaceData:
    """Path, exact step errors and samples of surface ``index`` (paper: R = 5 mm, 200 x 100).

    ``n_inner`` defaults to :func:`nctwin.steperror.inner_points_for_hidden_width` of
    :data:`HIDDEN` [0] (104 inner points, 325 inputs).
    """
    k = inner_points_for_hidden_width(HIDDEN[0]) if n_inner is None else n_inner
    path = iso_parametric_path(paper_surface(index))
    return SurfaceData(index, path, step_error_um(path), step_error_samples(path, k))


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


def paper_configs(n_inputs: int, *, seed: int = 0) -> tuple[BPConfig, TrainConfig]:
    """The paper's network and training settings (see the module docstring)."""
    model = BPConfig(n_inputs=n_inputs, hidden=HIDDEN, dropout=0.5, weight_init="normal")
    train_config = TrainConfig(
        seed=seed, max_epochs=2000, patience=2000, batch_size=1_000_000, window_lines=99,
        learning_rate=1e-5, val_share=0.1, loss="mse", optimiser="sgd", momentum=0.8,
    )  # fmt: skip
    return model, train_config


def variant_configs(
    n_inputs: int, *, epochs: int, dropout: float = 0.0, seed: int = 0
) -> tuple[BPConfig, TrainConfig]:
    """The closest variant that converges (see the module docstring).

    Raises
    ------
    ValueError
        If ``epochs`` < 1 or ``dropout`` is outside [0, 1).
    """
    if epochs < 1:
        raise ValueError(f"epochs = {epochs!r} is out of range: allowed >= 1")
    model = BPConfig(n_inputs=n_inputs, hidden=HIDDEN, dropout=dropout, weight_init="uniform")
    train_config = TrainConfig(
        seed=seed, max_epochs=epochs, patience=epochs, batch_size=16, window_lines=8,
        learning_rate=1e-2, val_share=0.1, loss="mse", optimiser="sgd", momentum=0.8,
    )  # fmt: skip
    return model, train_config


def finetune_configs(n_inputs: int, *, epochs: int, seed: int = 0) -> tuple[BPConfig, TrainConfig]:
    """Fine-tuning settings: :func:`variant_configs` without dropout, a tenth of its learning
    rate (1e-3) and ``epochs`` epochs (the paper gives no fine-tuning settings)."""
    model, train_config = variant_configs(n_inputs, epochs=epochs, dropout=0.0, seed=seed)
    return model, replace(train_config, learning_rate=1e-3)


def train(
    data: SurfaceData,
    rows: np.ndarray,
    model_config: BPConfig,
    train_config: TrainConfig,
    *,
    name: str,
    init: Trained | None = None,
    progress: bool = True,
) -> Trained:
    """Train (or fine-tune from ``init``) on the rows ``rows`` of ``data`` with the shared loop.

    The rows, in the given order, are cut into chunks of ``train_config.window_lines``.

    Raises
    ------
    ValueError
        If fewer than two chunks result (the loop needs one to validate on).
    """
    x, y = data.x[rows], data.y_um[rows]
    n_chunks = -(-len(rows) // train_config.window_lines)
    if n_chunks < 2:
        raise ValueError(
            f"rows = {len(rows)} is out of range: allowed at least "
            f"{train_config.window_lines + 1} (two chunks)"
        )
    if n_chunks < 20:  # small fine-tuning sets: smaller chunks, so that 10 % can validate
        train_config = replace(train_config, window_lines=max(1, len(rows) // 20))
    xs = np.array_split(x, -(-len(rows) // train_config.window_lines))
    ys = np.array_split(y, len(xs))
    return fit(model_config, train_config, xs, ys, name=name, init=init, progress=progress)


def predict_um(trained: Trained, x: np.ndarray) -> np.ndarray:
    r"""Predicted step errors in um, shape (n,), of samples ``x`` (n, n_inputs), in evaluation
    mode.

    The Z-score of the inputs (eq. 7) is folded into the first linear layer, which runs in
    float64 on the unscaled inputs: :math:`W' = W / \sigma` (per input column),
    :math:`b' = b - W' \mu`, so that :math:`W' x + b' = W (x - \mu) / \sigma + b`. The other
    layers run in float32, as in training, and the output is scaled back. This is the network
    :meth:`nctwin.train.Trained.predict` runs, rounded differently: it skips the float64
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
    data: SurfaceData,
    train_rows: np.ndarray,
    test_rows: np.ndarray,
    probabilities: tuple[float, ...],
    *,
    epochs: int,
    seed: int,
    progress: bool = True,
) -> pd.DataFrame:
    """Table 2: the variant trained with each dropout probability.

    Returns
    -------
    DataFrame
        ``dropout_p``, ``final_train_mse`` (last epoch, dropout active), ``test_mse`` (dropout
        off; both Z-scored), ``share_below_1um_pct`` and ``diverged`` (the training loss became
        NaN in every epoch; the numbers are then NaN).
    """
    rows = []
    for p in probabilities:
        model_cfg, train_cfg = variant_configs(data.x.shape[1], epochs=epochs, dropout=p, seed=seed)
        row = {"dropout_p": p, "final_train_mse": np.nan, "test_mse": np.nan,
               "share_below_1um_pct": np.nan, "diverged": True}  # fmt: skip
        try:
            net = train(
                data, train_rows, model_cfg, train_cfg, name=f"zhang2023_sweep_p{p:g}",
                progress=progress,
            )  # fmt: skip
        except TrainingDivergedError:
            rows.append(row)
            continue
        y = data.exact.error_um[test_rows]
        pred = predict_um(net, data.x[test_rows])
        row.update(
            final_train_mse=net.history["train"][-1],
            test_mse=scaled_mse(net, data.x[test_rows], y),
            share_below_1um_pct=transfer_metrics(pred, y)["share_below_1um_pct"],
            diverged=False,
        )
        rows.append(row)
    return pd.DataFrame(rows)


def _bins(paper: pd.DataFrame, metric: str) -> list[tuple[str, float, float]]:
    rows = paper[paper.metric == metric]
    out = []
    for r in rows.itertuples():
        lo = 0.0 if pd.isna(r.bin_lo) else float(r.bin_lo)
        hi = np.inf if pd.isna(r.bin_hi) else float(r.bin_hi)
        out.append((str(r.bin_label), lo, hi))
    if np.isfinite(out[-1][2]):  # the paper's last bin is closed: count what lies beyond it
        out.append((f"> {out[-1][2]:g}", out[-1][2], np.inf))
    return out


def error_histogram(
    predicted_um: np.ndarray, exact_um: np.ndarray, paper: pd.DataFrame
) -> pd.DataFrame:
    """Absolute- and relative-error histograms with the paper's bins, beside the paper's.

    Parameters
    ----------
    predicted_um, exact_um : ndarray, shape (n,)
    paper : DataFrame
        A table like ``zhang2023_table3`` (``metric`` ``abs_err`` in um, ``rel_err`` in %,
        ``bin_lo``/``bin_hi``, ``count``, ``ratio_pct``). Bins are [lo, hi); where the paper's
        last absolute bin is closed, one more row counts the errors beyond it.

    Returns
    -------
    DataFrame
        ``metric``, ``bin_label``, ``bin_lo``, ``bin_hi``, ``count``, ``ratio_pct``,
        ``paper_count``, ``paper_ratio_pct``.
    """
    abs_err = np.abs(predicted_um - exact_um)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel_err = np.where(exact_um > 0, abs_err / exact_um * 100.0, np.inf)
    rows = []
    for metric, err in (("abs_err", abs_err), ("rel_err", rel_err)):
        ref = paper[paper.metric == metric].set_index("bin_label")
        for label, lo, hi in _bins(paper, metric):
            count = int(np.count_nonzero((err >= lo) & (err < hi)))
            rows.append(
                {
                    "metric": metric,
                    "bin_label": label,
                    "bin_lo": lo,
                    "bin_hi": hi,
                    "count": count,
                    "ratio_pct": 100.0 * count / len(err),
                    "paper_count": ref["count"].get(label, np.nan),
                    "paper_ratio_pct": ref["ratio_pct"].get(label, np.nan),
                }
            )
    return pd.DataFrame(rows)


def transfer_metrics(predicted_um: np.ndarray, exact_um: np.ndarray) -> dict[str, float]:
    """Maximum and mean absolute error (um) and the share below 1 um (%) of a test set."""
    err = np.abs(predicted_um - exact_um)
    return {
        "max_abs_err_um": float(err.max()),
        "share_below_1um_pct": 100.0 * float(np.mean(err < 1.0)),
        "mean_abs_err_um": float(err.mean()),
    }


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
    start: Trained,
    data: SurfaceData,
    shares_pct: tuple[float, ...],
    train_config: TrainConfig,
    *,
    seed: int,
    progress: bool = True,
) -> list[TransferRun]:
    """Fine-tune ``start`` on ``shares_pct`` % of the samples of ``data`` and predict the rest
    (Tables 4-7); 0 % predicts every sample with ``start`` unchanged.

    Each share draws its rows with :func:`split` (seed ``seed``); the fine-tuning keeps the
    start network's scalers.
    """
    runs = []
    for pct in shares_pct:
        picked, rest = split(len(data.x), pct / 100.0, seed=seed)
        if len(picked):
            name = f"zhang2023_s{data.index}_ft{pct:g}"
            tuned = train(
                data, picked, start.model.config, train_config, name=name, init=start,
                progress=progress,
            )  # fmt: skip
        else:
            tuned = start
        runs.append(TransferRun(data.index, pct, tuned, rest, predict_um(tuned, data.x[rest])))
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
