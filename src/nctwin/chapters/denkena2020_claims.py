"""The Denkena chapter's conditions and claims: the paper's experiment beside ours
(:func:`paper_conditions`, written before any LSTM is trained), how a standing axis moves while
the tool cuts (:func:`standing_axis_motion`), and the paper's claims at its bars, judged on the
ensemble of seeds with each seed's own verdict and a bootstrap interval over the seeds
(:func:`judged_claims`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..report.claims import Claim, bootstrap_interval, claims_by_seed, with_seeds
from ..report.conditions import Condition
from ..report.papers import load_paper_table
from .denkena2020 import Recorded, Windows, _rmse, reversal_scores, summary, table2
from .denkena2020_bench import Process

__all__ = [
    "LEARNED_REQUIRES",
    "MODEL_REQUIRES",
    "MOST_PCT",
    "REDUCTION_BAND_PCT",
    "RMSE_TOL_PCT",
    "SEMI_STABLE_MIN_CASES",
    "SEMI_STABLE_MIN_VELOCITY_RATIO",
    "SEMI_STABLE_REQUIRES",
    "claims",
    "judged_claims",
    "paper_conditions",
    "standing_axis_motion",
]

#: The band the LSTM's reduction of the cutting-window RMSE is judged in (%): around the paper's
#: reduction (``lstm_rmse_lower_than_model``), wide enough for a different machine and test set. Its
#: lower end was the bar before the cutting window was scored; the band was written when the cutting
#: window was introduced, after the whole record's reduction (69 %) was known, in the same change,
#: and is kept as it was: a band chosen now would be chosen after looking.
REDUCTION_BAND_PCT = (10.0, 35.0)
#: Tolerance of the model's RMSE on the paper's rows (ramp, grooves), stated before looking.
RMSE_TOL_PCT = 30.0
#: "In most cases": more than this share of the test rows (process and axis), in %.
MOST_PCT = 50.0
#: Conditions the paper's claims on the LSTM are tested under.
LEARNED_REQUIRES = (
    "sample_rate",
    "variations",
    "train_processes",
    "test_processes",
    "run_duration",
    "ramp_model_rmse_x",
    "ramp_model_rmse_y",
    "test_off_grid",
)
#: Conditions of the claim on the semi-stable cuts, besides :data:`LEARNED_REQUIRES`.
SEMI_STABLE_REQUIRES = ("semi_stable_cases", "semi_stable_y_velocity")
#: "Several" semi-stable side cuts in -x in the test set (Fig. 8 and "other semi-stable
#: processes", Sec. 3.2): at least this many.
SEMI_STABLE_MIN_CASES = 3
#: Their vibration shows in the Y-axis velocity (Sec. 3.2): the standard deviation of the recorded
#: Y velocity over their cuts at least this multiple of that over the stable cuts along +/-x.
SEMI_STABLE_MIN_VELOCITY_RATIO = 2.0
#: Conditions the paper's claim on the model alone is tested under.
MODEL_REQUIRES = ("sample_rate", "groove_model_rmse")
_PAPER = "Denkena et al. 2020"


def _off_grid(values: dict[str, float], grid: dict[str, list[float]]) -> bool:
    """Whether any of a process' parameters is not among the Table 1 values."""
    return any(float(v) not in grid[k] for k, v in values.items())


def _model_rmse(processes, targets, recon, windows, kind: str, axis: str) -> float:
    """Mean model RMSE over the cut of the test processes of ``kind``, on ``axis``."""
    i = "XYZ".index(axis)
    values = [_rmse(recon[p.index][:, i], targets[p.index, :, i], windows.cutting[p.index])
              for p in processes if p.test and p.kind == kind]  # fmt: skip
    return float(np.mean(values)) if values else float("nan")


