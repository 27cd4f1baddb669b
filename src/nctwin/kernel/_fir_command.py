"""The FIR kernel's speed command (:mod:`nctwin.kernel.fir`): block feeds, lowered to each
junction's speed over the filter window centred on it, ramped rapids' stairs
(:mod:`nctwin.kernel.fir_rapids`), and the pauses, as a piecewise-constant speed along the path."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import PathGeometry
from ..toolpath import MotionKind, Toolpath
from . import _fir_loops, fir_rapids


@dataclass(frozen=True)
class Plan:
    """What the look-ahead decided, per block and per junction.

    Parameters
    ----------
    feed_mm_s : ndarray, shape (N,)
        Cruise feed of each block after the machine's limits.
    junction_mm_s : ndarray, shape (N + 1,)
        Speed at the start of each block (index N: the end of the program); 0 is a stop.
    pause_s : ndarray, shape (N + 1,)
        Time the command waits at each junction (filter drain before a stop, dwells).
    ramp_mm_s : ndarray, shape (N,), optional
        Velocity step of each rapid commanded as a staircase (``rapid_ramp``,
        :mod:`nctwin.kernel.fir_rapids`), NaN for every other block; none: no staircase.
    """

    feed_mm_s: np.ndarray
    junction_mm_s: np.ndarray
    pause_s: np.ndarray
    ramp_mm_s: np.ndarray | None = None


@dataclass(frozen=True)
class _Command:
    """Piecewise-constant speed command along the path.

    ``cuts`` (C,) are arc lengths; interval ``i`` runs from ``cuts[i]`` to ``cuts[i+1]`` at
    ``speed[i]`` inside block ``block[i]``; the command waits ``pause[c]`` at cut ``c``, in block
    ``pause_block[c]``.
    """

    cuts: np.ndarray
    speed: np.ndarray
    block: np.ndarray
    pause: np.ndarray
    pause_block: np.ndarray

    def knot_times(self, scale: np.ndarray | None = None) -> np.ndarray:
        """Time knots (2C,) of the command, speeds multiplied by ``scale``: arrival at and
        departure from each cut, whose arc length is :attr:`knot_s`."""
        speed = self.speed if scale is None else self.speed * scale
        arrive = np.empty(len(self.cuts))
        arrive[0] = 0.0
        np.cumsum(np.diff(self.cuts) / speed, out=arrive[1:])  # moving, then the pauses before
        arrive[1:] += np.cumsum(self.pause[:-1])
        knots = np.empty(2 * len(self.cuts))
        knots[0::2] = arrive
        knots[1::2] = arrive + self.pause
        return knots

    def sample_blocks(
        self, t_knots: np.ndarray, period_s: float, delay: int, kept: np.ndarray, i0: int, n: int
    ) -> np.ndarray:
        """Block of samples ``i0 <= i < i0 + n``, shape (n,): ``kept`` (M,) of the command's
        block at the time segment ``delay`` samples before.

        ``t_knots`` (2C,) from :meth:`knot_times`: segment ``2c`` is the pause at cut ``c``, in
        ``pause_block[c]``, or where that is -1 the next segment's (for the last pause, after
        the program's last move, that move's); segment ``2c + 1`` the move after it, in
        ``block[c]``. A segment owns the samples from the first at or after its start (1e-9
        periods of slack), ``delay`` on, up to the next segment's; the first segment every
        sample before that too.
        """
        seg = np.column_stack([self.pause_block, np.append(self.block, 0)]).ravel()[:-1]
        seg = np.where(seg < 0, np.append(seg[1:], seg[-2] if len(seg) > 1 else -1), seg)
        first = np.ceil(t_knots[1:-1] / period_s - 1e-9).astype(np.int64) + delay
        edges = np.clip(np.concatenate([[i0], first, [i0 + n]]), i0, i0 + n)
        return np.repeat(kept[seg], np.diff(edges))

    @property
    def knot_s(self) -> np.ndarray:
        """Arc-length knots (2C,) of the command: each cut twice."""
        return np.repeat(self.cuts, 2)


def _unique_with_index(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct values of ``x`` (N,), sorted, as ``np.unique``, and the index of each
    element among them (N,), as ``np.searchsorted`` would find it (no signed zeros or NaN).

    A stable sort: it merges the sorted runs the command's arc lengths come in (block starts,
    and the windows around them), where ``np.unique``'s quicksort sorts from scratch."""
    order = np.argsort(x, kind="stable")
    x = x[order]
    new = np.empty(len(x), dtype=bool)
    new[:1] = True
    np.not_equal(x[1:], x[:-1], out=new[1:])
    index = np.empty(len(x), dtype=np.intp)
    index[order] = np.cumsum(new) - 1
    return x[new], index


