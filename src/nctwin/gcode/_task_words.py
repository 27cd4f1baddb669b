"""The M-words LinuxCNC's task waits for, recovered from the interpreter's modal M state.

LinuxCNC's preview module (``gcode``) turns a program's spindle, coolant, pause and
tool-change words into empty canonical stubs that never reach Python, but each line's report
(``next_line``) carries the interpreter's active M-codes (``write_m_codes`` in
interp_write.cc, LinuxCNC 2.9), as they stand after the line before it:

* ``[1]`` the line's stop: 0 (``M0``), 1 (``M1``), 2 or 30 (program end), 60, else -1;
* ``[2]`` the spindle: 3, 4 or 5;
* ``[3]`` the line's tool change: 6 (``M6``), else -1;
* ``[4]`` mist: 7 on, 9 with mist and flood off, -1 with flood alone on;
* ``[5]`` flood: 8 on, else -1.

A line's words are where these change from one report to the next (a stop and a tool change
are the line's own); the report before the interpreter's first line holds no state (all
zeros) and starts nothing. They are placed as LinuxCNC runs a block (``execute_block`` in
interp_execute.cc): spindle, coolant and tool change before the line's motion, a pause after
it. A spindle stop on the line of a tool change is the tool change's own (LinuxCNC stops the
spindle for it) and is not a word of its own. A word that changes nothing (an ``M5`` with the
spindle stopped, a second ``M8``) leaves no trace in the state and is not seen.
"""

from __future__ import annotations

import numpy as np

__all__ = ["M_COLUMNS", "task_words"]

#: The active M-codes kept per report: stop, spindle, tool change, mist, flood.
M_COLUMNS = slice(1, 6)


def _coolant(state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mist on, flood on: shape (E,) each, from the kept M columns (E, 5)."""
    return state[:, 3] == 7, state[:, 4] == 8


def task_words(before: np.ndarray, line: np.ndarray, state: np.ndarray):
    """The M-words each executed line wrote, as far as the state shows them.

    Parameters
    ----------
    before : ndarray of int, shape (E,)
        Moves made before each report.
    line : ndarray of int, shape (E,)
        Each report's line (the line about to run).
    state : ndarray, shape (E, 5)
        Each report's stop, spindle, tool change, mist and flood codes (:data:`M_COLUMNS` of
        the active M-codes): the state after the previous line.

    Returns
    -------
    move : ndarray of int, shape (W,)
        For each word, the moves made before it (the word precedes that move).
    word_line : ndarray of int, shape (W,)
        The line that wrote it.
    value : ndarray of float, shape (W,)
        The M-code.
    """
    if len(state) < 2:
        empty = np.zeros(0, np.int64)
        return empty, empty, np.zeros(0)
    prev, now = state[:-1], state[1:]
    start, end, wrote = before[:-1], before[1:], line[:-1]  # the line that ran, its moves
    ran = np.isin(prev[:, 1], (3, 4, 5))  # a state to change from
    tool = ran & (now[:, 2] == 6)
    mist0, flood0 = _coolant(prev)
    mist1, flood1 = _coolant(now)
    n = len(now)
    # one column per word, in the order a block runs them: spindle, mist, flood, coolant off,
    # tool change (before the line's moves), stop (after them)
    mask = np.column_stack([
        ran & (now[:, 1] != prev[:, 1]) & ~tool,
        ran & mist1 & ~mist0,
        ran & flood1 & ~flood0,
        ran & (mist0 | flood0) & ~(mist1 | flood1),
        tool,
        ran & np.isin(now[:, 0], (0, 1)),
    ])  # fmt: skip
    where = np.column_stack([start] * 5 + [end])
    fixed = [np.full(n, m) for m in (7.0, 8.0, 9.0, 6.0)]
    code = np.column_stack([now[:, 1], *fixed, now[:, 0]])
    r, k = np.nonzero(mask)  # row-major: by line, then by the order above
    return where[r, k].astype(np.int64), wrote[r].astype(np.int64), code[r, k].astype(float)