def paper_conditions(
    processes: list[Process],
    targets: np.ndarray,
    recon: dict[int, np.ndarray],
    windows: Windows,
    grid: dict[str, list[float]],
    record_rate_hz: float,
    duration_s: float,
    velocity_mm_s: np.ndarray,
) -> list[Condition]:
    """The paper's experiment beside ours, its values read from ``data/papers/``.

    * Data: 250 Hz drive signals (Sec. 2.1); 181 variations, 160 train, 21 test (Sec. 2.3); the
      recording of Fig. 4 cuts until late in the run (Sec. 3.1), so ours must last as long.
    * The drive: the model's RMSE on the paper's one surviving Table 2 row (ramp, -y/+z, X
      standing) within :data:`RMSE_TOL_PCT` of the paper's, X and Y, on our test ramps; on the
      grooves (both axes moving; Figs. 4-5) within the same tolerance of the paper's range.
    * The test set: the paper's "comprises new process parameters" (abstract); its surviving
      Table 2 rows lie off the Table 1 grid. Met when at least half of our test processes do.
    * The semi-stable cases (Fig. 8, Sec. 3.2: a side milling in -x whose Y-axis velocity
      oscillates, and "other semi-stable processes"): at least :data:`SEMI_STABLE_MIN_CASES`
      semi-stable side cuts in -x in the test set, and their vibration visible in the recorded
      Y velocity: its standard deviation over their cuts at least
      :data:`SEMI_STABLE_MIN_VELOCITY_RATIO` times that over the stable straight cuts along
      +/-x (training and test), where Y stands still too.

    Parameters
    ----------
    processes : list of Process
    targets : ndarray, shape (P, R, 3)
        Filtered measured forces.
    recon : dict
        Test process index -> the model's forces, shape (R, 3).
    windows : Windows
    grid : dict
        Table 1: parameter -> values.
    record_rate_hz, duration_s : float
        Ours.
    velocity_mm_s : ndarray, shape (P, R, 3)
        Recorded axis velocities of every process.

    Returns
    -------
    list of Condition
    """
    q = load_paper_table("denkena2020_summary").set_index("quantity")["value"].astype(float)
    paper2 = load_paper_table("denkena2020_table2")
    figs = load_paper_table("denkena2020_figures")
    ramp = paper2[paper2["process"] == "ramp milling"].set_index("axis")
    given = paper2.dropna(subset=["ae_mm", "ap_max_mm", "feed_mm_min", "spindle_rpm"])
    paper_off = 100.0 * np.mean([_off_grid({"ae_mm": r.ae_mm, "ap_mm": r.ap_max_mm,
                                            "vf_mm_min": r.feed_mm_min, "n_rpm": r.spindle_rpm},
                                           grid) for r in given.itertuples()])  # fmt: skip
    test = [p for p in processes if p.test]
    ours_off = 100.0 * np.mean([_off_grid({"ae_mm": p.ae_mm, "ap_mm": p.ap_mm,
                                           "vf_mm_min": p.vf_mm_min, "n_rpm": p.n_rpm}, grid)
                                for p in test])  # fmt: skip
    lo, hi = figs["model_rmse_n"].min(), figs["model_rmse_n"].max()
    tol = RMSE_TOL_PCT / 100.0
    groove = np.mean([_model_rmse(processes, targets, recon, windows, "groove", a) for a in "XY"])
    conditions = [
        Condition("sample_rate", f"{_PAPER}, Sec. 2.1: drive signals sampled at", q["sample_rate"],
                  record_rate_hz, "Hz", tol_pct=0.0),
        Condition("variations", f"{_PAPER}, Sec. 2.3: process variations recorded",
                  q["parameter_variations"], len(processes), "processes", tol_pct=0.0),
        Condition("train_processes", f"{_PAPER}, Sec. 2.3: training processes",
                  q["train_datasets"], len(processes) - len(test), "processes", tol_pct=0.0),
        Condition("test_processes", f"{_PAPER}, Sec. 2.3: test processes", q["test_datasets"],
                  len(test), "processes", tol_pct=0.0),
        Condition("run_duration", f"{_PAPER}, Sec. 3.1 (Fig. 4: cut until "
                  f"{q['fig4_cut_end']:g} s): a run lasts at least as long", q["fig4_cut_end"],
                  duration_s, "s", low=q["fig4_cut_end"]),
    ]  # fmt: skip
    for axis in "XY":
        conditions.append(Condition(
            f"ramp_model_rmse_{axis.lower()}", f"{_PAPER}, Table 2 (ramp, -y/+z): the model's "
            f"RMSE in {axis} over the cut on our test ramps (within {RMSE_TOL_PCT:g} %)",
            ramp.loc[axis, "model_rmse_n"],
            _model_rmse(processes, targets, recon, windows, "ramp", axis), "N",
            tol_pct=RMSE_TOL_PCT))  # fmt: skip
    conditions += [
        Condition("groove_model_rmse", f"{_PAPER}, Sec. 3.1 (Figs. 4-5, {lo:g}-{hi:g} N): the "
                  f"model's RMSE over the cut on our test grooves, X and Y (within "
                  f"{RMSE_TOL_PCT:g} % of the paper's range)", float("nan"), groove, "N",
                  low=(1 - tol) * lo, high=(1 + tol) * hi),
        Condition("test_off_grid", f"{_PAPER}, abstract and Table 2: test processes whose "
                  "parameters lie off the Table 1 grid (at least half)", paper_off, ours_off, "%",
                  low=50.0),
    ]  # fmt: skip
    semi = [p.index for p in test if p.semi_stable and p.kind == "side"
            and p.feed_direction == "-x"]  # fmt: skip
    calm = [p.index for p in processes if not p.semi_stable and p.kind in ("side", "groove")
            and p.feed_direction in ("+x", "-x")]  # fmt: skip

    def y_std(indices: list[int]) -> float:
        return float(np.mean([velocity_mm_s[i, windows.cutting[i], 1].std() for i in indices]))

    conditions += [
        Condition("semi_stable_cases", f"{_PAPER}, Sec. 3.2 (Fig. 8 and other semi-stable "
                  "processes): semi-stable side milling in -x among the test processes (at "
                  f"least {SEMI_STABLE_MIN_CASES})", float("nan"), len(semi), "processes",
                  low=SEMI_STABLE_MIN_CASES),
        Condition("semi_stable_y_velocity", f"{_PAPER}, Sec. 3.2 (oscillating Y-axis velocity): "
                  "std of the recorded Y velocity over the cut, semi-stable -x side cuts over "
                  f"stable cuts along +/-x (at least {SEMI_STABLE_MIN_VELOCITY_RATIO:g})",
                  float("nan"), y_std(semi) / y_std(calm) if semi and calm else float("nan"),
                  "1", low=SEMI_STABLE_MIN_VELOCITY_RATIO),
    ]  # fmt: skip
    return conditions


