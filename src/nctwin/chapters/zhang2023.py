r"""The experiment of Zhang et al. (2023): a BP network learns the exact step error of ball-end
CL segments on one free-form surface and is fine-tuned to two more.

Per surface (Sec. "Sample construction"): the stand-in of :mod:`nctwin.physics.surfaces`, its
iso-parametric path (200 lines x 100 CC points, R = 5 mm, 19,800 segments), the exact step
error of every segment (:func:`nctwin.physics.steperror.step_error_um`, the network's target)
and the Table 1 samples (:func:`nctwin.physics.steperror.step_error_samples`, with the number of
inner points that makes the input width fit eq. 8 with a first hidden layer of 28).

Training runs through the shared loop :func:`nctwin.learn.train.fit`, which learns on "programs" of
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

import itertools
import time
from dataclasses import dataclass, replace
from functools import partial

import numpy as np
import pandas as pd
import torch

from ..checks import best_time_s
from ..learn.models import BPConfig
from ..learn.train import TrainConfig, Trained, TrainingDivergedError, fit, load_checkpoint
from ..physics.steperror import (
    StepError,
    chord_step_error_um,
    inner_points_for_hidden_width,
    step_error_iterative_um,
    step_error_samples,
    step_error_um,
)
from ..physics.surfaces import Cylinder, Sphere, ToolPath, iso_parametric_path, paper_surface
from ..report.tables import Claim, side_by_side

__all__ = [
    "HIDDEN",
    "SurfaceData",
    "TransferRun",
    "best_time_s",
    "chord_check",
    "claims",
    "dropout_sweep",
    "error_histogram",
    "finetune_configs",
    "paper_configs",
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

    ``n_inner`` defaults to :func:`nctwin.physics.steperror.inner_points_for_hidden_width` of
    :data:`HIDDEN` [0] (104 inner points, 325 inputs).
    """
    k = inner_points_for_hidden_width(HIDDEN[0]) if n_inner is None else n_inner
    path = iso_parametric_path(paper_surface(index))
    return SurfaceData(index, path, step_error_um(path), step_error_samples(path, k))


def surfaces_table(data: dict[int, SurfaceData], paper_surfaces: pd.DataFrame) -> pd.DataFrame:
    """The surfaces' sizes and step-error ranges beside the paper's (Fig. 4).

    Parameters
    ----------
    data : dict
        ``surface -> SurfaceData`` (paths of 200 x 100 CC points, 19,800 step errors each).
    paper_surfaces : pandas.DataFrame
        The paper table ``zhang2023_surfaces``.

    Returns
    -------
    pandas.DataFrame
        One row per surface: ``x_mm``, ``y_mm`` (extent of the CC points), ``z_max_mm``,
        ``segments``, ``err_min_um``, ``err_max_um``, ``below_0p01um_pct``, ``convex_pct``
        (rounded to 4 decimals), beside the paper's bounding box, sample count and step-error
        range (:func:`~nctwin.report.tables.side_by_side`).
    """
    ours = pd.DataFrame(
        [
            {
                "surface": i,
                "x_mm": np.ptp(d.path.cc_mm[..., 0]),
                "y_mm": np.ptp(d.path.cc_mm[..., 1]),
                "z_max_mm": d.path.surface.size_z_mm,
                "segments": d.path.n_segments,
                "err_min_um": d.exact.error_um.min(),
                "err_max_um": d.exact.error_um.max(),
                "below_0p01um_pct": 100 * np.mean(d.exact.error_um < 0.01),
                "convex_pct": 100 * d.exact.convex.mean(),
            }
            for i, d in data.items()
        ]
    ).round(4)
    return side_by_side(
        ours, paper_surfaces, on=["surface"],
        columns=["bbox_x_mm", "bbox_y_mm", "bbox_z_mm", "n_samples", "step_err_min_um",
                 "step_err_max_um"],
    )  # fmt: skip


def chord_check() -> pd.DataFrame:
    r"""The exact method against the chord formula
    :math:`e = (\rho \pm R)(1 - \cos\frac{\Delta\theta}{2})`.

    Sphere and cylinder of radius 40 mm, tool (R = 5 mm) outside (convex) and inside (concave),
    10 lines of 30 CC points (:func:`~nctwin.physics.surfaces.iso_parametric_path`).

    Returns
    -------
    pandas.DataFrame
        One row per shape and tool side: ``shape``, ``tool``, ``chord_formula_um``,
        ``max_abs_diff_um`` (largest difference over the 10 x 29 segments), ``below_1e-6um`` and
        ``classified_convex_pct``.
    """
    rows = []
    shapes = (Sphere(40.0), Sphere(40.0, inside=True), Cylinder(40.0), Cylinder(40.0, inside=True))
    for shape in shapes:
        path = iso_parametric_path(shape, n_lines=10, n_points=30)
        reference = chord_step_error_um(40.0, 5.0, shape.sweep_rad / 29, inside=shape.inside)
        result = step_error_um(path)
        rows.append(
            {
                "shape": type(shape).__name__.lower(),
                "tool": "inside" if shape.inside else "outside",
                "chord_formula_um": float(reference),
                "max_abs_diff_um": float(np.max(np.abs(result.error_um - reference))),
                "below_1e-6um": bool(np.max(np.abs(result.error_um - reference)) < 1e-6),
                "classified_convex_pct": 100 * result.convex.mean(),
            }
        )
    return pd.DataFrame(rows)


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


