"""Modal state: the modal groups and the tables of the G-codes the reader knows (and of the
ones it refuses, with why), and the cumulative maxima and anchored sums that carry state and
positions forward from line to line."""

from __future__ import annotations

import numpy as np

from ..toolpath import MotionKind
from ._lexer import _L

MM_PER_INCH = 25.4
#: Most blocks one line may make (turns of an arc, pecks and repeats of a canned cycle).
MAX_BLOCKS_PER_LINE = 1_000_000

# ---------------------------------------------------------------------------------------------
# Tables: modal groups and G-codes
# ---------------------------------------------------------------------------------------------
# modal groups (codes are 10 x the G number)
_MOTION, _NONMODAL, _PLANE, _UNITS, _DIST, _ARCDIST, _FEEDMODE = range(7)
_CUTTER, _TLO, _COORD, _PATH, _RETRACT = range(7, 12)
_GROUP_NAMES = (
    "motion",
    "non-modal",
    "plane",
    "units",
    "distance mode",
    "arc distance mode",
    "feed mode",
    "cutter compensation",
    "tool length offset",
    "coordinate system",
    "path control",
    "canned-cycle return mode",
)
_CYCLES = (730, 740, 810, 820, 830, 840, 850, 860, 870, 880, 890)
_G92S = (920, 921, 922, 923)
_HOMES = (280, 300)  # G28, G30: to reference point 1, 2
_G_GROUP = {
    **dict.fromkeys((0, 10, 20, 30, 800, *_CYCLES), _MOTION),
    **dict.fromkeys((40, 530, *_G92S, *_HOMES), _NONMODAL),
    **dict.fromkeys((170, 180, 190), _PLANE),
    **dict.fromkeys((200, 210), _UNITS),
    **dict.fromkeys((900, 910), _DIST),
    **dict.fromkeys((901, 911), _ARCDIST),
    940: _FEEDMODE,
    400: _CUTTER,
    **dict.fromkeys((430, 490), _TLO),
    **dict.fromkeys((540, 550, 560, 570, 580, 590, 591, 592, 593), _COORD),
    **dict.fromkeys((610, 611, 640), _PATH),
    **dict.fromkeys((980, 990), _RETRACT),
}


def _code_set(*codes: int) -> np.ndarray:
    """Membership table of G-codes (10 x the number), indexed by a code or by -1 (no code)."""
    table = np.zeros(1001, dtype=bool)
    table[list(codes)] = True
    return table