def standing_axis_motion(
    recorded: Recorded,
    windows: Windows,
    test: list[int],
    resolution_mm_s: float,
    axes: str = "XY",
    *,
    model: tuple[np.ndarray, dict[int, np.ndarray], np.ndarray] | None = None,
) -> pd.DataFrame:
    """How a standing axis moves while the tool cuts: for every test process and axis whose
    set point stands still through the cut, the share of cutting samples whose recorded
    velocity is not zero (at least one quantum of ``resolution_mm_s``) and the largest |v|;
    with ``model``, the model's RMSE over the cut beside what eq. 4's switch alone makes of
    that share: at :math:`v = 0` its friction is 0, at one quantum about :math:`\\pm F_{br}`,
    so an RMSE of :math:`F_{br} \\sqrt{\\mathrm{share}}`.

    Parameters
    ----------
    recorded : Recorded
    windows : Windows
    test : list of int
        Test process indices.
    resolution_mm_s : float
        The velocity quantum of the recording.
    axes : str
    model : (ndarray, dict, ndarray), optional
        Filtered measured forces (P, R, 3), the model's forces per test process (R, 3), and the
        fitted breakaway forces :math:`F_{br}` of X, Y, Z (3,).

    Returns
    -------
    pandas.DataFrame
        One row per standing axis: ``process``, ``feed_direction``, ``axis``, ``samples``,
        ``moving_share_pct``, ``max_abs_v_mm_s`` (with ``model``: ``model_rmse_n``,
        ``switch_rmse_n``); and a last row ``all`` pooling the samples.
    """
    rows, moving, total = [], 0, 0
    for p in test:
        process = recorded.processes[p]
        cut = windows.cutting[p]
        for axis in axes:
            i = "XYZ".index(axis)
            if windows.moving[p, cut, i].any():
                continue
            v = np.abs(recorded.inputs[p, cut, 3 + i])
            nonzero = int(np.sum(v >= 0.5 * resolution_mm_s))
            moving, total = moving + nonzero, total + len(v)
            rows.append({"process": process.kind, "feed_direction": process.feed_direction,
                         "axis": axis, "samples": len(v),
                         "moving_share_pct": 100.0 * nonzero / len(v),
                         "max_abs_v_mm_s": float(v.max())})  # fmt: skip
            if model is not None:
                targets, recon, breakaway = model
                rows[-1]["model_rmse_n"] = _rmse(recon[p][:, i], targets[p, :, i], cut)
                rows[-1]["switch_rmse_n"] = float(breakaway[i] * np.sqrt(nonzero / len(v)))
    rows.append(
        {
            "process": "all",
            "feed_direction": "",
            "axis": "",
            "samples": total,
            "moving_share_pct": 100.0 * moving / total if total else float("nan"),
            "max_abs_v_mm_s": max((r["max_abs_v_mm_s"] for r in rows), default=np.nan),
        }
    )
    return pd.DataFrame(rows)


