"""Denkena, Bergmann & Stoppel (2020): process forces from drive signals, LSTM vs the
model-based reconstruction.

The chapter's pipeline, kept out of the notebook:

1. :func:`design_processes` draws 160 training processes over the Table 1 grid and 21 test
   processes off it, the paper's ramp row among them (side and groove milling in eight feed
   directions, counter-clockwise circular pockets with a plunge, -y/+z ramps), and marks a
   seeded share of the straight training cuts and four side cuts in -x of the test set
   semi-stable (the tool vibrates normal to the feed near the tool-slide mode). The bench's
   compliance was fixed before, from the model's errors alone
   (:mod:`nctwin.chapters.denkena2020_calibration`).
2. :func:`run_processes` (:mod:`nctwin.chapters.denkena2020_bench`, the simulated test bench)
   interpolates each process, computes its milling forces and runs the drives.
3. :func:`fit_force_model` fits the paper's model (:mod:`nctwin.methods.denkena2020`) on the air
   moves in its four steps.
4. :func:`train_lstms` trains one stacked LSTM per force component and seed with the shared loop,
   in parallel; :func:`table2` and :func:`summary` score both methods, the LSTM by the mean of
   the seeds' predictions, and :func:`seed_table` and :func:`claims_by_seed` give the spread;
   the conditions and claims are in :mod:`nctwin.chapters.denkena2020_claims`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from ..learn.seeds import fit_seeds
from ..learn.train import TrainConfig, Trained
from ..methods import denkena2020 as fm
from ..physics import drives
from ..report.claims import claims_by_seed
from ..report.papers import side_by_side
from .denkena2020_bench import (
    DIRECTIONS,
    TOOL,
    AirMoves,
    Process,
    Recorded,
    Windows,
    process_windows,
    run_air_moves,
    run_processes,
)
from .denkena2020_figures import band_coverage, figure_cases, plot_cases

__all__ = [
    "DIRECTIONS",
    "AirMoves",
    "Process",
    "Recorded",
    "Windows",
    "band_coverage",
    "chatter_band_scores",
    "claims_by_seed",
    "design_processes",
    "figure_cases",
    "fit_force_model",
    "fitted_parameters",
    "kind_means",
    "plot_cases",
    "process_windows",
    "reversal_scores",
    "run_air_moves",
    "run_processes",
    "seed_table",
    "summary",
    "table2",
    "train_config",
    "train_lstms",
]


def _off_grid_value(rng: np.random.Generator, values: list[float], step: float) -> float:
    """A value within the range of ``values`` on a ``step`` raster, not among them."""
    while True:
        v = float(np.round(rng.uniform(min(values), max(values)) / step) * step)
        if v not in values:
            return v


def _start(rng: np.random.Generator, direction: str, vf_mm_min: float, duration_s: float):
    """Start of a straight cut or ramp: its path centred on (150, 150) mm within 20 mm, so
    every run stays inside the travel of the air moves; a pocket's anywhere in 90-210 mm."""
    z = float(rng.uniform(60, 140))
    if direction == "ccw":
        return (float(rng.uniform(90, 210)), float(rng.uniform(90, 210)), z)
    u = np.array(DIRECTIONS.get(direction, (0.0, -1.0)))
    half = 0.5 * vf_mm_min / 60.0 * (duration_s - 0.6)
    x, y = 150.0 - half * u + rng.uniform(-20, 20, 2)
    return (float(x), float(y), z)