def timing_table(
    data: SurfaceData, trained: Trained, k_inner: int, paper_t8: pd.DataFrame
) -> pd.DataFrame:
    """Table 8: the time to get the step errors of one surface, by method.

    Every time but the iterative method's is the shortest of 15 runs after 2 warm-ups
    (:func:`~nctwin.checks.best_time_s`); the iterative method runs on every 20th segment and is
    scaled to all of them, and its result is checked against the exact one (within 1e-6 um).

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
    t_samples = best_s(lambda: step_error_samples(d2.path, k_inner))
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


def claims(
    runs: pd.DataFrame,
    m1: dict[str, float],
    transfer_tab: pd.DataFrame,
    shares: tuple[float, ...],
    timing: pd.DataFrame,
) -> list[Claim]:
    """The chapter's claims: the paper's accuracy on surface 1 (with the converging variant and
    with the paper's own settings), dropout, fine-tuning, and the time of Table 8.

    Parameters
    ----------
    runs : pandas.DataFrame
        The surface-1 networks, one row each (``network``, ``test_mse``,
        ``share_below_1um_pct``), among them ``"paper settings (p = 0.5)"``,
        ``"variant (p = 0.5)"`` and ``"variant (p = 0)"``.
    m1 : dict
        :func:`transfer_metrics` of the variant without dropout on surface 1's test rows.
    transfer_tab : pandas.DataFrame
        :func:`transfer_table` of surfaces 2 and 3.
    shares : tuple of float
        The fine-tuning shares (%), in increasing order.
    timing : pandas.DataFrame
        :func:`timing_table`.

    Returns
    -------
    list of Claim
    """
    seconds = timing.set_index("method")["seconds"]
    t_predict = seconds["nn_prediction"]
    t_import = seconds["nn_prediction_with_model_import"]
    t_samples = seconds["nn_table1_samples"]
    t_exact = seconds["exact_vectorised"]
    transfer_by = transfer_tab.set_index(["surface", "finetune_pct"])
    share = transfer_by["share_below_1um_pct"]
    drops = [share[(s, a)] - share[(s, b)] for s in (2, 3) for a, b in itertools.pairwise(shares)]
    return [
        Claim("surface1_share_below_1um",
              "Surface 1, 70/30 split: > 99 % of test samples have absolute error < 1 um "
              "(Zhang et al. 2023, Table 3; converging variant without dropout)",
              m1["share_below_1um_pct"], ">", 99.0),
        Claim("surface1_paper_settings_share_below_1um",
              "Surface 1 with the paper's exact settings (N(0,1), dropout 0.5, SGD lr 1e-5, "
              "2000 epochs): > 99 % of test samples below 1 um",
              runs.set_index("network").loc["paper settings (p = 0.5)", "share_below_1um_pct"],
              ">", 99.0),
        Claim("dropout_helps",
              "Dropout 0.5 gives a lower test MSE than no dropout (Zhang et al. 2023, Fig. 6; "
              "value: test MSE with dropout minus without)",
              runs.set_index("network").loc["variant (p = 0.5)", "test_mse"]
              - runs.set_index("network").loc["variant (p = 0)", "test_mse"], "<", 0.0),
        Claim("surface3_15pct_share_below_1um",
              "Surface 3 after fine-tuning with 15 % of its samples: > 99 % below 1 um "
              "(Zhang et al. 2023, Abstract, Table 7)",
              share[(3, 15.0)], ">", 99.0),
        Claim("more_finetuning_never_worse",
              "More fine-tuning samples never lower the share below 1 um by more than noise "
              "(value: largest drop between consecutive shares, surfaces 2 and 3; noise: 1 "
              "percentage point)",
              max(drops), "<=", 1.0),
        Claim("exact_faster_than_nn",
              "(c) the exact vectorised step error is faster than (a) the network's prediction "
              "with model import (the paper's Table 8 definition); value: time ratio (c)/(a)",
              t_exact / t_import, "<", 1.0),
        Claim("exact_faster_than_nn_forward",
              "(c) is faster than the network's forward pass alone, without model import and "
              "without building its 325 inputs; value: time ratio",
              t_exact / t_predict, "<", 1.0),
        Claim("exact_faster_than_nn_with_inputs",
              "(c) is faster than the network including building its Table 1 inputs from the "
              "surface and the model import; value: time ratio",
              t_exact / (t_samples + t_import), "<", 1.0),
    ]  # fmt: skip
