"""G92 offsets and canned cycles (G73, G74, G81-G89): the constructs that carry state from line
to line in ways a cumulative sum cannot, interpreted one by one on the lines that hold them, as
LinuxCNC 2.9 does (``convert_axis_offsets`` in interp_convert.cc, interp_cycles.cc); and the
G28/G30 reference points under G92 offsets (``convert_home``).

In the fanuc dialect, G76 is a milling control's fine boring cycle: at each hole a rapid over
it and down to R (as G81), a feed to the bottom, the dwell P (if any), an oriented spindle stop,
a rapid shift by Q along the plane's first axis (+X in G17: Fanuc's shift direction parameter,
No. 5101 RD1/RD2 on a 0i, is taken as +), a rapid out to R (G99) or the initial level (G98) and
a rapid shift back, after which the spindle turns again. The stop and restart take no time
here. Sources: FANUC Series 15i/150i-MA Operator's Manual (Programming), p. 315 on
www.cncmanuals.com (Q is the shift at the bottom of the hole, positive, its sign ignored,
modal in the canned cycle, its direction a parameter); and the G76 format ``G76 X Y Z R Q P F
K`` with Q the shift and P the dwell, the tool stopped oriented at the bottom, shifted and
taken out by rapid, in a post on FANUC's canned cycles (blog.csdn.net/weixin_42153801/article/
details/113069589). That the shifts are rapids is this reader's reading (the 15i manual feeds an I/J
shift at F).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..toolpath import PLANE_AXES, MotionKind
from ._errors import _NEEDS_LINUXCNC
from ._modal import (
    _DWELLS,
    _IS_CYCLE,
    _IS_G92,
    _MOTION,
    _NONMODAL,
    MAX_BLOCKS_PER_LINE,
    MM_PER_INCH,
    _anchored,
    _ffill,
    _fmt_g,
)

#: LinuxCNC 2.9's G73/G83 retract above the last peck (``G83_RAPID_DELTA``, interp_internal.hh).
G83_RAPID_DELTA_IN = 0.010


@dataclass(frozen=True)
class _Lines:
    """Per-line words and modal state, the input of the line-by-line parts of the reader.

    ``W[letter]`` is the value of each line's word (NaN where absent), ``has[letter]`` its
    presence; the other fields hold the modal state in force at each line, after its own codes.
    """

    W: dict
    has: dict
    G: np.ndarray  # (groups, n): the G-code of each group on each line, -1 if none
    scale: np.ndarray  # mm per program unit
    motion: np.ndarray
    plane: np.ndarray
    incremental: np.ndarray
    retract_r: np.ndarray  # G99 (retract to R), else G98
    spindle: np.ndarray  # +1 clockwise, -1 counter-clockwise, 0 stopped
    p_scale: float
    rigid: np.ndarray | None = None  # fanuc dialect: lines of rigid tapping (after an M29)


class _LineError(Exception):
    """A line that cannot be interpreted (raised and caught inside the reader)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass(frozen=True)
class _Sticky:
    """The words a canned cycle keeps for later lines of the same cycle, in program units (P in
    seconds). LinuxCNC's ``cycle_p`` starts at 0 (a G84 without P dwells 0 s)."""

    r: float = np.nan
    depth: float = np.nan
    p: float = 0.0
    q: float = np.nan
    ijk: tuple[float, float, float] = (np.nan, np.nan, np.nan)


