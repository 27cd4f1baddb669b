"""Denkena, Bergmann & Stoppel (2020): process forces from drive signals, LSTM vs the
model-based reconstruction.

The chapter's pipeline, kept out of the notebook:

1. :func:`design_processes` draws 181 processes over the Table 1 grid (side and groove milling in
   eight feed directions, counter-clockwise circular pockets with a plunge, -y/+z ramps), marks
   a seeded share of the heavy ones semi-stable and splits 160/21 (stratified, seeded).
2. :func:`run_processes` (:mod:`nctwin.chapters.denkena2020_bench`, the simulated test bench)
   interpolates each process, computes its milling forces and runs the drives.
3. :func:`fit_force_model` fits the paper's model (:mod:`nctwin.methods.denkena2020`) on the air
   moves in its four steps.
4. :func:`train_lstms` trains one stacked LSTM per force component with the shared loop;
   :func:`table2` and :func:`summary` score both methods.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..learn.train import TrainConfig, Trained, fit
from ..methods import denkena2020 as fm
from ..physics import drives
from ..report.tables import Claim, side_by_side
from .denkena2020_bench import (
    DIRECTIONS,
    TOOL,
    AirMoves,
    Process,
    Recorded,
    run_air_moves,
    run_processes,
)

__all__ = [
    "DIRECTIONS",
    "AirMoves",
    "Process",
    "Recorded",
    "band_coverage",
    "claims",
    "design_processes",
    "figure_cases",
    "fit_force_model",
    "fitted_parameters",
    "kind_means",
    "plot_cases",
    "run_air_moves",
    "run_processes",
    "summary",
    "table2",
    "train_config",
    "train_lstms",
]


def design_processes(
    grid: dict[str, list[float]],
    *,
    seed: int,
    counts: tuple[int, int, int] = (121, 36, 24),
    test_counts: tuple[int, int, int] = (14, 4, 3),
    semi_stable_share: float = 0.3,
) -> list[Process]:
    """The experiment: processes over the Table 1 grid.

    Parameters
    ----------
    grid : dict
        ``{"ap_mm": [...], "ae_mm": [...], "vf_mm_min": [...], "n_rpm": [...]}`` (Table 1).
    seed : int
    counts : (int, int, int)
        Straight (side or groove; groove where ae = D), pocket and ramp processes
        (default 181 in all).
    test_counts : (int, int, int)
        How many of each go to the test set (default 21); the split is stratified and seeded,
        and at least one semi-stable straight process is in it.
    semi_stable_share : float
        Share of the heavy processes (ap * ae >= 12 mm²) that are semi-stable, in [0, 1].

    Returns
    -------
    list of Process
    """
    if not 0.0 <= semi_stable_share <= 1.0:
        raise ValueError(
            f"semi_stable_share = {semi_stable_share!r} is out of range: allowed [0, 1]"
        )
    for name, c, tc in (("counts", counts, test_counts),):
        if (
            len(c) != 3
            or len(tc) != 3
            or any(t > n - 1 or t < 1 for t, n in zip(tc, c, strict=True))
        ):
            raise ValueError(f"{name} = {c!r}, test_counts = {tc!r}: allowed 1 <= test < count")
    rng = np.random.default_rng([seed, 7])
    seen: set = set()
    rows = []
    for kind, count in zip(("straight", "pocket", "ramp"), counts, strict=True):
        made = 0
        while made < count:
            ae = float(rng.choice(grid["ae_mm"]))
            ap = float(rng.choice(grid["ap_mm"]))
            vf = float(rng.choice(grid["vf_mm_min"]))
            n = float(rng.choice(grid["n_rpm"]))
            if kind == "straight":
                direction = str(rng.choice(list(DIRECTIONS)))
                k = "groove" if ae >= TOOL.diameter_mm else "side"
            elif kind == "pocket":
                direction, k = "ccw", "pocket"
            else:
                direction, k = "-y/+z", "ramp"
            key = (k, direction, ae, ap, vf, n)
            if key in seen:
                continue
            seen.add(key)
            heavy = ap * ae >= 12.0 and k in ("side", "groove")
            semi = bool(heavy and rng.random() < semi_stable_share)
            start = (
                float(rng.uniform(90, 210)),
                float(rng.uniform(90, 210)),
                float(rng.uniform(60, 140)),
            )
            rows.append(
                [
                    k,
                    direction,
                    ae,
                    ap,
                    vf,
                    n,
                    start,
                    semi,
                    float(rng.uniform(45.0, 95.0)) if semi else 0.0,
                    float(rng.uniform(0.5, 0.9)) if semi else 0.0,
                ]
            )
            made += 1
    # stratified test split; one semi-stable straight process is always among the tests
    test = np.zeros(len(rows), dtype=bool)
    offsets = np.cumsum((0, *counts))
    for g, n_test in enumerate(test_counts):
        members = np.arange(offsets[g], offsets[g + 1])
        if g == 0:
            semi = members[[rows[i][7] for i in members]]
            pick = [int(rng.choice(semi))] if len(semi) else []
            rest = np.setdiff1d(members, pick)
            pick += list(rng.choice(rest, n_test - len(pick), replace=False))
        else:
            pick = list(rng.choice(members, n_test, replace=False))
        test[pick] = True
    return [Process(i, *r, test=bool(test[i])) for i, r in enumerate(rows)]


def fit_force_model(air: AirMoves, km_n_a: np.ndarray) -> tuple[fm.ForceModel, pd.DataFrame]:
    """Fit the paper's model in its four steps (Sec. 2.2).

    Parameters
    ----------
    air : AirMoves
    km_n_a : ndarray, shape (3,)
        Motor constants (data sheet).

    Returns
    -------
    ForceModel
    pandas.DataFrame
        The step-3 points (axis, velocity, :math:`\\tilde F_{fr}`) for Fig. 2.
    """
    axes, points, f_m, a_m = [], [], [], []
    for i in range(3):
        motor = km_n_a[i] * air.current_a[:, :, i]
        runs = {}
        for sign, kind in ((1, "line+"), (-1, "line-")):
            b = int(np.flatnonzero(air.kind == kind)[0])
            steady = np.abs(air.vel_mm_s[b, :, i] - air.speed_mm_s[b]) < 0.05 * abs(
                air.speed_mm_s[b]
            )
            runs[sign] = (air.pos_mm[b, steady, i], motor[b, steady])
        k, s_r, grid, table = fm.fit_restoring(*runs[1], *runs[-1])
        partial = fm.AxisModel(
            km_n_a[i], k, s_r, grid, table, fm.StribeckParams(0.0, 0.0, 1.0, 0.0)
        )
        vs, ffr = [], []
        for b in np.flatnonzero(air.kind == "const"):
            v = air.speed_mm_s[b]
            steady = np.abs(air.vel_mm_s[b, :, i] - v) < max(0.1 * abs(v), 0.05)
            if steady.sum() < 5:
                continue
            resid = motor[b, steady] - partial.position_force_n(air.pos_mm[b, steady, i])
            vs.append(v)
            ffr.append(float(resid.mean()))
        friction = fm.fit_stribeck(np.array(vs), np.array(ffr))
        axes.append(fm.AxisModel(km_n_a[i], k, s_r, grid, table, friction))
        points += [
            {"axis": "XYZ"[i], "v_mm_s": v, "friction_n": f} for v, f in zip(vs, ffr, strict=True)
        ]
        acc_runs = np.flatnonzero(air.kind == "accel")
        s = air.pos_mm[acc_runs, :, i].ravel()
        v = air.vel_mm_s[acc_runs, :, i].ravel()
        f_m.append(
            motor[acc_runs].ravel() - axes[i].position_force_n(s) - fm.stribeck_n(v, friction)
        )
        a_m.append(air.acc_mm_s2[acc_runs, :, i].ravel())
    masses = fm.fit_masses(f_m, a_m)
    return fm.ForceModel(tuple(axes), masses), pd.DataFrame(points)


def fitted_parameters(model: fm.ForceModel, machine: drives.FeedDriveMachine) -> pd.DataFrame:
    """The fitted model's parameters beside the simulated drive's, one row per axis.

    Parameters
    ----------
    model : ForceModel
        From :func:`fit_force_model`.
    machine : FeedDriveMachine
        The simulated drives (their true parameters).

    Returns
    -------
    pandas.DataFrame
        Three rows (X, Y, Z): restoring stiffness, rest point, Coulomb and breakaway friction,
        Stribeck velocity, viscous friction and own mass, each beside the drive's ``true_*``.
    """
    return pd.DataFrame([
        {"axis": "XYZ"[i], "k_n_mm": a.restoring_n_mm, "true_k_n_mm": t.restoring_n_mm,
         "s_r_mm": a.rest_point_mm, "true_s_r_mm": t.rest_point_mm,
         "F_C_n": a.friction.coulomb_n, "true_F_C_n": t.coulomb_n,
         "F_br_n": a.friction.breakaway_n, "true_F_S_n": t.breakaway_n,
         "v_s_mm_s": a.friction.stribeck_mm_s, "true_v_s_mm_s": t.stribeck_mm_s,
         "sigma_n_s_mm": a.friction.viscous_n_s_mm, "true_sigma_n_s_mm": t.viscous_n_s_mm,
         "m_kg": model.own_mass_kg[i], "true_m_kg": t.own_mass_kg}
        for i, (a, t) in enumerate(zip(model.axes, machine.axes, strict=True))
    ])  # fmt: skip


def reconstruct(model: fm.ForceModel, inputs: np.ndarray) -> np.ndarray:
    """Model-based forces (R, 3) from one process' recorded inputs (R, 14)."""
    return model.reconstruct(inputs[:, 0:3], inputs[:, 3:6], inputs[:, 6:9], inputs[:, 9:12])


