r"""Cycle time on a look-ahead planner with circular blend arcs and no jerk limit (LinuxCNC-like).

An analytic model of the kind of trajectory planner LinuxCNC 2.9 has (its "blend arc" planner):
the path is a queue of items, the moves and the circular arcs that round their junctions within
the blending tolerance; along every item the speed follows a trapezoid under a tangential
acceleration limit; look-ahead propagates every limit backward and forward. Nothing is fitted to
the recordings: the rules and constants are those of LinuxCNC's source (``emccanon.cc``,
``src/emc/tp/tp.c``, ``blendmath.c``, ``tc.c``; function names below), stated here as facts,
and where its behaviour was not clear from the source it was measured on LinuxCNC with short
test programs (below).

**What the planner receives.** LinuxCNC's canon first merges chains of straight feed moves that
lie within the naive-CAM tolerance ``G64 Q`` of one line (:func:`nctwin.naivecam.merge_naive_cam`).
The moves are the lines, rapids and arcs (whole) of non-zero length; feed and tangential
acceleration per move come from :func:`move_limits` (an arc keeps within its centripetal limit).

**Junction** :math:`j` between moves of length :math:`L_1, L_2`, the first ending along the unit
tangent :math:`u_1`, the second starting along :math:`u_2`:

* the half supplement of the turn, :math:`\theta = \arccos(-u_1 \cdot u_2) / 2`
  (:math:`\pi/2` straight on, 0 for a reversal);
* the tolerance :math:`T = \min(P, r L_1, r L_2)` with :math:`r = 1/4`, where :math:`P` is the
  ``G64 P`` in force and a plain ``G64`` (no tolerance) means :math:`P = r L` of the move;
* the largest distance from the corner along the moves the tolerance allows,
  :math:`d_{tol} = \cos\theta \, T / (1 - \sin\theta)`, and at most half of each move,
  :math:`d = \min(d_{tol}, L_1/2, L_2/2)`; the blend radius :math:`R = d \tan\theta`, the arc
  length :math:`R (\pi - 2\theta)`, and each move is shortened by :math:`d`;
* the blend arc's acceleration is that of its plane (``blendParamKinematics``,
  ``calculateInscribedDiameter``): :math:`a_j = \min_i a_{i,\max} / \sqrt{1 - n_i^2}` with
  :math:`n` the unit normal of the plane of :math:`u_1, u_2` (:func:`blend_plane_acc`: 1000
  mm/s² for any turn in XY on ``linuxcnc_sim``, 500 in any plane that holds Z);
* the speed through the arc :math:`v_j = \min(\sqrt{a_n R}, F_1, F_2)` with
  :math:`a_n = \sqrt{1 - 0.5^2}\, a_j` and the tangential :math:`a_j/2` (``acc_ratio_tan``);
* ``G61``/``G61.1``, a dwell, a change between rapid and feed motion (``tpCheckCanonType``) and
  the program's ends stop the tool (:math:`v_j = 0`), and so does a turn within
  :data:`STOP_TURN_RAD` of a reversal (:math:`2\theta` below it): measured on LinuxCNC, turns
  of :math:`\pi` - 0.002 to :math:`\pi` - 0.02 rad stop at the corner and :math:`\pi` - 0.05
  rad is blended (its source's own arc limit is 0.001 rad; what rejects the others is not
  modelled);
* a line's remainder between two arcs that the next arc would pass in under
  :data:`GAP_CYCLES` servo periods becomes part of that arc (``blendCheckConsume``).

**Items.** Along a line the tangential acceleration is the full :math:`a` the axes allow
(:math:`\min_i a_{i,\max} / |u_i|`), through straight-on junctions too (LinuxCNC halves it only
for a parabolic blend, ``tcGetOverallMaxAccel``), except on a move that keeps the parabolic end
condition it was queued with while blending is on: the move that ends the program or runs into
a dwell. That move accelerates and brakes at :math:`a/2`, and it is entered at most at its
triangle speed :math:`\sqrt{a L / 2}`. Every item runs at most at its length over
:data:`MIN_SEGMENT_CYCLES` servo periods (``tpComputeOptimalVelocity``), and the end of each is
no faster than the look-ahead's depth allows (:func:`depth_limits`, ``tpRunOptimization``:
:data:`OPTIMIZATION_DEPTH` items). Look-ahead: :math:`v_{j+1} \le \sqrt{v_j^2 + 2 a_k L_k}`
forward and backward over the items. Item time: the trapezoid (or triangle) from :math:`v_j` to
:math:`v_{j+1}` under the feed.

Measured on LinuxCNC (``linuxcnc_sim``, recorded live; model in brackets): one 60 mm line at
50 mm/s in the default ``G64``: 1.301 s (1.300); a 90° corner of two 100 mm lines at 50 mm/s,
``G64 P0.1``: 4.131 s (4.130), with a 0.5 s dwell instead of the blend: 4.704 s (4.700), under
``G61``: 4.113 s (4.100); six 10 mm lines with 90° corners at 100 mm/s, ``G64 P0.1``: 1.244 s
(1.242); 120° and 90° corners at 150 mm/s, ``G64 P0.5``: 1.082 s (1.080); four 25.4 mm moves
that turn back within 0.002 rad, plain ``G64``: 1.519 s (1.516); collinear chains at 200 mm/s,
plain ``G64``: 300 x 1 mm 1.740 s (1.739), 10 x 5 mm 0.528 s (0.526), 3 x 20 mm 0.616 s
(0.615), 300 x 0.2 mm 0.583 s (0.582, held at 142 mm/s by the depth), 300 x 0.05 mm 0.364 s
(0.364, held at 49 mm/s by the item length); zigzags of 45° moves, 20 x 5 mm in XY at
``G64 P0.5``: 2.237 s (2.237), 20 x 1 mm in XZ: 1.109 s (1.108); a rapid then a feed move:
0.483 s (0.483); a G2 quarter circle of 10 mm radius under ``G61``: 0.355 s (0.355). Naive-CAM
merging: 300 moves of 0.01-0.1 mm with 2° turns under ``G64 P0.01`` 0.407 s (0.412); the
public programs Cereal, Pasta and wheels, whose lines LinuxCNC reports are exactly those of the
merged moves. The model misses two collinear lines (1.301 s, model 1.275: LinuxCNC runs the
first at :math:`a/2` too) and 200 moves wiggling 0.004 mm about a line under ``G64 P0.01``,
merged into two lines (0.254 s, model 0.273). The live tests of :mod:`nctwin.kernel.linuxcnc`
check seven of these programs.

Not modelled: the parabolic blends LinuxCNC falls back to where no arc fits, its own blends
between a line and an arc or two arcs (here the line-line formula on the tangents), and helical
arcs' effective radius.
"""