def claims(
    table: pd.DataFrame,
    summary: pd.DataFrame,
    reversal: pd.DataFrame,
    paper_summary: pd.DataFrame,
    band_pct: tuple[float, float] = REDUCTION_BAND_PCT,
) -> list[Claim]:
    """The paper's claims (Sec. 3.1-3.2, Figs. 6-9) and one of ours, all over the cutting window.

    The paper's: the LSTM's mean RMSE lower than the model's by a share within ``band_pct`` (around
    the paper's ``lstm_rmse_lower_than_model``); in most cases (more than :data:`MOST_PCT` of the
    test rows) the LSTM's RMSE below the model's; on circular pockets the model's mean RMSE above
    the LSTM's; the ramp's LSTM RMSE below the average; in the reversal windows the model's RMSE
    above its RMSE on the rest of the cut, and above the LSTM's there; on the semi-stable side
    cuts in -x (Fig. 8) the LSTM's mean RMSE, in newtons, above its mean over the other test
    rows.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`~nctwin.chapters.denkena2020.table2`.
    summary : pandas.DataFrame
        :func:`~nctwin.chapters.denkena2020.summary` (column ``lstm_lower_pct``).
    reversal : pandas.DataFrame
        :func:`~nctwin.chapters.denkena2020.reversal_scores`.
    paper_summary : pandas.DataFrame
        The paper table ``denkena2020_summary``.
    band_pct : (float, float)
        The band of the reduction, stated before looking.

    Returns
    -------
    list of Claim
    """
    q = paper_summary.set_index("quantity")["value"].astype(float)
    pockets = table[table["process"] == "circular pocket"]
    ramps = table[table["process"] == "ramp milling"]
    semi = table["semi_stable"].astype(bool)
    lower = summary["lstm_lower_pct"].iloc[0]
    better = 100.0 * np.mean(table["lstm_cutting_rmse_n"] < table["model_cutting_rmse_n"])
    rev = reversal.set_index("window")
    lo, hi = band_pct
    paper = f"paper: {q['lstm_rmse_lower_than_model']:g} %, {_PAPER}, Sec. 3.2"
    learned = {"requires": LEARNED_REQUIRES}
    return [
        Claim("lstm_lower_at_least", f"Over the cut, the LSTM's mean RMSE is lower than the "
              f"model's by at least {lo:g} % ({paper})", lower, ">=", lo, **learned),
        Claim("lstm_lower_at_most", f"... and by at most {hi:g} % ({paper})", lower, "<=", hi,
              **learned),
        Claim("lstm_better_most", f"In most cases the LSTM's RMSE over the cut is below the "
              f"model's: % of test rows, process and axis ('most' read as over {MOST_PCT:g} %; "
              f"{_PAPER}, Sec. 3.2)", better, ">", MOST_PCT, **learned),
        Claim("pocket_model_worse", "On circular pockets the model's mean RMSE over the cut "
              f"exceeds the LSTM's (N, model minus LSTM; {_PAPER}, Figs. 6-7)",
              pockets["model_cutting_rmse_n"].mean() - pockets["lstm_cutting_rmse_n"].mean(),
              ">", 0.0, **learned),
        Claim("ramp_below_average", "On the ramps the LSTM's mean RMSE over the cut is lower "
              f"than its average over the test rows (ratio; paper: {q['ramp_lstm_rmse']:g}, "
              f"{_PAPER}, Sec. 3.2, Fig. 9)", ramps["lstm_cutting_rmse_n"].mean()
              / table["lstm_cutting_rmse_n"].mean(), "<", 1.0, **learned),
        Claim("reversal_model_fails", "The model fails where the feed direction reverses: its "
              "RMSE in the reversal windows over its RMSE on the rest of the cut "
              f"({_PAPER}, Sec. 3.1-3.2)", rev.loc["reversal windows", "model_rmse_n"]
              / rev.loc["rest of the cut", "model_rmse_n"], ">", 1.0, requires=MODEL_REQUIRES),
        Claim("reversal_model_worse", "In the reversal windows the model's RMSE exceeds the "
              f"LSTM's (N, model minus LSTM; {_PAPER}, abstract, Sec. 3.2)",
              rev.loc["reversal windows", "model_rmse_n"]
              - rev.loc["reversal windows", "lstm_rmse_n"],
              ">", 0.0, **learned),
        Claim("semi_stable_lstm_above", "On the semi-stable side cuts in -x the LSTM's mean "
              "RMSE over the cut exceeds its mean over the other test rows (N, semi-stable minus "
              f"the others; paper: such outliers lever the mean to {q['lstm_rmse_mean']:g} N "
              f"against a median of {q['lstm_rmse_median']:g} N, {_PAPER}, Sec. 3.2, Fig. 8)",
              table.loc[semi, "lstm_cutting_rmse_n"].mean()
              - table.loc[~semi, "lstm_cutting_rmse_n"].mean(), ">", 0.0,
              requires=LEARNED_REQUIRES + SEMI_STABLE_REQUIRES),
    ]  # fmt: skip


