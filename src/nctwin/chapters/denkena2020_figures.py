"""The Denkena chapter's figures: the test processes of the Figs. 4-9 analogues, their forces
with the MC-dropout band, and the band's coverage (re-exported by
:mod:`nctwin.chapters.denkena2020`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .denkena2020_bench import Process

__all__ = ["band_coverage", "figure_cases", "plot_cases"]


def _pick(table: pd.DataFrame, processes: list[Process], kind: str, **kw) -> int:
    """Index of the test process of the first row of ``table`` of ``kind`` (and the column
    values ``kw``)."""
    rows = table[(table["process"] == kind)]
    for k, v in kw.items():
        rows = rows[rows[k] == v]
    key = rows.iloc[0]
    return next(p.index for p in processes if p.test and p.vf_mm_min == key.vf_mm_min
                and p.n_rpm == key.n_rpm and p.ae_mm == key.ae_mm and p.ap_mm == key.ap_mm
                and p.feed_direction == key.feed_direction)  # fmt: skip


def figure_cases(table: pd.DataFrame, processes: list[Process]) -> dict[str, int]:
    """The test processes of the Figs. 4-9 analogues: a diagonal cut, a circular pocket, the
    semi-stable process with the largest LSTM RMSE (N, over the cut) and a ramp.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`table2`.
    processes : list of Process

    Returns
    -------
    dict
        Figure title -> process index.
    """
    diag = table[table["feed_direction"].str.len() == 4]
    semi = table[table["semi_stable"]]
    worst = semi.loc[semi["lstm_cutting_rmse_n"].idxmax()]
    return {
        "diagonal cut (Figs. 4-5)": _pick(table, processes, diag.iloc[0]["process"],
                                          feed_direction=diag.iloc[0]["feed_direction"]),
        "circular pocket (Figs. 6-7)": _pick(table, processes, "circular pocket"),
        "semi-stable (Fig. 8)": _pick(table, processes, worst["process"], semi_stable=True,
                                      ae_mm=worst["ae_mm"], ap_mm=worst["ap_mm"],
                                      vf_mm_min=worst["vf_mm_min"]),
        "ramp -y/+z (Fig. 9)": _pick(table, processes, "ramp milling"),
    }  # fmt: skip


def plot_cases(
    cases: dict[str, int],
    t_s: np.ndarray,
    targets: np.ndarray,
    recon: dict[int, np.ndarray],
    lstm: dict[int, np.ndarray],
    bands: dict[int, np.ndarray],
):
    """Measured (filtered) force, the model and the LSTM with its MC-dropout band (mean
    +- 1.96 standard deviations), X and Y, one row per case; only draws.

    Parameters
    ----------
    cases : dict
        Title -> process index (:func:`figure_cases`).
    t_s : ndarray, shape (R,)
        Sample times.
    targets : ndarray, shape (P, R, 3)
        Filtered measured forces.
    recon, lstm : dict
        Process index -> forces (R, 3) of the model and of the LSTM.
    bands : dict
        Process index -> MC-dropout forces (samples, R, 2) of X and Y.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(cases), 2, figsize=(11, 2.6 * len(cases)),
                             constrained_layout=True, sharex=True)  # fmt: skip
    for row, (title, i) in zip(axes, cases.items(), strict=True):
        mean, std = bands[i].mean(axis=0), bands[i].std(axis=0)
        for ax, name in zip(row, "XY", strict=True):
            j = "XYZ".index(name)
            t = t_s
            ax.plot(t, targets[i, :, j], "k", lw=0.8, label="measured, 120 Hz")
            ax.plot(t, recon[i][:, j], lw=0.7, label="model")
            ax.plot(t, lstm[i][:, j], lw=0.8, label="LSTM")
            ax.fill_between(t, mean[:, j] - 1.96 * std[:, j], mean[:, j] + 1.96 * std[:, j],
                            alpha=0.3, color="C1", lw=0, label="MC dropout 95 %")  # fmt: skip
            ax.set_title(f"{title}: F{name.lower()}", fontsize=9)
            ax.set_ylabel("force (N)")
    axes[0, 0].legend(frameon=False, fontsize=7, ncol=2)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    return fig


def band_coverage(
    targets: np.ndarray, bands: dict[int, np.ndarray], test: list[int]
) -> pd.DataFrame:
    """Empirical coverage of the MC-dropout band (mean +- 1.96 standard deviations) on the test
    processes, X and Y.

    Parameters
    ----------
    targets : ndarray, shape (P, R, 3)
        Filtered measured forces.
    bands : dict
        Process index -> MC-dropout forces (samples, R, 2) of X and Y.
    test : list of int
        The test processes.

    Returns
    -------
    pandas.DataFrame
        One row per axis: ``axis``, ``coverage_pct`` (share of test samples inside the band) and
        ``mean_band_halfwidth_n``.
    """
    return pd.DataFrame([
        {"axis": name,
         "coverage_pct": 100.0 * np.mean(np.concatenate([
             np.abs(targets[i, :, j] - bands[i][..., j].mean(axis=0))
             <= 1.96 * bands[i][..., j].std(axis=0) for i in test])),
         "mean_band_halfwidth_n": float(np.mean([1.96 * bands[i][..., j].std(axis=0).mean()
                                                 for i in test]))}
        for j, name in enumerate("XY")
    ])  # fmt: skip