from __future__ import annotations

import math

import numpy as np

from ..machine import MachineProfile
from ..naivecam import merge_naive_cam
from ..toolpath import MotionKind, Toolpath
from .result import Estimate

__all__ = [
    "NORMAL_ACC_RATIO",
    "STOP_TURN_RAD",
    "TANGENTIAL_ACC_RATIO",
    "TOLERANCE_RATIO",
    "blend_planner",
]

#: Share of the acceleration kept for the tangential direction in a blend arc, and on a move
#: with a parabolic end.
TANGENTIAL_ACC_RATIO = 0.5
#: Share of the acceleration available for the normal direction in a blend arc.
NORMAL_ACC_RATIO = math.sqrt(1.0 - TANGENTIAL_ACC_RATIO**2)
#: Largest blend tolerance as a share of each of the two moves' lengths.
TOLERANCE_RATIO = 0.25
#: A turn this close to a reversal (rad) stops the tool instead of being blended (measured).
STOP_TURN_RAD = 0.02
#: An item runs at most at its length over this many servo periods (``TP_MIN_SEGMENT_CYCLES``).
MIN_SEGMENT_CYCLES = 1.02
#: Items the look-ahead walks back from the newest one (``ARC_BLEND_OPTIMIZATION_DEPTH``).
OPTIMIZATION_DEPTH = 50
#: A line remainder shorter than this many periods at the next arc's speed joins the arc
#: (``ARC_BLEND_GAP_CYCLES``).
GAP_CYCLES = 4