@dataclass(frozen=True)
class _Anchors:
    """Where the positions of n lines are anchored (n, 3): the G53 lines (n,), the axes G92
    sets, the machine coordinate of G28/G30 (NaN elsewhere) and where one is given, the
    anchors, the incremental steps and their sums, the last anchor at or before each line, the
    program coordinate of each anchor (mm) and in its line's units where exact, and the count
    of steps so far."""

    g53: np.ndarray
    g92: np.ndarray
    target: np.ndarray
    home: np.ndarray
    anchor: np.ndarray
    step: np.ndarray
    csum: np.ndarray
    last: np.ndarray
    aval: np.ndarray
    uval: np.ndarray
    n_steps: np.ndarray

    @classmethod
    def of(cls, L: _Lines, axis_given, axis_val, hl, home_mm, cycle_line) -> _Anchors:
        n = len(L.scale)
        nonmodal = L.G[_NONMODAL]
        g53 = nonmodal == 530  # machine coordinates: program coordinates minus the G92 offset
        g92 = np.stack([L.has[x] for x in "XYZ"], axis=1) & (nonmodal == 920)[:, None]
        target = np.full((n, 3), np.nan)  # the machine coordinates of G28/G30 (NaN elsewhere)
        target[hl] = home_mm
        home = ~np.isnan(target)
        anchor = (
            (axis_given & ~L.incremental[:, None])
            | (cycle_line | _IS_G92[nonmodal] & (nonmodal != 920))[:, None]  # every axis moves
            | g92
            | home
        )
        step = np.where(axis_given & L.incremental[:, None] & ~cycle_line[:, None], axis_val, 0.0)
        last = np.where(anchor, np.arange(n)[:, None], -1)
        np.maximum.accumulate(last, axis=0, out=last)
        uval = np.stack([L.W[x] for x in "XYZ"], axis=1)  # ... in its line's units, where exact
        uval[g53] = np.nan
        uval[home] = np.nan
        return cls(
            g53, g92, target, home, anchor, step, np.cumsum(step, axis=0), last,
            np.where(home, target, axis_val), uval, np.cumsum(step != 0.0, axis=0),
        )  # fmt: skip

    def before(self, k: int, start: np.ndarray) -> np.ndarray:
        """Program coordinates before line k."""
        p = start.copy()
        for a in range(3):
            j = self.last[k - 1, a] if k else -1
            if j >= 0:
                p[a] = self.aval[j, a] + (self.csum[k - 1, a] - self.csum[j, a])
            elif k:
                p[a] = start[a] + (self.csum[k - 1, a] - 0.0)
        return p

    def in_units(self, k: int, cur: np.ndarray, scale: np.ndarray) -> np.ndarray:
        """Program coordinates ``cur`` (mm) before line k, in its units, exactly where known."""
        u = cur / scale[k]
        for a in range(3):
            j = self.last[k - 1, a] if k else -1
            if j >= 0 and self.n_steps[k - 1, a] == self.n_steps[j, a] and scale[j] == scale[k]:
                u[a] = u[a] if np.isnan(self.uval[j, a]) else self.uval[j, a]
        return u


def _special_positions(
    L: _Lines, axis_given, axis_val, hl, home_mm, cycle_line, moves, start, errors, cycles
):
    """Machine positions of a program with G92 offsets or canned cycles, and the offsets.

    Positions are followed in program coordinates (in mm), as LinuxCNC follows them, and the
    offsets added at the end, so that the arithmetic is LinuxCNC's. The G92 and cycle lines are
    interpreted one by one, in order (the blocks of each cycle go to ``cycles``, keyed by line);
    the positions of the other lines are anchored sums, as in the common case, whose anchors
    are filled in as the loop goes. A cycle works in program units, as LinuxCNC's: it starts
    from the number the program gave where there is one (a word, or the end of a cycle, in the
    same units and with no incremental step since).

    ``home_mm`` (len(hl), 3) holds the machine coordinate each G28/G30 line of ``hl`` sends an
    axis to (NaN for the others): in program coordinates, that coordinate minus the G92 offset
    in force, as LinuxCNC's ``find_relative`` makes it. ``moves`` marks the lines that move in
    their motion mode (not the G28/G30 lines, which leave the cycles' initial level as it is).
    """
    n = len(L.scale)
    nonmodal = L.G[_NONMODAL]
    an = _Anchors.of(L, axis_given, axis_val, hl, home_mm, cycle_line)
    aval, uval = an.aval, an.uval  # filled in as the loop goes
    off = np.zeros((n, 3))  # the G92 offsets in force at each line
    # a motion other than a canned cycle resets the cycles' initial level
    resets = np.cumsum((L.G[_MOTION] >= 0) & ~_IS_CYCLE[L.G[_MOTION]] | (moves & ~cycle_line))
    o, saved = np.zeros(3), np.zeros(3)  # G92 offsets, and parameters 5211-5213 (mm)
    il, sticky, last_cycle = None, _Sticky(), -1
    for k in np.flatnonzero(cycle_line | _IS_G92[nonmodal]):
        cur = an.before(k, start)
        if _IS_G92[nonmodal[k]]:
            cur, o, saved = _g92_line(L, k, an, cur, o, saved, off, axis_val, axis_given)
            if not cycle_line[k]:  # the motion of the line, after the offsets
                given = axis_given[k]
                aval[k, given] = np.where(
                    L.incremental[k], cur[given] + axis_val[k, given], axis_val[k, given]
                )
                if not L.incremental[k]:
                    uval[k, given] = np.array([L.W[x][k] for x in "XYZ"])[given]
        if cycle_line[k]:
            if last_cycle >= 0 and resets[k - 1] > resets[last_cycle]:
                il = None
            units = cur / L.scale[k] if _IS_G92[nonmodal[k]] else an.in_units(k, cur, L.scale)
            try:
                blocks, uval[k], il, sticky = _cycle(L, k, units, off[k], il, sticky)
            except _LineError as exc:
                errors.at_lines(np.array([k]), exc.reason)
                aval[k], uval[k] = cur, np.nan
            else:
                aval[k] = uval[k] * L.scale[k]
                cycles[int(k)] = blocks
            last_cycle = k
    pos = np.empty((n, 3))
    for a in range(3):
        prog = _anchored(an.anchor[:, a], aval[:, a], an.step[:, a], start[a])
        # a line without motion leaves the tool where it is, whatever its offsets
        pos[:, a] = _ffill(moves | an.home.any(1), prog + off[:, a], start[a])
    return pos, off


