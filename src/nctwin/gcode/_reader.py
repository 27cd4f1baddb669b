"""The reader: the words of each line and the modal state in force at it, LinuxCNC's order of
execution within a line, the arcs, and the blocks of each line, as a
:class:`~nctwin.toolpath.Toolpath`; and reading a program from a file."""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import numpy as np

from ..toolpath import (
    EVENT_DTYPE,
    PLANE_AXES,
    MotionKind,
    PathMode,
    Plane,
    Toolpath,
    arc_sweep,
)
from ._cycles import _Lines, _special_positions
from ._errors import _NEEDS_LINUXCNC, _NOT_FANUC, GCodeError, _Errors, _point_mm
from ._fanuc import _fanuc_words, check_dialect
from ._lexer import _L, _LETTERS, _clean, _lex
from ._modal import (
    _ARCDIST,
    _DIST,
    _DWELLS,
    _FEEDMODE,
    _G_CODES,
    _G_CODES_FANUC,
    _G_FANUC_NAMES,
    _G_FOREIGN,
    _G_GROUPS,
    _G_GROUPS_FANUC,
    _G_LINUXCNC,
    _G_NOT_FANUC,
    _GROUP_NAMES,
    _IS_ARC,
    _IS_CYCLE,
    _IS_G92,
    _IS_HOME,
    _KIND_OF_MOTION,
    _MOTION,
    _NONMODAL,
    _PATH,
    _PECKS,
    _PLANE,
    _Q_FANUC,
    _RETRACT,
    _ROW,
    _SINGLE,
    _SPINDLE_M,
    _STOPS,
    _TLO,
    _UNITS,
    MAX_BLOCKS_PER_LINE,
    MM_PER_INCH,
    _ffill,
    _fmt_g,
    offset_changes,
)
from ._tools import ToolTable, plain_positions, shift_by_offsets, tool_offsets


