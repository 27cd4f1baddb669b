"""Compiled loops of the FIR kernel (numba): sampling the command, the box cascade and the
axis-limit extremes, one pass over the samples each; the look-ahead's filtered path points; the
minimum over covering ranges that lowers the speed command.

Each loop performs the same floating-point operations, in the same order, as the numpy code it
replaces (``np.interp``, running sums with ``np.cumsum``, ``np.diff``, ``np.einsum``), or ones
that give the same bits for a stated reason (a maximum divided once: :func:`derivative_peaks`),
so the kernel's output does not depend on which one ran; ``tests/test_fir_loops.py`` checks
this bit for bit. numba compiles them on first use and caches the machine code beside this file.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._geometry_loops import path_points

__all__ = [
    "box_cascade",
    "box_flush",
    "box_stream",
    "derivative_peaks",
    "filtered_points",
    "limit_ratios",
    "range_min",
    "sample_command",
]


@njit(cache=True)
def sample_command(n_cmd, period_s, t_knots, x_knots, i0, out):  # pragma: no cover - compiled
    """Positions of a piecewise-linear command at ``(i0 + i) * period_s``, ``i < n_cmd``.

    ``t_knots`` (K,) non-decreasing from 0, ``x_knots`` (K, 3); writes ``out`` (n_cmd, 3). The same
    arithmetic as ``np.interp`` per axis (value at a knot exactly, ``slope * (t - t_j) + x_j``
    inside, the last value at and after the last knot); the knot search starts where a walk
    from the first knot would be at sample ``i0`` and walks forward, as the sample times
    increase. A segment's slopes are computed once, and its samples in one loop without
    branches; ``np.interp``'s fallbacks where that gives NaN (infinite positions) after.
    """
    k = len(t_knots)
    j = max(np.searchsorted(t_knots, i0 * period_s, side="right") - 1, 0)
    i = 0
    while i < n_cmd:
        t = (i0 + i) * period_s
        while j + 1 < k and t_knots[j + 1] <= t:
            j += 1
        if j == k - 1:  # at and after the last knot
            for a in range(3):
                out[i:, a] = x_knots[k - 1, a]
            return
        if t_knots[j] == t:  # on a knot
            for a in range(3):
                out[i, a] = x_knots[j, a]
            i += 1
            continue
        t0, t1 = t_knots[j], t_knots[j + 1]  # the samples strictly inside segment j
        x0, y0, z0 = x_knots[j, 0], x_knots[j, 1], x_knots[j, 2]
        sx = (x_knots[j + 1, 0] - x0) / (t1 - t0)
        sy = (x_knots[j + 1, 1] - y0) / (t1 - t0)
        sz = (x_knots[j + 1, 2] - z0) / (t1 - t0)
        first = i
        while i < n_cmd and (i0 + i) * period_s < t1:
            t = (i0 + i) * period_s
            out[i, 0] = sx * (t - t0) + x0
            out[i, 1] = sy * (t - t0) + y0
            out[i, 2] = sz * (t - t0) + z0
            i += 1
        for r in range(first, i):
            for a in range(3):
                if np.isnan(out[r, a]):
                    slope = (x_knots[j + 1, a] - x_knots[j, a]) / (t1 - t0)
                    v = slope * ((i0 + r) * period_s - t1) + x_knots[j + 1, a]
                    if np.isnan(v) and x_knots[j, a] == x_knots[j + 1, a]:
                        v = x_knots[j, a]
                    out[r, a] = v


@njit(cache=True)
def box_cascade(x, taps, out):  # pragma: no cover - compiled
    """Moving averages of ``taps`` (at least one, each > 1) in cascade over ``x`` (m, 3), held
    at its last value past its end, as :meth:`nctwin.kernel.fir.FirFilter.apply`: running sums
    of the positions relative to the first, differenced ``n`` apart, over ``n``.

    ``x`` may be any 2-D view, ``out[:m]`` itself included; ``out`` is
    (m + sum(taps) - len(taps), 3). Each stage runs in place in ``out``; the last ``n`` running
    sums are kept in a ring, so no other buffer of the signal's size is made.
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
def _through(v, first, taps, total, ring, count, last):  # pragma: no cover - compiled
    """Feed ``v`` (3,) to stage ``first`` of a streamed cascade and on through the later
    stages, in place: each stage ``s`` does what :func:`box_cascade`'s does with its next input
    (``count[s]`` inputs so far, its running sum ``total[s]`` (3,), its last ``n`` sums in
    ``ring[s]``), so the outputs are its bits; ``last[s]`` (3,) keeps the stage's output."""
    for s in range(first, len(taps)):
        n = taps[s]
        j = count[s]
        slot = j % n
        for a in range(3):
            c = v[a] if j == 0 else total[s, a] + v[a]
            total[s, a] = c
            d = c if j < n else c - ring[s, slot, a]
            ring[s, slot, a] = c
            v[a] = d / n
            last[s, a] = v[a]
        count[s] = j + 1