def move_limits(moves: Toolpath, machine: MachineProfile) -> tuple[np.ndarray, np.ndarray]:
    r"""Feed and tangential acceleration of each move as LinuxCNC plans it, shapes (M,).

    Lines and rapids: the feed (the rapid feed for rapids) within the control's maximum and
    the axes' velocities, :math:`\min_i v_{i,\max} / |u_i|`, and the path acceleration the
    axes allow, :math:`\min_i a_{i,\max} / |u_i|` (canon's ``getStraightAcceleration``).
    Arcs: the same with the plane's two axes taking the planar share of the length and the
    third the helical share; then the centripetal limit of ``pmCircleActualMaxVel``: the speed
    stays within :math:`\sqrt{a_n r}` with :math:`a_n` = :data:`NORMAL_ACC_RATIO` :math:`a`,
    and the tangential acceleration is :math:`a/2` where that limit binds, else
    :math:`a \sqrt{1 - (F^2 / (r a))^2}`.

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length (no dwells).
    machine : MachineProfile
    """
    vmax = np.asarray(machine.axis_max_velocity_mm_s)
    amax = np.asarray(machine.axis_max_acceleration_mm_s2)
    share = np.abs(moves.directions)  # of each axis in the move's length
    arc = np.flatnonzero(moves.is_arc)
    if len(arc):
        ax = moves._plane_axes[arc]
        rows = np.arange(len(arc))
        planar = moves.radius_mm[arc] * np.abs(moves.sweep_rad[arc]) / moves.lengths_mm[arc]
        s = np.empty((len(arc), 3))
        s[rows, ax[:, 0]] = planar
        s[rows, ax[:, 1]] = planar
        s[rows, ax[:, 2]] = np.sqrt(np.maximum(1.0 - planar**2, 0.0))
        share[arc] = s
    with np.errstate(divide="ignore"):
        v_axes = np.min(vmax / share, axis=1)
        acc = np.min(amax / share, axis=1)
    rapid = moves.kind == MotionKind.RAPID
    feed = np.where(rapid, machine.rapid_feed_mm_s, moves.feed_mm_s)
    feed = np.minimum(np.minimum(feed, machine.max_feed_mm_s), v_axes)
    if len(arc):
        r, a, f = moves.radius_mm[arc], acc[arc], feed[arc]
        a_normal = f**2 / r
        cut = a_normal > NORMAL_ACC_RATIO * a
        feed[arc] = np.where(cut, np.sqrt(NORMAL_ACC_RATIO * a * r), f)
        ratio = np.sqrt(np.maximum(1.0 - (a_normal / a) ** 2, 0.0))
        acc[arc] = a * np.where(cut, TANGENTIAL_ACC_RATIO, ratio)
    return feed, acc