def _draw(rng: np.random.Generator, grid: dict, kind: str, off_grid: bool, groove_share: float,
          side_minus_x: bool = False):  # fmt: skip
    """Kind, feed direction, ae, ap, f, n of a new process: on the grid or off it
    (``side_minus_x``: a side cut in -x, ae below D, off the grid)."""
    if off_grid:
        groove = kind == "straight" and not side_minus_x and rng.random() < groove_share
        ae = TOOL.diameter_mm if groove else _off_grid_value(rng, grid["ae_mm"], 0.5)
        while side_minus_x and ae >= TOOL.diameter_mm:
            ae = _off_grid_value(rng, grid["ae_mm"], 0.5)
        ap = _off_grid_value(rng, grid["ap_mm"], 0.5)
        vf = _off_grid_value(rng, grid["vf_mm_min"], 50.0)
        n = _off_grid_value(rng, grid["n_rpm"], 100.0)
    else:
        ae, ap, vf, n = (
            float(rng.choice(grid[c])) for c in ("ae_mm", "ap_mm", "vf_mm_min", "n_rpm")
        )
    if kind == "straight":
        direction = "-x" if side_minus_x else str(rng.choice(list(DIRECTIONS)))
        return ("groove" if ae >= TOOL.diameter_mm else "side", direction, ae, ap, vf, n)
    return (
        ("pocket", "ccw", ae, ap, vf, n) if kind == "pocket" else ("ramp", "-y/+z", ae, ap, vf, n)
    )


#: Frequency of the tool-slide mode of the bench (Hz), :math:`\sqrt{k_c / m_c} / 2\pi`.
MODE_HZ = float(np.sqrt(drives.COMPLIANCE_STIFFNESS_N_MM * 1e3 / drives.COMPLIANCE_MASS_KG)
                / (2.0 * np.pi))  # fmt: skip
#: A semi-stable cut vibrates at this multiple of :data:`MODE_HZ` (regenerative chatter sets in
#: just above the natural frequency of the mode that limits stability).
CHATTER_RATIO = (1.0, 1.3)
#: Amplitude of that vibration normal to the feed (mm), drawn in this range.
CHATTER_AMPLITUDE_MM = (0.03, 0.06)


