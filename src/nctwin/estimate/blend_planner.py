r"""Cycle time on a look-ahead planner with circular blend arcs and no jerk limit (LinuxCNC-like).

An analytic model of the kind of trajectory planner LinuxCNC has (its "blend arc" planner): the
path is a chain of moves; every junction is rounded by a circular arc within the blending
tolerance, which replaces the last and first stretch of the two moves; the speed through the arc
is limited by the normal acceleration; along lines and arcs the speed follows trapezoids under
a tangential acceleration limit; look-ahead propagates every limit backward and forward. Nothing
is fitted to the recordings: the rules and constants are those of LinuxCNC's planner source
(``src/emc/tp/blendmath.c``, ``tc.c``), stated here as facts, and where its behaviour was not
clear from the source it was measured on LinuxCNC with short test programs (below).

Junction :math:`j` between moves of length :math:`L_1, L_2` with unit directions
:math:`u_1, u_2`:

* the half supplement of the turn, :math:`\theta = \arccos(-u_1 \cdot u_2) / 2`
  (:math:`\pi/2` straight on, 0 for a reversal);
* the tolerance :math:`T = \min(P, r L_1, r L_2)` with :math:`r = 1/4`, where :math:`P` is the
  ``G64 P`` in force and a plain ``G64`` (no tolerance) means :math:`P = r L` of the move;
* the largest distance from the corner along the lines the tolerance allows,
  :math:`d_{tol} = \cos\theta \, T / (1 - \sin\theta)`, and at most half of each move,
  :math:`d = \min(d_{tol}, L_1/2, L_2/2)`; the blend radius :math:`R = d \tan\theta`, the arc
  length :math:`R (\pi - 2\theta)`, and each move is shortened by :math:`d`;
* the speed through the arc :math:`v_j = \min(\sqrt{a_n R}, F_1, F_2)` with the normal
  acceleration :math:`a_n = \sqrt{1 - 0.5^2}\, a` and the tangential :math:`a/2` (LinuxCNC's
  ``acc_ratio_tan``), :math:`a` the path acceleration the axes allow
  (:math:`\min_i a_{i,\max} / |u_i|`, the smaller of the two moves);
* ``G61``/``G61.1``, a dwell and the program's ends stop the tool (:math:`v_j = 0`), and so does
  a turn within :data:`STOP_TURN_RAD` of a reversal (:math:`2\theta` below it): measured on
  LinuxCNC, turns of :math:`\pi` - 0.002 to :math:`\pi` - 0.02 rad stop at the corner and
  :math:`\pi` - 0.05 rad is blended (its source's own arc limit is 0.001 rad; what rejects
  the others is not modelled).

Along a line the tangential acceleration is the full :math:`a`, through straight-on junctions
too (LinuxCNC halves it only for a parabolic blend, ``tcGetOverallMaxAccel``), except on a move
that keeps the parabolic end condition it was queued with while blending is on: the move that
ends the program or runs into a dwell. That move accelerates and brakes at :math:`a/2`, and it
is entered at most at its triangle speed :math:`\sqrt{a L / 2}`.
Look-ahead: :math:`v_{j+1} \le \sqrt{v_j^2 + 2 a_k L_k}` forward and backward over lines and
arcs. Segment time: the trapezoid (or triangle) from :math:`v_j` to :math:`v_{j+1}` under the
feed; a move (its line and half of each of its arcs) takes at least one servo period (the
planner completes at most one move per cycle). Arcs of the program are taken as chords
(:func:`nctwin.realkernel.model_blocks`).

Measured on LinuxCNC (``linuxcnc_sim``, recorded live; model in brackets): one 60 mm line at
50 mm/s in the default ``G64``: 1.301 s (1.300); a 90° corner of two 100 mm lines at 50 mm/s,
``G64 P0.1``: 4.131 s (4.130), with a 0.5 s dwell instead of the blend: 4.704 s (4.700), under
``G61``: 4.113 s (4.100); six 10 mm lines with 90° corners at 100 mm/s, ``G64 P0.1``: 1.244 s
(1.242); 120° and 90° corners at 150 mm/s, ``G64 P0.5``: 1.082 s (1.080); four 25.4 mm moves
that turn back within 0.002 rad, plain ``G64``: 1.519 s (1.516); collinear chains at 200 mm/s,
plain ``G64``: 300 x 1 mm 1.740 s (1.739), 10 x 5 mm 0.528 s (0.526), 3 x 20 mm 0.616 s
(0.615). The recorded speed traces show the full acceleration on lines, through straight-on
junctions, into arcs and stops, the arc speed :math:`v_j`, and :math:`a/2` on the last move,
entered at its triangle speed. The model misses two collinear lines (1.301 s, model 1.275: LinuxCNC
runs the first at :math:`a/2` too) and 300 collinear 0.2 mm lines (0.584 s, model 0.519:
LinuxCNC holds 142 mm/s on them, not 200). The live tests of :mod:`nctwin.kernel.linuxcnc`
check four of these programs.

Not modelled: the naive-CAM merging of ``G64 Q``, the parabolic blends LinuxCNC falls back to
where no arc fits, the arc blends between circular moves, and what limits the speed on chains of
moves a few servo periods long.
"""

from __future__ import annotations

import math

import numpy as np

from ..machine import MachineProfile
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