@njit(cache=True)
def box_stream(x, x0, taps, total, ring, count, last, out):  # pragma: no cover - compiled
    """The next ``len(x)`` inputs (m, 3) of :func:`box_cascade`, streamed: writes the same
    ``len(x)`` outputs to ``out`` (m, 3) (without the final ``+ x0``). ``x0`` (3,) the first
    input; the state ``total`` (S, 3), ``ring`` (S, max(taps), 3), ``count`` (S,) starts at
    zero; ``last`` (S, 3) holds each stage's latest output, for :func:`box_flush`."""
    v = np.empty(3)
    for i in range(x.shape[0]):
        for a in range(3):
            v[a] = x[i, a] - x0[a]
        _through(v, 0, taps, total, ring, count, last)
        for a in range(3):
            out[i, a] = v[a]


@njit(cache=True)
def box_flush(x_last, x0, taps, total, ring, count, last, out):  # pragma: no cover - compiled
    """The tail of a streamed cascade: each stage in turn is held at its last input (the first
    stage at ``x_last - x0``, a later one at the earlier stage's last output), ``n - 1`` more
    inputs each, as :func:`box_cascade` holds them; writes the ``sum(taps) - len(taps)``
    outputs to ``out`` (without the final ``+ x0``)."""
    v = np.empty(3)
    held = np.empty(3)
    row = 0
    for s in range(len(taps)):
        for a in range(3):
            held[a] = x_last[a] - x0[a] if s == 0 else last[s - 1, a]
        for _ in range(taps[s] - 1):
            for a in range(3):
                v[a] = held[a]
            _through(v, s, taps, total, ring, count, last)
            for a in range(3):
                out[row, a] = v[a]
            row += 1


#: Samples per chunk of the derivative loops (their buffers stay in the first-level cache).
CHUNK = 512


@njit(cache=True)
def _chunk_derivatives(flat, r0, r1, period_s, vel, acc):  # pragma: no cover - compiled
    """Velocities and accelerations of samples ``r0 <= i < r1`` (``1 <= r0 < r1``) of the
    positions ``flat`` (3 n,), sample-major: backward differences over the period.

    Writes ``vel[3:]`` and ``acc[3:]``, (3 (r1 - r0),) axis fastest, accelerations from sample 2
    on; ``vel[:3]`` and ``acc[:3]`` hold sample ``r0 - 1``'s (the caller carries them from the
    previous chunk). Loops over contiguous slices without branches: LLVM vectorises them,
    divisions included.
    """
    m = 3 * (r1 - r0)
    now, before, v = flat[3 * r0 : 3 * r1], flat[3 * r0 - 3 : 3 * r1 - 3], vel[3 : 3 + m]
    for k in range(m):
        v[k] = (now[k] - before[k]) / period_s
    skip = 3 * (max(r0, 2) - r0)  # sample 1 has no acceleration
    a, v_now, v_before = acc[3 + skip : 3 + m], vel[3 + skip : 3 + m], vel[skip:m]
    for k in range(m - skip):
        a[k] = (v_now[k] - v_before[k]) / period_s


@njit(cache=True)
def derivative_peaks(pos, period_s):  # pragma: no cover - compiled
    """Largest magnitude of velocity, acceleration and jerk per axis of ``pos`` (n, 3),
    C-contiguous.

    Returns (3, 3): row = derivative order (velocity from sample 1 on, acceleration from 2, jerk
    from 3, successive backward differences over the period), column = axis. By chunks of
    :data:`CHUNK` samples (:func:`_chunk_derivatives`), the three orders of an axis in one loop.
    The jerk's peak is the largest difference of accelerations divided once by the period:
    division by a positive number rounds monotonically, so this is the largest of the divided
    differences, bit for bit.
    """
    n = pos.shape[0]
    flat = pos.reshape(-1)
    vel = np.empty(3 * CHUNK + 3)
    acc = np.empty(3 * CHUNK + 3)
    peak = np.zeros((3, 3))
    for r0 in range(1, n, CHUNK):
        r1 = min(r0 + CHUNK, n)
        _chunk_derivatives(flat, r0, r1, period_s, vel, acc)
        if r0 == 1:
            # sample 1 has no acceleration, samples 1 and 2 no jerk: sample 2's acceleration
            # (0 without it) in their place, and before them, adds nothing to the peaks
            for a in range(3):
                acc[a] = acc[3 + a] = acc[6 + a] if r1 > 2 else 0.0
        end = 3 * (r1 - r0) + 3
        for a in range(3):
            top_v, top_acc, top_dacc = peak[0, a], peak[1, a], peak[2, a]
            for k in range(3 + a, end, 3):
                top_v = max(top_v, abs(vel[k]))
                top_acc = max(top_acc, abs(acc[k]))
                top_dacc = max(top_dacc, abs(acc[k] - acc[k - 3]))
            peak[0, a], peak[1, a], peak[2, a] = top_v, top_acc, top_dacc
        vel[:3] = vel[end - 3 : end]
        acc[:3] = acc[end - 3 : end]
    for a in range(3):
        peak[2, a] /= period_s
    return peak


