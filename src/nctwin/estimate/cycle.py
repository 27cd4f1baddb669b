"""The shop floor's cycle time: an estimate's motion plus the times that are no motion, and the
feed and rapid overrides.

An :class:`~nctwin.estimate.result.Estimate` times the blocks of a program (its moves and
dwells). A machine also spends time on lines that are no motion: tool changes, spindle starts,
optional stops, the start and the end of a run; a profile's ``[control.sequence]``
(:class:`~nctwin.controls.SequenceControl`) says how long, net of the motion of the lines
involved, as :mod:`nctwin.calibrate` measures them. :class:`CycleTime` adds them where the
program's M, S and T words (:attr:`Toolpath.events <nctwin.toolpath.Toolpath.events>`) put
them:

* **Tool change**: one per ``M6`` word, :attr:`SequenceControl.tool_change_s`, or
  :attr:`SequenceControl.first_tool_change_s` before the program's first ``M3``/``M4`` (the
  spindle at rest, no return before it).
* **Spindle start**: one per ``M3`` or ``M4`` word, ``SequenceControl.spindle_s(S)`` with the
  S in force (the last S word before it or on its line; 0 rev/min where none was given).
* **Optional stop**: one per ``M1`` word outside a tool change,
  :attr:`SequenceControl.optional_stop_s`. An ``M1`` is inside a tool change when the spindle
  is off (no ``M3``/``M4`` yet, or the last one was ended by an ``M5``, ``M6``, ``M2`` or
  ``M30``) and the next of ``M3``, ``M4``, ``M6``, ``M2``, ``M30`` after it is an ``M6``: the
  ``M5``, ``G91 G28 Z0.``, ``M01``, ``Tn M6`` of a Fanuc post, whose ``M01`` the calibrated
  tool change already holds.
* **Program start and end**: once each.

The cycle time is all of them plus the blocks' times. The **motion time** is what a machine's
log shows between a spindle start and its stop: for each spindle run, from its first block after
the ``M3``/``M4`` to the word that stops it (``M5``, or an ``M6``, ``M2``, ``M30``, or the end
of the program), summed over the runs; the times of the words between (an ``M1``, a second
``M3`` that changes the speed) are in it. A program that starts no spindle has none (None).

A word precedes the block its event names (RS274/NGC: a line's M and S words act before its
motion, :class:`~nctwin.toolpath.Toolpath`), so the timeline is the events and blocks in that
order. Coolant (``M7``-``M9``) takes no time: the profile has no setting for it. Canned cycles
are not told apart: the reader expands them into rapids and feed lines, and the tool path keeps
no mark of which block came from a cycle.

:func:`apply_overrides` turns the feed and rapid overrides of a machine's panel into the
inputs of any estimator: the profile's rapid feed and the program's feeds, scaled.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..checks import check_range
from ..controls import SequenceControl
from ..machine import Profile
from ..toolpath import MotionKind, Toolpath
from .result import Estimate

__all__ = ["BREAKDOWN", "OVERRIDE_MAX_PCT", "CycleTime", "apply_overrides"]

#: Highest feed or rapid override (%); the lowest is just above 0.
OVERRIDE_MAX_PCT = 200.0

#: The keys of :attr:`CycleTime.breakdown`, in order.
BREAKDOWN = (
    "feed_lines",
    "arcs",
    "rapids",
    "dwells",
    "tool_changes",
    "spindle_starts",
    "optional_stops",
    "program_start_end",
)

#: The block kinds of each motion entry of the breakdown.
_KINDS = {
    "feed_lines": (MotionKind.LINEAR,),
    "arcs": (MotionKind.ARC_CW, MotionKind.ARC_CCW),
    "rapids": (MotionKind.RAPID,),
    "dwells": (MotionKind.DWELL,),
}

#: M words that stop the spindle (``M6``, ``M2`` and ``M30`` too) and that start it.
_STOPS = (5.0, 6.0, 2.0, 30.0)
_STARTS = (3.0, 4.0)


@dataclass(frozen=True, eq=False)
class CycleTime:
    """The cycle time of a program: its blocks and the times that are no motion.

    Build it with :meth:`of`.

    Parameters
    ----------
    estimate : Estimate
        The blocks' times.
    cycle_time_s : float
        Program start to program end: the blocks, the tool changes, the spindle starts, the
        optional stops, the program start and end (s).
    motion_time_s : float or None
        Summed over the spindle runs, from the first block after the spindle start to the
        spindle stop (s); None for a program that starts no spindle.
    breakdown : dict of str to float
        Seconds by :data:`BREAKDOWN` key; they sum to ``cycle_time_s``.
    counts : dict of str to int
        ``tool_changes``, ``spindle_starts``, ``optional_stops`` and ``spindle_runs`` (the
        windows of the motion time).
    """

    estimate: Estimate
    cycle_time_s: float
    motion_time_s: float | None
    breakdown: dict[str, float]
    counts: dict[str, int]

    @classmethod
    def of(cls, estimate: Estimate, sequence: SequenceControl | None = None) -> CycleTime:
        """The cycle time of ``estimate``'s program with the non-motion times of ``sequence``
        (None: all 0, the cycle time is the blocks')."""
        seq = SequenceControl() if sequence is None else sequence
        tp, block_s = estimate.toolpath, np.asarray(estimate.block_times_s, float)
        ev = tp.events[np.argsort(tp.events["block"], kind="stable")]
        event_s, kinds, windows = _walk(ev, seq)
        # the timeline: event i precedes block ev.block[i]; block k follows the events at <= k
        n, e = len(block_s), len(ev)
        timeline = np.empty(n + e)
        block_pos = np.arange(n) + np.searchsorted(ev["block"], np.arange(n), side="right")
        timeline[block_pos] = block_s
        timeline[np.arange(e) + ev["block"]] = event_s
        ends = np.concatenate([[0.0], np.cumsum(timeline)])
        motion = None
        if windows:
            stop_block = np.append(ev["block"], n)  # of each event; the end for index e
            stop_pos = np.append(np.arange(e) + ev["block"], n + e)
            motion = float(sum(ends[stop_pos[i]] - ends[block_pos[a]]
                               for a, i in windows if stop_block[i] > a))  # fmt: skip
        breakdown = {k: float(block_s[np.isin(tp.kind, kind)].sum()) for k, kind in _KINDS.items()}
        for k in ("tool_changes", "spindle_starts", "optional_stops"):
            breakdown[k] = float(event_s[kinds == k].sum())
        breakdown["program_start_end"] = float(seq.program_start_s + seq.program_end_s)
        counts = {k: int((kinds == k).sum()) for k in ("tool_changes", "spindle_starts",
                                                      "optional_stops")}  # fmt: skip
        counts["spindle_runs"] = len(windows)
        cycle = estimate.cycle_time_s + float(event_s.sum()) + breakdown["program_start_end"]
        return cls(estimate, cycle, motion, breakdown, counts)

    def summary(self) -> dict:
        """``cycle_time_s``, ``motion_time_s``, ``breakdown`` and ``counts`` (what ``nctwin
        estimate --json`` adds to the estimate's summary)."""
        return {
            "cycle_time_s": self.cycle_time_s,
            "motion_time_s": self.motion_time_s,
            "breakdown": dict(self.breakdown),
            "counts": dict(self.counts),
        }


def _walk(ev: np.ndarray, seq: SequenceControl) -> tuple[np.ndarray, np.ndarray, list]:
    """Each event's time (s) and kind (a breakdown key, or "" for none), and the spindle runs
    as (block where it starts, index of the event that stops it, ``len(ev)`` for the end)."""
    e = len(ev)
    word, value = ev["word"], ev["value"]
    m = np.where(word == "M", value, np.nan)
    # the next of M3/M4/M6/M2/M30 after each event (NaN: none)
    nxt, after = np.full(e, np.nan), np.nan
    for i in range(e - 1, -1, -1):
        nxt[i] = after
        if m[i] in _STARTS or m[i] in _STOPS[1:]:
            after = m[i]
    # the S in force at each event: the last S before it or on its line
    rpm, rpm_s = np.zeros(e), 0.0
    group = np.flatnonzero(np.diff(ev["block"]) | np.diff(ev["line"])) + 1
    for lo, hi in zip(np.r_[0, group], np.r_[group, e], strict=True):
        s = np.flatnonzero(word[lo:hi] == "S")
        rpm_s = float(value[lo + s[-1]]) if s.size else rpm_s
        rpm[lo:hi] = rpm_s
    event_s, kinds = np.zeros(e), np.full(e, "", dtype="U16")
    windows, start, spun = [], None, False
    for i in range(e):
        if m[i] == 6.0:
            event_s[i], kinds[i] = seq.tool_change_at_s(first=not spun), "tool_changes"
        elif m[i] in _STARTS:
            event_s[i], kinds[i] = seq.spindle_s(rpm[i]), "spindle_starts"
        elif m[i] == 1.0 and not (start is None and nxt[i] == 6.0):
            event_s[i], kinds[i] = seq.optional_stop_s, "optional_stops"
        if m[i] in _STARTS and start is None:
            start, spun = int(ev["block"][i]), True
        elif m[i] in _STOPS and start is not None:
            windows.append((start, i))
            start = None
    if start is not None:
        windows.append((start, e))
    return event_s, kinds, windows


def apply_overrides(
    toolpath: Toolpath,
    profile: Profile,
    *,
    rapid_override_pct: float = 100.0,
    feed_override_pct: float = 100.0,
) -> tuple[Toolpath, Profile]:
    """The inputs of an estimator under a machine panel's overrides.

    Parameters
    ----------
    toolpath : Toolpath
    profile : Profile
    rapid_override_pct : float
        Scales the machine's ``rapid_feed_mm_s``, in (0, 200] %; the machine's other limits
        still hold (an estimator that caps rapids at the axis or the maximum feed still does).
    feed_override_pct : float
        Scales the programmed feeds of the blocks that are no rapid, in (0, 200] %; the
        machine's ``max_feed_mm_s`` still caps them.

    Returns
    -------
    Toolpath, Profile
        The same objects at 100 %.

    Raises
    ------
    ValueError
        For an override out of its range, naming it, its value and the range.
    """
    for name, pct in (("rapid_override_pct", rapid_override_pct),
                      ("feed_override_pct", feed_override_pct)):  # fmt: skip
        check_range(name, pct, 0.0, OVERRIDE_MAX_PCT, low_open=True)
    if rapid_override_pct != 100.0:
        rapid = profile.machine.rapid_feed_mm_s * rapid_override_pct / 100.0
        profile = replace(profile, machine=replace(profile.machine, rapid_feed_mm_s=rapid))
    if feed_override_pct != 100.0:
        scale = np.where(toolpath.kind == MotionKind.RAPID, 1.0, feed_override_pct / 100.0)
        toolpath = replace(toolpath, feed_mm_s=toolpath.feed_mm_s * scale)
    return toolpath, profile