def junction_blends(
    length_mm: np.ndarray,
    directions: np.ndarray,
    feed_mm_s: np.ndarray,
    acc_mm_s2: np.ndarray,
    tol_mm: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Blend arcs at the junctions of M moves: speed limit, consumed length and arc length.

    Parameters
    ----------
    length_mm, feed_mm_s, acc_mm_s2 : ndarray, shape (M,)
        Length, feed and path acceleration of each move.
    directions : ndarray, shape (M, 3)
        Unit direction of each move.
    tol_mm : ndarray, shape (M,)
        Blending tolerance the move starts with (``inf``: no tolerance, 0: exact stop).

    Returns
    -------
    v_mm_s : ndarray, shape (M - 1,)
        Speed limit at the junction after each move but the last (0: the tool stops).
    d_mm : ndarray, shape (M - 1,)
        Length the blend takes off the end of the move before and the start of the move after
        (0 where no arc is made).
    arc_mm : ndarray, shape (M - 1,)
        Length of the blend arc (0 where none is made).
    """
    l1, l2 = length_mm[:-1], length_mm[1:]
    p = tol_mm[1:]
    limit = TOLERANCE_RATIO * np.minimum(l1, l2)
    tol = np.minimum(np.where(np.isinf(p), limit, p), limit)
    dot = np.clip(np.einsum("ij,ij->i", directions[:-1], directions[1:]), -1.0, 1.0)
    theta = np.arccos(-dot) / 2.0
    sin_t = np.sin(theta)
    straight = sin_t >= 1.0 - 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        d_tol = np.cos(theta) * tol / (1.0 - sin_t)
        d = np.minimum(np.minimum(l1, l2) / 2.0, d_tol)
        radius = np.where(straight, np.inf, np.tan(theta) * d)
    a_n = NORMAL_ACC_RATIO * np.minimum(acc_mm_s2[:-1], acc_mm_s2[1:])
    v = np.minimum(np.sqrt(a_n * radius), np.minimum(feed_mm_s[:-1], feed_mm_s[1:]))
    v = np.where((p > 0) & (2.0 * theta >= STOP_TURN_RAD), v, 0.0)
    arc = (v > 0) & ~straight
    arc_radius = np.where(arc, radius, 0.0)
    return v, np.where(arc, d, 0.0), arc_radius * (np.pi - 2.0 * theta)


def segment_times(
    length_mm: np.ndarray, feed_mm_s: np.ndarray, acc_mm_s2: np.ndarray, v_mm_s: np.ndarray
) -> np.ndarray:
    """Times of S segments from rest to rest through junction speed limits, with look-ahead.

    Parameters
    ----------
    length_mm, feed_mm_s, acc_mm_s2 : ndarray, shape (S,)
        Length, feed and tangential acceleration of each segment.
    v_mm_s : ndarray, shape (S - 1,)
        Speed limits at the junctions.

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
    from ..realkernel import features, model_blocks  # the moves as the chapter's methods see them

    moves, source = model_blocks(toolpath)
    if not len(moves):
        return Estimate("planner", machine.name, toolpath.dwell_s.copy(), toolpath)
    x = features(moves, machine)
    feed, length, acc = x[:, 0], x[:, 1], x[:, 5]
    tol = moves.effective_tolerance_mm(machine.blend_tol_mm)
    # a dwell between two moves stops the tool; the move before it keeps its parabolic end
    after = np.searchsorted(source, np.flatnonzero(toolpath.kind == MotionKind.DWELL))
    parabolic_end = np.zeros(len(moves), bool)
    parabolic_end[after[(after > 0) & (after <= len(moves))] - 1] = True
    parabolic_end[-1] = True
    parabolic_end &= tol > 0
    tol[after[after < len(moves)]] = 0.0
    v, d, arc = junction_blends(length, moves.directions, feed, acc, tol)
    # a move with a parabolic end runs at a / 2 and is entered at most at its triangle speed
    a_line = acc * np.where(parabolic_end, TANGENTIAL_ACC_RATIO, 1.0)
    v = np.where(parabolic_end[1:], np.minimum(v, np.sqrt(a_line * length)[1:]), v)
    # the chain line 0, arc 0, line 1, ..., line M-1, with the arcs of unblended junctions empty
    m = len(moves)
    seg_len = np.empty(2 * m - 1)
    seg_len[0::2] = length - np.concatenate([[0.0], d]) - np.concatenate([d, [0.0]])
    seg_len[1::2] = arc
    seg_acc = np.empty(2 * m - 1)
    seg_acc[0::2] = a_line
    seg_acc[1::2] = TANGENTIAL_ACC_RATIO * np.minimum(acc[:-1], acc[1:])
    seg_feed = np.empty(2 * m - 1)
    seg_feed[0::2] = feed
    seg_feed[1::2] = np.where(arc > 0, v, np.minimum(feed[:-1], feed[1:]))
    t = segment_times(seg_len, seg_feed, seg_acc, np.repeat(v, 2))
    move_t = t[0::2] + np.concatenate([[0.0], t[1::2] / 2]) + np.concatenate([t[1::2] / 2, [0.0]])
    move_t = np.maximum(move_t, machine.period_s)
    block_t = np.bincount(source, weights=move_t, minlength=len(toolpath)) + toolpath.dwell_s
    return Estimate("planner", machine.name, block_t, toolpath)