def _g92_line(L: _Lines, k: int, an: _Anchors, cur, o, saved, off, axis_val, axis_given):
    """The G92 family at line ``k`` (interp_convert.cc, ``convert_axis_offsets``): the offsets
    from line ``k`` on go to ``off`` and the anchors' values are updated; returns the program
    coordinates at the line, the offsets (3,) and parameters 5211-5213 (3,) (mm)."""
    nonmodal = L.G[_NONMODAL]
    g53, home = an.g53, an.home
    if nonmodal[k] == 920:  # the current point gets the given coordinates
        new = (cur + o) - axis_val[k]
        o = np.where(an.g92[k], new, o)
        saved = o.copy()
        cur = np.where(an.g92[k], axis_val[k], cur)
    elif nonmodal[k] == 923:  # back to the offsets kept in the parameters
        cur = (cur + o) - saved
        o = saved.copy()
    else:  # G92.1 clears the parameters too, G92.2 keeps them
        cur = cur + o
        o = np.zeros(3)
        saved = saved if nonmodal[k] == 922 else np.zeros(3)
    off[k:] = o
    an.aval[k:][g53[k:]] = axis_val[k:][g53[k:]] - o
    an.aval[k:][home[k:]] = (an.target[k:] - o)[home[k:]]
    an.aval[k] = cur
    if nonmodal[k] != 920:
        an.uval[k] = np.nan
    return cur, o, saved


@dataclass(frozen=True)
class _CycleWords:
    """A canned cycle's line as read, in program units: its code (ten times the G number) and
    name, R and the depth as given or kept, the R plane and the bottom, the first hole's
    coordinates on the plane's two axes and the step between repeats (0 in G90), the dwell P
    (s), Q and G87's I, J, K."""

    c: int
    name: str
    r_word: float
    depth: float
    r: float
    bottom: float
    aa: float
    bb: float
    step: list
    p: float
    q: float
    ijk: tuple


def _cycle(L: _Lines, k: int, cur, off, il, sticky: _Sticky):
    """The moves of the canned cycle of line ``k``, as LinuxCNC 2.9 makes them.

    Follows interp_cycles.cc: ``convert_cycle`` and ``convert_cycle_xy`` (and its _yz, _zx
    twins, here one function over the plane's axes), the CYCLE_MACRO repeat loop and the
    ``convert_cycle_g*`` functions. The computation runs in program units and coordinates, as
    LinuxCNC's; each point is then converted to machine millimetres, adding the G92 offset as
    LinuxCNC's canon does.

    Parameters
    ----------
    L : _Lines
    k : int
        Line index.
    cur, off : ndarray, shape (3,)
        Program coordinates before the line (program units), and the G92 offset (mm).
    il : float or None
        The initial level (program units) LinuxCNC keeps from the first of a run of cycles
        (``cycle_il``), None when a motion other than a cycle came since.
    sticky : _Sticky

    Returns
    -------
    blocks : list of (kind, point mm (3,), dwell s, exact path)
    end : ndarray, shape (3,)
        The program coordinates after the line (program units, at the clearance height).
    il : float
    sticky : _Sticky

    Raises
    ------
    _LineError
        With LinuxCNC's reason, where it refuses the line.
    """
    w, il = _cycle_words(L, k, cur, il, sticky)
    repeats = _cycle_repeats(L, k, w)
    blocks, end = _cycle_blocks(L, k, w, repeats, cur, off, il)
    sticky = replace(sticky, r=w.r_word, depth=w.depth, p=w.p, q=w.q, ijk=w.ijk)
    return blocks, end, il, sticky


