r"""Speeds and times along the blend-arc planner's queue (:mod:`nctwin.estimate.blend_planner`):
the trapezoid of every item, the stops on whole servo periods, and LinuxCNC's lazy look-ahead
that sets the end speed of every item (``tpRunOptimization``, ``tpComputeOptimalVelocity``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    "OPTIMIZATION_CUTOFF",
    "OPTIMIZATION_DEPTH",
    "optimised_end_speeds",
    "segment_times",
    "stops_on_periods",
]


#: Items the look-ahead walks back from the newest one (``ARC_BLEND_OPTIMIZATION_DEPTH``).
OPTIMIZATION_DEPTH = 50


#: The lazy look-ahead stops after passing more items at their peak than this
#: (``TP_OPTIMIZATION_CUTOFF``).
OPTIMIZATION_CUTOFF = 4


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


def stops_on_periods(t_s: np.ndarray, v_mm_s: np.ndarray, period_s: float) -> np.ndarray:
    """Item times with the tool coming to rest on a servo period.

    LinuxCNC splits the last cycle of a segment between it and the next only where the motion
    goes on (``tpCheckEndCondition`` returns early for a segment that ends in a stop, which is
    removed once its distance to go is within ``TP_POS_EPSILON``), so a stop falls on a cycle
    and the time from rest to rest is a whole number of periods. Measured on LinuxCNC: three
    7 mm moves at 37 mm/s under ``G61.1`` take 0.681 s (trapezoids: 0.6786 s), 40 chords of
    0.3 mm at 60 mm/s 1.400 s (1.379 s).

    Parameters
    ----------
    t_s : ndarray, shape (S,)
        Times of the items (continuous, :func:`segment_times`).
    v_mm_s : ndarray, shape (S - 1,)
        Speed limits at the junctions; 0 is a stop (the ends of the queue are stops).
    period_s : float

    Returns
    -------
    ndarray, shape (S,)
        ``t_s`` with the rest of each stop's last period added to the item that stops.
    """
    stops = np.flatnonzero(np.concatenate([[0.0], v_mm_s, [0.0]]) == 0)
    run = np.add.reduceat(t_s, stops[:-1])  # rest to rest; every item has a positive length
    whole = np.ceil(run / period_s - 1e-9) * period_s
    out = t_s.copy()
    out[stops[1:] - 1] += whole - run
    return out


@njit(cache=True)
def _optimise(q_len, q_acc, q_max, blended, last_item, new_len, new_acc, new_max, depth, cutoff):
    """Compiled body of :func:`optimised_end_speeds` (same arguments)."""  # pragma: no cover
    end = np.zeros(len(q_len))
    at_max = np.zeros(len(q_len), np.bool_)
    for s in range(len(last_item)):
        last = last_item[s]
        if last < 0:
            continue
        peaks = 0
        non_tangent = not blended[last]
        if not non_tangent:  # the newest move, still parabolic: its triangle speed
            end[last] = min(q_max[last], math.sqrt(new_acc[s] * new_len[s]), new_max[s])
        for x in range(depth):
            k = last - x
            if k < 1:
                break
            if not blended[k - 1]:
                if non_tangent:
                    break
                non_tangent = True
                continue
            v = math.sqrt(end[k] * end[k] + 2.0 * q_acc[k] * q_len[k])
            v_max = min(q_max[k], q_max[k - 1])
            if v >= v_max:
                v = v_max
                at_max[k - 1] = True
            end[k - 1] = v
            if at_max[k]:
                peaks += 1
                if peaks > cutoff:
                    break
    return end


def optimised_end_speeds(
    length_mm: np.ndarray,
    acc_mm_s2: np.ndarray,
    max_mm_s: np.ndarray,
    blended: np.ndarray,
    last_item: np.ndarray,
    new_length_mm: np.ndarray,
    new_acc_mm_s2: np.ndarray,
    new_max_mm_s: np.ndarray,
) -> np.ndarray:
    r"""End speeds of S queue items as LinuxCNC's look-ahead leaves them (``tpRunOptimization``,
    ``tpComputeOptimalVelocity``), replayed once per queued move.

    Each time a move is queued, the optimiser starts from the newest move, still parabolic
    (its triangle speed :math:`\sqrt{a_t L}`), and walks back through at most
    :data:`OPTIMIZATION_DEPTH` items, raising each end speed to
    :math:`\sqrt{v_{end}^2 + 2 a L}` of the item after it, within the planning limit of both
    items (where it reaches that limit the item is marked at its peak). It stops at the second
    junction that is not blended, and, being lazy (``TP_OPTIMIZATION_LAZY``), once it has
    passed more than :data:`OPTIMIZATION_CUTOFF` items at their peak. Ends the walks never reach
    keep the speed of the last walk that did: on a chain of short items the speed dips where
    a walk from a long move ran out.

    Parameters
    ----------
    length_mm, acc_mm_s2, max_mm_s : ndarray, shape (S,)
        Length, tangential acceleration and planning speed limit of each item.
    blended : ndarray of bool, shape (S,)
        The item ends in a junction the tool passes without stopping.
    last_item : ndarray of int64, shape (Q,)
        For each queued move after the first, the last item queued before it (-1: none).
    new_length_mm, new_acc_mm_s2, new_max_mm_s : ndarray, shape (Q,)
        The newest move when it is queued: its length (trimmed at the start only), its
        acceleration at the parabolic end, and its speed limit.

    Returns
    -------
    ndarray, shape (S,)
    """
    args = [np.ascontiguousarray(a, dtype=np.float64) for a in (length_mm, acc_mm_s2, max_mm_s)]
    new = [np.ascontiguousarray(a, dtype=np.float64) for a in (new_length_mm, new_acc_mm_s2)]
    return _optimise(
        *args,
        np.ascontiguousarray(blended, dtype=np.bool_),
        np.ascontiguousarray(last_item, dtype=np.int64),
        *new,
        np.ascontiguousarray(new_max_mm_s, dtype=np.float64),
        OPTIMIZATION_DEPTH,
        OPTIMIZATION_CUTOFF,
    )