def parse(
    text: str,
    *,
    source: str | None = None,
    units: str = "mm",
    dwell_p_unit: str | None = None,
    dialect: str = "rs274ngc",
    block_delete: bool = False,
    start_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    g28_reference_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    g30_reference_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    arc_tol_mm: float = 0.005,
    arc_tol_rel: float = 0.001,
    tool_table: ToolTable | None = None,
) -> Toolpath:
    """Read a part program.

    Parameters
    ----------
    text : str
        The program.
    source : str, optional
        File name used in error messages.
    units : {"mm", "inch"}
        Units in force before the program's own G20/G21.
    dwell_p_unit : {"s", "ms"}, optional
        Unit of P in G4 and in the dwells of canned cycles: seconds (RS274/NGC, LinuxCNC) or
        milliseconds (Fanuc). Default: the dialect's, ``"s"`` for ``"rs274ngc"`` and ``"ms"``
        for ``"fanuc"``; one given wins over the dialect's.
    dialect : {"rs274ngc", "fanuc"}
        The language of the program: LinuxCNC 2.9's RS274/NGC (default), or a Fanuc milling
        control's (M29 rigid tapping, G76 fine boring, P in milliseconds; see the package's
        docstring).
    block_delete : bool
        Whether the block-delete switch is on (lines starting with ``/`` are skipped).
    start_mm : tuple of 3 floats
        Tool position before the first block.
    g28_reference_mm, g30_reference_mm : tuple of 3 floats
        The reference points G28 and G30 send the tool to (LinuxCNC's parameters #5161-#5163
        and #5181-#5183, in mm): X, Y, Z in the Toolpath's coordinates, the machine
        coordinates of a machine whose work offsets (G54-G59) and tool lengths are zero, as
        this reader reads a program; a G92 offset does not move them. Default: LinuxCNC's
        zeros. On a real machine, where G28 goes to its home position, this is that position
        minus the work offset (and minus the tool length along Z).
    arc_tol_mm, arc_tol_rel : float
        An arc whose start and end radii differ by more than
        ``max(arc_tol_mm, arc_tol_rel * radius)`` is rejected.
    tool_table : ToolTable, optional
        The machine's tools, whose offsets ``G43 H<n>`` applies (:mod:`._tools`); default
        none: every offset 0, as on nctwin's own LinuxCNC table.

    Returns
    -------
    Toolpath

    Raises
    ------
    GCodeError
        For the lines that cannot be read: the first one's number, text and reason, and up to
        :data:`MAX_ERRORS` of them in the message and in ``errors``.
    ValueError
        For a bad keyword argument, naming it and its allowed values.
    """
    if units not in ("mm", "inch"):
        raise ValueError(f"units must be 'mm' or 'inch', got {units!r}")
    check_dialect(dialect)
    if dwell_p_unit is None:
        dwell_p_unit = "ms" if dialect == "fanuc" else "s"
    if dwell_p_unit not in ("s", "ms"):
        raise ValueError(f"dwell_p_unit must be 's' or 'ms', got {dwell_p_unit!r}")
    for name, v in (("arc_tol_mm", arc_tol_mm), ("arc_tol_rel", arc_tol_rel)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
    start = _point_mm("start_mm", start_mm)
    references = np.stack(
        [
            _point_mm("g28_reference_mm", g28_reference_mm),
            _point_mm("g30_reference_mm", g30_reference_mm),
        ]
    )

    text = text.replace("\r\n", "\n").replace("\r", "\n")
    raw_lines = text.split("\n")
    b = _clean(text, block_delete)
    line_starts = np.concatenate([[0], np.flatnonzero(b == 10) + 1])
    errors = _Errors(raw_lines, line_starts, source)
    errors.fanuc = dialect == "fanuc"
    words = _lex(b, errors)

    # the program ends with M2/M30: nothing after it is read
    ends = (words["code"] == _L["M"]) & np.isin(words["value"], (2.0, 30.0))
    n_lines = int(words["line"][ends][0]) + 1 if ends.any() else len(line_starts)
    keep = words["line"] < n_lines
    tp = _interpret(
        {k: v[keep] for k, v in words.items()},
        n_lines,
        errors,
        inch=units == "inch",
        p_scale=1e-3 if dwell_p_unit == "ms" else 1.0,
        start=start,
        references=references,
        arc_tol=(arc_tol_mm, arc_tol_rel),
        fanuc=dialect == "fanuc",
        table=tool_table,
    )
    errors.raise_all(n_lines)
    return tp


def _interpret(
    words, n, errors: _Errors, *, inch, p_scale, start, references, arc_tol, fanuc, table
) -> Toolpath:
    """Modal interpretation of the words of lines ``0..n-1``; returns the Toolpath.

    ``references`` (2, 3) holds the reference points of G28 and G30 (mm); ``fanuc``: the
    program is in the fanuc dialect; ``table``: the tool table (or None).
    """
    code, value, line = words["code"], words["value"], words["line"]
    W, has = _single_words(code, value, line, n, errors)
    G = _g_codes(words, n, errors, fanuc)
    st = _modal_state(W, has, G, n, inch, errors)
    dwell_t, fanuc_dwell = _dwells(W, has, G, st, p_scale, errors)
    act = _line_actions(W, has, G, st, fanuc_dwell, references, errors)
    rigid = None
    if fanuc:  # M29 rigid tapping; M98/M99 and K repeats refused
        rigid = _fanuc_words(code, value, line, has, G, st.motion, act.cycle_line, errors)
    turns = _motion_words(W, has, st, act, n, fanuc, errors)
    # ---- positions (machine coordinates: program coordinates plus the G92 offsets); a G28/G30
    # line ends with its axes at the reference point, whatever the offsets
    axis_val = np.stack([W["X"], W["Y"], W["Z"]], axis=1) * st.scale[:, None]
    tlo = tool_offsets(W, has, G, n, table, errors)
    if tlo.any():  # the tool length offsets, on the lines in absolute distance mode
        axis_val = shift_by_offsets(axis_val, tlo, st.incremental, G)
        under = f"a canned cycle under a tool length offset {_NEEDS_LINUXCNC}"
        errors.at_lines(act.cycle_line & tlo.any(1), under)
    special = act.cycle_line | _IS_G92[G[_NONMODAL]]
    cycles: dict[int, list] = {}
    hl, home_mm = act.home_lines, act.home_mm
    if special.any():
        L = _Lines(
            W, has, G, st.scale, st.motion, st.plane, st.incremental,
            _ffill(G[_RETRACT] >= 0, G[_RETRACT] == 990, True),
            _spindle(code, value, line, n), p_scale, rigid,
        )  # fmt: skip
        pos, off = _special_positions(
            L, act.axis_given, axis_val, hl, home_mm, act.cycle_line, act.moves, start, errors,
            cycles,
        )  # fmt: skip
    else:
        pos, off = plain_positions(act, axis_val, st.incremental, start, n)
    prev = np.vstack([start, pos[:-1]]) if n else pos
    # the intermediate point of each G28/G30 line: its axis words in the distance mode in force
    to = np.where(st.incremental[hl, None], prev[hl] + axis_val[hl], axis_val[hl] + off[hl])
    via = np.where(act.named, to, prev[hl])
    # ---- arcs
    center = np.full((n, 3), np.nan)
    ai = np.flatnonzero(act.arc_line)
    if len(ai):
        center[ai] = _arc_centers(
            ai, prev, pos, st.plane, st.motion, W, has, st.scale, st.arc_absolute, off, errors,
            arc_tol,
        )  # fmt: skip
    blocks = _line_blocks(st, act, start, prev, pos, center, turns, via, dwell_t, cycles)
    return _toolpath(words, G, st, blocks)


@dataclass(frozen=True)
class _Modal:
    """The modal state in force at each of n lines, after the line's own codes, shapes (n,):
    mm per program unit, the motion code, the plane, G91, G91.1, the path-control code, and
    the lines with G64, G4 and G92; the feed (mm/s, NaN: none), the path mode and G64's P and
    Q (mm, NaN outside G64)."""

    scale: np.ndarray
    motion: np.ndarray
    plane: np.ndarray
    incremental: np.ndarray
    arc_absolute: np.ndarray
    g64: np.ndarray
    dwell_line: np.ndarray
    g92_line: np.ndarray
    feed: np.ndarray
    mode: np.ndarray
    blend_p: np.ndarray
    blend_q: np.ndarray


@dataclass(frozen=True)
class _Actions:
    """What each of n lines does: the axes it names (n, 3), whether it names any, arcs,
    canned cycles, moves; its G28/G30 return (``home_lines``, H of them, the axes their words
    name (H, 3) and the reference point, NaN for the axes that stay), and the words I, J, K."""

    axis_given: np.ndarray
    any_axis: np.ndarray
    arc_line: np.ndarray
    cycle_line: np.ndarray
    moves: np.ndarray
    home_line: np.ndarray
    home_lines: np.ndarray
    named: np.ndarray
    home_mm: np.ndarray
    ijk: np.ndarray


def _single_words(code, value, line, n, errors: _Errors) -> tuple[dict, dict]:
    """One value per line and letter; a letter twice in a line is an error (not G, M).
    Returns each letter's value per line (NaN where absent) and its presence, shapes (n,)."""
    row = _ROW[code]
    single = row >= 0
    key = line[single] * len(_SINGLE) + row[single]
    counts = np.bincount(key, minlength=n * len(_SINGLE))
    if counts.max(initial=0) > 1:
        dup = counts.reshape(n, len(_SINGLE)) > 1
        errors.at_lines(dup.any(1), lambda i: f"word {_SINGLE[np.argmax(dup[i])]} given twice")
    table = np.full((len(_SINGLE), n), np.nan)
    table[row[single], line[single]] = value[single]
    W = dict(zip(_SINGLE, table, strict=True))
    has = dict(zip(_SINGLE, ~np.isnan(table), strict=True))
    return W, has


def _g_codes(words, n, errors: _Errors, fanuc) -> np.ndarray:
    """G-codes: one per modal group and line; the code (ten times its number) of each group
    on each line, -1 where none, shape (groups, n)."""
    value, line = words["value"], words["line"]
    g = words["code"] == _L["G"]
    gval, gline = value[g], line[g]
    gcode = np.rint(gval * 10).astype(np.int64)
    codes, groups = (_G_CODES_FANUC, _G_GROUPS_FANUC) if fanuc else (_G_CODES, _G_GROUPS)
    idx = np.minimum(np.searchsorted(codes, gcode), len(codes) - 1)
    known = (codes[idx] == gcode) & (np.abs(gval * 10 - gcode) < 1e-6)
    if not known.all():
        errors.at_pos(
            words["pos"][g][~known],
            lambda pos: _g_reason(float(value[np.searchsorted(words["pos"], pos)]), fanuc),
        )
    gcode, gline, grp = gcode[known], gline[known], groups[idx[known]]
    g80 = gcode == 800
    if g80.any():  # read_g: G80 gives way to another motion code of its line (or G80)
        taken = np.zeros(n, dtype=bool)
        taken[gline[(grp == _MOTION) & ~g80]] = True
        first = np.zeros(len(gcode), dtype=bool)
        first[np.flatnonzero(g80)[np.unique(gline[g80], return_index=True)[1]]] = True
        keep = ~g80 | (first & ~taken[gline])
        gcode, gline, grp = gcode[keep], gline[keep], grp[keep]
    n_groups = len(_GROUP_NAMES)
    gdup = np.bincount(gline * n_groups + grp, minlength=n * n_groups).reshape(n, n_groups) > 1
    errors.at_lines(
        gdup.any(1),
        lambda i: f"two G-codes of the {_GROUP_NAMES[np.argmax(gdup[i])]} group in one line",
    )
    G = np.full((n_groups, n), -1, dtype=np.int64)
    G[grp, gline] = gcode
    return G


def _modal_state(W, has, G, n, inch, errors: _Errors) -> _Modal:
    """The modal state per line (after the line's own codes, which run before its motion)."""
    scale = np.where(_ffill(G[_UNITS] >= 0, G[_UNITS] == 200, inch), MM_PER_INCH, 1.0)
    path_code = _ffill(G[_PATH] >= 0, G[_PATH], -1)
    g64 = G[_PATH] == 640
    # F runs before the line's G20/G21, and a change of units keeps the feed in mm/min; G94
    # runs before F and sets the feed to 0, no feed (LinuxCNC's convert_feed_mode)
    errors.at_lines(has["F"] & (W["F"] <= 0), "feed rate F must be > 0")
    scale_before = np.concatenate([[MM_PER_INCH if inch else 1.0], scale[:-1]])
    feed = _ffill(has["F"] | (G[_FEEDMODE] == 940), W["F"] * scale_before / 60.0, np.nan)
    errors.at_lines(has["H"] & (G[_TLO] != 430), "H word without G43")
    errors.at_lines(g64 & ((W["P"] < 0) | (W["Q"] < 0)), "G64 P and Q must be >= 0")
    mode = np.select(
        [path_code == 640, path_code == 610, path_code == 611],
        [PathMode.BLEND, PathMode.EXACT_PATH, PathMode.EXACT_STOP],
        PathMode.DEFAULT,
    )
    blend_p = _ffill(g64, W["P"] * scale, np.nan)
    blend_q = _ffill(g64, W["Q"] * scale, np.nan)
    blend_p[mode != PathMode.BLEND] = np.nan
    blend_q[mode != PathMode.BLEND] = np.nan
    return _Modal(
        scale=scale,
        motion=_ffill(G[_MOTION] >= 0, G[_MOTION], -1),
        plane=_ffill(G[_PLANE] >= 0, (G[_PLANE] - 170) // 10, int(Plane.XY)),
        incremental=_ffill(G[_DIST] >= 0, G[_DIST] == 910, False),
        arc_absolute=_ffill(G[_ARCDIST] >= 0, G[_ARCDIST] == 901, False),
        g64=g64,
        dwell_line=G[_NONMODAL] == 40,
        g92_line=G[_NONMODAL] == 920,
        feed=feed,
        mode=mode,
        blend_p=blend_p,
        blend_q=blend_q,
    )


def _dwells(W, has, G, st: _Modal, p_scale, errors: _Errors) -> tuple[np.ndarray, np.ndarray]:
    """Dwells: P, or X alone (Fanuc), which is then no axis word. Returns each line's dwell
    time (s) and the lines whose X is a dwell time, shapes (n,)."""
    dwell_line = st.dwell_line
    fanuc_dwell = dwell_line & ~has["P"] & has["X"]
    dwell_t = np.where(has["P"], W["P"] * p_scale, W["X"])
    ijk = has["I"] | has["J"] | has["K"]
    errors.at_lines(dwell_line & ~has["P"] & ~has["X"], "G4 without a dwell time (P)")
    errors.at_lines(dwell_line & has["P"] & st.g64, "P word used by both G4 and G64")
    errors.at_lines(
        dwell_line & _IS_ARC[G[_MOTION]], "G4 cannot share a line with G2/G3: both use P"
    )
    errors.at_lines(dwell_line & (dwell_t < 0), "dwell time must be >= 0")
    errors.at_lines(
        fanuc_dwell & (has["Y"] | has["Z"] | ijk | has["R"] | (G[_MOTION] >= 0)),
        "G4 with X as its time cannot share a line with motion: give the dwell time with P",
    )
    return dwell_t, fanuc_dwell


def _line_actions(W, has, G, st: _Modal, fanuc_dwell, references, errors: _Errors) -> _Actions:
    """What each line does: its motion (the modal one, if it has axis words), G92, or a
    G28/G30 return, which leaves the motion mode as it is."""
    motion = st.motion
    ijk = has["I"] | has["J"] | has["K"]
    axis_given = np.stack([has["X"] & ~fanuc_dwell, has["Y"], has["Z"]], axis=1)
    # the G28/G30 lines (few, hl): their axis words give the intermediate point, then the axes
    # they name (all, if none) go to the reference point, home_mm (NaN for the axes that stay)
    home_line = _IS_HOME[G[_NONMODAL]]
    hl = np.flatnonzero(home_line)
    named = axis_given[hl]
    home_mm = np.where(
        named | ~named.any(1)[:, None], references[(G[_NONMODAL, hl] == 300).astype(int)], np.nan
    )
    axis_given[st.g92_line] = False  # G92 takes the axis words as the current position
    axis_given[hl] = False
    any_axis = axis_given.any(1)
    arc_line = _IS_ARC[motion] & (any_axis | ijk)
    arc_line[hl] = False
    cycle_line = _IS_CYCLE[motion] & any_axis
    moves = any_axis | arc_line
    errors.at_lines(
        any_axis & ((motion < 0) | (motion == 800)),
        "axis words without an active motion mode (G0/G1/G2/G3 or a canned cycle)",
    )
    errors.at_lines(
        st.g92_line & ~(has["X"] | has["Y"] | has["Z"]), "G92 without an axis word (X, Y or Z)"
    )
    errors.at_lines(
        (st.g92_line | home_line) & (G[_MOTION] >= 0) & (G[_MOTION] != 800),
        lambda i: (
            f"{_fmt_g(int(G[_NONMODAL, i]))} and {_fmt_g(int(G[_MOTION, i]))} cannot share a"
            " line: both use the axis words"
        ),
    )
    explicit_cycle = _IS_CYCLE[G[_MOTION]]
    errors.at_lines(
        explicit_cycle & ~any_axis,
        lambda i: f"{_fmt_g(int(G[_MOTION, i]))} without an axis word: all axes missing",
    )
    errors.at_lines(cycle_line & (G[_NONMODAL] == 530), "G53 can only be used with G0 or G1")
    feed_line = moves & ((motion == 10) | arc_line | cycle_line)
    errors.at_lines(
        feed_line & np.isnan(st.feed),
        lambda i: f"{_fmt_g(int(motion[i]))} with no feed rate set (F)",
    )
    return _Actions(
        axis_given, any_axis, arc_line, cycle_line, moves, home_line, hl, named, home_mm, ijk
    )


def _motion_words(W, has, st: _Modal, act: _Actions, n, fanuc, errors: _Errors) -> np.ndarray:
    """The words that need a motion to use them; returns the turns of each line's arc (n,)."""
    motion, cycle_line, arc_line = st.motion, act.cycle_line, act.arc_line
    p_ok = st.dwell_line | st.g64 | arc_line | (cycle_line & _DWELLS[motion])
    errors.at_lines(
        has["P"] & ~p_ok,
        "P word without G2, G3, G4, G64 or a canned cycle that dwells"
        f" (G74{', G76' if fanuc else ''}, G82, G84, G86, G88, G89)",
    )
    errors.at_lines(
        has["Q"] & ~(st.g64 | (cycle_line & (_Q_FANUC if fanuc else _PECKS)[motion])),
        f"Q word without G64, G73{', G76' if fanuc else ''} or G83",
    )
    errors.at_lines(
        (act.ijk & ~(arc_line | (cycle_line & (motion == 870))))
        | (has["R"] & ~(arc_line | cycle_line)),
        "I/J/K/R words without an arc (G2/G3) or a canned cycle to use them",
    )
    if has["L"].any():  # repeats of a canned cycle: a whole number >= 1
        errors.at_lines(has["L"] & ~cycle_line, "L word without a canned cycle to repeat")
        repeats = np.rint(W["L"])
        errors.at_lines(np.abs(W["L"] - repeats) > 1e-4, "L word must be a whole number")
        errors.at_lines(repeats < 0, "negative L word")
        errors.at_lines(cycle_line & (repeats == 0), "cannot do zero repeats of a canned cycle")
    turns = np.ones(n, dtype=np.int64)
    arc_p = arc_line & has["P"]
    if arc_p.any():  # turns of an arc: a whole number >= 1
        p_turns = np.where(arc_p, np.rint(W["P"]), 1.0)
        errors.at_lines(
            arc_p & (np.abs(W["P"] - p_turns) > 0.001), "P value not an integer with G2 or G3"
        )
        errors.at_lines(p_turns < 1, "P value should be 1 or greater with G2 or G3")
        errors.at_lines(
            p_turns > MAX_BLOCKS_PER_LINE, f"P value of G2/G3 above {MAX_BLOCKS_PER_LINE} turns"
        )
        turns = np.clip(p_turns, 1, MAX_BLOCKS_PER_LINE).astype(np.int64)
    return turns


def _line_blocks(st: _Modal, act: _Actions, start, prev, pos, center, turns, via, dwell_t, cycles):
    """Blocks: a dwell, then the motion of the line (its turns, or its canned cycle)."""
    kind = np.full(len(pos), MotionKind.DWELL, dtype=np.int8)
    for c, k in _KIND_OF_MOTION.items():
        kind[st.motion == c] = k
    kind[act.home_line] = MotionKind.RAPID
    moves = act.moves | act.home_line
    simple = moves & ~act.cycle_line
    dwell_line, hl = st.dwell_line, act.home_lines
    if cycles or (turns > 1).any() or (dwell_line & moves).any() or len(hl):
        return _blocks(
            start, prev, pos, center, st.plane, kind, simple, turns, hl, via, dwell_line,
            dwell_t, cycles,
        )  # fmt: skip
    bl = np.flatnonzero(moves | dwell_line)
    return {
        "line": bl,
        "start_mm": prev[bl],
        "end_mm": pos[bl],  # a dwell line has no axis words: its position is the previous one
        "kind": np.where(dwell_line[bl], MotionKind.DWELL, kind[bl]).astype(np.int8),
        "center_mm": center[bl],
        "dwell_s": np.where(dwell_line[bl], dwell_t[bl], 0.0),
        "exact": np.zeros(len(bl), dtype=bool),
    }


def _toolpath(words, G, st: _Modal, blocks: dict) -> Toolpath:
    """The Toolpath of the blocks, with the M, S and T words and the offsets as events."""
    ev = np.isin(words["code"], (_L["M"], _L["S"], _L["T"]))
    off_line, off_value = offset_changes(G)
    code = np.concatenate([words["code"][ev], np.full(len(off_line), _L["G"])])
    value = np.concatenate([words["value"][ev], off_value])
    line = np.concatenate([words["line"][ev], off_line])
    bl, events = blocks["line"], np.zeros(len(code), dtype=EVENT_DTYPE)
    events["block"] = np.searchsorted(bl, line, side="left")
    stop = (code == _L["M"]) & np.isin(value, _STOPS)  # they run after the motion
    events["block"][stop] = np.searchsorted(bl, line[stop], side="right")
    events["line"] = line + 1
    events["word"] = np.array(list(_LETTERS))[code]
    events["value"] = value
    events = events[np.lexsort((events["line"], events["block"]))]
    mode, blend_p, blend_q = st.mode[bl], st.blend_p[bl], st.blend_q[bl]
    exact = blocks["exact"]  # the moves of canned cycles run in exact-path mode
    mode[exact], blend_p[exact], blend_q[exact] = PathMode.EXACT_PATH, np.nan, np.nan
    return Toolpath(
        start_mm=blocks["start_mm"],
        end_mm=blocks["end_mm"],
        kind=blocks["kind"],
        feed_mm_s=st.feed[bl],
        center_mm=blocks["center_mm"],
        plane=st.plane[bl],
        dwell_s=blocks["dwell_s"],
        line=bl + 1,
        path_mode=mode,
        blend_tol_mm=blend_p,
        naive_tol_mm=blend_q,
        events=events,
    )


def _g_reason(gval: float, fanuc: bool = False) -> str:
    """Why a G-code is not read (in the fanuc dialect if ``fanuc``)."""
    code, name = int(np.rint(gval * 10)), f"G{gval:g}"
    if fanuc:
        what = (_G_NOT_FANUC | _G_LINUXCNC | _G_FOREIGN | _G_FANUC_NAMES).get(code)
        return f"{name} ({what}) {_NOT_FANUC}" if what else f"{name} is not supported"
    if code in _G_LINUXCNC:
        return f"{name} {_G_LINUXCNC[code]} {_NEEDS_LINUXCNC}"
    if code in _G_FOREIGN:
        return f"{name} ({_G_FOREIGN[code]}) is not supported: LinuxCNC has no {name} either"
    return f"{name} is not supported"


def _spindle(code, value, line, n) -> np.ndarray:
    """The spindle's turning at each line, after its M3/M4/M5/M19: +1 clockwise, -1 counter-
    clockwise, 0 stopped (as at the start)."""
    m = (code == _L["M"]) & np.isin(value, list(_SPINDLE_M))
    state = np.zeros(n, dtype=np.int64)
    state[line[m]] = [_SPINDLE_M[v] for v in value[m]]
    given = np.zeros(n, dtype=bool)
    given[line[m]] = True
    return _ffill(given, state, 0)


def _arc_centers(ai, prev, pos, plane, motion, W, has, scale, arc_absolute, off, errors, arc_tol):
    """Centres (len(ai), 3) of the arcs on lines ``ai``, checking radius and words."""
    pl = plane[ai]
    ax = PLANE_AXES[pl]
    rows = np.arange(len(ai))
    s, e = prev[ai], pos[ai]
    sa, sb, sn = s[rows, ax[:, 0]], s[rows, ax[:, 1]], s[rows, ax[:, 2]]
    ea, eb = e[rows, ax[:, 0]], e[rows, ax[:, 1]]
    ccw = motion[ai] == 30
    lines = np.zeros(len(plane), dtype=bool)

    def flag(mask, reason):
        lines[:] = False
        lines[ai[mask]] = True
        errors.at_lines(lines, reason)

    ijk_has = np.stack([has["I"][ai], has["J"][ai], has["K"][ai]], axis=1)
    ijk = np.nan_to_num(np.stack([W["I"][ai], W["J"][ai], W["K"][ai]], axis=1)) * scale[ai, None]
    r_word = W["R"][ai] * scale[ai]
    use_r = has["R"][ai]
    flag(use_r & ijk_has.any(1), "arc given with both R and I/J/K")
    flag(~use_r & ~ijk_has.any(1), "arc needs a centre (I/J/K) or a radius (R)")
    wrong = ijk_has[rows, ax[:, 2]] & ~use_r
    flag(
        wrong,
        lambda i: (
            f"{'IJK'[PLANE_AXES[plane[i], 2]]} is not an arc-centre word in the "
            f"G{17 + plane[i]} plane"
        ),
    )

    # centre from I/J/K (G90.1: program coordinates, which the G92 offset moves)
    ca = np.where(arc_absolute[ai], off[ai, ax[:, 0]], sa) + ijk[rows, ax[:, 0]]
    cb = np.where(arc_absolute[ai], off[ai, ax[:, 1]], sb) + ijk[rows, ax[:, 1]]
    # centre from R: on the left of the chord for a CCW arc of at most 180 degrees
    da, db = ea - sa, eb - sb
    chord = np.hypot(da, db)
    flag(use_r & (chord == 0), "a full circle cannot be given with R")
    with np.errstate(invalid="ignore", divide="ignore"):
        half = 0.5 * chord
        flag(
            use_r & (np.abs(r_word) < half - arc_tol[0]),
            "arc radius R is smaller than half the distance from start to end",
        )
        h = np.sqrt(np.maximum(r_word**2 - half**2, 0.0))
        side = np.where(ccw, 1.0, -1.0) * np.sign(r_word)
        ra = np.where(use_r, 0.5 * (sa + ea) - side * h * db / chord, ca)
        rb = np.where(use_r, 0.5 * (sb + eb) + side * h * da / chord, cb)
    r_start = np.hypot(sa - ra, sb - rb)
    r_end = np.hypot(ea - ra, eb - rb)
    flag(r_start == 0, "arc radius is zero")
    bad = ~use_r & (np.abs(r_start - r_end) > np.maximum(arc_tol[0], arc_tol[1] * r_start))
    flag(
        bad,
        lambda i: "arc radius differs between start ({:.4f} mm) and end ({:.4f} mm)".format(
            *(r[np.searchsorted(ai, i)] for r in (r_start, r_end))
        ),
    )
    c = np.empty((len(ai), 3))
    c[rows, ax[:, 0]] = ra
    c[rows, ax[:, 1]] = rb
    c[rows, ax[:, 2]] = sn
    return c


def _blocks(
    start, prev, pos, center, plane, kind, simple, turns, hl, via, dwell_line, dwell_t, cycles
):
    """The blocks of each line, in order: its dwell, then its motion (one block per turn of an
    arc, the two rapids of a G28/G30 line of ``hl``, the first to its intermediate point
    ``via``, or the moves of its canned cycle). Each block starts where the previous one
    ended."""
    # lines and arcs: an arc of T turns is T-1 full turns then the arc, each with its share of
    # the helix's travel along the plane's normal
    ml = np.flatnonzero(simple)
    t = turns[ml]
    homes = np.searchsorted(ml, hl)
    t[homes] += 1
    first = np.cumsum(t) - t
    mline = np.repeat(ml, t)
    sub = np.arange(len(mline)) - np.repeat(first, t)
    mend, mcen = pos[mline], center[mline]
    mend[first[homes]] = via
    multi = turns[mline] > 1
    if multi.any():
        i, j = mline[multi], sub[multi]
        rows = np.arange(len(i))
        nax = PLANE_AXES[plane[i], 2]
        s, e, cen = prev[i], pos[i], center[i]
        sweep = np.abs(arc_sweep(s, e, cen, plane[i], kind[i] == MotionKind.ARC_CCW))
        with np.errstate(invalid="ignore", divide="ignore"):
            per_turn = 2.0 * np.pi / (sweep + 2.0 * np.pi * (turns[i] - 1))
        sn = s[rows, nax]
        dn = e[rows, nax] - sn
        inner = j < turns[i] - 1
        end = np.where(inner[:, None], s, e)
        end[rows, nax] = np.where(inner, sn + dn * (per_turn * (j + 1)), e[rows, nax])
        cen[rows, nax] = sn + dn * (per_turn * j)
        mend[multi], mcen[multi] = end, cen
    dl = np.flatnonzero(dwell_line)
    cl = sorted(cycles)
    cb = [blk for k in cl for blk in cycles[k]]  # (kind, point, dwell, exact) of cycle moves
    n_c = [len(cycles[k]) for k in cl]
    line = np.concatenate([dl, mline, np.repeat(np.array(cl, dtype=np.int64), n_c)])
    sub = np.concatenate([np.full(len(dl), -1), sub, *[np.arange(m) for m in n_c]])
    order = np.lexsort((sub, line))  # by line: the dwell first, then the motion in its order
    nan3 = np.full((len(dl), 3), np.nan)
    end = np.concatenate([nan3, mend, np.array([blk[1] for blk in cb]).reshape(-1, 3)])[order]
    kind = np.concatenate([np.full(len(dl), MotionKind.DWELL), kind[mline], [b[0] for b in cb]])
    dwell_s = np.concatenate([dwell_t[dl], np.zeros(len(mline)), [b[2] for b in cb]])
    exact = np.concatenate([np.zeros(len(dl) + len(mline), bool), [b[3] for b in cb]])
    # a G4 dwell stays where the previous block ended
    last = np.where(order >= len(dl), np.arange(len(order)), -1)
    np.maximum.accumulate(last, out=last)
    end = np.where((last >= 0)[:, None], end[np.maximum(last, 0)], start)
    return {
        "line": line[order],
        "start_mm": np.vstack([start, end])[:-1],
        "end_mm": end,
        "kind": kind.astype(np.int8)[order],
        "center_mm": np.concatenate([nan3, mcen, np.full((len(cb), 3), np.nan)])[order],
        "dwell_s": dwell_s[order],
        "exact": exact.astype(bool)[order],
    }


# ---------------------------------------------------------------------------------------------
# Files
# ---------------------------------------------------------------------------------------------
def parse_file(path: str | PathLike, **kwargs) -> Toolpath:
    """Read a program from a file (UTF-8, or Latin-1 if it is not UTF-8); see :func:`parse`."""
    text, source = read_text(path)
    return parse(text, source=source, **kwargs)


def read_text(path: str | PathLike) -> tuple[str, str]:
    """A program file's text (UTF-8, or Latin-1 if it is not UTF-8) and its name for messages."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise GCodeError(0, "", f"cannot read the file: {exc.strerror or exc}", str(p)) from None
    try:
        return data.decode("utf-8"), str(p)
    except UnicodeDecodeError:
        return data.decode("latin-1"), str(p)