# ----------------------------------------------------------------------------------------------
# The LSTM


def train_config(seed: int = 0, max_epochs: int = 25) -> TrainConfig:
    """The chapter's training settings: windows of 125 samples (0.5 s), batches of 64, Adam at
    5e-3, MSE, early stopping after 5 epochs without improvement.

    Parameters
    ----------
    seed : int
    max_epochs : int

    Returns
    -------
    TrainConfig
    """
    return TrainConfig(seed=seed, max_epochs=max_epochs, patience=5, batch_size=64,
                       window_lines=125, learning_rate=5e-3, loss="mse")  # fmt: skip


def train_lstms(
    recorded: Recorded, targets: np.ndarray, train_config: TrainConfig, *, progress: bool = True
) -> tuple[dict[str, Trained], fm.InputScaling]:
    """One network per force component on the training processes (:func:`nctwin.learn.train.fit`).

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
        Filtered forces (:func:`target_forces`).
    train_config : TrainConfig
    progress : bool

    Returns
    -------
    dict
        ``{"X": Trained, "Y": ..., "Z": ...}``.
    InputScaling
    """
    train = np.array([not p.test for p in recorded.processes])
    scaling = fm.InputScaling.fit(recorded.inputs[train], targets[train])
    xs = [scaling.inputs(x) for x in recorded.inputs[train]]
    nets = {}
    for i, axis in enumerate("XYZ"):
        ys = [scaling.force(y[:, [i]], i) for y in targets[train]]
        nets[axis] = fit(
            fm.MODEL_CONFIG,
            train_config,
            xs,
            ys,
            name=f"denkena2020_{axis.lower()}",
            progress=progress,
        )
    return nets, scaling