def design_processes(
    grid: dict[str, list[float]],
    *,
    seed: int,
    duration_s: float,
    paper_test: Sequence[dict] = (),
    counts: tuple[int, int, int] = (121, 36, 24),
    test_counts: tuple[int, int, int] = (14, 4, 3),
    semi_stable_share: float = 0.1,
    semi_stable_test: int = 4,
) -> list[Process]:
    """The experiment: training processes on the Table 1 grid, test processes off it.

    Parameters
    ----------
    grid : dict
        ``{"ap_mm": [...], "ae_mm": [...], "vf_mm_min": [...], "n_rpm": [...]}`` (Table 1).
    seed : int
    duration_s : float
        Length of every run (the paths are placed so that they stay in the travel).
    paper_test : sequence of dict
        Test processes the paper gives (``kind``, ``feed_direction``, ``ae_mm``, ``ap_mm``,
        ``vf_mm_min``, ``n_rpm``); they take places of their kind in the test set.
    counts : (int, int, int)
        Straight (side or groove; groove where ae = D), pocket and ramp processes
        (default 181 in all).
    test_counts : (int, int, int)
        How many of each are test processes (default 21): the paper's, then new ones whose every
        parameter is drawn within the Table 1 range off its values (ap and ae on a 0.5 mm raster,
        f on 50 mm/min, n on 100 1/min; a straight test cut is a groove with the share of
        grooves on the grid).
    semi_stable_share : float
        Probability that a training side or groove cut is semi-stable, in [0, 1], drawn
        independently of its parameters (so semi-stability is not confounded with the size of
        the force).
    semi_stable_test : int
        How many of the straight test processes are semi-stable side cuts in -x (the paper's
        Fig. 8), off the grid like the others; the rest of them are stable. Semi-stable: the
        tool vibrates normal to the feed at :data:`CHATTER_RATIO` times the tool-slide mode,
        with an amplitude in :data:`CHATTER_AMPLITUDE_MM`
        (:func:`~nctwin.chapters.denkena2020_bench.chatter_regeneration_mm`).

    Returns
    -------
    list of Process
        The training processes first, then the test processes.
    """
    if not 0.0 <= semi_stable_share <= 1.0:
        raise ValueError(
            f"semi_stable_share = {semi_stable_share!r} is out of range: allowed [0, 1]"
        )
    if (
        len(counts) != 3
        or len(test_counts) != 3
        or any(t > n - 1 or t < 1 for t, n in zip(test_counts, counts, strict=True))
    ):
        raise ValueError(
            f"counts = {counts!r}, test_counts = {test_counts!r}: allowed 1 <= test < count"
        )
    if not 0 <= semi_stable_test <= test_counts[0]:
        raise ValueError(f"semi_stable_test = {semi_stable_test!r} is out of range: allowed 0 to "
                         f"{test_counts[0]}")  # fmt: skip
    kinds = ("straight", "pocket", "ramp")
    group = {"side": "straight", "groove": "straight", "pocket": "pocket", "ramp": "ramp"}
    given = {k: [q for q in paper_test if group[q["kind"]] == k] for k in kinds}
    if any(len(given[k]) > t for k, t in zip(kinds, test_counts, strict=True)):
        raise ValueError(f"paper_test has more processes of a kind than test_counts = "
                         f"{test_counts!r}")  # fmt: skip
    rng = np.random.default_rng([seed, 7])
    semi_rng = np.random.default_rng([seed, 8])  # the semi-stable test cuts: their own stream
    groove_share = grid["ae_mm"].count(TOOL.diameter_mm) / len(grid["ae_mm"])
    seen: set = set()
    rows = []
    for test in (False, True):
        for kind, count, n_test in zip(kinds, counts, test_counts, strict=True):
            made = 0
            todo = list(given[kind]) if test else []
            n_semi = semi_stable_test if test and kind == "straight" else 0
            while made < (n_test if test else count - n_test):
                semi_test = test and made >= n_test - n_semi
                r = semi_rng if semi_test else rng
                if todo:
                    q = todo.pop(0)
                    k, direction = q["kind"], q["feed_direction"]
                    ae, ap, vf, n = (float(q[c]) for c in ("ae_mm", "ap_mm", "vf_mm_min", "n_rpm"))
                else:
                    k, direction, ae, ap, vf, n = _draw(r, grid, kind, test, groove_share,
                                                        side_minus_x=semi_test)  # fmt: skip
                key = (k, direction, ae, ap, vf, n)
                if key in seen:
                    continue
                seen.add(key)
                if test:
                    semi = semi_test
                else:
                    semi = bool(k in ("side", "groove") and rng.random() < semi_stable_share)
                rows.append([k, direction, ae, ap, vf, n, _start(r, direction, vf, duration_s),
                             semi, MODE_HZ * float(r.uniform(*CHATTER_RATIO)) if semi else 0.0,
                             float(r.uniform(*CHATTER_AMPLITUDE_MM)) if semi else 0.0,
                             test])  # fmt: skip
                made += 1
    return [Process(i, *r[:-1], test=r[-1]) for i, r in enumerate(rows)]


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


