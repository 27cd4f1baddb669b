"""Compiled sample loops of the FIR kernel (numba): sampling the command, the box cascade and the
axis-limit extremes, one pass over the samples each; and the minimum over covering ranges that
lowers the speed command.

Each loop performs the same floating-point operations, in the same order, as the numpy code it
replaces (``np.interp``, running sums with ``np.cumsum``, ``np.diff``), so the kernel's output
does not depend on which one ran; ``tests/test_fir_loops.py`` checks this bit for bit. numba
compiles them on first use and caches the machine code beside this file.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["box_cascade", "derivative_peaks", "limit_ratios", "range_min", "sample_command"]


@njit(cache=True)
def sample_command(n_cmd, period_s, t_knots, x_knots, out):  # pragma: no cover - compiled
    """Positions of a piecewise-linear command at ``i * period_s``, ``i < n_cmd``.

    ``t_knots`` (K,) non-decreasing from 0, ``x_knots`` (K, 3); writes ``out`` (n_cmd, 3). The same
    arithmetic as ``np.interp`` per axis (value at a knot exactly, ``slope * (t - t_j) + x_j``
    inside, the last value at and after the last knot); the knot search walks forward, as the
    sample times increase.
    """
    k = len(t_knots)
    j = 0
    for i in range(n_cmd):
        t = i * period_s
        while j + 1 < k and t_knots[j + 1] <= t:
            j += 1
        if j == k - 1:
            for a in range(3):
                out[i, a] = x_knots[k - 1, a]
        elif t_knots[j] == t:
            for a in range(3):
                out[i, a] = x_knots[j, a]
        else:
            dt = t_knots[j + 1] - t_knots[j]
            for a in range(3):
                slope = (x_knots[j + 1, a] - x_knots[j, a]) / dt
                v = slope * (t - t_knots[j]) + x_knots[j, a]
                if np.isnan(v):
                    v = slope * (t - t_knots[j + 1]) + x_knots[j + 1, a]
                    if np.isnan(v) and x_knots[j, a] == x_knots[j + 1, a]:
                        v = x_knots[j, a]
                out[i, a] = v


@njit(cache=True)
def box_cascade(x, taps, out):  # pragma: no cover - compiled
    """Moving averages of ``taps`` (at least one, each > 1) in cascade over ``x`` (m, 3), held
    at its last value past its end, as :meth:`nctwin.kernel.fir.FirFilter.apply`: running sums
    of the positions relative to the first, differenced ``n`` apart, over ``n``.

    ``x`` may be any 2-D view; ``out`` is (m + sum(taps) - len(taps), 3). Each stage runs in
    place in ``out``; the last ``n`` running sums are kept in a ring, so no other buffer of
    the signal's size is made.
    """
    m = x.shape[0]
    ring = np.empty((taps.max(), 3))
    x0 = np.empty(3)
    last = np.empty(3)
    total = np.zeros(3)
    for a in range(3):
        x0[a] = x[0, a]
    for stage in range(len(taps)):
        n = taps[stage]
        for a in range(3):
            last[a] = x[m - 1, a] - x0[a] if stage == 0 else out[m - 1, a]
        for i in range(m + n - 1):
            slot = i % n
            for a in range(3):
                if i >= m:
                    v = last[a]
                elif stage == 0:
                    v = x[i, a] - x0[a]
                else:
                    v = out[i, a]
                c = v if i == 0 else total[a] + v
                total[a] = c
                s = c if i < n else c - ring[slot, a]
                ring[slot, a] = c
                out[i, a] = s / n
        m += n - 1
    for i in range(m):
        for a in range(3):
            out[i, a] += x0[a]


@njit(cache=True)
def derivative_peaks(pos, period_s, vel):  # pragma: no cover - compiled
    """Axis velocities and the largest magnitude of velocity, acceleration and jerk per axis.

    ``pos`` (n, 3); writes ``vel`` (n, 3), backward differences with ``vel[0] = 0``; returns
    (3, 3): row = derivative order (velocity from sample 1 on, acceleration, jerk as
    successive backward differences over the period), column = axis. One pass per axis, the
    previous velocity and acceleration carried along.
    """
    n = pos.shape[0]
    peak = np.zeros((3, 3))
    for a in range(3):
        vel[0, a] = 0.0
        v_prev = 0.0
        acc_prev = 0.0
        top_v = 0.0
        top_acc = 0.0
        top_jerk = 0.0
        for i in range(1, n):
            v = (pos[i, a] - pos[i - 1, a]) / period_s
            vel[i, a] = v
            top_v = max(top_v, abs(v))
            if i >= 2:
                acc = (v - v_prev) / period_s
                top_acc = max(top_acc, abs(acc))
                if i >= 3:
                    top_jerk = max(top_jerk, abs((acc - acc_prev) / period_s))
                acc_prev = acc
            v_prev = v
        peak[0, a] = top_v
        peak[1, a] = top_acc
        peak[2, a] = top_jerk
    return peak


@njit(cache=True)
def limit_ratios(vel, period_s, limits, over, ratio):  # pragma: no cover - compiled
    """Per sample, the largest ratio of an axis derivative to its limit, over the (order, axis)
    pairs that ``over`` (3, 3) marks.

    ``vel`` (n, 3) as :func:`derivative_peaks` writes it; ``limits`` (3, 3) as its peaks (row =
    order, column = axis); writes ``ratio`` (n,): the derivative of order ``k`` (0 velocity, 1
    acceleration, 2 jerk) counts at sample ``i`` from ``i = k + 1`` on, 0 where none counts.
    The same differences as :func:`derivative_peaks` (and ``np.diff`` over the period).
    """
    n = vel.shape[0]
    for i in range(n):
        ratio[i] = 0.0
    for a in range(3):
        acc_prev = 0.0
        for i in range(1, n):
            if over[0, a]:
                ratio[i] = max(ratio[i], abs(vel[i, a]) / limits[0, a])
            if i >= 2:
                acc = (vel[i, a] - vel[i - 1, a]) / period_s
                if over[1, a]:
                    ratio[i] = max(ratio[i], abs(acc) / limits[1, a])
                if i >= 3 and over[2, a]:
                    ratio[i] = max(ratio[i], abs((acc - acc_prev) / period_s) / limits[2, a])
                acc_prev = acc


@njit(cache=True)
def range_min(n, lo, hi, value):  # pragma: no cover - compiled
    """For each of ``n`` cells, the minimum ``value`` of the ranges ``[lo, hi)`` covering it.

    ``lo``, ``hi`` (R,) integers with ``0 <= lo`` and ``hi <= n`` (empty ranges, ``hi <= lo``,
    cover nothing), ``value`` (R,) not NaN; returns (n,), ``inf`` where no range covers the
    cell. The ranges paint the cells no lower value has painted, lowest value first;
    ``skip[c]`` leads from a painted cell towards the next unpainted one (union-find, paths
    shortened as they are walked): O(R log R) for the order, O(n + R) for the painting.
    """
    out = np.full(n, np.inf)
    skip = np.arange(n + 1)  # skip[c] == c: cell c unpainted (n: the end)
    for r in np.argsort(value, kind="mergesort"):
        c = lo[r]
        while c < hi[r]:
            if skip[c] != c:  # painted: jump on, halving the path
                skip[c] = skip[skip[c]]
                c = skip[c]
            else:
                out[c] = value[r]
                skip[c] = hi[r]  # every cell up to hi[r] is painted once this range is done
                c += 1
    return out