# G76 (760) is a cycle only in the fanuc dialect: fine boring, which dwells P and shifts by Q (the
# rs274ngc table below does not know it, so no line's motion is 760 there)
_IS_CYCLE, _IS_G92 = _code_set(*_CYCLES, 760), _code_set(*_G92S)
_IS_HOME, _IS_ARC = _code_set(*_HOMES), _code_set(20, 30)
_PECKS, _Q_FANUC = _code_set(730, 830), _code_set(730, 760, 830)  # cycles with a Q word
_DWELLS = _code_set(740, 760, 820, 840, 860, 880, 890)  # cycles with a P dwell
_G_CODES = np.array(sorted(_G_GROUP), dtype=np.int64)
_G_GROUPS = np.array([_G_GROUP[c] for c in _G_CODES], dtype=np.int64)
#: Codes the rs274ngc table reads that a Fanuc milling control reads otherwise, or lacks: refused
#: in the fanuc dialect, with what they are there.
_G_NOT_FANUC = {
    870: "back boring, which a Fanuc control runs with a Q shift and an oriented spindle stop",
    921: "workpiece coordinate system preset on a Fanuc control",
    922: "a LinuxCNC offset code",
    923: "a LinuxCNC offset code",
    901: "absolute arc centres, a LinuxCNC code",
    911: "a LinuxCNC code; on a Fanuc control, the maximum incremental amount check",
}
#: What codes LinuxCNC reads otherwise are on a Fanuc milling control (refused there too).
_G_FANUC_NAMES = {
    50: "high-speed cycle machining",
    51: "AI contour control",
    80: "look-ahead control",
    520: "local coordinate system",
    100: "data setting",
}
_FANUC_GROUP = {c: g for c, g in _G_GROUP.items() if c not in _G_NOT_FANUC} | {760: _MOTION}
_G_CODES_FANUC = np.array(sorted(_FANUC_GROUP), dtype=np.int64)
_G_GROUPS_FANUC = np.array([_FANUC_GROUP[c] for c in _G_CODES_FANUC], dtype=np.int64)
#: Codes LinuxCNC reads and this reader does not: what they are.
_G_LINUXCNC = {
    **dict.fromkeys((410, 411, 420, 421), "cutter compensation"),
    **dict.fromkeys((281, 301), "reference-point setting"),
    100: "data setting",
    930: "inverse-time feed",
    950: "feed per revolution",
    960: "constant surface speed",
    970: "spindle RPM mode",
    330: "spindle-synchronised motion",
    331: "rigid tapping",
    760: "threading cycle",
    **dict.fromkeys((50, 51, 52, 53), "spline"),
    **dict.fromkeys((382, 383, 384, 385), "probing"),
    **dict.fromkeys((70, 80), "lathe diameter/radius mode"),
    **dict.fromkeys((431, 432), "dynamic tool length offset"),
    520: "local coordinate offset",
}
#: Codes of other controls that LinuxCNC does not read either.
_G_FOREIGN = {
    **dict.fromkeys((680, 690), "coordinate rotation"),
    **dict.fromkeys((500, 510), "scaling"),
    **dict.fromkeys((150, 160), "polar coordinates"),
}
_KIND_OF_MOTION = {
    0: MotionKind.RAPID,
    10: MotionKind.LINEAR,
    20: MotionKind.ARC_CW,
    30: MotionKind.ARC_CCW,
}
_SINGLE = "FHIJKLNPQRSTXYZ"  # letters allowed once per line
_ROW = np.full(26, -1, dtype=np.int64)  # letter code -> row of the per-line word table
_ROW[[_L[c] for c in _SINGLE]] = np.arange(len(_SINGLE))
_STOPS = (0.0, 1.0, 2.0, 30.0, 60.0)  # M-codes LinuxCNC runs after the motion of their line
_SPINDLE_M = {3.0: 1, 4.0: -1, 5.0: 0, 19.0: 0}  # M-code -> spindle turning (+1 cw, -1 ccw)


# ---------------------------------------------------------------------------------------------
# Carrying modal state and positions forward
# ---------------------------------------------------------------------------------------------
def _ffill(given: np.ndarray, values: np.ndarray, initial):
    """Carry ``values`` forward from the lines where ``given``; ``initial`` before the first."""
    idx = np.where(given, np.arange(len(given)), -1)
    np.maximum.accumulate(idx, out=idx)
    return np.where(idx >= 0, values[np.maximum(idx, 0)], initial)


def _anchored(anchor: np.ndarray, value: np.ndarray, step: np.ndarray, initial: float):
    """Positions along one axis: the ``value`` of the last ``anchor`` line (``initial`` before
    the first) plus the ``step`` of each line since."""
    csum = np.cumsum(step)
    return _ffill(anchor, value, initial) + (csum - _ffill(anchor, csum, 0.0))


def _fmt_g(code: int) -> str:
    return f"G{code // 10}" + (f".{code % 10}" if code % 10 else "")


def offset_changes(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The lines (0-based) that set an offset LinuxCNC's task waits for the motion to set, with
    the :data:`~nctwin.toolpath.OFFSET_EVENTS` value of the first a line sets (it runs the tool
    length offset, the coordinate system, then G92): every G43 and G49, every G92.x, and a
    G54-G59.3 that changes the system in force (LinuxCNC ignores the one in force)."""
    coord = G[_COORD]
    before = np.concatenate([[540], _ffill(coord >= 0, coord, 540)[:-1]])
    masks = ((G[_TLO] >= 0, 43.0), ((coord >= 0) & (coord != before), 54.0),
             (_IS_G92[G[_NONMODAL]], 92.0))  # fmt: skip
    line = np.concatenate([np.flatnonzero(m) for m, _ in masks])
    value = np.concatenate([np.full(int(m.sum()), v) for m, v in masks])
    line, first = np.unique(line, return_index=True)  # a line's first, in the order it runs
    return line, value[first]
