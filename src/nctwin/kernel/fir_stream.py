"""The FIR kernel's block times without its trajectory: :func:`nctwin.kernel.fir.run` followed
by :func:`nctwin.targets.block_targets`, in memory that does not grow with the motion's
duration.

A run stores every sample of the motion (positions, velocities, times, blocks: about 150 bytes a
sample with the junction search), 5.9 GB for a program of ten hours at a 1 ms period. The block
times need none of it at once. Each pass here samples the command, filters it and reads it in
chunks of :data:`CHUNK_SAMPLES` samples:

* the box cascade runs as a stream (:func:`~nctwin.kernel._fir_loops.box_stream`), its running
  sums carried from chunk to chunk, so every sample has the bits of the whole-array filter;
* the axis limits are checked chunk by chunk (derivatives need the three samples before a
  chunk, which are carried), and the samples that exceed one slow the command down as
  :func:`~nctwin.kernel.fir.run` does (:func:`~nctwin.kernel.fir.slow_down`);
* the junction points (Chien et al. 2023, eq. 1) are searched in the chunk that holds their
  block switch, with the samples around it, and the path length travelled is summed with a
  carry, as ``np.cumsum`` sums it.

So the times, lengths and junction samples are those of ``block_targets(fir.run(...))``, bit for
bit (``tests/test_fir_stream.py``), for a few megabytes of samples at a time.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..checks import check_int
from ..controls import FirControl
from ..machine import Machine
from ..targets import CHUNK_JUNCTIONS, BlockTargets, _junction_chunk, block_targets
from ..toolpath import MotionKind, Toolpath
from . import _fir_loops
from .fir import (
    LIMIT_RTOL,
    MAX_SLOWDOWNS,
    Prepared,
    _first_change,
    _refined,
    prepare,
    run,
    slow_down,
)

__all__ = ["CHUNK_SAMPLES", "stream_block_targets"]

#: Samples per chunk of a pass (6 MB of positions).
CHUNK_SAMPLES = 1 << 18
#: Samples either side of a block switch the junction search reads (``block_targets``').
SEARCH_SAMPLES = 250


def _ends(prep: Prepared, t_knots: np.ndarray, n_cmd: int, chunk: int) -> tuple[int, int]:
    """How many command samples rest at the start (``head``) and at the end (``still``), as
    :func:`nctwin.kernel.fir._interpolate` counts them on the whole command."""
    ts, x_knots = prep.fir.period_s, np.ascontiguousarray(prep.x_knots)
    first, last = prep.tp.start_mm[0], prep.tp.end_mm[-1]
    head = still = None
    buf = np.empty((chunk, 3))
    for lo in range(1, n_cmd, chunk):  # sample 0 is set to the start
        m = min(chunk, n_cmd - lo)
        _fir_loops.sample_command(m, ts, t_knots, x_knots, lo, buf[:m])
        if lo + m == n_cmd:
            buf[m - 1] = last
        k = _first_change(buf[:m], first)
        if k < m:
            head = lo + k
            break
    for hi in range(n_cmd - 1, 0, -chunk):  # sample n_cmd - 1 is set to the end
        lo = max(hi - chunk, 0)
        m = hi - lo
        _fir_loops.sample_command(m, ts, t_knots, x_knots, lo, buf[:m])
        if lo == 0:
            buf[0] = first
        k = _first_change(buf[:m][::-1], last)
        if k < m:
            still = n_cmd - hi + k
            break
    return (n_cmd if head is None else head), (n_cmd if still is None else still)


def _positions(prep: Prepared, t_knots: np.ndarray, chunk: int) -> Iterator[tuple[int, np.ndarray]]:
    """The filtered positions of one pass, ``(first sample, positions (m, 3))`` chunk by chunk
    in order, the last chunk with the filter's tail: the samples of
    :func:`nctwin.kernel.fir._interpolate`."""
    fir = prep.fir
    ts, x_knots = fir.period_s, np.ascontiguousarray(prep.x_knots)
    n_cmd = int(np.ceil(t_knots[-1] / ts - 1e-9)) + 1
    taps = np.array([n for n in fir.taps if n > 1], dtype=np.int64)
    lag = int(taps.sum()) - len(taps)
    first, last = prep.tp.start_mm[0].copy(), prep.tp.end_mm[-1].copy()
    head, still = _ends(prep, t_knots, n_cmd, chunk)
    rest_from = n_cmd - still + lag if still < n_cmd else 0
    total = np.zeros((len(taps), 3))
    ring = np.empty((len(taps), int(taps.max()), 3))
    count = np.zeros(len(taps), dtype=np.int64)
    latest = np.empty((len(taps), 3))
    cmd = np.empty((chunk, 3))
    for lo in range(0, n_cmd, chunk):
        m = min(chunk, n_cmd - lo)
        end = lo + m == n_cmd
        out = np.empty((m + (lag if end else 0), 3))
        _fir_loops.sample_command(m, ts, t_knots, x_knots, lo, cmd[:m])
        if lo == 0:
            cmd[0] = first
        if end:
            cmd[m - 1] = last
        _fir_loops.box_stream(cmd[:m], first, taps, total, ring, count, latest, out[:m])
        if end:
            _fir_loops.box_flush(last, first, taps, total, ring, count, latest, out[m:])
        out += first
        out[: max(head - lo, 0)] = first
        out[max(rest_from - lo, 0) :] = last
        yield lo, out


def _limit_excess(
    prep: Prepared, t_knots: np.ndarray, chunk: int
) -> tuple[np.ndarray, np.ndarray] | None:
    """The samples of a pass above an axis limit and their ratios to it (both (B,)), as
    :func:`nctwin.kernel.fir._limit_ratio` finds them; None where none is."""
    ts, limits = prep.fir.period_s, prep.limits
    peak = np.zeros((3, 3))
    for _, pos in _with_history(_positions(prep, t_knots, chunk)):
        peak = np.maximum(peak, _fir_loops.derivative_peaks(pos, ts))
    over = peak > limits * (1.0 + LIMIT_RTOL)
    if not over.any():
        return None
    bad, value = [], []
    for lo, pos in _with_history(_positions(prep, t_knots, chunk)):
        ratio = np.empty(len(pos))
        _fir_loops.limit_ratios(pos, ts, limits, over, ratio)
        skip = 3 if lo else 0  # the carried samples belong to the chunk before
        hit = np.flatnonzero(ratio[skip:] > 1.0 + LIMIT_RTOL) + skip
        bad.append(hit + lo)
        value.append(ratio[hit])
    return np.concatenate(bad), np.concatenate(value)


def _with_history(chunks: Iterator[tuple[int, np.ndarray]]) -> Iterator[tuple[int, np.ndarray]]:
    """Each chunk with the three samples before it prepended (backward differences up to the
    jerk need them), as ``(its first sample's index, positions)``."""
    before = None
    for lo, pos in chunks:
        if before is None:
            yield lo, pos
        else:
            yield lo - len(before), np.concatenate([before, pos])
        before = (pos if before is None else np.concatenate([before, pos]))[-3:]


def stream_block_targets(
    toolpath: Toolpath,
    machine: Machine,
    control: FirControl,
    *,
    chunk_samples: int = CHUNK_SAMPLES,
) -> BlockTargets:
    """``block_targets(fir.run(toolpath, machine, control), toolpath)``, the same bits, in
    memory bounded by ``chunk_samples`` (at least 2 x :data:`SEARCH_SAMPLES` + 2) rather than by
    the motion's duration.

    Raises
    ------
    ValueError
        For ``chunk_samples`` out of range.
    """
    low = 2 * SEARCH_SAMPLES + 2
    check_int("chunk_samples", chunk_samples, low)
    prep = prepare(toolpath, machine, control)
    ts = control.period_s
    if prep is None or prep.cmd.knot_times()[-1] / ts < chunk_samples:  # one chunk: a run
        return block_targets(run(toolpath, machine, control), toolpath)
    cmd = prep.cmd
    taps = [n for n in prep.fir.taps if n > 1]
    lag = sum(taps) - len(taps)
    scale = np.ones(len(cmd.speed))
    for _ in range(MAX_SLOWDOWNS + 1):
        t_knots = cmd.knot_times(scale)
        excess = _limit_excess(prep, _refined(t_knots, prep.refinement), chunk_samples)
        if excess is None:
            break
        slow_down(scale, t_knots, *excess, lag, ts)
    refined = _refined(t_knots, prep.refinement)
    return _junctions(toolpath, prep, t_knots, _positions(prep, refined, chunk_samples), lag)


def _junctions(
    toolpath: Toolpath,
    prep: Prepared,
    t_knots: np.ndarray,
    chunks: Iterator[tuple[int, np.ndarray]],
    lag: int,
) -> BlockTargets:
    """:func:`nctwin.targets.block_targets` on the final pass, chunk by chunk.

    The samples since the first one a junction still to search may read are kept (positions,
    blocks, path length travelled): a junction is searched once the samples up to
    :data:`SEARCH_SAMPLES` past its block switch are there (all of them at the end), so every
    window is the one ``block_targets`` reads, clipped at the motion's ends only."""
    n, ts = len(toolpath), prep.fir.period_s
    points = toolpath.end_mm[:-1]
    leaving_dwell = toolpath.kind[:-1] == MotionKind.DWELL
    junction = np.zeros(n + 1, dtype=np.int64)
    travelled_at = np.zeros(n + 1)
    start, pos_b, lab_b, trav_b = 0, np.empty((0, 3)), np.empty(0, np.int64), np.empty(0)
    next_k = 1
    for lo, pos in chunks:
        label = prep.cmd.sample_blocks(t_knots, ts, lag // 2, prep.kept, lo, len(pos))
        joined = pos if not len(pos_b) else np.vstack([pos_b[-1:], pos])
        steps = np.linalg.norm(np.diff(joined, axis=0), axis=1)
        carry = trav_b[-1] if len(trav_b) else 0.0
        travelled = np.cumsum(np.concatenate([[carry], steps]))[(1 if len(trav_b) else 0) :]
        pos_b, lab_b = np.vstack([pos_b, pos]), np.concatenate([lab_b, label])
        trav_b = np.concatenate([trav_b, travelled])
        end = lo + len(pos)
        ks = np.arange(next_k, min(int(lab_b[-1]), n - 1) + 1)
        switch = np.maximum(start + np.searchsorted(lab_b, ks, side="left"), 1)
        ready = int(np.searchsorted(switch, end - SEARCH_SAMPLES, side="left"))
        _search(ks[:ready], switch[:ready], start, pos_b, lab_b, trav_b, points,
                leaving_dwell, junction, travelled_at)  # fmt: skip
        next_k += ready
        first = switch[ready] if ready < len(ks) else end  # the next switch, or after the end
        keep = max(first - SEARCH_SAMPLES - 1 - start, 0)
        start, pos_b, lab_b, trav_b = start + keep, pos_b[keep:], lab_b[keep:], trav_b[keep:]
    n_samples = start + len(lab_b)
    ks = np.arange(next_k, n)
    switch = np.clip(start + np.searchsorted(lab_b, ks, side="left"), 1, n_samples - 1)
    _search(ks, switch, start, pos_b, lab_b, trav_b, points, leaving_dwell, junction,
            travelled_at)  # fmt: skip
    junction[n], travelled_at[n] = n_samples - 1, trav_b[-1]
    np.maximum.accumulate(junction, out=junction)
    np.maximum.accumulate(travelled_at, out=travelled_at)  # the path length grows with time
    return BlockTargets(junction_sample=junction, length_mm=np.diff(travelled_at),
                        time_s=np.diff(junction) * ts)  # fmt: skip


def _search(ks, switch, start, pos, label, travelled, points, leaving_dwell, junction, at):
    """The junction points of junctions ``ks`` (J,) whose block switches are ``switch`` (J,),
    in kept samples from ``start`` on; writes their samples to ``junction`` and the path length
    travelled there to ``at``, by batches of :data:`~nctwin.targets.CHUNK_JUNCTIONS`."""
    if not len(ks):
        return
    axes = np.ascontiguousarray(pos.T)
    offsets = np.arange(-SEARCH_SAMPLES, SEARCH_SAMPLES + 1)
    for a in range(0, len(ks), CHUNK_JUNCTIONS):
        k = ks[a : a + CHUNK_JUNCTIONS]
        found = _junction_chunk(axes, label, points[k - 1], switch[a : a + CHUNK_JUNCTIONS] - start,
                                leaving_dwell[k - 1], offsets)  # fmt: skip
        junction[k] = found + start
        at[k] = travelled[found]
