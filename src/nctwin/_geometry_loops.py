"""Compiled loops of :meth:`nctwin.geometry.PathGeometry.points` and ``block_at`` (numba).

It performs the same floating-point operations, in the same order, as the numpy expression it
replaces (``np.searchsorted``, ``np.clip``, the line and arc formulas with libm's ``cos`` and
``sin``), so the positions do not depend on which one ran; ``tests/test_geometry.py`` checks
this bit for bit. One pass over the query points, no temporary arrays: the FIR kernel's
look-ahead evaluates the path at 24 points per junction in every step of its speed search.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["block_index", "block_indices", "path_points"]


@njit(cache=True)
def block_index(s_start_mm, s, k):  # pragma: no cover - compiled
    """The block of arc length ``s`` (not NaN) on a path of N > 0 blocks whose starts, and
    the total length last, are ``s_start_mm`` (N + 1,): ``searchsorted(s_start_mm, s,
    "right") - 1`` clipped to the blocks, found by galloping from block ``k`` (the block of
    the previous query: queries come in runs near each other), then bisecting.
    """
    n = len(s_start_mm) - 1
    # first index whose start exceeds s, between lo and hi
    if s_start_mm[k] <= s:
        lo, step = k + 1, 1
        hi = lo
        while hi <= n and s_start_mm[hi] <= s:
            lo = hi + 1
            hi = lo + step
            step *= 2
        hi = min(hi, n + 1)
    else:
        hi, step = k, 1
        lo = hi
        while lo > 0 and s_start_mm[lo - 1] > s:
            hi = lo - 1
            lo = hi - step
            step *= 2
        lo = max(lo, 0)
    while lo < hi:
        mid = (lo + hi) >> 1
        if s_start_mm[mid] <= s:
            lo = mid + 1
        else:
            hi = mid
    return min(max(lo - 1, 0), n - 1)


@njit(cache=True)
def block_indices(s_start_mm, s_mm, out):  # pragma: no cover - compiled
    """:func:`block_index` of each arc length of ``s_mm`` (Q,), not NaN, into ``out`` (Q,):
    :meth:`nctwin.geometry.PathGeometry.block_at`, in one pass for queries in order."""
    k = 0
    for q in range(len(s_mm)):
        k = block_index(s_start_mm, s_mm[q], k)
        out[q] = k


@njit(cache=True)
def path_points(  # pragma: no cover - compiled
    s_mm,
    s_start_mm,
    lengths_mm,
    start_mm,
    chord_mm,
    is_arc,
    plane_axes,
    theta0_rad,
    sweep_rad,
    r0_mm,
    r1_mm,
    center_mm,
    normal_mm,
    out,
):
    """Positions at arc lengths ``s_mm`` (Q,) on a path of N > 0 blocks; writes ``out`` (Q, 3).

    ``s_start_mm`` (N + 1,) and ``lengths_mm`` (N,) parametrise the path; ``start_mm``,
    ``chord_mm``, ``center_mm`` (N, 3); ``is_arc`` (N,); ``plane_axes`` (N, 3) the first,
    second and normal axis of each block's plane; ``theta0_rad``, ``sweep_rad``, ``r0_mm``,
    ``r1_mm``, ``normal_mm`` (N,) the arcs' start angle, sweep, start and end radius and travel
    along the normal. Arc lengths are clipped to the path; a block is found as
    ``searchsorted(s_start_mm, s, "right") - 1`` clipped to the blocks, by galloping from the
    block of the previous query.
    """
    n = len(lengths_mm)
    total = s_start_mm[n]
    k = 0
    for q in range(len(s_mm)):
        s = s_mm[q]
        if s < 0.0:
            s = 0.0
        if s > total:
            s = total
        k = block_index(s_start_mm, s, k)
        length = lengths_mm[k]
        frac = (s - s_start_mm[k]) / length if length > 0 else 0.0
        if frac < 0.0:
            frac = 0.0
        if frac > 1.0:
            frac = 1.0
        if is_arc[k]:
            a0, a1, a2 = plane_axes[k, 0], plane_axes[k, 1], plane_axes[k, 2]
            phi = theta0_rad[k] + sweep_rad[k] * frac
            r = r0_mm[k] + (r1_mm[k] - r0_mm[k]) * frac
            out[q, a0] = center_mm[k, a0] + r * np.cos(phi)
            out[q, a1] = center_mm[k, a1] + r * np.sin(phi)
            out[q, a2] = start_mm[k, a2] + normal_mm[k] * frac
        else:
            for a in range(3):
                out[q, a] = start_mm[k, a] + frac * chord_mm[k, a]