def blend_plane_acc(u1: np.ndarray, u2: np.ndarray, axis_acc_mm_s2: np.ndarray) -> np.ndarray:
    r"""Acceleration of blend arcs in the plane of two directions (LinuxCNC's
    ``calculateInscribedDiameter``): :math:`\min_i a_{i,\max} / \sqrt{1 - n_i^2}` with
    :math:`n = u_1 \times u_2 / |u_1 \times u_2|` the plane's normal; ``inf`` where the
    directions are parallel (no plane).

    Parameters
    ----------
    u1, u2 : ndarray, shape (K, 3)
        Unit directions of the moves before and after each junction.
    axis_acc_mm_s2 : ndarray, shape (3,)

    Returns
    -------
    ndarray, shape (K,)
    """
    n = np.cross(u1, u2)
    norm = np.linalg.norm(n, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        n = n / norm[:, None]
        in_plane = np.sqrt(np.maximum(1.0 - n**2, 0.0))  # share of each axis in the plane
        acc = np.min(np.asarray(axis_acc_mm_s2) / in_plane, axis=1)
    return np.where(norm > 0, acc, np.inf)


def junction_blends(
    length_mm: np.ndarray,
    end_tangents: np.ndarray,
    start_tangents: np.ndarray,
    feed_mm_s: np.ndarray,
    tol_mm: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Blend arcs at the junctions of M moves: speed limit, consumed length, arc length and the
    arc's acceleration.

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
        d = np.minimum(np.minimum(l1, l2) / 2.0, d_tol)
        radius = np.where(straight, np.inf, np.tan(theta) * d)
        v = np.minimum(
            np.sqrt(NORMAL_ACC_RATIO * acc * radius), np.minimum(feed_mm_s[:-1], feed_mm_s[1:])
        )
    v = np.where((p > 0) & (2.0 * theta >= STOP_TURN_RAD), v, 0.0)
    arc = (v > 0) & ~straight
    arc_radius = np.where(arc, radius, 0.0)
    return v, np.where(arc, d, 0.0), arc_radius * (np.pi - 2.0 * theta), acc


def segment_times(
    length_mm: np.ndarray, feed_mm_s: np.ndarray, acc_mm_s2: np.ndarray, v_mm_s: np.ndarray
) -> np.ndarray:
    """Times of S segments from rest to rest through junction speed limits, with look-ahead.

    Parameters
    ----------
    length_mm, feed_mm_s, acc_mm_s2 : ndarray, shape (S,)
        Length, feed and tangential acceleration of each segment.
    v_mm_s : ndarray, shape (S - 1,)
        Speed limits at the junctions, none above the feed on either side.

    Returns
    -------
    ndarray, shape (S,)
    """
    v = np.concatenate([[0.0], v_mm_s, [0.0]]).tolist()
    two_al = (2.0 * acc_mm_s2 * length_mm).tolist()
    for k in range(len(two_al)):  # forward: reachable from the junction before
        v[k + 1] = min(v[k + 1], math.sqrt(v[k] * v[k] + two_al[k]))
    for k in range(len(two_al) - 1, -1, -1):  # backward: the tool can still stop in time
        v[k] = min(v[k], math.sqrt(v[k + 1] * v[k + 1] + two_al[k]))
    v = np.asarray(v)
    v0, v1, a = v[:-1], v[1:], acc_mm_s2
    peak = np.minimum(feed_mm_s, np.sqrt((2.0 * a * length_mm + v0**2 + v1**2) / 2.0))
    cruise = length_mm - (2.0 * peak**2 - v0**2 - v1**2) / (2.0 * a)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (2.0 * peak - v0 - v1) / a + np.maximum(cruise, 0.0) / peak
    return np.where(length_mm > 0, t, 0.0)


def depth_limits(length_mm: np.ndarray, acc_mm_s2: np.ndarray) -> np.ndarray:
    r"""Speed limit at the end of each of S queue items from the look-ahead's depth.

    LinuxCNC's optimiser (``tpRunOptimization``) walks back :data:`OPTIMIZATION_DEPTH` items
    from the newest one, which may end no faster than it can stop at :math:`a/2` (its
    parabolic end): the end of item :math:`k` is last raised when item :math:`k + D + 1` is
    queued, to :math:`v_k^2 = \sum_{j=k+1}^{k+D} 2 a_j L_j + a_{k+D+1} L_{k+D+1} / 2`. ``inf``
    where that window reaches the end of the program (the stop there is the look-ahead's).

    Parameters
    ----------
    length_mm, acc_mm_s2 : ndarray, shape (S,)

    Returns
    -------
    ndarray, shape (S,)
    """
    n, depth = len(length_mm), OPTIMIZATION_DEPTH
    c = np.concatenate([[0.0], np.cumsum(2.0 * acc_mm_s2 * length_mm)])
    k = np.arange(n - depth - 1)
    newest = k + depth + 1
    v2 = c[newest] - c[k + 1] + 0.5 * acc_mm_s2[newest] * length_mm[newest]
    return np.concatenate([np.sqrt(v2), np.full(n - len(k), np.inf)])


def blend_planner(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    """Cycle time on the blend-arc look-ahead planner (see the module docstring).

    Parameters
    ----------
    toolpath : Toolpath
        N blocks (arcs are taken as chords).
    machine : MachineProfile
        Axis velocity and acceleration limits, maximum and rapid feed, period, tolerance.

    Returns
    -------
    Estimate
        ``method="planner"``, per-block times of shape (N,) (a dwell its own time; a blend arc's
        time is shared by the two moves it joins).
    """
    merged, merged_source = merge_naive_cam(toolpath)
    source = np.flatnonzero((merged.kind != MotionKind.DWELL) & (merged.lengths_mm > 0))
    if not len(source):
        return Estimate("planner", machine.name, toolpath.dwell_s.copy(), toolpath)
    moves = merged.take(source)
    length = moves.lengths_mm
    feed, acc = move_limits(moves, machine)
    tol = moves.effective_tolerance_mm(machine.blend_tol_mm)
    # a dwell between two moves stops the tool; the move before it keeps its parabolic end
    after = np.searchsorted(source, np.flatnonzero(merged.kind == MotionKind.DWELL))
    parabolic_end = np.zeros(len(moves), bool)
    parabolic_end[after[(after > 0) & (after <= len(moves))] - 1] = True
    parabolic_end[-1] = True
    parabolic_end &= tol > 0
    tol[after[after < len(moves)]] = 0.0
    # LinuxCNC does not blend between a rapid and a feed move: the tool stops (tpCheckCanonType)
    rapid = moves.kind == MotionKind.RAPID
    tol[1:][rapid[1:] != rapid[:-1]] = 0.0
    axis_acc = np.asarray(machine.axis_max_acceleration_mm_s2)
    v, d, arc, arc_acc = junction_blends(
        length, moves.end_tangents, moves.start_tangents, feed, tol, axis_acc
    )
    # a move with a parabolic end runs at a / 2 and is entered at most at its triangle speed
    a_line = acc * np.where(parabolic_end, TANGENTIAL_ACC_RATIO, 1.0)
    v = np.where(parabolic_end[1:], np.minimum(v, np.sqrt(a_line * length)[1:]), v)
    # the queue: line 0, arc 0, line 1, ..., line M-1; the arcs of unblended junctions empty
    m = len(moves)
    item_len = np.empty(2 * m - 1)
    item_len[0::2] = length - np.concatenate([[0.0], d]) - np.concatenate([d, [0.0]])
    item_len[1::2] = arc
    # a line remainder the next arc passes in under GAP_CYCLES periods becomes part of it
    rem = item_len[0:-1:2]
    with np.errstate(divide="ignore", invalid="ignore"):
        eat = (arc > 0) & (rem < GAP_CYCLES * machine.period_s * v)
    item_len[1::2] += np.where(eat, rem, 0.0)
    item_len[0:-1:2] = np.where(eat, 0.0, rem)
    item_acc = np.empty(2 * m - 1)
    item_acc[0::2] = a_line
    item_acc[1::2] = TANGENTIAL_ACC_RATIO * np.where(arc > 0, arc_acc, 0.0)
    item_feed = np.empty(2 * m - 1)
    item_feed[0::2] = feed
    item_feed[1::2] = v
    end_limit = np.append(np.repeat(v, 2), 0.0)  # at the end of each item
    # the items LinuxCNC queues: the non-empty ones; an empty one passes its limit on
    keep = np.flatnonzero(item_len > 0)
    group = np.searchsorted(keep, np.arange(2 * m - 1))  # item each empty one ends into
    limit = np.full(len(keep), np.inf)
    np.minimum.at(limit, np.minimum(group, len(keep) - 1), end_limit)
    q_len, q_acc = item_len[keep], item_acc[keep]
    q_feed = np.minimum(item_feed[keep], q_len / (MIN_SEGMENT_CYCLES * machine.period_s))
    limit = np.minimum(limit, depth_limits(q_len, q_acc))
    limit = np.minimum(limit[:-1], np.minimum(q_feed[:-1], q_feed[1:]))
    t = np.zeros(2 * m - 1)
    t[keep] = segment_times(q_len, q_feed, q_acc, limit)
    move_t = t[0::2] + np.concatenate([[0.0], t[1::2] / 2]) + np.concatenate([t[1::2] / 2, [0.0]])
    block_t = np.bincount(merged_source[source], weights=move_t, minlength=len(toolpath))
    block_t += toolpath.dwell_s
    return Estimate("planner", machine.name, block_t, toolpath)