def train_config(seed: int = 0, max_epochs: int = 200) -> TrainConfig:
    """The chapter's training settings (the paper gives none but the loss): windows of 125
    samples (0.5 s), batches of 64, Adam at 5e-3, MSE, early stopping after 5 epochs without
    improvement; ``max_epochs`` is a safety cap only (the notebook reports the best epochs).

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
    recorded: Recorded,
    targets: np.ndarray,
    seeds: Sequence[int],
    *,
    max_epochs: int = 200,
    axes: str = "XY",
    n_jobs: int = 2,
) -> tuple[dict[int, dict[str, Trained]], fm.InputScaling]:
    """One network per force component and seed on the training processes, all of them in
    parallel (:func:`nctwin.learn.seeds.fit_seeds`: one task per network and seed through
    :func:`nctwin.runner.run_tasks`, one torch thread each, so the same bits as one after the
    other; each cached by :func:`nctwin.learn.train.fit` as ``denkena2020_<axis>_seed<s>``).

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
        Filtered forces (:func:`target_forces`).
    seeds : sequence of int
        Training seeds (initial weights, validation split, window offsets, batch order,
        dropout masks); the data and the scaling are the same for every seed.
    max_epochs : int
        Safety cap of :func:`train_config`.
    axes : str
        Components trained (the paper scores X and Y).
    n_jobs : int
        Parallel trainings.

    Returns
    -------
    dict
        ``{seed: {"X": Trained, "Y": ...}}``, in the order of ``seeds``.
    InputScaling
    """
    train = np.array([not p.test for p in recorded.processes])
    scaling = fm.InputScaling.fit(recorded.inputs[train], targets[train])
    xs = [scaling.inputs(x) for x in recorded.inputs[train]]
    jobs = {}
    for axis in axes:
        i = "XYZ".index(axis)
        ys = [scaling.force(y[:, [i]], i) for y in targets[train]]
        jobs[axis] = (fm.MODEL_CONFIG, train_config(seeds[0], max_epochs), xs, ys)
    out = fit_seeds({f"denkena2020_{a.lower()}": job for a, job in jobs.items()}, seeds,
                    n_jobs=n_jobs)  # fmt: skip
    nets = {s: {a: out[f"denkena2020_{a.lower()}"][k] for a in axes} for k, s in enumerate(seeds)}
    return nets, scaling


# ----------------------------------------------------------------------------------------------
# Scores


def _rmse(a: np.ndarray, b: np.ndarray, where: np.ndarray | None = None) -> float:
    """RMSE of ``a - b`` over the samples ``where`` (all if None); NaN if there are none."""
    if where is not None:
        a, b = a[where], b[where]
    return float(np.sqrt(np.mean((a - b) ** 2))) if len(a) else float("nan")


_PROCESS_NAMES = {"side": "side milling", "groove": "groove milling",
                  "pocket": "circular pocket", "ramp": "ramp milling"}  # fmt: skip


def table2(
    recorded: Recorded,
    targets: np.ndarray,
    lstm: dict[int, np.ndarray],
    model: dict[int, np.ndarray],
    windows: Windows,
    axes: str = "XY",
) -> pd.DataFrame:
    """RMSE of the LSTM and the model per test process and axis, in four windows.

    The paper scores the process, so the headline window is the cut (``*_cutting_*``: the tool
    in the material); beside it the whole record (``lstm_rmse_n``, ``model_rmse_n``, air moves
    and the final stop included), the samples where the axis moves (``*_moving_*``) and those
    where it stands still (``*_standstill_*``; NaN where there are none). ``max_abs_force_n`` is
    max |F| over the cut, and ``*_cutting_nrmse`` the cutting RMSE divided by it.

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
        Filtered measured forces (the paper's reference).
    lstm, model : dict
        Process index -> forces (R, 3).
    windows : Windows
        :func:`process_windows` of ``recorded.processes``.
    axes : str
        Axes reported (paper: X and Y).

    Returns
    -------
    pandas.DataFrame
        One row per test process and axis.
    """
    rows = []
    for p in recorded.processes:
        if not p.test:
            continue
        cut = windows.cutting[p.index]
        for axis in axes:
            i = "XYZ".index(axis)
            f = targets[p.index, :, i]
            moving = windows.moving[p.index, :, i]
            peak = float(np.abs(f[cut]).max())
            row = {"process": _PROCESS_NAMES[p.kind], "feed_direction": p.feed_direction,
                   "ae_mm": p.ae_mm, "ap_mm": p.ap_mm, "vf_mm_min": p.vf_mm_min,
                   "n_rpm": p.n_rpm, "axis": axis}  # fmt: skip
            for name, pred in (("lstm", lstm[p.index][:, i]), ("model", model[p.index][:, i])):
                row[f"{name}_rmse_n"] = _rmse(pred, f)
                row[f"{name}_cutting_rmse_n"] = _rmse(pred, f, cut)
                row[f"{name}_moving_rmse_n"] = _rmse(pred, f, moving)
                row[f"{name}_standstill_rmse_n"] = _rmse(pred, f, ~moving)
            row["max_abs_force_n"] = peak
            row["lstm_cutting_nrmse"] = row["lstm_cutting_rmse_n"] / peak
            row["model_cutting_nrmse"] = row["model_cutting_rmse_n"] / peak
            row["semi_stable"] = p.semi_stable
            rows.append(row)
    return pd.DataFrame(rows)


def reversal_scores(
    targets: np.ndarray,
    lstm: dict[int, np.ndarray],
    model: dict[int, np.ndarray],
    windows: Windows,
    test: list[int],
    axes: str = "XY",
) -> pd.DataFrame:
    """RMSE of both methods in the reversal windows of the test processes and in the rest of
    their cuts, pooled over the test processes with a reversal and over ``axes``.

    Returns
    -------
    pandas.DataFrame
        Rows ``reversal windows`` and ``rest of the cut``: ``samples``, ``lstm_rmse_n``,
        ``model_rmse_n``.
    """
    err = {"lstm": [], "model": [], "rev": [], "cut": []}
    for p in test:
        for axis in axes:
            i = "XYZ".index(axis)
            if not windows.reversal[p, :, i].any():
                continue
            f = targets[p, :, i]
            err["lstm"].append(lstm[p][:, i] - f)
            err["model"].append(model[p][:, i] - f)
            err["rev"].append(windows.reversal[p, :, i])
            err["cut"].append(windows.cutting[p])
    e = {k: np.concatenate(v) for k, v in err.items()}
    rows = []
    for label, where in (("reversal windows", e["rev"]), ("rest of the cut", e["cut"] & ~e["rev"])):
        rows.append({"window": label, "samples": int(where.sum()),
                     "lstm_rmse_n": _rmse(e["lstm"], 0.0 * e["lstm"], where),
                     "model_rmse_n": _rmse(e["model"], 0.0 * e["model"], where)})  # fmt: skip
    return pd.DataFrame(rows)


def chatter_band_scores(
    recorded: Recorded,
    targets: np.ndarray,
    lstm: dict[int, np.ndarray],
    model: dict[int, np.ndarray],
    windows: Windows,
    *,
    band_hz: float = 3.0,
    axes: str = "XY",
) -> pd.DataFrame:
    """Where the error on the semi-stable test cuts lies: each method's RMSE over the cut and
    the part of it within ``band_hz`` of the cut's vibration frequency (the error's spectrum over
    the cut, by Parseval: ``band`` squared plus ``rest`` squared is the RMSE squared).

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
    lstm, model : dict
        Process index -> forces (R, 3).
    windows : Windows
    band_hz : float
        Half width of the band around ``chatter_hz``, > 0.
    axes : str

    Returns
    -------
    pandas.DataFrame
        One row per semi-stable test process and axis: ``process`` (index), ``axis``,
        ``chatter_hz``, then per method ``*_rmse_n``, ``*_band_rmse_n`` and ``*_rest_rmse_n``.
    """
    if not band_hz > 0.0:
        raise ValueError(f"band_hz = {band_hz!r} is out of range: allowed > 0")
    rate_hz = 1.0 / float(recorded.t_s[1] - recorded.t_s[0])
    rows = []
    for p in recorded.processes:
        if not (p.test and p.semi_stable):
            continue
        cut = windows.cutting[p.index]
        freqs = np.fft.rfftfreq(int(cut.sum()), 1.0 / rate_hz)
        near = np.abs(freqs - p.chatter_hz) <= band_hz
        for axis in axes:
            i = "XYZ".index(axis)
            row = {"process": p.index, "axis": axis, "chatter_hz": p.chatter_hz}
            for name, pred in (("lstm", lstm[p.index][:, i]), ("model", model[p.index][:, i])):
                err = pred[cut] - targets[p.index, cut, i]
                band = np.fft.irfft(np.fft.rfft(err) * near, n=len(err))
                row[f"{name}_rmse_n"] = _rmse(err, 0.0 * err)
                row[f"{name}_band_rmse_n"] = _rmse(band, 0.0 * band)
                row[f"{name}_rest_rmse_n"] = _rmse(err - band, 0.0 * err)
            rows.append(row)
    return pd.DataFrame(rows)


def _lower_pct(table: pd.DataFrame, window: str) -> float:
    return 100.0 * (
        1.0 - table[f"lstm_{window}rmse_n"].mean() / table[f"model_{window}rmse_n"].mean()
    )


def summary(table: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Mean LSTM and model RMSE over the cut, % lower, median LSTM RMSE; the % lower over the
    whole record and on moving samples; beside the paper's numbers (``paper``: the
    ``denkena2020_summary`` table)."""
    q = paper.set_index("quantity")["value"]
    return pd.DataFrame(
        [
            {
                "mean_lstm_rmse_n": table["lstm_cutting_rmse_n"].mean(),
                "mean_model_rmse_n": table["model_cutting_rmse_n"].mean(),
                "lstm_lower_pct": _lower_pct(table, "cutting_"),
                "median_lstm_rmse_n": table["lstm_cutting_rmse_n"].median(),
                "record_lstm_lower_pct": _lower_pct(table, ""),
                "moving_lstm_lower_pct": _lower_pct(table, "moving_"),
                "paper_mean_lstm_rmse_n": q["lstm_rmse_mean"],
                # implied by the two printed numbers (mean LSTM RMSE, % lower)
                "paper_mean_model_rmse_n": q["lstm_rmse_mean"]
                / (1.0 - q["lstm_rmse_lower_than_model"] / 100.0),
                "paper_lstm_lower_pct": q["lstm_rmse_lower_than_model"],
                "paper_median_lstm_rmse_n": q["lstm_rmse_median"],
            }
        ]
    )


