r"""Learned cycle-time estimators for a machine with shipped recordings: Chien et al. (2023)'s
BiLSTM and Sun et al. (2022)'s per-axis networks, trained on LinuxCNC's recordings
(:mod:`nctwin.recordings`), for ``nctwin estimate --method bilstm|axis_nn``.

The networks see a program as its *moves* (:func:`model_blocks`): lines, rapids (a line at
the rapid feed) and arcs cut into chords of at most :data:`ARC_CHORD_RAD`, the way the training
programs' curves are written; a dwell adds its time. Their features follow LinuxCNC's rules for
this profile: the tolerance is the program's ``G64 P`` (a plain ``G64`` means no tolerance, a
feature value of :data:`TOL_CAP_MM`), and where no ``G61``/``G64`` is set, the profile's
0.0254 mm; the feed is the programmed one clipped to what the axes allow along the move.

Chien's features (:func:`nctwin.methods.chien2023.features`) are extended by two columns: the
path acceleration the axes allow along the move, :math:`a_k = \min_i a_{i,\max} / |u_{k,i}|`
(LinuxCNC moves in 3D, and its Z axis is half as quick as X and Y), and the naive-CAM tolerance
``G64 Q`` (LinuxCNC merges nearly collinear short lines within it; a ``G64 P`` without Q sets
Q = P). The targets are Chien's (eq. 1-3): the average feed per move and the time ratio
:math:`s_k = F_k \tilde t_k / l_k`, learned as :math:`\ln s_k`: on LinuxCNC the ratio spans three
decades (a 0.01 mm line at 200 mm/s takes a servo period or more, 20 times its nominal time),
and a squared loss on :math:`s_k` itself is ruled by those few lines. The predicted cycle time
is :math:`\sum_k e^{\widehat{\ln s_k}} l_k / F_k` (:func:`nctwin.methods.chien2023.block_times_s`);
the per-axis networks give it by eq. 9-10 (:func:`nctwin.methods.sun2022.block_times_s`).

A network can predict a move faster than any control runs it (on a 100 mm square at 20 mm/s,
both give about 18 s for moves that take at least 20 s). For ``nctwin estimate`` (:func:`bilstm`,
:func:`axis_nn`) every move's time is raised to its physical floor, its length over its feed
within the machine's limits (:func:`move_floors_s`), and the :class:`Estimate` says how many
were raised; the chapter's numbers (:func:`predict_bilstm`, :func:`predict_axis_nn`) are the
networks' own.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..controls import PlannerControl
from ..gcode import parse
from ..geometry import PathGeometry
from ..learn.train import TrainConfig, Trained, fit
from ..machine import Machine, Profile
from ..methods import chien2023, sun2022
from ..recordings import NAME as RECORDINGS
from ..recordings import RecordedProgram, load_recordings
from ..targets import BlockTargets
from ..toolpath import MotionKind, Toolpath
from .blend_limits import move_limits
from .result import Estimate

__all__ = [
    "ARC_CHORD_MM",
    "ARC_CHORD_RAD",
    "BILSTM_CONFIG",
    "FEATURES",
    "TIME_TARGETS",
    "TOL_CAP_MM",
    "TRAINING_SETS",
    "MoveData",
    "axis_nn",
    "axis_nn_move_times",
    "bilstm",
    "bilstm_move_times",
    "features",
    "model_blocks",
    "move_data",
    "move_floors_s",
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
BILSTM_CONFIG = dataclasses.replace(chien2023.BILSTM_CONFIG, n_inputs=len(FEATURES))


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


def features(moves: Toolpath, machine: Machine, control: PlannerControl) -> np.ndarray:
    r"""Features of each move, shape (M, 7), columns :data:`FEATURES`.

    Chien et al. (2023, Sec. 2.2) :math:`(F, l_k, \theta_k, \theta_{k+1}, \varepsilon)` with
    LinuxCNC's rules for the feed and tolerance (see the module docstring; the tolerance where
    the program sets none is ``control``'s), the path acceleration :math:`a_k` the axes allow
    along the move (:func:`nctwin.limits.path_limits`) and the naive-CAM tolerance. The tool
    starts and ends at rest (corner angle :math:`\pi`).
    """
    feed, acc = move_limits(moves, machine, arc_ratio="feed")
    n = len(moves)
    theta = np.append(moves.corner_angles_rad, np.pi)
    if n:
        theta[0] = np.pi
    tol = moves.effective_tolerance_mm(control.blend_tol_mm)
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
        :func:`nctwin.methods.sun2022.features` of the moves (feed as in ``features``).
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
    name: str,
    tp: Toolpath,
    machine: Machine,
    control: PlannerControl,
    targets: BlockTargets | None = None,
) -> MoveData:
    """Features (and, from a recording's per-block ``targets``, targets) of a program.

    A recorded program must have no arcs (its blocks are the moves); without ``targets`` the
    targets are NaN and ``measured_s`` is NaN.
    """
    moves, source = model_blocks(tp)
    x = features(moves, machine, control)
    feed, length = x[:, 0], x[:, 1]
    clipped = dataclasses.replace(moves, feed_mm_s=feed)
    ax = sun2022.features(clipped, machine.rapid_feed_mm_s)
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


def recorded_move_data(rec: RecordedProgram, machine: Machine, control: PlannerControl) -> MoveData:
    """:func:`move_data` of a shipped recording of one of nctwin's programs."""
    return move_data(rec.name, parse(rec.program), machine, control, rec.targets)


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
    ratio = np.exp(y) if time_target == "log_ratio" else y
    return chien2023.block_times_s(ratio, data.features[:, 0], data.features[:, 1])


def predict_bilstm(model: Trained, data: MoveData, time_target: str = "log_ratio") -> float:
    """Predicted cycle time: the sum of :func:`bilstm_move_times` plus the dwells."""
    return float(bilstm_move_times(model, data, time_target).sum()) + data.dwell_s


def train_axis_nns(
    data: Sequence[MoveData], train_config: TrainConfig, *, name: str = "linuxcnc_axis_nn"
) -> list[Trained]:
    """Sun et al.'s per-axis networks (one per X, Y, Z; 9 features, 5 and 10 tanh units)."""
    return [
        fit(
            sun2022.MODEL_CONFIG,
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
    kept above :data:`nctwin.methods.sun2022.MIN_FEED_SHARE` of the programmed feed."""
    return float(axis_nn_move_times(models, data).sum()) + data.dwell_s


def axis_nn_move_times(models: Sequence[Trained], data: MoveData) -> np.ndarray:
    """Predicted time of each move, :math:`l_k / \\lVert \\hat f_k \\rVert`, shape (M,)."""
    axis = np.column_stack(
        [m.predict(data.axis_features[:, a])[:, 0] for a, m in enumerate(models)]
    )
    return sun2022.block_times_s(axis, data.features[:, 1], data.features[:, 0])


#: Sets of recordings the learned methods can learn from (:func:`training_data`).
TRAINING_SETS = ("train", "broad", "cam")


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


def training_data(profile: Profile, sets: Sequence[str] = ("train", "broad")) -> list[MoveData]:
    """The recordings of ``profile``'s machine of the training ``sets`` as :class:`MoveData`
    (features on its machine and its ``[control.planner]``).

    ``sets`` picks among ``train`` (paper 1's programs), ``broad`` (the broad set) and ``cam``
    (the CAM-style set, :mod:`nctwin.programs.camstyle`); the chapter's methods learn from the
    first two.

    Raises
    ------
    ValueError
        If the profile names no shipped recordings (its ``recordings`` key), or a set is
        unknown.
    """
    unknown = set(sets) - set(TRAINING_SETS)
    if unknown:
        raise ValueError(
            f"sets = {tuple(sets)!r} is not allowed: allowed {', '.join(TRAINING_SETS)}"
        )
    if profile.recordings != RECORDINGS:
        raise ValueError(
            f"recordings = {profile.recordings!r} of machine profile {profile.name} names no "
            f"shipped recordings to learn from: allowed {RECORDINGS!r} (LinuxCNC's)"
        )
    machine, control = profile.machine, profile.control("planner")
    recs = load_recordings()
    return [
        recorded_move_data(rec, machine, control)
        for name, rec in recs.items()
        if name.startswith(tuple(f"{s}_" for s in sets))
    ]


def trained_models(profile: Profile, seed: int = 0) -> tuple[Trained, list[Trained]]:
    """The chapter's BiLSTM and per-axis networks for ``profile`` (trained once, then loaded
    from the cache's ``models``)."""
    data = training_data(profile)
    bilstm_cfg, axis_cfg = train_configs(seed)
    return train_bilstm(data, bilstm_cfg), train_axis_nns(data, axis_cfg)


def move_floors_s(data: MoveData) -> np.ndarray:
    """Physical floor of each move, its length over its feed within the machine's limits
    (:func:`features`: the programmed feed, the rapid feed for rapids, clipped to the maximum
    feed and to the axis velocities along the move, :func:`~nctwin.estimate.blend_limits.
    move_limits`), shape (M,): no control runs a move faster."""
    return data.features[:, 1] / data.features[:, 0]


def _floored_estimate(
    tp: Toolpath, data: MoveData, move_times_s: np.ndarray, method: str, machine: Machine
) -> Estimate:
    """Per-block :class:`~nctwin.estimate.result.Estimate` from per-move predictions, each
    raised to its physical floor (:func:`move_floors_s`); dwells keep their time."""
    _, source = model_blocks(tp)
    floor = move_floors_s(data)
    clamped = move_times_s < floor
    t = np.where(clamped, floor, move_times_s)
    blocks = np.bincount(source, weights=t, minlength=len(tp)) + tp.dwell_s
    return Estimate(
        method,
        machine.name,
        blocks,
        tp,
        floor_time_s=float(floor.sum()) + data.dwell_s,
        clamped_moves=int(clamped.sum()),
        unclamped_time_s=float(move_times_s.sum()) + data.dwell_s,
    )


def bilstm(tp: Toolpath, profile: Profile) -> Estimate:
    """``nctwin estimate --method bilstm``: the chapter's BiLSTM (a profile with the LinuxCNC
    recordings only), every move at least its physical floor (:func:`move_floors_s`)."""
    model, _ = trained_models(profile)
    data = move_data("program", tp, profile.machine, profile.control("planner"))
    return _floored_estimate(tp, data, bilstm_move_times(model, data), "bilstm", profile.machine)


def axis_nn(tp: Toolpath, profile: Profile) -> Estimate:
    """``nctwin estimate --method axis_nn``: the chapter's per-axis networks (a profile with
    the LinuxCNC recordings only), every move at least its physical floor
    (:func:`move_floors_s`)."""
    _, models = trained_models(profile)
    data = move_data("program", tp, profile.machine, profile.control("planner"))
    models_times = axis_nn_move_times(models, data)
    return _floored_estimate(tp, data, models_times, "axis_nn", profile.machine)
