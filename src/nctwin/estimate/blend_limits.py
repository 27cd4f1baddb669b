r"""The limits LinuxCNC's blend-arc planner (:mod:`nctwin.estimate.blend_planner`) puts on moves
and on the junctions between them: each move's feed and tangential acceleration
(:func:`move_limits`), the blend arcs between lines (:func:`junction_blends`), the junctions
passed as tangent (:func:`tangent_junctions`) and the parabolic blends
(:func:`parabolic_junctions`, :func:`parabolic_blend_speeds`).

**Junction** :math:`j` between moves of length :math:`L_1, L_2`, the first ending along the unit
tangent :math:`u_1`, the second starting along :math:`u_2` (:func:`junction_blends`):

* the half supplement of the turn, :math:`\theta = \arccos(-u_1 \cdot u_2) / 2`
  (:math:`\pi/2` straight on, 0 for a reversal);
* the tolerance :math:`T = \min(P, r L_1, r L_2)` with :math:`r` = :data:`TOLERANCE_RATIO`,
  where :math:`P` is the smaller ``G64 P`` of the two moves and a plain ``G64`` (no tolerance)
  means :math:`P = r L` of the move (``tcFindBlendTolerance``);
* the largest distance from the corner along the moves the tolerance allows,
  :math:`d_{tol} = \cos\theta \, T / (1 - \sin\theta)`, and at most half of each move,
  :math:`d_g = \min(d_{tol}, L_1/2, L_2/2)`, the largest radius :math:`R_g = d_g \tan\theta`;
  the arc is only as large as its planned speed
  :math:`v_p = \min(\sqrt{a_n R_g}, \max(F_1, F_2))` needs (``blendComputeParameters``):
  :math:`R = \max(v_p^2 / a_n, \min(v_p t_b / (\pi - 2\theta), R_g))` with the blend time
  :math:`t_b = \min(\sqrt{a_j d_g}, v_p) / (a_j/2)`, so a slow or sharp corner gets a small arc;
  the arc length is :math:`R (\pi - 2\theta)`, and each move is shortened by
  :math:`d = R / \tan\theta`;
* the blend arc's acceleration is that of its plane (``blendParamKinematics``,
  ``calculateInscribedDiameter``): :math:`a_j = \min_i a_{i,\max} / \sqrt{1 - n_i^2}` with
  :math:`n` the unit normal of the plane of :math:`u_1, u_2` (:func:`blend_plane_acc`);
* the speed through the arc :math:`v_j = \min(\sqrt{a_n R}, F_1, F_2)` with
  :math:`a_n` = :data:`NORMAL_ACC_RATIO` :math:`a_j` and the tangential
  :data:`TANGENTIAL_ACC_RATIO` :math:`a_j` (``acc_ratio_tan``);
* a turn within :data:`STOP_TURN_RAD` of a reversal stops the tool (``tpSetupTangent``'s sharp
  corner).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..limits import path_limits
from ..machine import Machine
from ..toolpath import MotionKind, Toolpath
from .blend_junctions import KINK_RATIO, blend_plane_acc

__all__ = [
    "MIN_SEGMENT_CYCLES",
    "NORMAL_ACC_RATIO",
    "STOP_TURN_RAD",
    "TANGENTIAL_ACC_RATIO",
    "TOLERANCE_RATIO",
    "MoveLimits",
    "junction_blends",
    "move_limits",
    "parabolic_blend_speeds",
    "parabolic_junctions",
    "tangent_junctions",
]

#: Share of the acceleration kept for the tangential direction in a blend arc, and on a move
#: with a parabolic end.
TANGENTIAL_ACC_RATIO = 0.5
#: Share of the acceleration available for the normal direction in a blend arc.
NORMAL_ACC_RATIO = math.sqrt(1.0 - TANGENTIAL_ACC_RATIO**2)
#: Largest blend tolerance as a share of each of the two moves' lengths.
TOLERANCE_RATIO = 0.25
#: A turn this close to a reversal (rad) stops the tool instead of being blended
#: (``SHARP_CORNER_DEG`` = 2 in ``tpSetupTangent``).
STOP_TURN_RAD = math.radians(2.0)
#: An item runs at most at its length over this many servo periods (``TP_MIN_SEGMENT_CYCLES``).
MIN_SEGMENT_CYCLES = 1.02


def move_limits(
    moves: Toolpath,
    machine: Machine,
    acc_scale: np.ndarray | None = None,
    *,
    finalized: np.ndarray | None = None,
    arc_ratio: str = "max_speed",
) -> tuple[np.ndarray, np.ndarray]:
    r"""Feed and tangential acceleration of each move as LinuxCNC plans it, shapes (M,).

    Lines and rapids: the feed (the rapid feed for rapids) within the control's maximum and
    the axes' velocities, :math:`\min_i v_{i,\max} / |u_i|`, and the path acceleration the
    axes allow, :math:`a = \min_i a_{i,\max} / |u_i|` (canon's ``getStraightVelocity``,
    ``getStraightAcceleration``; :func:`nctwin.limits.path_limits`, whose rule for arcs is
    LinuxCNC's: the plane's two axes take the planar share :math:`r\phi/l` of the length and the
    third the helical share :math:`h/l`).

    Arcs (``arc_ratio="max_speed"``, LinuxCNC's rule), in three steps:

    * canon's ``ARC_FEED`` gives the arc the speed limit
      :math:`v_{\max} = \min(v_a, \sqrt{a_n a_p r}\; l / (r\phi))` with :math:`v_a` the
      axes' limit above and :math:`a_p` the smaller acceleration of the plane's two axes (X and
      Z in ``G18``, Y and Z in ``G19``), :math:`a_n` = :data:`NORMAL_ACC_RATIO`;
    * when the next move is queued the arc is finalized (``tcFinalizeLength``,
      ``tcUpdateCircleAccRatio``, ``pmCircleActualMaxVel``): with its overall acceleration
      :math:`a' = a s` (``tcGetOverallMaxAccel``: ``acc_scale`` :math:`s`) and its effective
      radius :math:`r_e = r + h^2/r` (``pmCircleEffectiveMinRadius``, with the whole rise
      :math:`h`), the normal acceleration at *the speed limit*, not at the feed,
      :math:`a_v = v_{\max}^2 / r_e`, decides: above :math:`a_n a'` the limit drops to
      :math:`\sqrt{a_n a' r_e}` and the tangential acceleration is :math:`a'/2`, else it is
      :math:`a' \sqrt{1 - (a_v / a')^2}`: a slow arc of small radius accelerates at
      :math:`a'/2` as a fast one does;
    * an arc never finalized (the program's last move, a move before a dwell; ``finalized``
      False) keeps the tangential acceleration :math:`a'/2` it was queued with (``tcInit``).

    The feed is the programmed one within :math:`v_{\max}`.
    ``arc_ratio="feed"`` is the rule as first written, from the programmed feed
    :math:`F` instead: a speed within :math:`\sqrt{a_n a' r}` and the tangential acceleration
    :math:`a' \sqrt{1 - (F^2 / (r a'))^2}` (:math:`a'/2` where that limit binds); the learned
    methods' features keep it (:mod:`nctwin.estimate.learned`).

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length (no dwells).
    machine : Machine
    acc_scale : ndarray, shape (M,), optional
        Share of the acceleration each move may use (LinuxCNC halves it on both moves of a
        parabolic blend, ``tcGetOverallMaxAccel``); 1 by default.
    finalized : ndarray of bool, shape (M,), optional
        The move is finalized (all but the last by default).
    arc_ratio : {"max_speed", "feed"}
        The rule for arcs (above).
    """
    if arc_ratio not in ("max_speed", "feed"):
        raise ValueError(f"arc_ratio = {arc_ratio!r} is not allowed: allowed max_speed, feed")
    return MoveLimits.of(moves, machine).at(acc_scale, finalized=finalized, arc_ratio=arc_ratio)


@dataclasses.dataclass(frozen=True)
class MoveLimits:
    r"""What :func:`move_limits` needs of M moves, A of them arcs, that no share of their
    acceleration changes: computed once per program (:meth:`of`), evaluated per share
    (:meth:`at`).

    Parameters
    ----------
    feed_mm_s : ndarray, shape (M,)
        The programmed feed (the rapid feed for rapids) within the control's maximum and the
        axes' velocities.
    top_mm_s : ndarray, shape (M,)
        The same with no programmed feed: the speed limit of the machine along each move.
    acc_mm_s2 : ndarray, shape (M,)
        The path acceleration the axes allow, :math:`\min_i a_{i,\max} / |u_i|`.
    arc : ndarray of int, shape (A,)
        Indices of the arcs.
    radius_mm, eff_radius_mm : ndarray, shape (A,)
        Each arc's radius :math:`r` and effective radius :math:`r_e = r + h^2/r`.
    arc_max_mm_s : ndarray, shape (A,)
        ``ARC_FEED``'s speed limit :math:`v_{\max}`.
    arc_normal_acc_mm_s2 : ndarray, shape (A,)
        The normal acceleration at that limit, :math:`a_v = v_{\max}^2 / r_e`.
    """

    feed_mm_s: np.ndarray
    top_mm_s: np.ndarray
    acc_mm_s2: np.ndarray
    arc: np.ndarray
    radius_mm: np.ndarray
    eff_radius_mm: np.ndarray
    arc_max_mm_s: np.ndarray
    arc_normal_acc_mm_s2: np.ndarray

    @classmethod
    def of(cls, moves: Toolpath, machine: Machine) -> MoveLimits:
        """The limits of M moves of non-zero length (no dwells) on ``machine``."""
        limits = path_limits(moves, machine)
        v_axes = limits.velocity_mm_s
        rapid = moves.kind == MotionKind.RAPID

        def within(feed: np.ndarray) -> np.ndarray:
            feed = np.where(rapid, machine.rapid_feed_mm_s, feed)
            return np.minimum(np.minimum(feed, machine.max_feed_mm_s), v_axes)

        arc = np.flatnonzero(moves.is_arc)
        r = moves.radius_mm[arc]
        ax = moves._plane_axes[arc]
        axis_acc = np.asarray(machine.axis_max_acceleration_mm_s2)
        plane_acc = np.minimum(axis_acc[ax[:, 0]], axis_acc[ax[:, 1]])
        length = moves.lengths_mm[arc]
        planar = r * np.abs(moves.sweep_rad[arc])
        v_max = np.minimum(v_axes[arc], np.sqrt(NORMAL_ACC_RATIO * plane_acc * r) * length / planar)
        rise_sq = np.maximum(length**2 - planar**2, 0.0)
        r_eff = r + rise_sq / r
        return cls(
            feed_mm_s=within(moves.feed_mm_s),
            top_mm_s=within(np.full(len(moves), np.inf)),
            acc_mm_s2=limits.acceleration_mm_s2,
            arc=arc,
            radius_mm=r,
            eff_radius_mm=r_eff,
            arc_max_mm_s=v_max,
            arc_normal_acc_mm_s2=v_max**2 / r_eff,
        )

    def at(
        self,
        acc_scale: np.ndarray | None = None,
        *,
        finalized: np.ndarray | None = None,
        arc_ratio: str = "max_speed",
        top: bool = False,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Feed and tangential acceleration, shapes (M,), as :func:`move_limits` (``top``: of
        the machine's speed limits instead of the programmed feed)."""
        feed = (self.top_mm_s if top else self.feed_mm_s).copy()
        acc = self.acc_mm_s2 * acc_scale if acc_scale is not None else self.acc_mm_s2.copy()
        arc = self.arc
        if not len(arc):
            return feed, acc
        r, a, f = self.radius_mm, acc[arc], feed[arc]
        if arc_ratio == "feed":
            a_normal = f**2 / r
            cut = a_normal > NORMAL_ACC_RATIO * a
            feed[arc] = np.where(cut, np.sqrt(NORMAL_ACC_RATIO * a * r), f)
            ratio = np.sqrt(np.maximum(1.0 - (a_normal / a) ** 2, 0.0))
            acc[arc] = a * np.where(cut, TANGENTIAL_ACC_RATIO, ratio)
            return feed, acc
        if finalized is None:
            finalized = np.arange(len(feed)) < len(feed) - 1
        a_v = self.arc_normal_acc_mm_s2
        done = finalized[arc]
        cut = done & (a_v > NORMAL_ACC_RATIO * a)
        v_max = np.where(cut, np.sqrt(NORMAL_ACC_RATIO * a * self.eff_radius_mm), self.arc_max_mm_s)
        ratio = np.sqrt(np.maximum(1.0 - (a_v / a) ** 2, 0.0))
        ratio = np.where(cut | ~done, TANGENTIAL_ACC_RATIO, ratio)
        feed[arc] = np.minimum(f, v_max)
        acc[arc] = a * ratio
        return feed, acc


def junction_blends(
    length_mm: np.ndarray,
    end_tangents: np.ndarray,
    start_tangents: np.ndarray,
    feed_mm_s: np.ndarray,
    tol_mm: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
    *,
    sized_arcs: bool = True,
    stop_turn_rad: float = STOP_TURN_RAD,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Blend arcs at the junctions of M moves: speed limit, consumed length, arc length, the
    arc's acceleration and its own speed.

    Parameters
    ----------
    length_mm, feed_mm_s : ndarray, shape (M,)
        Length and feed of each move.
    end_tangents, start_tangents : ndarray, shape (M, 3)
        Unit tangent at the end and at the start of each move.
    tol_mm : ndarray, shape (M,)
        Blending tolerance the move starts with (``inf``: no tolerance, 0: exact stop).
    axis_acc_mm_s2 : ndarray, shape (3,)
        Acceleration limit of each axis.
    sized_arcs : bool
        Size each arc for its planned speed (LinuxCNC); False takes the largest arc the
        tolerance and the moves allow (the ablation of the chapter).
    stop_turn_rad : float
        A turn closer than this to a reversal stops the tool (:data:`STOP_TURN_RAD`).

    Returns
    -------
    v_mm_s : ndarray, shape (M - 1,)
        Speed limit at the junction after each move but the last (0: the tool stops).
    d_mm : ndarray, shape (M - 1,)
        Length the blend takes off the end of the move before and the start of the move after
        (0 where no arc is made).
    arc_mm : ndarray, shape (M - 1,)
        Length of the blend arc (0 where none is made).
    acc_mm_s2 : ndarray, shape (M - 1,)
        Acceleration of the blend arc (:func:`blend_plane_acc`; ``inf`` where none is made).
    arc_speed_mm_s : ndarray, shape (M - 1,)
        Speed of the blend arc itself (0 where none is made): LinuxCNC runs the arc as a
        segment of its own at its planned speed, up to the larger of the two feeds
        (``blendComputeParameters``' goal speed); ``v_mm_s``, the smaller of it and both feeds,
        holds at its ends (``tpGetRealFinalVel``).
    """
    l1, l2 = length_mm[:-1], length_mm[1:]
    p = tol_mm[1:]
    limit = TOLERANCE_RATIO * np.minimum(l1, l2)
    tol = np.minimum(np.where(np.isinf(p), limit, p), limit)
    u1, u2 = end_tangents[:-1], start_tangents[1:]
    dot = np.clip(np.einsum("ij,ij->i", u1, u2), -1.0, 1.0)
    theta = np.arccos(-dot) / 2.0
    sin_t = np.sin(theta)
    straight = sin_t >= 1.0 - 1e-12
    acc = blend_plane_acc(u1, u2, axis_acc_mm_s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_tol = np.cos(theta) * tol / (1.0 - sin_t)
        d_geom = np.minimum(np.minimum(l1, l2) / 2.0, d_tol)
        r_plan = np.tan(theta) * d_geom
        a_n = NORMAL_ACC_RATIO * acc
        if sized_arcs:  # the arc is only as large as its planned speed needs
            v_plan = np.minimum(np.sqrt(a_n * r_plan), np.maximum(feed_mm_s[:-1], feed_mm_s[1:]))
            a_para = TANGENTIAL_ACC_RATIO * acc
            t_blend = np.minimum(np.sqrt(2.0 * a_para * d_geom), v_plan) / a_para
            r_blend = np.minimum(t_blend * v_plan / (np.pi - 2.0 * theta), r_plan)
            r_plan = np.maximum(v_plan**2 / a_n, r_blend)
        radius = np.where(straight, np.inf, r_plan)
        d = np.where(straight, d_geom, radius / np.tan(theta))
        v_arc = np.minimum(np.sqrt(a_n * radius), np.maximum(feed_mm_s[:-1], feed_mm_s[1:]))
        v = np.minimum(v_arc, np.minimum(feed_mm_s[:-1], feed_mm_s[1:]))
    v = np.where((p > 0) & (2.0 * theta >= stop_turn_rad), v, 0.0)
    arc = (v > 0) & ~straight
    arc_radius = np.where(arc, radius, 0.0)
    return (
        v,
        np.where(arc, d, 0.0),
        arc_radius * (np.pi - 2.0 * theta),
        acc,
        np.where(arc, v_arc, 0.0),
    )


def tangent_junctions(
    moves: Toolpath,
    feed_mm_s: np.ndarray,
    acc_mm_s2: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
    period_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Junctions of M moves that LinuxCNC passes as tangent (``tpSetupTangent``), (M - 1,).

    Before it makes a blend arc, LinuxCNC asks what the kink would cost: the change of
    direction at the speed :math:`v = \min(v_1, v_2)` (each move's feed within its limits and
    its length per :data:`MIN_SEGMENT_CYCLES` periods) in one servo period, plus the next
    move's acceleration, :math:`\Delta a = (v / T_s + a_2)(u_2 - u_1)`, as a share of each
    axis's limit, :math:`k = \max_i |\Delta a_i| / a_{i,\max}` (doubled where an arc takes
    part). Where :math:`k` < :data:`KINK_RATIO` the junction is tangent: no blend arc, no stop,
    in ``G61`` (exact path) too, and both moves accelerate at :math:`1 - k` of their limit
    (``tcGetOverallMaxAccel``).

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length.
    feed_mm_s, acc_mm_s2 : ndarray, shape (M,)
        Feed and acceleration of each move (:func:`move_limits`).
    axis_acc_mm_s2 : ndarray, shape (3,)
    period_s : float
        Servo period.

    Returns
    -------
    tangent : ndarray of bool, shape (M - 1,)
    kink_share : ndarray, shape (M - 1,)
        :math:`k` of each junction.
    """
    u1, u2 = moves.end_tangents[:-1], moves.start_tangents[1:]
    v = np.minimum(feed_mm_s, moves.lengths_mm / (MIN_SEGMENT_CYCLES * period_s))
    a_inst = np.minimum(v[:-1], v[1:]) / period_s + acc_mm_s2[1:]
    share = np.max(np.abs(a_inst[:, None] * (u2 - u1)) / np.asarray(axis_acc_mm_s2), axis=1)
    arc = moves.is_arc
    share = np.where(arc[:-1] | arc[1:], share / TANGENTIAL_ACC_RATIO, share)
    return share < KINK_RATIO, share


def parabolic_junctions(
    moves: Toolpath,
    tol_mm: np.ndarray,
    stop_turn_rad: float = STOP_TURN_RAD,
    *,
    in_plane: bool = False,
) -> np.ndarray:
    """Junctions of M moves that LinuxCNC joins with a parabolic blend, shape (M - 1,).

    A junction with a circular move gets a blend arc only if the other move lies in the arc's
    plane (two arcs: parallel planes); otherwise ``tpCreateLineArcBlend`` (``ArcLine``,
    ``ArcArc``) fails and ``tpChooseBestBlend`` falls back to a parabolic blend (or, with the
    planner's ``arc_blends``, to a tangent pass where that is faster). Straight-on junctions,
    stops (a tolerance of 0, a near-reversal) and line-line junctions are not parabolic.
    ``in_plane=True`` keeps the junctions in the arc's plane too: every junction with an arc
    that is blended somehow.
    """
    m = len(moves)
    arc = moves.is_arc
    normal = np.zeros((m, 3))
    normal[np.arange(m), moves._plane_axes[:, 2]] = 1.0  # of the arc's plane
    u1, u2 = moves.end_tangents[:-1], moves.start_tangents[1:]
    b = np.cross(u1, u2)
    size = np.linalg.norm(b, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = b / size[:, None]

    def parallel(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.abs(np.abs(np.einsum("ij,ij->i", x, y)) - 1.0) < 1e-6

    planar = (parallel(b, normal[:-1]) | ~arc[:-1]) & (parallel(b, normal[1:]) | ~arc[1:])
    planar &= ~(arc[:-1] & arc[1:]) | parallel(normal[:-1], normal[1:])
    dot = np.clip(np.einsum("ij,ij->i", u1, u2), -1.0, 1.0)
    straight = dot >= 1.0 - 1e-12
    reversal = np.arccos(-dot) < stop_turn_rad  # stops
    blended = (arc[:-1] | arc[1:]) & (tol_mm[1:] > 0) & ~straight & ~reversal
    return blended if in_plane else blended & ~planar


def parabolic_blend_speeds(
    length_mm: np.ndarray,
    feed_mm_s: np.ndarray,
    acc_mm_s2: np.ndarray,
    end_tangents: np.ndarray,
    start_tangents: np.ndarray,
    tol_mm: np.ndarray,
) -> np.ndarray:
    r"""Speed at the junctions of M moves if they were joined by parabolic blends, (M - 1,).

    ``tpComputeBlendVelocity`` with the halved accelerations :math:`a_1, a_2`: each move's
    reachable speed :math:`v_{r,i} = \min(\sqrt{a_i L_i}, F_i)`, the blend time
    :math:`t_b = \min(L_1/v_{r,1}, L_2/v_{r,2}, \max(v_{r,1}/a_1, v_{r,2}/a_2))`, and the
    speed :math:`v_i = \min(v_{r,i}, a_i t_b, 2\sqrt{a_1 T / \cos\theta})`. The move before
    stops over :math:`v_1/a_1` while the next speeds up (``tpUpdateBlend``), at most to
    :math:`v_2`: the junction is passed as if at :math:`\min(v_1, v_2, a_2 v_1 / a_1)`.
    """
    l1, l2, a1, a2 = length_mm[:-1], length_mm[1:], acc_mm_s2[:-1], acc_mm_s2[1:]
    vr1 = np.minimum(np.sqrt(a1 * l1), feed_mm_s[:-1])
    vr2 = np.minimum(np.sqrt(a2 * l2), feed_mm_s[1:])
    t_blend = np.minimum(np.minimum(l1 / vr1, l2 / vr2), np.maximum(vr1 / a1, vr2 / a2))
    dot = np.clip(np.einsum("ij,ij->i", end_tangents[:-1], start_tangents[1:]), -1.0, 1.0)
    cos_t = np.cos(np.arccos(-dot) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_tol = np.where(cos_t > 1e-3, 2.0 * np.sqrt(a1 * tol_mm[1:] / cos_t), np.inf)
    v1 = np.minimum(np.minimum(vr1, t_blend * a1), v_tol)
    v2 = np.minimum(np.minimum(vr2, t_blend * a2), v_tol)
    return np.minimum(v1, np.minimum(v2, a2 * v1 / a1))