# ----------------------------------------------------------------------------------------------
# Scores


def _rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)))


def table2(
    recorded: Recorded,
    targets: np.ndarray,
    lstm: dict[int, np.ndarray],
    model: dict[int, np.ndarray],
    axes: str = "XY",
) -> pd.DataFrame:
    """RMSE of the LSTM and the model per test process and axis, with max |F_meas|.

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
        Filtered measured forces (the paper's reference).
    lstm, model : dict
        Process index -> forces (R, 3).
    axes : str
        Axes reported (paper: X and Y).
    """
    rows = []
    for p in recorded.processes:
        if not p.test:
            continue
        for axis in axes:
            i = "XYZ".index(axis)
            f = targets[p.index, :, i]
            rows.append(
                {
                    "process": {
                        "side": "side milling",
                        "groove": "groove milling",
                        "pocket": "circular pocket",
                        "ramp": "ramp milling",
                    }[p.kind],
                    "feed_direction": p.feed_direction,
                    "ae_mm": p.ae_mm,
                    "ap_mm": p.ap_mm,
                    "vf_mm_min": p.vf_mm_min,
                    "n_rpm": p.n_rpm,
                    "axis": axis,
                    "lstm_rmse_n": _rmse(lstm[p.index][:, i], f),
                    "model_rmse_n": _rmse(model[p.index][:, i], f),
                    "max_abs_force_n": float(np.abs(f).max()),
                    "semi_stable": p.semi_stable,
                }
            )
    return pd.DataFrame(rows)