def judged_claims(
    recorded: Recorded,
    targets: np.ndarray,
    per_seed: dict[int, dict[int, np.ndarray]],
    recon: dict[int, np.ndarray],
    windows: Windows,
    paper_summary: pd.DataFrame,
) -> tuple[list[Claim], pd.DataFrame]:
    """The claims on the ensemble (the mean of the seeds' predictions), each claim on the LSTM
    with how many single seeds pass it and a 90 % bootstrap interval over the seeds
    (:func:`~nctwin.report.claims.bootstrap_interval`), and every claim for each seed alone.

    The ensemble of a resample depends only on which seeds it draws, so each distinct draw is
    evaluated once.

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
    per_seed : dict
        Seed -> (test process index -> that seed's LSTM forces, shape (R, 3)).
    recon : dict
        Test process index -> the model's forces, shape (R, 3).
    windows : Windows
    paper_summary : pandas.DataFrame

    Returns
    -------
    list of Claim
        The ensemble's claims, those on the LSTM :func:`~nctwin.report.claims.with_seeds`.
    pandas.DataFrame
        :func:`~nctwin.report.claims.claims_by_seed`.
    """
    seeds, test = list(per_seed), list(recon)
    cache: dict[tuple[int, ...], list[Claim]] = {}

    def evaluate(members: tuple[int, ...]) -> list[Claim]:
        if members not in cache:
            lstm = {i: np.mean([per_seed[seeds[k]][i] for k in members], axis=0) for i in test}
            table = table2(recorded, targets, lstm, recon, windows)
            cache[members] = claims(table, summary(table, paper_summary),
                                    reversal_scores(targets, lstm, recon, windows, test),
                                    paper_summary)  # fmt: skip
        return cache[members]

    ensemble = evaluate(tuple(range(len(seeds))))
    alone = {s: evaluate((k,)) for k, s in enumerate(seeds)}
    rows = np.arange(len(seeds))[:, None]
    out = []
    for j, c in enumerate(ensemble):
        if c.id == "reversal_model_fails":  # the model alone: no seeds
            out.append(c)
            continue
        interval = bootstrap_interval(
            rows, lambda d, j=j: evaluate(tuple(sorted(int(k) for k in d[:, 0])))[j].value
        )
        out.append(with_seeds(c, [alone[s][j].value for s in seeds], interval))
    return out, claims_by_seed(ensemble, alone)
