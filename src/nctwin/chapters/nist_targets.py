r"""Targets of the learned cycle-time methods from a real machine's log
(:mod:`nctwin.chapters.nist_learned` says how they are used): the spans between a run's block
events (:func:`block_spans`), the lines that carry non-motion time (:func:`non_motion_lines`),
Chien et al.'s per-move average feed of a span (:func:`span_targets`) and Sun et al.'s
nearest feed record per move (:func:`axis_targets`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mtconnect import Track
from ..runtimes import ProgramLines
from ..toolpath import MotionKind, Toolpath

__all__ = ["WAIT_M_CODES", "Spans", "axis_targets", "block_spans", "non_motion_lines",
           "span_targets"]  # fmt: skip

#: M-codes the control waits at: program stop, optional stop, spindle start (CW, CCW) and stop,
#: tool change, spindle orientation. Coolant (M7-M9) moves on at once.
WAIT_M_CODES = (0, 1, 3, 4, 5, 6, 19)


@dataclass(frozen=True)
class Spans:
    """The spans a run's ``Block_Number`` events time over a motion window.

    Parameters
    ----------
    first_line, end_line : numpy.ndarray of int64, shape (S,)
        Span ``s`` times the lines ``first_line[s] .. end_line[s] - 1``: from the event of
        ``first_line[s]`` to the event of the next observed line ``end_line[s]``.
    t0_s, t1_s : numpy.ndarray, shape (S,)
        The times of those two events (s).
    """

    first_line: np.ndarray
    end_line: np.ndarray
    t0_s: np.ndarray
    t1_s: np.ndarray

    @property
    def time_s(self) -> np.ndarray:
        """The time of each span (s), shape (S,)."""
        return self.t1_s - self.t0_s


def block_spans(block_t_s: np.ndarray, block: np.ndarray, first_cut: int, m30: int) -> Spans:
    """The spans between consecutive block events over the motion window.

    Parameters
    ----------
    block_t_s, block : numpy.ndarray, shape (n,)
        A run's ``Block_Number`` events (:attr:`nctwin.mtconnect.Run.block_t_s`,
        :attr:`~nctwin.mtconnect.Run.block`).
    first_cut, m30 : int
        The window's first line and its M30 line (:class:`~nctwin.runtimes.ProgramLines`).

    Returns
    -------
    Spans
        From the first event at or past ``first_cut`` (where ``Verdict.motion_s`` starts) to
        the first event at or past ``m30`` (where it ends); events of a line not past the one
        before (none in a valid run) are skipped.
    """
    t, b = np.asarray(block_t_s, float), np.asarray(block, np.int64)
    keep = b >= first_cut
    t, b = t[keep], b[keep]
    end = np.flatnonzero(b >= m30)
    if end.size:
        t, b = t[: end[0] + 1], b[: end[0] + 1]
    ahead = np.r_[True, b[1:] > np.maximum.accumulate(b)[:-1]] if b.size else b.astype(bool)
    t, b = t[ahead], b[ahead]
    return Spans(b[:-1], b[1:], t[:-1], t[1:])


def non_motion_lines(lines: ProgramLines, tp: Toolpath) -> np.ndarray:
    """The lines of a program that carry time no move accounts for.

    Parameters
    ----------
    lines : ProgramLines
        The program's tool changes (from the ``G28`` line to the ``M6`` line), spindle starts
        (the ``M3``/``M4`` line and the next line with a block) and optional stops.
    tp : Toolpath
        The whole program: its dwells' lines and the lines of :data:`WAIT_M_CODES`.

    Returns
    -------
    numpy.ndarray of int64, shape (k,)
        Sorted, unique 1-based lines.
    """
    spans = np.concatenate([lines.tool_changes, lines.spindle_starts]).reshape(-1, 2)
    ranged = [np.arange(a, z + 1) for a, z in spans]
    ev = tp.events
    waits = ev["line"][(ev["word"] == "M") & np.isin(ev["value"], WAIT_M_CODES)]
    dwells = tp.line[tp.kind == MotionKind.DWELL]
    parts = [*ranged, lines.optional_stops, waits, dwells]
    return np.unique(np.concatenate([np.asarray(p, np.int64).ravel() for p in parts]))


def span_targets(
    move_line: np.ndarray,
    length_mm: np.ndarray,
    feed_mm_s: np.ndarray,
    spans: Spans,
    non_motion: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Chien's per-move targets from the spans: the span's average feed and the log time ratio.

    Parameters
    ----------
    move_line : numpy.ndarray of int64, shape (M,)
        The program line of each move, in program order.
    length_mm, feed_mm_s : numpy.ndarray, shape (M,)
        Each move's length :math:`l_k` and feed feature :math:`F_k`.
    spans : Spans
        :func:`block_spans` (S spans).
    non_motion : numpy.ndarray of int64, shape (k,)
        :func:`non_motion_lines`.

    Returns
    -------
    targets : numpy.ndarray, shape (M, 2)
        The average feed :math:`\bar f` (mm/s) of the move's span, its length over its time,
        and :math:`\ln (F_k \tilde t_k / l_k) = \ln (F_k / \bar f)` (the move's time at the
        span's average feed); both NaN for a move in no span, in a span that holds a line of
        ``non_motion`` or whose time is not positive.
    span : numpy.ndarray of int64, shape (M,)
        The span of each move (-1: none, or a span left NaN).
    move_t_s : numpy.ndarray, shape (M, 2)
        The start and end time of each move, its span's time laid over the span's moves in
        proportion to their length (NaN where ``span`` is -1).
    """
    move_line = np.asarray(move_line, np.int64)
    length = np.asarray(length_mm, float)
    k = np.searchsorted(spans.first_line, move_line, side="right") - 1
    inside = k >= 0
    inside[inside] = move_line[inside] < spans.end_line[k[inside]]
    # spans that hold a non-motion line, or no time
    held = np.searchsorted(non_motion, spans.first_line, side="left")
    blocked = (held < len(non_motion)) & (
        np.r_[non_motion, np.iinfo(np.int64).max][held] < spans.end_line
    )
    ok_span = ~blocked & (spans.time_s > 0)
    span = np.where(inside, k, -1)
    span[inside] = np.where(ok_span[k[inside]], k[inside], -1)
    use = span >= 0
    span_len = np.bincount(span[use], weights=length[use], minlength=len(spans.first_line))
    targets = np.full((len(move_line), 2), np.nan)
    move_t = np.full((len(move_line), 2), np.nan)
    if use.any():
        s = span[use]
        with np.errstate(invalid="ignore", divide="ignore"):
            avg = span_len[s] / spans.time_s[s]
            targets[use, 0] = np.where(avg > 0, avg, np.nan)
            targets[use, 1] = np.log(np.asarray(feed_mm_s, float)[use] / targets[use, 0])
        # cumulative length within each span (moves of a span are consecutive)
        cum = np.cumsum(length[use])
        first = np.r_[True, s[1:] != s[:-1]]
        base = np.maximum.accumulate(np.where(first, cum - length[use], 0.0))
        end = cum - base
        share0, share1 = (end - length[use]) / span_len[s], end / span_len[s]
        dt = spans.time_s[s]
        move_t[use, 0] = spans.t0_s[s] + share0 * dt
        move_t[use, 1] = spans.t0_s[s] + share1 * dt
    return targets, span, move_t


