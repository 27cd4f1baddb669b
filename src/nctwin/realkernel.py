r"""Predicting a real controller: every cycle-time method against LinuxCNC's recordings.

The measured machine is LinuxCNC (:mod:`nctwin.kernel.linuxcnc`, profile ``linuxcnc_sim``); its
recordings are shipped (:mod:`nctwin.recordings`). This module turns them into training data and
runs every method on a program the way the chapter "Predicting a real controller" compares them:

* ``cam``: length over feed (:func:`nctwin.estimate.cam`);
* ``block_overlap``: Lee et al. (2022), with its time constants identified from LinuxCNC's
  acceleration limits (:func:`identified_block_overlap_machine`);
* ``kernel``: nctwin's FIR kernel with its time constants and acceleration limits fitted to the
  training recordings (:func:`fit_fir`);
* ``bilstm``: Chien et al. (2023)'s BiLSTM trained on the recordings (:func:`train_bilstm`);
* ``axis_nn``: Sun et al. (2022)'s per-axis networks trained on the recordings
  (:func:`train_axis_nns`);
* ``planner``: no paper's method, the blend-arc look-ahead planner of
  :mod:`nctwin.estimate.blend_planner`, LinuxCNC's rules written down as physics;
* ``planner_fitted``: the same planner with the six axis limits it reads from the profile
  identified from the training recordings instead (:func:`fit_planner`).

The learned methods see a program as its *moves* (:func:`model_blocks`): lines, rapids (a line at
the rapid feed) and arcs cut into chords of at most :data:`ARC_CHORD_RAD`, the way the training
programs' curves are written; a dwell adds its time. Their features follow LinuxCNC's rules for
this profile: the tolerance is the program's ``G64 P`` (a plain ``G64`` means no tolerance, a
feature value of :data:`TOL_CAP_MM`), and where no ``G61``/``G64`` is set, the profile's
0.0254 mm; the feed is the programmed one clipped to what the axes allow along the move.

Chien's features are extended by two columns: the path acceleration the axes allow along the
move, :math:`a_k = \min_i a_{i,\max} / |u_{k,i}|` (LinuxCNC moves in 3D, and its Z axis is half
as quick as X and Y), and the naive-CAM tolerance ``G64 Q`` (LinuxCNC merges nearly collinear
short lines within it; a ``G64 P`` without Q sets Q = P). The targets are Chien's (eq. 1-3):
the average feed per move and the time ratio :math:`s_k = F_k \tilde t_k / l_k`, learned as
:math:`\ln s_k`: on LinuxCNC the ratio spans three decades (a 0.01 mm line at 200 mm/s takes a
servo period or more, 20 times its nominal time), and a squared loss on :math:`s_k` itself is
ruled by those few lines. The predicted cycle time is
:math:`\sum_k e^{\widehat{\ln s_k}} l_k / F_k`.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from scipy.optimize import least_squares

from .estimate import Estimate, block_overlap, cam, kernel
from .estimate.blend_planner import blend_planner, move_limits
from .features import BlockTargets, sun2022_features
from .gcode import parse
from .geometry import PathGeometry
from .machine import MachineProfile
from .models import ModelConfig
from .recordings import MACHINE as RECORDED_MACHINE
from .recordings import RecordedProgram, load_recordings
from .sun2022 import MIN_FEED_SHARE
from .sun2022 import MODEL_CONFIG as AXIS_NN_CONFIG
from .toolpath import MotionKind, PathMode, Toolpath
from .train import TrainConfig, Trained, fit

__all__ = [
    "ARC_CHORD_RAD",
    "AXIS_NN_CONFIG",
    "BILSTM_CONFIG",
    "FEATURES",
    "FIR_FIELDS",
    "METHOD_COLUMNS",
    "PLANNER_FIT_START",
    "PLANNER_RULES",
    "TIME_TARGETS",
    "TOL_CAP_MM",
    "TRAINING_SETS",
    "MoveData",
    "PlannerFit",
    "axis_nn_estimate",
    "axis_nn_move_times",
    "best_method",
    "bilstm_estimate",
    "bilstm_move_times",
    "features",
    "fit_fir",
    "fit_planner",
    "identified_block_overlap_machine",
    "method_rows",
    "method_summary",
    "model_blocks",
    "move_data",
    "path_control",
    "planner_ablation",
    "planner_block_gaps",
    "predict_axis_nn",
    "predict_bilstm",
    "recorded_move_data",
    "train_axis_nns",
    "train_bilstm",
    "train_configs",
    "trained_models",
    "training_data",
]

#: Largest sweep of one chord of an arc (rad) in :func:`model_blocks`.
ARC_CHORD_RAD = 0.1
#: Longest chord of an arc (mm) in :func:`model_blocks`.
ARC_CHORD_MM = 1.0
#: Tolerance feature of a move without a tolerance (plain ``G64``; mm).
TOL_CAP_MM = 2.0
#: Column names of :func:`features`.
FEATURES = (
    "feed_mm_s", "length_mm", "theta_start_rad", "theta_end_rad", "tol_mm", "acc_mm_s2",
    "naive_tol_mm",
)  # fmt: skip
#: Chien et al.'s BiLSTM (10 hidden units per direction, tanh, linear output) on seven features.
BILSTM_CONFIG = ModelConfig("bilstm", n_inputs=len(FEATURES), n_outputs=2, hidden=10)


def model_blocks(tp: Toolpath) -> tuple[Toolpath, np.ndarray]:
    """The moves a learned method sees: lines, rapids and chords of arcs, of non-zero length.

    Returns
    -------
    moves : Toolpath
        M blocks, none of them an arc or a dwell.
    source : ndarray of int64, shape (M,)
        The block of ``tp`` each move comes from.
    """
    moving = (tp.kind != MotionKind.DWELL) & (tp.lengths_mm > 0)
    idx = np.flatnonzero(moving)
    sweep = np.where(tp.is_arc[idx], np.abs(tp.sweep_rad[idx]), 0.0)
    radius = np.where(tp.is_arc[idx], tp.radius_mm[idx], 1.0)
    pieces = np.where(
        tp.is_arc[idx],
        np.maximum(np.ceil(np.maximum(sweep / ARC_CHORD_RAD, sweep * radius / ARC_CHORD_MM)), 1),
        1,
    ).astype(np.int64)
    source = np.repeat(idx, pieces)
    j = np.arange(len(source)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    n = np.repeat(pieces, pieces)
    geo = PathGeometry(tp)
    s0 = geo.s_start_mm[source]
    length = tp.lengths_mm[source]
    start = geo.points(s0 + length * j / n)
    end = geo.points(s0 + length * (j + 1) / n)
    exact = n == 1  # keep the programmed points bit for bit where nothing is cut
    start[exact] = tp.start_mm[source[exact]]
    end[exact] = tp.end_mm[source[exact]]
    moves = dataclasses.replace(
        tp.take(source),
        start_mm=start,
        end_mm=end,
        kind=np.where(tp.is_arc[source], MotionKind.LINEAR, tp.kind[source]).astype(np.int8),
        center_mm=np.full((len(source), 3), np.nan),
    )
    return moves, source


def features(moves: Toolpath, machine: MachineProfile) -> np.ndarray:
    r"""Features of each move, shape (M, 6), columns :data:`FEATURES`.

    Chien et al. (2023, Sec. 2.2) :math:`(F, l_k, \theta_k, \theta_{k+1}, \varepsilon)` with
    LinuxCNC's rules for the feed and tolerance (see the module docstring), and the path
    acceleration :math:`a_k` the axes allow along the move. The tool starts and ends at rest
    (corner angle :math:`\pi`).
    """
    feed, acc = move_limits(moves, machine)
    n = len(moves)
    theta = np.append(moves.corner_angles_rad, np.pi)
    if n:
        theta[0] = np.pi
    tol = moves.effective_tolerance_mm(machine.blend_tol_mm)
    naive = moves.effective_naive_tol_mm()
    return np.column_stack(
        [feed, moves.lengths_mm, theta[:n], theta[1:], np.minimum(tol, TOL_CAP_MM), acc, naive]
    )


@dataclass(frozen=True, eq=False)
class MoveData:
    """One recorded program as the learned methods see it.

    Parameters
    ----------
    name : str
    moves : Toolpath
        :func:`model_blocks` of the program (M moves).
    features : ndarray, shape (M, 7)
        :func:`features`.
    targets : ndarray, shape (M, 2)
        Average feed (mm/s) and log time ratio :math:`\\ln s_k = \\ln (F_k \\tilde t_k / l_k)`;
        both NaN where a move's two junction points coincide (:math:`\\tilde t_k = 0`).
    axis_features : ndarray, shape (M, 3, 9)
        :func:`nctwin.features.sun2022_features` of the moves (feed as in ``features``).
    axis_targets : ndarray, shape (M, 3)
        Average axis feeds: the average feed times the move's direction.
    dwell_s : float
        Dwell time of the program (not part of any move).
    measured_s : float
        Recorded cycle time.
    """

    name: str
    moves: Toolpath
    features: np.ndarray
    targets: np.ndarray
    axis_features: np.ndarray
    axis_targets: np.ndarray
    dwell_s: float
    measured_s: float


def move_data(
    name: str, tp: Toolpath, machine: MachineProfile, targets: BlockTargets | None = None
) -> MoveData:
    """Features (and, from a recording's per-block ``targets``, targets) of a program.

    A recorded program must have no arcs (its blocks are the moves); without ``targets`` the
    targets are NaN and ``measured_s`` is NaN.
    """
    moves, source = model_blocks(tp)
    x = features(moves, machine)
    feed, length = x[:, 0], x[:, 1]
    clipped = dataclasses.replace(moves, feed_mm_s=feed)
    ax = sun2022_features(clipped, machine.rapid_feed_mm_s)
    dwell = float(tp.dwell_s.sum())
    if targets is None:
        y = np.full((len(moves), 2), np.nan)
        measured = np.nan
    else:
        if len(source) != len(np.unique(source)):
            raise ValueError(f"{name}: a recorded program with arcs cannot give move targets")
        t = targets.time_s[source]
        with np.errstate(invalid="ignore", divide="ignore"):
            avg = np.where(t > 0, targets.length_mm[source] / t, np.nan)
        with np.errstate(divide="ignore"):
            log_ratio = np.where(t > 0, np.log(feed * t / length), np.nan)
        y = np.column_stack([avg, log_ratio])
        measured = targets.cycle_time_s
    return MoveData(
        name=name,
        moves=moves,
        features=x,
        targets=y,
        axis_features=ax,
        axis_targets=np.nan_to_num(y[:, :1]) * moves.directions,
        dwell_s=dwell,
        measured_s=measured,
    )


def recorded_move_data(rec: RecordedProgram, machine: MachineProfile) -> MoveData:
    """:func:`move_data` of a shipped recording of one of nctwin's programs."""
    return move_data(rec.name, parse(rec.program), machine, rec.targets)


# ------------------------------------------------------------------------------------------------
# Learned methods


#: Second output of the BiLSTM: the log time ratio (the chapter's), or the ratio itself (the
#: Chien chapter's, kept as an ablation).
TIME_TARGETS = ("log_ratio", "ratio")


def _check_time_target(time_target: str) -> None:
    if time_target not in TIME_TARGETS:
        raise ValueError(f"time_target = {time_target!r} is unknown: allowed {TIME_TARGETS}")


def train_bilstm(
    data: Sequence[MoveData],
    train_config: TrainConfig,
    *,
    name: str = "linuxcnc_bilstm",
    time_target: str = "log_ratio",
) -> Trained:
    """Chien et al.'s BiLSTM (:data:`BILSTM_CONFIG`) on the recordings ``data``.

    ``time_target`` ``"ratio"`` learns :math:`s_k` itself instead of :math:`\\ln s_k`.
    """
    _check_time_target(time_target)
    ys = [d.targets for d in data]
    if time_target == "ratio":
        ys = [np.column_stack([y[:, 0], np.exp(y[:, 1])]) for y in ys]
        name = f"{name}_ratio"
    return fit(BILSTM_CONFIG, train_config, [d.features for d in data], ys, name=name,
               progress=False)  # fmt: skip


def bilstm_move_times(model: Trained, data: MoveData, time_target: str = "log_ratio") -> np.ndarray:
    """Predicted time of each move, :math:`e^{\\widehat{\\ln s_k}} l_k / F_k` (or
    :math:`\\max(\\hat s_k, 0) l_k / F_k` for ``time_target="ratio"``), shape (M,)."""
    _check_time_target(time_target)
    y = model.predict(data.features)[:, 1]
    ratio = np.exp(y) if time_target == "log_ratio" else np.maximum(y, 0.0)
    return ratio * data.features[:, 1] / data.features[:, 0]


def predict_bilstm(model: Trained, data: MoveData, time_target: str = "log_ratio") -> float:
    """Predicted cycle time: the sum of :func:`bilstm_move_times` plus the dwells."""
    return float(bilstm_move_times(model, data, time_target).sum()) + data.dwell_s


def train_axis_nns(
    data: Sequence[MoveData], train_config: TrainConfig, *, name: str = "linuxcnc_axis_nn"
) -> list[Trained]:
    """Sun et al.'s per-axis networks (one per X, Y, Z; 9 features, 5 and 10 tanh units)."""
    return [
        fit(
            AXIS_NN_CONFIG,
            train_config,
            [d.axis_features[:, a] for d in data],
            [d.axis_targets[:, a : a + 1] for d in data],
            name=f"{name}-{'xyz'[a]}",
            progress=False,
        )
        for a in range(3)
    ]


def predict_axis_nn(models: Sequence[Trained], data: MoveData) -> float:
    """Predicted cycle time (Sun et al. 2022, eq. 9-10) plus the dwells; the resultant feed is
    kept above :data:`nctwin.sun2022.MIN_FEED_SHARE` of the programmed feed."""
    return float(axis_nn_move_times(models, data).sum()) + data.dwell_s


def axis_nn_move_times(models: Sequence[Trained], data: MoveData) -> np.ndarray:
    """Predicted time of each move, :math:`l_k / \\lVert \\hat f_k \\rVert`, shape (M,)."""
    axis = np.column_stack(
        [m.predict(data.axis_features[:, a])[:, 0] for a, m in enumerate(models)]
    )
    feed = data.features[:, 0]
    resultant = np.maximum(np.linalg.norm(axis, axis=1), MIN_FEED_SHARE * feed)
    return data.features[:, 1] / resultant


# ------------------------------------------------------------------------------------------------
# Analytic and simulated methods


def identified_block_overlap_machine(tp: Toolpath, machine: MachineProfile) -> MachineProfile:
    """``machine`` with Lee et al.'s time constants identified from its acceleration limits.

    A linear acc/dec filter of time constant :math:`A_T` adds :math:`A_T` to a line at feed
    :math:`F`; LinuxCNC, accelerating at :math:`A`, adds :math:`F / A`. So
    :math:`A_T = F / A` with :math:`F` the program's main cutting feed (the one it cuts longest
    at) and :math:`A` the X/Y acceleration, and :math:`A_{TR} = F_r / A`, both rounded to whole
    periods; LinuxCNC has no bell stage and no in-position wait (it blends rapids too).
    """
    a = min(machine.axis_max_acceleration_mm_s2[:2])
    cut = np.isin(tp.kind, (MotionKind.LINEAR, MotionKind.ARC_CW, MotionKind.ARC_CCW))
    feed = np.minimum(tp.feed_mm_s[cut], machine.max_feed_mm_s)
    if feed.size:
        values, inverse = np.unique(feed, return_inverse=True)
        main = values[np.argmax(np.bincount(inverse, weights=tp.lengths_mm[cut]))]
    else:
        main = machine.rapid_feed_mm_s
    ti = machine.period_s

    def periods(t: float) -> float:
        return max(round(t / ti), 1) * ti

    return dataclasses.replace(
        machine,
        cut_time_constant_s=periods(main / a),
        rapid_time_constant_s=periods(machine.rapid_feed_mm_s / a),
        rapid_bell_s=0.0,
        rapid_type="linear",
        inposition_time_s=(0.0, 0.0, 0.0),
    )


#: Fields of :class:`~nctwin.machine.MachineProfile` that :func:`fit_fir` fits.
FIR_FIELDS = ("fir_t1_s", "fir_t2_s", "fir_acc_scale", "fir_blend_ratio", "fir_block_periods")


def _fir_trial(programs: Sequence[tuple[Toolpath, float]], machine: MachineProfile) -> dict:
    measured = np.array([m for _, m in programs])
    sim = np.array([kernel(tp, machine).cycle_time_s for tp, _ in programs])
    err = 100 * np.abs(sim / measured - 1)
    return {
        "score": float(np.abs(np.log(sim / measured)).mean()),
        "mean_err_pct": float(err.mean()),
        "max_err_pct": float(err.max()),
    }


def fit_fir(
    programs: Sequence[tuple[Toolpath, float]],
    machine: MachineProfile,
    grid: dict[str, Sequence[float]],
    *,
    n_jobs: int = 2,
) -> tuple[MachineProfile, list[dict]]:
    """Fit the FIR kernel to recorded cycle times by a grid search.

    LinuxCNC has no jerk limit and accelerates at a constant rate; the FIR kernel accelerates at
    :math:`F / T_1` with jerk :math:`F / (T_1 T_2)`, and caps an axis's feed at
    :math:`a_i T_1`. No single (T1, T2) is LinuxCNC, so the profile's FIR fields
    (:data:`FIR_FIELDS`: time constants, acceleration scale, blend ratio, block rate; see
    :class:`~nctwin.machine.MachineProfile`) are fitted: the grid point with the lowest mean
    absolute log ratio of simulated (:func:`nctwin.estimate.kernel`) to recorded cycle time
    wins.

    Parameters
    ----------
    programs : sequence of (Toolpath, float)
        Training programs and their recorded cycle times.
    machine : MachineProfile
        The recorded machine's profile.
    grid : dict
        Values to try for each field of :data:`FIR_FIELDS`.
    n_jobs : int
        joblib workers (one grid point each).

    Returns
    -------
    best : MachineProfile
        ``machine`` with the best values.
    trials : list of dict
        Every grid point with its score, mean and largest absolute error (%).
    """
    if set(grid) != set(FIR_FIELDS):
        raise ValueError(f"grid has keys {sorted(grid)}: allowed exactly {list(FIR_FIELDS)}")
    values = itertools.product(*(grid[n] for n in FIR_FIELDS))
    points = [dict(zip(FIR_FIELDS, v, strict=True)) for v in values]
    jobs = (delayed(_fir_trial)(programs, dataclasses.replace(machine, **p)) for p in points)
    scores = Parallel(n_jobs=n_jobs)(jobs)
    trials = [p | r for p, r in zip(points, scores, strict=True)]
    best = min(trials, key=lambda r: r["score"])
    return dataclasses.replace(machine, **{n: best[n] for n in FIR_FIELDS}), trials


#: Generic start of :func:`fit_planner`: every axis at this acceleration (mm/s^2) and velocity
#: (mm/s), not the profile's.
PLANNER_FIT_START = (500.0, 100.0)


@dataclass(frozen=True)
class PlannerFit:
    """What :func:`fit_planner` identified.

    Parameters
    ----------
    machine : MachineProfile
        The profile with the identified axis limits.
    limits : DataFrame
        One row per axis and limit: ``axis``, ``limit`` (``acceleration_mm_s2`` or
        ``velocity_mm_s``), ``start``, ``fitted``, ``profile`` (the value the profile had).
    mean_err_pct, max_err_pct : float
        Mean and largest absolute cycle-time error (%) of the fitted planner on the programs.
    evaluations : int
        Planner runs over the programs the fit took.
    """

    machine: MachineProfile
    limits: pd.DataFrame
    mean_err_pct: float
    max_err_pct: float
    evaluations: int


def fit_planner(
    programs: Sequence[tuple[Toolpath, float]],
    machine: MachineProfile,
    start: tuple[float, float] = PLANNER_FIT_START,
) -> PlannerFit:
    r"""Identify the blend-arc planner's axis limits from recorded cycle times.

    The planner's rules are LinuxCNC's (:mod:`nctwin.estimate.blend_planner`); its constants are
    the six axis limits it reads from the profile, :math:`a_{i,\max}` and :math:`v_{i,\max}`
    for X, Y and Z, which a user of a control need not know. They are fitted here, without the
    profile's values, by least squares on the log ratio of planned to recorded cycle time per
    program: scipy's trust-region reflective method on the logarithm of each limit, with
    finite differences of relative step 1e-3, from the generic ``start`` (every axis at the
    same acceleration and velocity). The fit plans each stop with half a servo period, not
    with the tool at rest on a whole period (``stop_periods="mean"``): whole periods make the
    planned time a step function of the limits, which finite differences cannot follow. The
    velocities are bounded by the profile's maximum feed
    (``[TRAJ] MAX_LINEAR_VELOCITY``): an axis limit above the path's is never reached, and no
    recording can tell it. Everything else in the profile (maximum and rapid feed, servo period,
    default tolerance) is kept.

    Parameters
    ----------
    programs : sequence of (Toolpath, float)
        Training programs and their recorded cycle times.
    machine : MachineProfile
        The recorded machine's profile (its axis limits are only reported, not used).
    start : (float, float)
        Acceleration (mm/s^2) and velocity (mm/s) every axis starts from.

    Returns
    -------
    PlannerFit

    Raises
    ------
    ValueError
        If there are no programs, a recorded time is not positive, or ``start`` lies outside
        the bounds (acceleration 10 to 1e5 mm/s^2, velocity 1 mm/s to the maximum feed).
    """
    if not programs:
        raise ValueError("programs is empty: the planner's limits need at least one recording")
    measured = np.array([t for _, t in programs], dtype=float)
    if not (measured > 0).all():
        raise ValueError(f"measured cycle times {measured[measured <= 0][:3]} s: allowed > 0")
    lower = np.log([10.0] * 3 + [1.0] * 3)
    upper = np.log([1e5] * 3 + [machine.max_feed_mm_s] * 3)
    x0 = np.log([start[0]] * 3 + [start[1]] * 3)
    if not ((x0 >= lower) & (x0 <= upper)).all():
        raise ValueError(
            f"start = {start!r} is out of range: allowed acceleration [10, 1e5] mm/s^2, "
            f"velocity [1, {machine.max_feed_mm_s:g}] mm/s"
        )

    def profile(x: np.ndarray) -> MachineProfile:
        e = np.exp(x)
        return dataclasses.replace(
            machine,
            axis_max_acceleration_mm_s2=tuple(float(v) for v in e[:3]),
            axis_max_velocity_mm_s=tuple(float(v) for v in e[3:]),
        )

    def planned_s(m: MachineProfile, stop_periods: str) -> np.ndarray:
        return np.array(
            [blend_planner(tp, m, stop_periods=stop_periods).cycle_time_s for tp, _ in programs]
        )

    def residual(x: np.ndarray) -> np.ndarray:
        return np.log(planned_s(profile(x), "mean") / measured)

    fit = least_squares(residual, x0, bounds=(lower, upper), diff_step=1e-3, method="trf")
    fitted = profile(fit.x)
    err = 100 * np.abs(planned_s(fitted, "whole") / measured - 1)
    limits = pd.DataFrame(
        [{"axis": axis, "limit": limit, "start": s, "fitted": getattr(fitted, field)[i],
          "profile": getattr(machine, field)[i]}
         for limit, field, s in (("acceleration_mm_s2", "axis_max_acceleration_mm_s2", start[0]),
                                 ("velocity_mm_s", "axis_max_velocity_mm_s", start[1]))
         for i, axis in enumerate("XYZ")]
    )  # fmt: skip
    return PlannerFit(fitted, limits, float(err.mean()), float(err.max()), int(fit.nfev))


def analytic_times(
    tp: Toolpath,
    machine: MachineProfile,
    fir_fitted: MachineProfile,
    planner_fitted: MachineProfile,
) -> dict:
    """Cycle times of the methods that need no training data, or only constants fitted to it:
    CAM, Lee's block overlap with identified constants, the fitted FIR kernel, the blend-arc
    planner (:mod:`nctwin.estimate.blend_planner`) and the same with fitted axis limits."""
    lee = identified_block_overlap_machine(tp, machine)
    return {
        "cam": cam(tp, machine).cycle_time_s,
        "block_overlap": block_overlap(tp, lee).cycle_time_s,
        "kernel": kernel(tp, fir_fitted).cycle_time_s,
        "planner": blend_planner(tp, machine).cycle_time_s,
        "planner_fitted": blend_planner(tp, planner_fitted).cycle_time_s,
    }


# ------------------------------------------------------------------------------------------------
# Tables

#: Sets of recordings the learned methods can learn from (:func:`training_data`).
TRAINING_SETS = ("train", "broad", "cam")

#: Columns of :func:`method_rows` (the chapter's ``methods.csv``).
METHOD_COLUMNS = ("program", "set", "method", "measured_s", "predicted_s", "err_pct")


def method_rows(
    programs: dict[str, tuple[str, Toolpath, MoveData]],
    machine: MachineProfile,
    fir_fitted: MachineProfile,
    planner_fitted: MachineProfile,
    bilstm: Trained,
    axis_nns: Sequence[Trained],
) -> pd.DataFrame:
    """Every method on every program.

    Parameters
    ----------
    programs : dict
        Name -> (set, parsed program, its :class:`MoveData` with ``measured_s``).

    Returns
    -------
    DataFrame
        One row per program x method, columns :data:`METHOD_COLUMNS`; ``err_pct`` is signed,
        (predicted - measured) / measured x 100.
    """
    rows = []
    for name, (group, tp, data) in programs.items():
        times = analytic_times(tp, machine, fir_fitted, planner_fitted)
        times["bilstm"] = predict_bilstm(bilstm, data)
        times["axis_nn"] = predict_axis_nn(axis_nns, data)
        for method, t in times.items():
            rows.append(
                {"program": name, "set": group, "method": method, "measured_s": data.measured_s,
                 "predicted_s": t, "err_pct": 100.0 * (t - data.measured_s) / data.measured_s}
            )  # fmt: skip
    return pd.DataFrame(rows, columns=list(METHOD_COLUMNS))


def path_control(tp: Toolpath, machine: MachineProfile) -> str:
    """The path-control modes a program's moves run in, LinuxCNC's rules, as G-code.

    ``G61`` (exact path), ``G61.1`` (exact stop), ``G64`` (no tolerance), ``G64 P Q0`` (a
    tolerance, no naive-CAM merging) or ``G64 P Q>0`` (a tolerance, merging within Q; a
    ``G64 P`` without Q sets Q = P); several are joined by ``", "`` in their order in the
    program.
    """
    moving = tp.kind != MotionKind.DWELL
    tol = tp.effective_tolerance_mm(machine.blend_tol_mm)[moving]
    naive = tp.effective_naive_tol_mm()[moving]
    mode = tp.path_mode[moving]
    label = np.where(
        mode == PathMode.EXACT_STOP, "G61.1",
        np.where(mode == PathMode.EXACT_PATH, "G61",
                 np.where(np.isinf(tol), "G64", np.where(naive > 0, "G64 P Q>0", "G64 P Q0"))),
    )  # fmt: skip
    _, first = np.unique(label, return_index=True)
    return ", ".join(label[np.sort(first)])


#: The rule sets of :func:`planner_ablation`: name -> keyword arguments of
#: :func:`~nctwin.estimate.blend_planner.blend_planner`. The last is the planner as it was
#: before the CAM-style recordings showed the rules for kinks and arcs missing, before stops
#: were put on whole servo periods, and with the near-reversal threshold it had then measured.
PLANNER_RULES = {
    "all": {},
    "no kinks": {"kinks": False},
    "largest arcs": {"sized_arcs": False},
    "stops off periods": {"stop_periods": "off"},
    "as first written": {
        "kinks": False,
        "sized_arcs": False,
        "stop_periods": "off",
        "stop_turn_rad": 0.02,
    },
}


def planner_ablation(
    programs: dict[str, tuple[str, Toolpath, float]], machine: MachineProfile
) -> pd.DataFrame:
    """The blend-arc planner with and without its rules for nearly tangent junctions, for the
    size of blend arcs and for stops on whole servo periods (:data:`PLANNER_RULES`).

    The planner learns nothing from recordings, so for it the training sets are held-out
    programs: a check of its rules on programs that were not used to find them.

    Parameters
    ----------
    programs : dict
        Name -> (set, parsed program, recorded cycle time in s).

    Returns
    -------
    DataFrame
        One row per program x rule set: ``program``, ``set``, ``mode`` (the program's
        :func:`path_control`), ``rules``, ``measured_s``, ``predicted_s`` and the signed
        ``err_pct``.
    """
    rows = []
    for name, (group, tp, measured) in programs.items():
        mode = path_control(tp, machine)
        for rules, kwargs in PLANNER_RULES.items():
            t = blend_planner(tp, machine, **kwargs).cycle_time_s
            rows.append(
                {"program": name, "set": group, "mode": mode, "rules": rules,
                 "measured_s": measured, "predicted_s": t,
                 "err_pct": 100.0 * (t - measured) / measured}
            )  # fmt: skip
    return pd.DataFrame(rows)


def planner_block_gaps(rec: RecordedProgram, machine: MachineProfile, n: int = 3) -> pd.DataFrame:
    """The ``n`` blocks of a recording of nctwin's own programs whose time the blend-arc planner
    misses most: block, kind, length (mm), programmed feed (mm/s), recorded and planned time
    (s), sorted by block."""
    if not (isinstance(n, int) and n >= 1):
        raise ValueError(f"n = {n!r} is out of range: allowed integers >= 1")
    if rec.source != "nctwin":
        raise ValueError(
            f"recording {rec.name!r} has source = {rec.source!r}: allowed 'nctwin' (a program "
            "whose text is shipped)"
        )
    tp = parse(rec.program)
    planned = blend_planner(tp, machine).block_times_s
    measured = rec.targets.time_s
    worst = np.sort(np.argsort(-np.abs(planned - measured), kind="stable")[:n])
    return pd.DataFrame(
        {"block": worst, "kind": [MotionKind(k).name.lower() for k in tp.kind[worst]],
         "length_mm": tp.lengths_mm[worst], "feed_mm_s": tp.feed_mm_s[worst],
         "measured_s": measured[worst], "planner_s": planned[worst]}
    )  # fmt: skip


def method_summary(rows: pd.DataFrame, by: Sequence[str] = ("set", "method")) -> pd.DataFrame:
    """Median and worst absolute error (%) per group of ``rows`` (by default per set and
    method), and how often it underestimates."""
    g = rows.assign(abs_err_pct=rows.err_pct.abs()).groupby(list(by), sort=False)
    return g.agg(
        programs=("program", "size"),
        median_abs_err_pct=("abs_err_pct", "median"),
        worst_abs_err_pct=("abs_err_pct", "max"),
        underestimates=("err_pct", lambda e: int((e < 0).sum())),
    ).reset_index()


# ------------------------------------------------------------------------------------------------
# The chapter's trained models, for the command line


def train_configs(seed: int = 0, scale: float = 1.0) -> tuple[TrainConfig, TrainConfig]:
    """The chapter's training settings: the BiLSTM's and the per-axis networks'.

    ``scale`` multiplies the epoch budgets (1 is the chapter's).
    """
    bilstm = TrainConfig(seed=seed, max_epochs=max(5, round(150 * scale)), patience=15,
                         log_inputs=(1,))  # fmt: skip
    axis = TrainConfig(seed=seed, loss="mse", window_lines=256, batch_size=8,
                       max_epochs=max(5, round(200 * scale)), patience=20,
                       learning_rate=1e-2)  # fmt: skip
    return bilstm, axis


def training_data(
    machine: MachineProfile, sets: Sequence[str] = ("train", "broad")
) -> list[MoveData]:
    """The recordings of ``machine`` of the training ``sets`` as :class:`MoveData`.

    ``sets`` picks among ``train`` (paper 1's programs), ``broad`` (the broad set) and ``cam``
    (the CAM-style set, :mod:`nctwin.programs.camstyle`); the chapter's methods learn from the
    first two.

    Raises
    ------
    ValueError
        If ``machine`` is not the machine of the shipped recordings, or a set is unknown.
    """
    unknown = set(sets) - set(TRAINING_SETS)
    if unknown:
        raise ValueError(
            f"sets = {tuple(sets)!r} is not allowed: allowed {', '.join(TRAINING_SETS)}"
        )
    if machine.name != RECORDED_MACHINE:
        raise ValueError(
            f"machine = {machine.name!r} has no recordings to learn from: allowed "
            f"{RECORDED_MACHINE!r} (the LinuxCNC recordings)"
        )
    recs = load_recordings()
    return [
        recorded_move_data(rec, machine)
        for name, rec in recs.items()
        if name.startswith(tuple(f"{s}_" for s in sets))
    ]


def trained_models(machine: MachineProfile, seed: int = 0) -> tuple[Trained, list[Trained]]:
    """The chapter's BiLSTM and per-axis networks for ``machine`` (trained once, then loaded
    from ``data/cache/models``)."""
    data = training_data(machine)
    bilstm_cfg, axis_cfg = train_configs(seed)
    return train_bilstm(data, bilstm_cfg), train_axis_nns(data, axis_cfg)


def _block_times(
    tp: Toolpath, move_times_s: np.ndarray, method: str, machine: MachineProfile
) -> Estimate:
    """Per-block :class:`~nctwin.estimate.Estimate` from per-move times (dwells keep theirs)."""
    _, source = model_blocks(tp)
    t = np.bincount(source, weights=move_times_s, minlength=len(tp)) + tp.dwell_s
    return Estimate(method, machine.name, t, tp)


def bilstm_estimate(tp: Toolpath, machine: MachineProfile) -> Estimate:
    """``nctwin estimate --method bilstm``: the chapter's BiLSTM (LinuxCNC recordings only)."""
    model, _ = trained_models(machine)
    data = move_data("program", tp, machine)
    return _block_times(tp, bilstm_move_times(model, data), "bilstm", machine)


def axis_nn_estimate(tp: Toolpath, machine: MachineProfile) -> Estimate:
    """``nctwin estimate --method axis_nn``: the chapter's per-axis networks (LinuxCNC only)."""
    _, models = trained_models(machine)
    data = move_data("program", tp, machine)
    return _block_times(tp, axis_nn_move_times(models, data), "axis_nn", machine)


def best_method(summary: pd.DataFrame) -> str:
    """The method with the lowest median error on the public programs (on the test paths where
    no public program was run): the default of ``nctwin estimate`` for the recorded machine."""
    group = "public" if (summary.set == "public").any() else "test paths"
    rows = summary[summary.set == group].sort_values(
        ["median_abs_err_pct", "worst_abs_err_pct"], kind="stable"
    )
    return str(rows.method.iloc[0])