def seed_table(
    tables: dict[int, pd.DataFrame], nets: dict[int, dict[str, Trained]]
) -> pd.DataFrame:
    """One row per seed: its networks' best and last epochs, whether early stopping ended them
    (``converged_*``, :attr:`nctwin.learn.train.Trained.converged`), and its own cutting-window
    scores.

    Parameters
    ----------
    tables : dict
        Seed -> :func:`table2` of that seed's LSTMs alone.
    nets : dict
        Seed -> ``{"X": Trained, ...}``.
    """
    return pd.DataFrame([
        {"seed": s, **{f"best_epoch_{a}": n.best_epoch for a, n in nets[s].items()},
         **{f"epochs_{a}": len(n.history["train"]) for a, n in nets[s].items()},
         **{f"converged_{a}": n.converged for a, n in nets[s].items()},
         "mean_lstm_rmse_n": t["lstm_cutting_rmse_n"].mean(),
         "lstm_lower_pct": _lower_pct(t, "cutting_")}
        for s, t in tables.items()
    ])  # fmt: skip


def kind_means(table: pd.DataFrame, paper2: pd.DataFrame) -> pd.DataFrame:
    """Our Table 2 rows (cutting window) averaged by kind of process and axis (and the
    semi-stable ones on their own), beside what survives of the paper's Table 2.

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
        :func:`~nctwin.report.papers.side_by_side` on ``process, axis`` of the mean
        ``lstm_rmse_n``, ``model_rmse_n`` (over the cut) and ``max_abs_force_n``.
    """
    cut = table.drop(columns=["lstm_rmse_n", "model_rmse_n"]).rename(
        columns={"lstm_cutting_rmse_n": "lstm_rmse_n", "model_cutting_rmse_n": "model_rmse_n"}
    )
    cols = ["lstm_rmse_n", "model_rmse_n", "max_abs_force_n"]
    ours_kind = cut.groupby(["process", "axis"])[cols].mean().reset_index()
    semi = cut[cut["semi_stable"]].groupby("axis")[cols].mean()
    semi = semi.reset_index().assign(process="semi-stable")
    ours_kind = pd.concat([ours_kind, semi], ignore_index=True)
    paper_rows = paper2.assign(process=paper2["process"].replace({"side milling": "semi-stable"}))
    return side_by_side(ours_kind, paper_rows, on=["process", "axis"], columns=cols)
