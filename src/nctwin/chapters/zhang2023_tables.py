"""Tables of the Zhang chapter that only count and compare: the paper's Table 2 in both
readings of its dropout probability, error histograms with the paper's bins, and the transfer
metrics (re-exported by :mod:`nctwin.chapters.zhang2023`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["dropout_conventions", "error_histogram", "transfer_metrics"]


def dropout_conventions(sweep: pd.DataFrame, paper_t2: pd.DataFrame) -> pd.DataFrame:
    """Table 2 in both readings of the paper's p.

    Eq. 13 makes p the probability of *keeping* a unit; PyTorch's ``Dropout(p)`` drops with
    probability p. For each of the paper's p, the run that drops 1 - p (the paper's convention)
    and the run that drops p (PyTorch's), beside the paper's MSE; the two coincide at p = 0.5.

    Parameters
    ----------
    sweep : pandas.DataFrame
        :func:`dropout_sweep` over drop probabilities that include p and 1 - p of every paper
        row (``dropout_p`` = drop probability).
    paper_t2 : pandas.DataFrame
        The paper table ``zhang2023_table2`` (``dropout_p``, ``mse``).

    Returns
    -------
    pandas.DataFrame
        ``paper_p``, ``paper_mse``; ``keep_*`` (drop 1 - p) and ``drop_*`` (drop p) columns of
        ``final_train_mse``, ``test_mse`` and ``share_below_1um_pct``.
    """
    by = sweep.assign(key=sweep["dropout_p"].round(6)).set_index("key")
    cols = ("final_train_mse", "test_mse", "share_below_1um_pct")
    rows = []
    for r in paper_t2.itertuples():
        row = {"paper_p": r.dropout_p, "paper_mse": r.mse}
        for prefix, drop in (("keep", 1.0 - r.dropout_p), ("drop", r.dropout_p)):
            row[f"{prefix}_drop_prob"] = round(drop, 6)
            for c in cols:
                row[f"{prefix}_{c}"] = by.loc[round(drop, 6), c]
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
    predicted_um: np.ndarray,
    exact_um: np.ndarray,
    paper: pd.DataFrame,
    *,
    min_exact_um: float = 0.0,
) -> pd.DataFrame:
    """Absolute- and relative-error histograms with the paper's bins, beside the paper's.

    Parameters
    ----------
    predicted_um, exact_um : ndarray, shape (n,)
    paper : DataFrame
        A table like ``zhang2023_table3`` (``metric`` ``abs_err`` in um, ``rel_err`` in %,
        ``bin_lo``/``bin_hi``, ``count``, ``ratio_pct``). Bins are [lo, hi); where the paper's
        last absolute bin is closed, one more row counts the errors beyond it.
    min_exact_um : float
        Relative errors count only the samples whose exact step error is at least this (the
        paper's smallest step error: its samples all are); absolute errors count all.

    Returns
    -------
    DataFrame
        ``metric``, ``bin_label``, ``bin_lo``, ``bin_hi``, ``count``, ``ratio_pct`` (of
        ``samples``), ``samples`` (the samples counted), ``paper_count``, ``paper_ratio_pct``.
    """
    abs_err = np.abs(predicted_um - exact_um)
    kept = exact_um >= min_exact_um
    with np.errstate(divide="ignore", invalid="ignore"):
        rel_err = np.where(exact_um > 0, abs_err / exact_um * 100.0, np.inf)[kept]
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
                    "samples": len(err),
                    "paper_count": ref["count"].get(label, np.nan),
                    "paper_ratio_pct": ref["ratio_pct"].get(label, np.nan),
                }
            )
    return pd.DataFrame(rows)


def transfer_metrics(predicted_um: np.ndarray, exact_um: np.ndarray) -> dict[str, float]:
    """Maximum and mean absolute error (um) and the shares below 1 um and 0.5 um (%) of a test
    set."""
    err = np.abs(predicted_um - exact_um)
    return {
        "max_abs_err_um": float(err.max()),
        "share_below_1um_pct": 100.0 * float(np.mean(err < 1.0)),
        "share_below_0p5um_pct": 100.0 * float(np.mean(err < 0.5)),
        "mean_abs_err_um": float(err.mean()),
    }