def axis_targets(
    directions: np.ndarray, span: np.ndarray, move_t_s: np.ndarray, spans: Spans, feed: Track
) -> np.ndarray:
    """Sun's per-axis targets: the logged feed record nearest each move, times its direction.

    Parameters
    ----------
    directions : numpy.ndarray, shape (M, 3)
        Each move's unit direction.
    span, move_t_s : numpy.ndarray, shapes (M,) and (M, 2)
        :func:`span_targets`' span of each move and its time interval.
    spans : Spans
    feed : Track
        The run's ``Feed_Rate`` records (:attr:`nctwin.mtconnect.Run.feed_mm_s`, mm/s).

    Returns
    -------
    numpy.ndarray, shape (M, 3)
        The record nearest in time to the move's interval (one inside it where any is: the
        one nearest its middle) among the records within the move's span, times the move's
        direction; NaN where the span holds no record or ``span`` is -1.
    """
    span = np.asarray(span, np.int64)
    out = np.full((len(span), 3), np.nan)
    use = span >= 0
    if not use.any() or not feed.t_s.size:
        return out
    s = span[use]
    mid = move_t_s[use].mean(axis=1)
    lo = np.searchsorted(feed.t_s, spans.t0_s[s], side="left")  # first record in the span
    hi = np.searchsorted(feed.t_s, spans.t1_s[s], side="right") - 1  # last record in it
    j = np.clip(np.searchsorted(feed.t_s, mid), lo, np.maximum(hi, lo))  # first at/after mid
    before = np.clip(j - 1, lo, None)
    pick = np.where(
        np.abs(feed.t_s[np.minimum(before, len(feed.t_s) - 1)] - mid)
        <= np.abs(feed.t_s[np.minimum(j, len(feed.t_s) - 1)] - mid),
        before,
        j,
    )
    value = np.where(hi >= lo, feed.value[np.minimum(pick, len(feed.t_s) - 1)], np.nan)
    out[use] = value[:, None] * np.asarray(directions, float)[use]
    return out