def _cycle_words(L: _Lines, k: int, cur, il, sticky: _Sticky) -> tuple[_CycleWords, float]:
    """The words of the canned cycle of line ``k`` (those of the same cycle on the line before
    carry over), and the initial level."""
    c, name = int(L.motion[k]), _fmt_g(int(L.motion[k]))
    a, b, nrm = PLANE_AXES[L.plane[k]]
    W = {x: float(L.W[x][k]) for x in "XYZIJKRPQL"}
    has = {x: bool(L.has[x][k]) for x in "XYZIJKRPQL"}
    same = k > 0 and L.motion[k - 1] == c  # the same cycle ran last: its words carry over
    depth_letter = "XYZ"[nrm]

    def word(letter: str, kept: float, missing: str) -> float:
        if has[letter]:
            return W[letter]
        if same:
            return kept
        raise _LineError(missing)

    if c in (740, 840) and a != 0:  # convert_cycle_g74_g84 maps the plane's axes a second time
        raise _LineError(
            f"{name} in the G{17 + L.plane[k]} plane (whose feeds LinuxCNC 2.9 sends along swapped"
            f" axes) {_NEEDS_LINUXCNC}"
        )
    r_word = word("R", sticky.r, f"R clearance plane unspecified in {name}")
    depth = word(depth_letter, sticky.depth, f"{depth_letter} value unspecified in {name}")
    if il is None:
        il = float(cur[nrm])
    if L.incremental[k]:
        step = [W["XYZ"[x]] if has["XYZ"[x]] else 0.0 for x in (a, b)]
        r = r_word + il
        bottom = r + depth
        aa, bb = float(cur[a]), float(cur[b])
    else:
        step = [0.0, 0.0]
        r, bottom = r_word, depth
        aa, bb = (W["XYZ"[x]] if has["XYZ"[x]] else float(cur[x]) for x in (a, b))
    if r < bottom:
        raise _LineError(f"R less than {depth_letter} in {name}")
    p, q, ijk = sticky.p, sticky.q, sticky.ijk
    if c == 760:  # Fanuc fine boring: Q is the shift at the bottom, its sign ignored
        q = abs(word("Q", sticky.q, "Q word (the shift at the bottom) missing with G76"))
    if _DWELLS[c]:  # (tapping and G76 may go without P: they dwell the P kept, 0 at first)
        if not (has["P"] or same or c in (740, 760, 840)):
            raise _LineError(f"dwell time P word missing with {name}")
        p = W["P"] * L.p_scale if has["P"] else sticky.p
    elif c in (730, 830):
        q = word("Q", sticky.q, f"Q word missing with {name}")
        if not q > 0:
            raise _LineError(f"negative or zero Q value used in {name}")
    elif c == 870:
        ijk = tuple(
            word(x, v, f"{x} word missing with G87") for x, v in zip("IJK", ijk, strict=True)
        )
    return _CycleWords(c, name, r_word, depth, r, bottom, aa, bb, step, p, q, ijk), il


def _cycle_repeats(L: _Lines, k: int, w: _CycleWords) -> int:
    """The spindle a cycle needs and its repeats (L), refused where LinuxCNC refuses them."""
    c, name = w.c, w.name
    spindle = L.spindle[k]
    if L.rigid is not None and L.rigid[k]:  # rigid tapping: the control turns the spindle
        spindle = 1 if c == 840 else -1
    if c in (860, 870, 880, 740, 840) and spindle == 0:
        raise _LineError(f"spindle not turning in {name}")
    if (c, spindle) in ((840, -1), (740, 1)):
        turning = "counterclockwise" if spindle == -1 else "clockwise"
        raise _LineError(f"spindle turning {turning} in {name}")
    repeats = int(np.rint(float(L.W["L"][k]))) if bool(L.has["L"][k]) else 1
    per_repeat = 12 + (3 * (w.r - w.bottom) / w.q if c in (730, 830) else 0)
    values = (w.r, w.bottom, w.aa, w.bb, *w.step, per_repeat)
    if not (np.isfinite(values).all() and repeats * per_repeat <= MAX_BLOCKS_PER_LINE):
        raise _LineError(f"{name} would make more than {MAX_BLOCKS_PER_LINE} moves")
    return repeats