def _command(
    tp: Toolpath, geo: PathGeometry, p: Plan, length_s: float, t1_s: float, period_s: float
) -> _Command:
    """The speed command: block feeds, lowered to each junction's speed over the filter window
    centred on it (the filters' ``length_s``), ramped rapids' stairs between those windows (each
    held for the first box, ``t1_s`` and one ``period_s``), and the pauses."""
    n = len(tp)
    s_start = geo.s_start_mm
    half = 0.5 * length_s + 2 * period_s  # the window, and a margin for sampling
    v = p.junction_mm_s
    zone = (v > 0) & np.isfinite(v)
    z_lo = np.maximum(s_start[zone] - v[zone] * half, 0.0)
    z_hi = np.minimum(s_start[zone] + v[zone] * half, geo.total_mm)
    ramped = [] if p.ramp_mm_s is None else np.flatnonzero(np.isfinite(p.ramp_mm_s))
    # a ramped rapid's stairs, between the windows of its two junctions, each held for the
    # first box's length (T1 / Ts + 1 taps), so that the ramps of two stairs never overlap
    window = np.where(zone, v * half, 0.0)  # a junction's window reaches this far either side
    stairs = {k: (s_start[k] + window[k], s_start[k + 1] - window[k + 1], v[k], v[k + 1],
                  p.feed_mm_s[k], p.ramp_mm_s[k], t1_s + period_s)
              for k in ramped}  # fmt: skip
    extra = [fir_rapids.stair_cuts_mm(*args) for args in stairs.values()]
    cuts, index = _unique_with_index(np.concatenate([s_start, z_lo, z_hi, *extra]))
    at, i_lo, i_hi = np.split(index, [len(s_start), len(s_start) + len(z_lo)])[:3]
    i_hi = i_hi[: len(z_lo)]
    mid = 0.5 * (cuts[:-1] + cuts[1:])
    block = geo.block_at_ordered(mid)
    speed = p.feed_mm_s[block].copy()
    if zone.any():
        speed = np.minimum(speed, _fir_loops.range_min(len(mid), i_lo, i_hi, v[zone]))
    # the intervals of a block are a run of ``block`` (non-decreasing, as ``mid`` increases)
    ks = np.fromiter(stairs, dtype=np.intp, count=len(stairs))
    lo, hi = np.searchsorted(block, ks, side="left"), np.searchsorted(block, ks, side="right")
    for k, a, b in zip(ks, lo, hi, strict=True):
        speed[a:b] = np.minimum(speed[a:b], fir_rapids.staircase_mm_s(mid[a:b], *stairs[k]))
    pause = np.zeros(len(cuts))
    np.add.at(pause, at, p.pause_s)
    # a pause belongs to the dwell it is, else to the block that ends at the stop
    pause_block = np.full(len(cuts), -1)
    owner = np.where(tp.kind == MotionKind.DWELL, np.arange(n), np.maximum(np.arange(n) - 1, 0))
    has = p.pause_s[:n] > 0
    pause_block[at[:n][has]] = owner[has]
    return _Command(cuts, speed, block, pause, pause_block)
