"""Where LinuxCNC's task stops the tool for a word that waits for the motion, and how long the
tool then rests (the planner's queue busters).

LinuxCNC's task sends a canonical command to the motion controller or to I/O only once the
command's preconditions hold (``emcTaskCheckPreconditions`` in emctaskmain.cc, LinuxCNC 2.9):
a program pause (``M0``, and ``M1`` with the optional stop on, LinuxCNC's default), a spindle
command (``M3``, ``M4``, ``M5``), a tool change (``M6``), a coolant command (``M7``, ``M8``,
``M9``) and a dwell wait for the motion *and* I/O to be done (``WAITING_FOR_MOTION_AND_IO``),
so the planner's queue drains and the tool stops before them; a tool length offset (``G43``,
``G49``), the G5x and G92 offsets and the XY rotation wait for the motion too (the tool path's
``G`` events, :data:`~nctwin.toolpath.OFFSET_EVENTS`). Then the tool rests while task and I/O
do the command and the interpreter reads on; the times at rest are the ``[control.planner]``
settings of :class:`~nctwin.controls.PlannerControl`, measured on live runs (see the
``linuxcnc_sim`` profile). A pause rests until the operator presses cycle start, which has no
defined time: here a pause stops the tool and adds nothing (the motion time excludes the
operator's wait).

What is modelled, where the control's ``word_stops`` is on (LinuxCNC's; otherwise only the
dwells): the words of a tool path's events (M-codes and offsets) and its dwells, between the
first and the last move (a wait before the first move or after the last is no part of the
motion, as in a recording).
"""

from __future__ import annotations

import numpy as np

from ..controls import PlannerControl
from ..toolpath import MotionKind, Toolpath

__all__ = ["PAUSES", "WAITING_M_CODES", "pause_count", "task_stops"]

#: M-codes the task runs only after the motion has stopped, by the setting of their rest.
WAITING_M_CODES = {
    0.0: None,
    1.0: None,
    3.0: "spindle_wait_s",
    4.0: "spindle_wait_s",
    5.0: "spindle_wait_s",
    6.0: "tool_change_wait_s",
    7.0: "coolant_wait_s",
    8.0: "coolant_wait_s",
    9.0: "coolant_wait_s",
}
#: The program pauses, whose rest is the operator's (counted as 0 s).
PAUSES = (0.0, 1.0)


def _moving_blocks(toolpath: Toolpath) -> np.ndarray:
    return np.flatnonzero((toolpath.kind != MotionKind.DWELL) & (toolpath.lengths_mm > 0))


def task_stops(
    toolpath: Toolpath,
    merged_source: np.ndarray,
    source: np.ndarray,
    control: PlannerControl,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the planner's moves stop for the task, and the rests.

    Parameters
    ----------
    toolpath : Toolpath
        N blocks, with events.
    merged_source : ndarray of int64, shape (K,)
        The block of ``toolpath`` of each block of the naive-CAM merged tool path
        (:func:`nctwin.naivecam.merge_naive_cam`).
    source : ndarray of int64, shape (M,)
        The merged blocks that are the planner's moves (no dwells, length > 0), in order.
    control : PlannerControl
        The times at rest.

    Returns
    -------
    after : ndarray of int64, shape (S,)
        Sorted: for each stop (a dwell or a waiting word), how many moves precede it (0 ... M).
    rest_block : ndarray of int64, shape (R,)
        The block of ``toolpath`` the rest is booked on: the dwell, or the block the word
        precedes.
    rest_s : ndarray, shape (R,)
        The rests (s) beyond a dwell's own time.
    """
    dwell = np.flatnonzero(toolpath.kind == MotionKind.DWELL)
    ev = toolpath.events
    m = np.where(ev["word"] == "M", ev["value"], np.nan)
    waiting = np.isin(m, list(WAITING_M_CODES)) & control.word_stops
    # offsets set together (LinuxCNC's G55 sets the G5x and G92 offsets and the rotation) are
    # one stop: one rest per block they precede
    offset = np.unique(ev["block"][ev["word"] == "G"]) if control.word_stops else []
    word_block = np.concatenate([ev["block"][waiting], offset]).astype(np.int64)
    moving = merged_source[source]
    merged_dwell = np.flatnonzero(np.isin(merged_source, dwell))
    after = np.union1d(
        np.searchsorted(source, merged_dwell),
        np.searchsorted(moving, word_block),  # the word precedes its block
    )
    if not len(moving):
        return after, np.zeros(0, np.int64), np.zeros(0)
    first, last = moving[0], moving[-1]
    settings = [WAITING_M_CODES[v] for v in m[waiting]] + ["offset_wait_s"] * len(offset)
    rest_s = [getattr(control, name) if name else 0.0 for name in settings]
    inside_word = (word_block > first) & (word_block <= last)
    inside_dwell = (dwell > first) & (dwell < last)
    rest_block = np.concatenate([word_block[inside_word], dwell[inside_dwell]])
    rest = np.concatenate(
        [np.asarray(rest_s, float)[inside_word], np.full(inside_dwell.sum(), control.dwell_wait_s)]
    )
    return after, rest_block.astype(np.int64), rest


def pause_count(toolpath: Toolpath) -> int:
    """The program pauses (``M0``, ``M1``) between the first and the last move: their rests,
    the operator's, are not counted."""
    moving = _moving_blocks(toolpath)
    if not len(moving):
        return 0
    ev = toolpath.events
    pause = (ev["word"] == "M") & np.isin(ev["value"], PAUSES)
    b = ev["block"][pause]
    return int(((b > moving[0]) & (b <= moving[-1])).sum())