@njit(cache=True)
def limit_ratios(pos, period_s, limits, over, ratio):  # pragma: no cover - compiled
    """Per sample, the largest ratio of an axis derivative of ``pos`` (n, 3), C-contiguous, to
    its limit, over the (order, axis) pairs that ``over`` (3, 3) marks.

    ``limits`` (3, 3) as the peaks of :func:`derivative_peaks` (row = order, column = axis);
    writes ``ratio`` (n,): the derivative of order ``k`` (0 velocity, 1 acceleration, 2 jerk)
    counts at sample ``i`` from ``i = k + 1`` on, 0 where none counts. The same differences as
    :func:`derivative_peaks` (and ``np.diff`` over the period), by chunks; in a chunk, one
    branch-free loop over its samples per marked pair, axis by axis and order by order, the
    order in which a sample's maximum takes them.
    """
    n = pos.shape[0]
    flat = pos.reshape(-1)
    vel = np.empty(3 * CHUNK + 3)
    acc = np.empty(3 * CHUNK + 3)
    ratio[:] = 0.0
    for r0 in range(1, n, CHUNK):
        r1 = min(r0 + CHUNK, n)
        _chunk_derivatives(flat, r0, r1, period_s, vel, acc)
        for a in range(3):
            for order in range(3):
                if not over[order, a]:
                    continue
                first = max(r0, order + 1)  # the first sample the derivative counts at
                limit = limits[order, a]
                for i in range(first, r1):
                    k = 3 * (i - r0) + 3 + a
                    if order == 0:
                        r = abs(vel[k]) / limit
                    elif order == 1:
                        r = abs(acc[k]) / limit
                    else:
                        r = abs((acc[k] - acc[k - 3]) / period_s) / limit
                    ratio[i] = max(ratio[i], r)
        end = 3 * (r1 - r0) + 3
        vel[:3] = vel[end - 3 : end]
        acc[:3] = acc[end - 3 : end]


#: Junctions per batch of :func:`filtered_points` (its buffers are reused batch by batch).
BATCH = 64


@njit(cache=True)
def filtered_points(s_mm, speed_mm_s, offsets_s, weights, path, out):  # pragma: no cover - compiled
    """The filter's weighted mean of path points around each of K arc lengths, at a speed.

    ``s_mm``, ``speed_mm_s`` (K,); ``offsets_s``, ``weights`` (L,); ``path`` the arrays of
    :attr:`nctwin.geometry.PathGeometry.loop_arrays`. Writes ``out`` (K, 3): the sum over ``l``
    of ``weights[l]`` times the point at ``s_mm[k] + speed_mm_s[k] * offsets_s[l]``, summed in
    order of ``l`` from 0.0, as ``np.einsum("l,klc->kc", ...)`` does. The points are found by
    :func:`~nctwin._geometry_loops.path_points`, :data:`BATCH` junctions at a time.
    """
    nodes = len(weights)
    s = np.empty(BATCH * nodes)
    points = np.empty((BATCH * nodes, 3))
    for k0 in range(0, len(s_mm), BATCH):
        k1 = min(k0 + BATCH, len(s_mm))
        q = s[: (k1 - k0) * nodes]
        p = points[: len(q)]
        for k in range(k0, k1):
            for j in range(nodes):
                q[(k - k0) * nodes + j] = s_mm[k] + speed_mm_s[k] * offsets_s[j]
        path_points(q, *path, p)
        for k in range(k0, k1):
            sx = sy = sz = 0.0  # the three axes' sums side by side (each in order of l)
            for j in range((k - k0) * nodes, (k - k0 + 1) * nodes):
                w = weights[j - (k - k0) * nodes]
                sx += w * p[j, 0]
                sy += w * p[j, 1]
                sz += w * p[j, 2]
            out[k, 0], out[k, 1], out[k, 2] = sx, sy, sz


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
