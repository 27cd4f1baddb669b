"""The fanuc dialect's own words: M29 (rigid tapping) before a G84 or G74, and the Fanuc words
the reader does not read (M98/M99 subprograms, K repeats of a canned cycle), refused with why.

Sources (www.cncmanuals.com): FANUC Series 0i/0i Mate Model B Connection Manual (Function),
B-63833EN-1/02, chapter 9 (spindle speed function), p. 540, whose rigid-tapping examples give
``M29 S1000`` in a block of its own, then ``G84 Z-100. R-20. F..``, then ``G80``; and FANUC
Power Mate i-D/H Descriptions, B-63172EN/01, 12.2 (rigid tap): M29 S before the G74/G84
command selects rigid tapping, G80 cancels it, and the spindle and the tapping axis then move
as a two-axis linear interpolation (the same path and feed as a floating tap).
"""

from __future__ import annotations

import numpy as np

from ..machine import DIALECTS
from ._errors import _Errors
from ._lexer import _L
from ._modal import _MOTION, _fmt_g

_TAPPING = (740, 840)
_NOT_READ_M = {98.0: "subprogram call", 99.0: "subprogram return"}


def check_dialect(dialect) -> None:
    """Refuse a dialect that is not one of :data:`DIALECTS`, naming the parameter and them."""
    if dialect not in DIALECTS:
        allowed = ", ".join(repr(d) for d in DIALECTS)
        raise ValueError(f"dialect = {dialect!r} is not allowed: allowed {allowed}")


def _fanuc_words(code, value, line, has, G, motion, cycle_line, errors: _Errors) -> np.ndarray:
    """Check the fanuc dialect's own words; return which lines run a rigid tapping cycle.

    An M29 makes the first canned-cycle line at or after it rigid tapping, and the lines of
    that cycle after it until another motion code (the sources name G80 as what cancels rigid
    tapping; another motion code is taken to end it too); a G80 between the M29 and the cycle
    cancels it. A cycle other than
    G84 or G74 after an M29 is refused, naming the M29's line. Rigid tapping moves as floating
    tapping does; only the reader's checks of the spindle's turning are left out (the control
    turns the spindle itself, synchronised with the tapping axis).
    """
    n = len(motion)
    rigid = np.zeros(n, dtype=bool)
    is_m = code == _L["M"]
    for m, what in _NOT_READ_M.items():
        errors.at_lines(
            np.unique(line[is_m & (value == m)]),
            f"M{m:g} ({what}) is not supported in the fanuc dialect",
        )
    errors.at_lines(
        cycle_line & has["K"],
        "K (the repeats of a Fanuc canned cycle) is not supported: write L",
    )
    m29 = np.unique(line[is_m & (value == 29.0)])
    if not len(m29):
        return rigid
    cycles = np.flatnonzero(cycle_line)
    g80 = np.flatnonzero(G[_MOTION] == 800)
    changes = np.flatnonzero(G[_MOTION] >= 0)
    for k in m29:
        i = np.searchsorted(cycles, k)
        if i == len(cycles):
            continue
        cyc = int(cycles[i])
        j = np.searchsorted(g80, k)
        if j < len(g80) and g80[j] < cyc:  # G80 before the cycle cancels the M29
            continue
        c = int(motion[cyc])
        if c not in _TAPPING:
            errors.at_lines(
                np.array([cyc]),
                f"{_fmt_g(c)} after M29 (rigid tapping, line {k + 1}): M29 must be followed by"
                " G84 or G74",
            )
            continue
        later = changes[changes > cyc]
        stop = next((int(x) for x in later if G[_MOTION, x] != c), n)
        rigid[cyc:stop] = True
    return rigid