def summary(table: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Mean LSTM and model RMSE, % lower, median LSTM RMSE; beside the paper's numbers
    (``paper``: the ``denkena2020_summary`` table)."""
    q = paper.set_index("quantity")["value"]
    mean_l, mean_m = table["lstm_rmse_n"].mean(), table["model_rmse_n"].mean()
    return pd.DataFrame(
        [
            {
                "mean_lstm_rmse_n": mean_l,
                "mean_model_rmse_n": mean_m,
                "lstm_lower_pct": 100.0 * (1.0 - mean_l / mean_m),
                "median_lstm_rmse_n": table["lstm_rmse_n"].median(),
                "paper_mean_lstm_rmse_n": q["lstm_rmse_mean"],
                # implied by the two printed numbers (mean LSTM RMSE, % lower)
                "paper_mean_model_rmse_n": q["lstm_rmse_mean"]
                / (1.0 - q["lstm_rmse_lower_than_model"] / 100.0),
                "paper_lstm_lower_pct": q["lstm_rmse_lower_than_model"],
                "paper_median_lstm_rmse_n": q["lstm_rmse_median"],
            }
        ]
    )


def kind_means(table: pd.DataFrame, paper2: pd.DataFrame) -> pd.DataFrame:
    """Our Table 2 rows averaged by kind of process and axis (and the semi-stable ones on their
    own), beside what survives of the paper's Table 2.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`table2`.
    paper2 : pandas.DataFrame
        The paper table ``denkena2020_table2`` (its ``side milling`` rows are the semi-stable
        ones).

    Returns
    -------
    pandas.DataFrame
        :func:`~nctwin.report.tables.side_by_side` on ``process, axis`` of the mean
        ``lstm_rmse_n``, ``model_rmse_n`` and ``max_abs_force_n``.
    """
    ours_kind = (
        table.groupby(["process", "axis"])[["lstm_rmse_n", "model_rmse_n", "max_abs_force_n"]]
        .mean()
        .reset_index()
    )
    semi = table[table["semi_stable"]].groupby("axis")[["lstm_rmse_n", "model_rmse_n"]].mean()
    semi = semi.reset_index().assign(process="semi-stable")
    ours_kind = pd.concat([ours_kind, semi], ignore_index=True)
    paper_rows = paper2.assign(process=paper2["process"].replace({"side milling": "semi-stable"}))
    return side_by_side(ours_kind, paper_rows, on=["process", "axis"],
                        columns=["lstm_rmse_n", "model_rmse_n", "max_abs_force_n"])  # fmt: skip


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
    semi-stable process with the largest LSTM RMSE and a ramp.

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
    return {
        "diagonal cut (Figs. 4-5)": _pick(table, processes, diag.iloc[0]["process"],
                                          feed_direction=diag.iloc[0]["feed_direction"]),
        "circular pocket (Figs. 6-7)": _pick(table, processes, "circular pocket"),
        "semi-stable (Fig. 8)": _pick(
            table, processes,
            table.loc[table[table["semi_stable"]]["lstm_rmse_n"].idxmax(), "process"],
            semi_stable=True,
        ),
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


def claims(table: pd.DataFrame, summary: pd.DataFrame) -> list[Claim]:
    """The chapter's claims (Sec. 3.2, Figs. 6-8).

    The LSTM's mean RMSE is lower than the model's by at least 10 %; on circular pockets the
    model's mean RMSE exceeds the LSTM's; the worst LSTM case is a semi-stable process.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`table2`.
    summary : pandas.DataFrame
        :func:`summary` (column ``lstm_lower_pct``).

    Returns
    -------
    list of Claim
    """
    pockets = table[table["process"] == "circular pocket"]
    worst = table.loc[table["lstm_rmse_n"].idxmax()]
    return [
        Claim("lstm_mean_rmse_lower", "The LSTM's mean RMSE is lower than the model's by at least "
              "10 % (paper: 20.8 %, Sec. 3.2)", summary["lstm_lower_pct"].iloc[0], ">=", 10.0),
        Claim("pocket_model_worse", "On circular pockets the model's mean RMSE exceeds the LSTM's "
              "(N, model minus LSTM; paper: 104.4/149.1 vs 49.8/38.3 N, Figs. 6-7)",
              pockets["model_rmse_n"].mean() - pockets["lstm_rmse_n"].mean(), ">", 0.0),
        Claim("worst_lstm_semi_stable", "The worst LSTM case is a semi-stable process (1 = yes; "
              "paper: Fig. 8, 88.6 N)", float(worst["semi_stable"]), "==", 1.0),
    ]  # fmt: skip