def _cycle_blocks(L: _Lines, k: int, w: _CycleWords, repeats: int, cur, off, old: float):
    """The blocks of a cycle's holes (the CYCLE_MACRO loop) from the initial level ``old``,
    and the program coordinates after them."""
    s = float(L.scale[k])
    a, b, nrm = PLANE_AXES[L.plane[k]]
    r = w.r
    blocks = []
    at = np.zeros(3)  # program coordinates of the last point

    def go(kind: MotionKind, u: float, v: float, h: float, exact: bool = True) -> None:
        at[[a, b, nrm]] = u, v, h
        blocks.append((kind, at * s + off, 0.0, exact))

    def dwell(t: float) -> None:
        blocks.append((MotionKind.DWELL, at * s + off, t, True))

    rapid = MotionKind.RAPID
    current = float(cur[nrm])
    at[:] = cur
    if old < r:  # below the R plane: straight up to it first (before the exact-path mode is set)
        go(rapid, cur[a], cur[b], r, exact=False)
        old = current = r
    clear = r if L.retract_r[k] else old
    delta = G83_RAPID_DELTA_IN * (1.0 if s == MM_PER_INCH else MM_PER_INCH)
    aa, bb = w.aa, w.bb
    for repeat in range(repeats):  # CYCLE_MACRO
        aa, bb = aa + w.step[0], bb + w.step[1]
        if repeat == 0 and current > r:
            go(rapid, aa, bb, current)
            go(rapid, aa, bb, r)
        else:
            go(rapid, aa, bb, clear)
            if clear > r:
                go(rapid, aa, bb, r)
        _hole(w, go, dwell, aa, bb, clear, delta, (a, b, nrm), bool(L.incremental[k]))
    end = np.zeros(3)
    end[[a, b, nrm]] = aa, bb, clear
    return blocks, end


def _hole(w: _CycleWords, go, dwell, aa, bb, clear, delta, axes, incremental) -> None:
    """One hole of a cycle from its R plane down and out to ``clear``, by the cycle's kind."""
    c, r, bottom, p, q = w.c, w.r, w.bottom, w.p, w.q
    rapid, feed = MotionKind.RAPID, MotionKind.LINEAR
    if c in (730, 830):  # peck drilling: chip breaking (G73) or full retract (G83)
        depth_now = r - q
        while depth_now > bottom:
            go(feed, aa, bb, depth_now)
            if c == 830:
                go(rapid, aa, bb, r)
            go(rapid, aa, bb, depth_now + delta)
            depth_now = depth_now - q
        go(feed, aa, bb, bottom)
        go(rapid, aa, bb, clear)
    elif c == 760:  # Fanuc fine boring (see the module docstring)
        go(feed, aa, bb, bottom)
        if p > 0:
            dwell(p)
        if q > 0:  # the oriented stop (M19) takes no time here; the shift is a rapid
            go(rapid, aa + q, bb, bottom)
        go(rapid, aa + q, bb, clear)
        if q > 0:  # shift back, then the spindle restarts (no time here either)
            go(rapid, aa, bb, clear)
    elif c == 870:  # back boring, in and out off centre by I/J with the spindle oriented
        a, b, nrm = axes
        oa, ob = aa + w.ijk[a], bb + w.ijk[b]
        middle = w.ijk[nrm] + (bottom if incremental else 0.0)
        go(rapid, oa, ob, r)
        go(rapid, oa, ob, bottom)
        go(rapid, aa, bb, bottom)
        go(feed, aa, bb, middle)
        go(feed, aa, bb, bottom)
        go(rapid, oa, ob, bottom)
        go(rapid, oa, ob, clear)
        go(rapid, aa, bb, clear)
    else:
        go(feed, aa, bb, bottom)
        if c == 850:  # feed out to R, then rapid
            go(feed, aa, bb, r)
        if _DWELLS[c]:
            dwell(p)
        if c in (740, 840, 890):  # tapping and boring: feed out
            go(feed, aa, bb, clear)
        elif c != 880:  # G88: the operator takes the tool out at a program stop
            go(rapid, aa, bb, clear)
