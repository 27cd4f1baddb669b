r"""Cycle time on a look-ahead planner with circular blend arcs and no jerk limit (LinuxCNC-like).

An analytic model of the kind of trajectory planner LinuxCNC has (its "blend arc" planner): the
path is a chain of moves; every junction is rounded by a circular arc within the blending
tolerance; the speed through the arc is limited by the normal acceleration; between junctions the
speed follows a trapezoid under a tangential acceleration limit; look-ahead propagates every
limit backward and forward. Nothing is fitted: the rules and constants are those the LinuxCNC
planner documents in its source (``src/emc/tp/blendmath.c``), stated here as facts.

Junction :math:`j` between moves of length :math:`L_1, L_2` with unit directions
:math:`u_1, u_2`:

* the half supplement of the turn, :math:`\theta = \arccos(-u_1 \cdot u_2) / 2`
  (:math:`\pi/2` straight on, 0 for a reversal);
* the tolerance :math:`T = \min(P, r L_1, r L_2)` with :math:`r = 1/4`, where :math:`P` is the
  ``G64 P`` in force and a plain ``G64`` (no tolerance) means :math:`P = r L` of the move;
* the largest distance from the corner along the lines the tolerance allows,
  :math:`d_{tol} = \cos\theta \, T / (1 - \sin\theta)`, and at most half of each move,
  :math:`d = \min(d_{tol}, L_1/2, L_2/2)`; the blend radius :math:`R = d \tan\theta`;
* the speed through the arc :math:`v_j = \min(\sqrt{a_n R}, F_1, F_2)` with the normal
  acceleration :math:`a_n = \sqrt{1 - 0.5^2}\, a` (LinuxCNC keeps half the acceleration for the
  tangential direction during a blend), :math:`a` the path acceleration the axes allow
  (:math:`\min_i a_{i,\max} / |u_i|`, the smaller of the two moves);
* ``G61``/``G61.1``, a dwell and the program's ends stop the tool (:math:`v_j = 0`).

Along move :math:`k` the tangential acceleration is :math:`a/2` where an end of the move is
blended, :math:`a` where both ends stop. Look-ahead: :math:`v_{j+1} \le \sqrt{v_j^2 + 2 a_k L_k}`
forward and backward. Move time: the trapezoid (or triangle) from :math:`v_j` to :math:`v_{j+1}`
under the feed, at least one servo period (the planner completes at most one move per cycle).
Arcs are taken as chords (:func:`nctwin.realkernel.model_blocks`).

Not modelled: the naive-CAM merging of ``G64 Q``, the parabolic blends LinuxCNC falls back to
where no arc fits (near-reversals), and the arc blends between circular moves.
"""

from __future__ import annotations

import math

import numpy as np

from ..machine import MachineProfile
from ..toolpath import MotionKind, Toolpath
from .result import Estimate

__all__ = ["NORMAL_ACC_RATIO", "TANGENTIAL_ACC_RATIO", "TOLERANCE_RATIO", "blend_planner"]

#: Share of the acceleration kept for the tangential direction during a blend.
TANGENTIAL_ACC_RATIO = 0.5
#: Share of the acceleration available for the normal direction in a blend arc.
NORMAL_ACC_RATIO = math.sqrt(1.0 - TANGENTIAL_ACC_RATIO**2)
#: Largest blend tolerance as a share of each of the two moves' lengths.
TOLERANCE_RATIO = 0.25


def junction_speeds(
    length_mm: np.ndarray,
    directions: np.ndarray,
    feed_mm_s: np.ndarray,
    acc_mm_s2: np.ndarray,
    tol_mm: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Blend-arc speed limits at the junctions of M moves, before look-ahead.

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
        Speed limit at the junction after each move but the last.
    blended : ndarray of bool, shape (M - 1,)
        Whether the junction is rounded by a blend arc.
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
    v = np.where(p > 0, v, 0.0)
    return v, (p > 0) & ~straight & (radius > 0)


def move_times(
    length_mm: np.ndarray, feed_mm_s: np.ndarray, acc_mm_s2: np.ndarray, v_mm_s: np.ndarray,
    period_s: float,
) -> np.ndarray:  # fmt: skip
    """Times of M moves from rest to rest through junction speed limits, with look-ahead.

    Parameters
    ----------
    length_mm, feed_mm_s, acc_mm_s2 : ndarray, shape (M,)
        Length, feed and tangential acceleration of each move.
    v_mm_s : ndarray, shape (M - 1,)
        Speed limits at the junctions.
    period_s : float
        Shortest time of a move.

    Returns
    -------
    ndarray, shape (M,)
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
    t = (2.0 * peak - v0 - v1) / a + np.maximum(cruise, 0.0) / peak
    return np.maximum(t, period_s)


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
        ``method="planner"``, per-block times of shape (N,) (a dwell its own time).
    """
    from ..realkernel import features, model_blocks  # the moves as the chapter's methods see them

    moves, source = model_blocks(toolpath)
    if not len(moves):
        return Estimate("planner", machine.name, toolpath.dwell_s.copy(), toolpath)
    x = features(moves, machine)
    feed, length, acc = x[:, 0], x[:, 1], x[:, 5]
    tol = moves.effective_tolerance_mm(machine.blend_tol_mm)
    # a dwell between two moves stops the tool
    after = np.searchsorted(source, np.flatnonzero(toolpath.kind == MotionKind.DWELL))
    tol[after[after < len(moves)]] = 0.0
    v, blended = junction_speeds(length, moves.directions, feed, acc, tol)
    ends = np.concatenate([[False], blended]) | np.concatenate([blended, [False]])
    a_t = acc * np.where(ends, TANGENTIAL_ACC_RATIO, 1.0)
    t = move_times(length, feed, a_t, v, machine.period_s)
    block_t = np.bincount(source, weights=t, minlength=len(toolpath)) + toolpath.dwell_s
    return Estimate("planner", machine.name, block_t, toolpath)
