"""G-code (RS274/NGC subset of a 3-axis mill) to :class:`~nctwin.toolpath.Toolpath` and back.

The reader is vectorised: the text is lexed into words with numpy on the raw bytes, modal state is
carried forward with cumulative maxima, and positions with anchored cumulative sums. Nothing loops
over lines in Python, which is what makes it fast (see ``benchmarks/parse.py``).

What is read
------------
* Motion G0, G1, G2, G3 (I/J/K centres, R radii of both signs, full circles, helices), dwell G4
  (P in seconds by default, ``dwell_p_unit="ms"`` for Fanuc-style milliseconds; X in seconds).
* Modal state: G17/G18/G19, G20/G21 (converted to mm), G90/G91, G90.1/G91.1, G94, F.
* Prologue codes kept as state with no motion: G40, G43 (H; tool lengths are taken as zero),
  G49, G53 (machine coordinates; work offsets are taken as zero), G54-G59.3, G80, G61, G61.1 and
  G64 with P (blending tolerance) and Q (naive CAM tolerance).
* N numbers, ``( )`` and ``;`` comments, block delete ``/`` (off by default: the block runs, as
  with the switch off), ``%`` tape markers, M, S and T words (kept as events), any case, with or
  without spaces. M2 and M30 end the program: what follows is not read, as on a control.

Anything else (O-words, ``#`` parameters, expressions, canned cycles, cutter compensation,
rotary axes, ...) raises :class:`GCodeError` naming the construct, its line and its text.
"""

from __future__ import annotations

import re
from os import PathLike
from pathlib import Path

import numpy as np

from .toolpath import EVENT_DTYPE, PLANE_AXES, MotionKind, PathMode, Plane, Toolpath

__all__ = ["GCodeError", "dump", "parse", "parse_file"]

MM_PER_INCH = 25.4


class GCodeError(ValueError):
    """A program that cannot be read, with the line number, the line text and the reason.

    Parameters
    ----------
    line : int
        1-based line number (0 when the error is not tied to a line).
    text : str
        The offending line as written.
    reason : str
        What is wrong, naming the construct.
    source : str, optional
        File name, for messages.
    """

    def __init__(self, line: int, text: str, reason: str, source: str | None = None) -> None:
        self.line, self.text, self.reason, self.source = line, text, reason, source
        super().__init__(str(self))

    def __str__(self) -> str:
        where = f"{self.source or '<string>'}:{self.line}"
        text = self.text.strip()
        return f"{where}: {self.reason}" + (f"  [{text[:120]}]" if text else "")


# ---------------------------------------------------------------------------------------------
# Tables: letters and G-codes
# ---------------------------------------------------------------------------------------------
_LETTERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
_L = {c: i for i, c in enumerate(_LETTERS)}
_ALLOWED_LETTERS = set("FGHIJKMNPQRSTXYZ")
_LETTER_REASON = {
    "O": "O-words (subroutines, loops, conditionals) are not supported",
    "D": "D words (cutter radius compensation) are not supported",
    "L": "L words (G10 data setting, canned-cycle repeats) are not supported",
    "E": "E words are not supported",
    **{a: f"axis {a} is not supported: nctwin reads 3-axis XYZ programs" for a in "ABCUVW"},
}
_CHAR_REASON = {
    "#": "#parameters are not supported",
    "[": "expressions [...] are not supported",
    "]": "expressions [...] are not supported",
    "(": "unbalanced parentheses: comments cannot nest or span lines",
    ")": "unbalanced parentheses: comments cannot nest or span lines",
    "/": "block delete '/' is only allowed at the start of a line",
    "=": "parameter assignment is not supported",
    "<": "named parameters are not supported",
    ">": "named parameters are not supported",
}

# modal groups (codes are 10 x the G number)
_MOTION, _NONMODAL, _PLANE, _UNITS, _DIST, _ARCDIST, _FEEDMODE = range(7)
_CUTTER, _TLO, _COORD, _PATH = range(7, 11)
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
)
_G_GROUP = {
    0: _MOTION,
    10: _MOTION,
    20: _MOTION,
    30: _MOTION,
    800: _MOTION,
    40: _NONMODAL,
    530: _NONMODAL,
    170: _PLANE,
    180: _PLANE,
    190: _PLANE,
    200: _UNITS,
    210: _UNITS,
    900: _DIST,
    910: _DIST,
    901: _ARCDIST,
    911: _ARCDIST,
    940: _FEEDMODE,
    400: _CUTTER,
    430: _TLO,
    490: _TLO,
    540: _COORD,
    550: _COORD,
    560: _COORD,
    570: _COORD,
    580: _COORD,
    590: _COORD,
    591: _COORD,
    592: _COORD,
    593: _COORD,
    610: _PATH,
    611: _PATH,
    640: _PATH,
}
_G_CODES = np.array(sorted(_G_GROUP), dtype=np.int64)
_G_GROUPS = np.array([_G_GROUP[c] for c in _G_CODES], dtype=np.int64)
_G_UNSUPPORTED = {
    **dict.fromkeys((410, 411, 420, 421), "cutter radius compensation"),
    **dict.fromkeys(range(730, 900, 10), "canned cycles"),
    **dict.fromkeys((280, 281, 300, 301), "reference-point return (needs the machine's home)"),
    **dict.fromkeys((920, 921, 922, 923), "coordinate offsets (G92)"),
    100: "data setting (G10)",
    930: "inverse-time feed (G93)",
    950: "feed per revolution (G95)",
    330: "spindle-synchronised motion",
    331: "rigid tapping",
    760: "threading cycles",
    50: "splines (G5)",
    51: "splines (G5.1)",
    52: "NURBS (G5.2)",
    **dict.fromkeys((382, 383, 384, 385), "probing"),
    **dict.fromkeys((70, 80), "lathe diameter/radius mode"),
    **dict.fromkeys((680, 690), "coordinate rotation"),
    **dict.fromkeys((500, 510), "scaling"),
    **dict.fromkeys((150, 160), "polar coordinates"),
    **dict.fromkeys((980, 990), "canned-cycle return mode"),
    431: "dynamic tool length offset (G43.1)",
    432: "additional tool length offset (G43.2)",
    520: "local coordinate system (G52)",
}
_KIND_OF_MOTION = {
    0: MotionKind.RAPID,
    10: MotionKind.LINEAR,
    20: MotionKind.ARC_CW,
    30: MotionKind.ARC_CCW,
}
_SINGLE = "FHIJKNPQRSTXYZ"  # letters allowed once per line
_ROW = np.full(26, -1, dtype=np.int64)  # letter code -> row of the per-line word table
_ROW[[_L[c] for c in _SINGLE]] = np.arange(len(_SINGLE))


_PAREN = re.compile(r"\([^()\n]*\)")
_SEMI = re.compile(r";[^\n]*")
_TAPE = re.compile(r"(?m)^[ \t]*%[^\n]*")
_BLOCK_DELETE_LINE = re.compile(r"(?m)^[ \t]*/[^\n]*")
_BLOCK_DELETE_MARK = re.compile(r"(?m)^([ \t]*)/")
# byte tables: upper-casing with blanks mapped to 0 (removed), and character classes
_UPPER = np.arange(256, dtype=np.uint8)
_UPPER[97:123] -= 32
_UPPER[[32, 9, 13, 12, 11, 0]] = 0
_OTHER, _NL, _LETTER, _DIGIT, _DOT, _SIGN = range(6)
_CLASS = np.full(256, _OTHER, dtype=np.uint8)
_CLASS[10] = _NL
_CLASS[65:91] = _LETTER
_CLASS[48:58] = _DIGIT
_CLASS[46] = _DOT
_CLASS[[43, 45]] = _SIGN
_SPACE = np.arange(256, dtype=np.uint8)  # letters and newlines become blanks between numbers
_SPACE[(_CLASS == _LETTER) | (_CLASS == _NL)] = 32


class _Errors:
    """Errors found so far, keyed by their position in the text; the earliest one is raised."""

    def __init__(self, raw_lines: list[str], line_starts: np.ndarray, source: str | None):
        self.raw_lines, self.line_starts, self.source = raw_lines, line_starts, source
        self.found: list[tuple[int, int, str]] = []

    def at_pos(self, pos: int, reason: str) -> None:
        line = int(np.searchsorted(self.line_starts, pos, side="right")) - 1
        self.found.append((pos, line, reason))

    def at_lines(self, mask: np.ndarray, reason) -> None:
        """Record ``reason`` (a string, or a function of the line index) at the first line of
        ``mask`` (only the first matters: it is the earliest)."""
        hits = np.flatnonzero(mask)
        if len(hits):
            i = int(hits[0])
            self.found.append(
                (int(self.line_starts[i]), i, reason(i) if callable(reason) else reason)
            )

    def first_pos(self) -> int:
        """Position of the earliest error, or the end of the text."""
        return min(f[0] for f in self.found) if self.found else 1 << 62

    def first_line(self) -> int:
        return min(f[1] for f in self.found) if self.found else len(self.line_starts)

    def raise_first(self) -> None:
        if self.found:
            _, line, reason = min(self.found)
            text = self.raw_lines[line] if line < len(self.raw_lines) else ""
            raise GCodeError(line + 1, text, reason, self.source)


# ---------------------------------------------------------------------------------------------
# Lexing
# ---------------------------------------------------------------------------------------------
def _clean(text: str, block_delete: bool) -> np.ndarray:
    """Strip tape markers, comments, block-delete marks, blanks and case; keep the lines.

    Returns the program as upper-case bytes (uint8 array) with one ``\\n`` per source line.
    """
    if "%" in text:
        marks = [m.start() for m in _TAPE.finditer(text)]
        if len(marks) >= 2:  # the program lies between the first two tape markers
            text = text[: marks[1]]
        text = _TAPE.sub("", text)
    if "(" in text:
        text = _PAREN.sub("", text)
    if ";" in text:
        text = _SEMI.sub("", text)
    if "/" in text:
        text = (_BLOCK_DELETE_LINE if block_delete else _BLOCK_DELETE_MARK).sub(
            "" if block_delete else r"\1", text
        )
    b = _UPPER[np.frombuffer(text.encode("utf-8"), dtype=np.uint8)]
    return b[b != 0]


def _lex(b: np.ndarray, errors: _Errors) -> dict[str, np.ndarray]:
    """Split cleaned bytes into words: letter code, value and line index of each."""
    cls = _CLASS[b]
    is_nl = cls == _NL
    is_letter = cls == _LETTER
    is_dot = cls == _DOT
    is_sign = cls == _SIGN
    is_num = cls >= _DIGIT

    for pos in np.flatnonzero(cls == _OTHER)[:1]:
        c = chr(b[pos])
        reason = _CHAR_REASON.get(c, f"unexpected character {c!r}")
        errors.at_pos(int(pos), reason if b[pos] < 128 else "non-ASCII character outside a comment")

    letters = np.flatnonzero(is_letter)
    codes = b[letters] - 65
    bad_letter = ~np.isin(codes, [_L[c] for c in _ALLOWED_LETTERS])
    for pos in letters[bad_letter][:1]:
        c = chr(b[pos])
        errors.at_pos(int(pos), _LETTER_REASON.get(c, f"{c} words are not supported"))

    # a number must follow a letter: [+-]?(digits[.digits] | .digits), nothing else
    prev_nl = np.concatenate([[True], is_nl[:-1]])
    for pos in np.flatnonzero(is_num & prev_nl)[:1]:
        errors.at_pos(int(pos), "number without a word letter")
    ext = np.append(cls, _NL)  # class of each byte, and a newline past the end
    p = letters + 1
    p += ext[p] == _SIGN
    p += ext[p] == _DOT
    malformed = ext[p] != _DIGIT
    sign_pos = np.flatnonzero(is_sign)
    dot_pos = np.flatnonzero(is_dot)
    dot_word = np.searchsorted(letters, dot_pos)  # the word (letter index + 1) of each dot
    stray = np.concatenate(
        [
            sign_pos[
                ~np.concatenate([[False], is_letter[:-1]])[sign_pos]
            ],  # sign not after a letter
            dot_pos[1:][dot_word[1:] == dot_word[:-1]],  # second dot in a word
        ]
    )
    stray_word = np.searchsorted(letters, stray) - 1
    stray = stray[stray_word >= 0]  # (one before any letter is a number without a letter)
    malformed[stray_word[stray_word >= 0]] = True
    # (a word cut short by a character that is itself an error is reported by that error)
    telling = malformed & (ext[p] != _OTHER)
    for pos in np.sort(np.concatenate([letters[telling], stray]))[:1]:
        word = letters[np.searchsorted(letters, pos, side="right") - 1]
        errors.at_pos(int(pos), f"malformed number after word {chr(b[word])}")

    # numbers are read as Python reads floats (correctly rounded), up to the first error
    cut = min(errors.first_pos(), int(letters[malformed][0]) if malformed.any() else 1 << 62)
    n_ok = int(np.searchsorted(letters, cut))
    value = np.full(len(letters), np.nan)
    value[:n_ok] = np.array(_SPACE[b[:cut]].tobytes().split(), dtype=np.float64)
    big = np.isinf(value)
    for pos in letters[big][:1]:
        errors.at_pos(int(pos), "number out of range")
    line = np.searchsorted(errors.line_starts, letters, side="right") - 1
    keep = ~(bad_letter | malformed | big) & (np.arange(len(letters)) < n_ok)
    return {"code": codes[keep].astype(np.int64), "value": value[keep], "line": line[keep]}


# ---------------------------------------------------------------------------------------------
# Modal interpretation
# ---------------------------------------------------------------------------------------------
def _ffill(given: np.ndarray, values: np.ndarray, initial):
    """Carry ``values`` forward from the lines where ``given``; ``initial`` before the first."""
    idx = np.where(given, np.arange(len(given)), -1)
    np.maximum.accumulate(idx, out=idx)
    return np.where(idx >= 0, values[np.maximum(idx, 0)], initial)


def _fmt_g(code: int) -> str:
    return f"G{code // 10}" + (f".{code % 10}" if code % 10 else "")


def parse(
    text: str,
    *,
    source: str | None = None,
    units: str = "mm",
    dwell_p_unit: str = "s",
    block_delete: bool = False,
    start_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    arc_tol_mm: float = 0.005,
    arc_tol_rel: float = 0.001,
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
    dwell_p_unit : {"s", "ms"}
        Unit of P in G4: seconds (RS274/NGC, LinuxCNC) or milliseconds (Fanuc).
    block_delete : bool
        Whether the block-delete switch is on (lines starting with ``/`` are skipped).
    start_mm : tuple of 3 floats
        Tool position before the first block.
    arc_tol_mm, arc_tol_rel : float
        An arc whose start and end radii differ by more than
        ``max(arc_tol_mm, arc_tol_rel * radius)`` is rejected.

    Returns
    -------
    Toolpath

    Raises
    ------
    GCodeError
        For any line that cannot be read: the earliest one, with its number, text and reason.
    ValueError
        For a bad keyword argument, naming it and its allowed values.
    """
    if units not in ("mm", "inch"):
        raise ValueError(f"units must be 'mm' or 'inch', got {units!r}")
    if dwell_p_unit not in ("s", "ms"):
        raise ValueError(f"dwell_p_unit must be 's' or 'ms', got {dwell_p_unit!r}")
    for name, v in (("arc_tol_mm", arc_tol_mm), ("arc_tol_rel", arc_tol_rel)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
    start = np.asarray(start_mm, dtype=float)
    if start.shape != (3,) or not np.isfinite(start).all():
        raise ValueError(f"start_mm must be 3 finite numbers, got {start_mm!r}")

    text = text.replace("\r\n", "\n").replace("\r", "\n")
    raw_lines = text.split("\n")
    b = _clean(text, block_delete)
    line_starts = np.concatenate([[0], np.flatnonzero(b == 10) + 1])
    errors = _Errors(raw_lines, line_starts, source)
    words = _lex(b, errors)

    # the program ends with M2/M30: nothing after it is read. Words after the first lexical
    # error are not interpreted (an earlier modal error is still found and reported first).
    ends = (words["code"] == _L["M"]) & np.isin(words["value"], (2.0, 30.0))
    end_line = int(words["line"][ends][0]) + 1 if ends.any() else len(line_starts)
    errors.found = [e for e in errors.found if e[1] < end_line]
    n_lines = min(errors.first_line(), end_line)
    keep = words["line"] < n_lines
    code, value, line = words["code"][keep], words["value"][keep], words["line"][keep]
    tp = _interpret(
        code,
        value,
        line,
        n_lines,
        errors,
        units=units,
        dwell_p_unit=dwell_p_unit,
        start=start,
        arc_tol=(arc_tol_mm, arc_tol_rel),
    )
    errors.raise_first()
    return tp


def _interpret(code, value, line, n, errors: _Errors, *, units, dwell_p_unit, start, arc_tol):
    """Modal interpretation of the words of lines ``0..n-1``; returns the Toolpath."""
    # ---- one value per line and letter; a letter twice in a line is an error (not G, M)
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

    # ---- G-codes: one per modal group and line
    g = code == _L["G"]
    gval, gline = value[g], line[g]
    gcode = np.rint(gval * 10).astype(np.int64)
    idx = np.minimum(np.searchsorted(_G_CODES, gcode), len(_G_CODES) - 1)
    known = (_G_CODES[idx] == gcode) & (np.abs(gval * 10 - gcode) < 1e-6)
    for i in np.flatnonzero(~known)[:1]:
        what = _G_UNSUPPORTED.get(int(gcode[i]))
        name = f"G{gval[i]:g}"
        errors.at_lines(
            np.arange(n) == gline[i],
            f"{name} ({what}) is not supported" if what else f"{name} is not supported",
        )
    gcode, gline, grp = gcode[known], gline[known], _G_GROUPS[idx[known]]
    n_groups = len(_GROUP_NAMES)
    gdup = np.bincount(gline * n_groups + grp, minlength=n * n_groups).reshape(n, n_groups) > 1
    errors.at_lines(
        gdup.any(1),
        lambda i: f"two G-codes of the {_GROUP_NAMES[np.argmax(gdup[i])]} group in one line",
    )
    G = np.full((n_groups, n), -1, dtype=np.int64)
    G[grp, gline] = gcode

    # ---- modal state per line
    inch = _ffill(G[_UNITS] >= 0, G[_UNITS] == 200, units == "inch")
    scale = np.where(inch, MM_PER_INCH, 1.0)
    motion = _ffill(G[_MOTION] >= 0, G[_MOTION], -1)
    plane = _ffill(G[_PLANE] >= 0, (G[_PLANE] - 170) // 10, int(Plane.XY))
    incremental = _ffill(G[_DIST] >= 0, G[_DIST] == 910, False)
    arc_absolute = _ffill(G[_ARCDIST] >= 0, G[_ARCDIST] == 901, False)
    path_code = _ffill(G[_PATH] >= 0, G[_PATH], -1)
    g64 = G[_PATH] == 640
    dwell_line = G[_NONMODAL] == 40

    errors.at_lines(has["F"] & (W["F"] <= 0), "feed rate F must be > 0")
    feed = _ffill(has["F"], W["F"] * scale / 60.0, np.nan)

    errors.at_lines(dwell_line & has["P"] & g64, "P word used by both G4 and G64")
    errors.at_lines(has["P"] & ~dwell_line & ~g64, "P word without G4 or G64")
    errors.at_lines(has["Q"] & ~g64, "Q word without G64")
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

    # ---- dwells
    p_scale = 1e-3 if dwell_p_unit == "ms" else 1.0
    dwell_t = np.where(has["P"], W["P"] * p_scale, W["X"])
    errors.at_lines(dwell_line & ~has["P"] & ~has["X"], "G4 without a dwell time (P)")
    errors.at_lines(dwell_line & has["P"] & has["X"], "G4 with both P and X")
    errors.at_lines(dwell_line & (dwell_t < 0), "dwell time must be >= 0")
    errors.at_lines(
        dwell_line & (has["Y"] | has["Z"] | (G[_MOTION] >= 0)), "G4 cannot share a line with motion"
    )

    # ---- positions: absolute words set, incremental words add
    axis_given = np.stack([has["X"] & ~dwell_line, has["Y"], has["Z"]], axis=1)  # (n, 3)
    axis_val = np.stack([W["X"], W["Y"], W["Z"]], axis=1) * scale[:, None]
    pos = np.empty((n, 3))
    for a in range(3):
        csum = np.cumsum(np.where(axis_given[:, a] & incremental, axis_val[:, a], 0.0))
        anchor = axis_given[:, a] & ~incremental
        pos[:, a] = _ffill(anchor, axis_val[:, a], start[a]) + (csum - _ffill(anchor, csum, 0.0))
    prev = np.vstack([start, pos[:-1]]) if n else pos

    moves = axis_given.any(1)
    errors.at_lines(
        moves & ((motion < 0) | (motion == 800)),
        "axis words without an active motion mode (G0/G1/G2/G3)",
    )
    arc_line = moves & ((motion == 20) | (motion == 30))
    feed_line = moves & ((motion == 10) | arc_line)
    errors.at_lines(
        feed_line & np.isnan(feed), lambda i: f"{_fmt_g(int(motion[i]))} with no feed rate set (F)"
    )
    ijk = has["I"] | has["J"] | has["K"]
    errors.at_lines((ijk | has["R"]) & ~arc_line, "I/J/K/R words without an arc (G2/G3) move")

    # ---- arcs
    center = np.full((n, 3), np.nan)
    ai = np.flatnonzero(arc_line)
    if len(ai):
        center[ai] = _arc_centers(
            ai, prev, pos, plane, motion, W, has, scale, arc_absolute, errors, arc_tol
        )

    # ---- blocks: one per motion or dwell line
    bl = np.flatnonzero(moves | dwell_line)
    kind = np.full(n, MotionKind.DWELL, dtype=np.int8)
    for c, k in _KIND_OF_MOTION.items():
        kind[motion == c] = k
    kind[dwell_line] = MotionKind.DWELL
    ev = np.isin(code, (_L["M"], _L["S"], _L["T"]))
    events = np.zeros(int(ev.sum()), dtype=EVENT_DTYPE)
    events["block"] = np.searchsorted(bl, line[ev], side="left")
    events["line"] = line[ev] + 1
    events["word"] = np.array(list(_LETTERS))[code[ev]]
    events["value"] = value[ev]
    end = pos[bl]  # a dwell line has no axis words: its position is the previous one
    return Toolpath(
        start_mm=prev[bl],
        end_mm=end,
        kind=kind[bl],
        feed_mm_s=feed[bl],
        center_mm=center[bl],
        plane=plane[bl],
        dwell_s=np.where(dwell_line[bl], dwell_t[bl], 0.0),
        line=bl + 1,
        path_mode=mode[bl],
        blend_tol_mm=blend_p[bl],
        naive_tol_mm=blend_q[bl],
        events=events,
    )


def _arc_centers(ai, prev, pos, plane, motion, W, has, scale, arc_absolute, errors, arc_tol):
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

    # centre from I/J/K
    ca = np.where(arc_absolute[ai], 0.0, sa) + ijk[rows, ax[:, 0]]
    cb = np.where(arc_absolute[ai], 0.0, sb) + ijk[rows, ax[:, 1]]
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


# ---------------------------------------------------------------------------------------------
# Files and writing
# ---------------------------------------------------------------------------------------------
def parse_file(path: str | PathLike, **kwargs) -> Toolpath:
    """Read a program from a file (UTF-8, or Latin-1 if it is not UTF-8); see :func:`parse`."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise GCodeError(0, "", f"cannot read the file: {exc.strerror or exc}", str(p)) from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return parse(text, source=str(p), **kwargs)


def _num(x: float) -> str:
    """Shortest decimal that reads back to the same float, never in exponent form."""
    return np.format_float_positional(x, unique=True, trim="-")


def dump(tp: Toolpath, *, title: str | None = None) -> str:
    """Write a tool path as a program: mm, absolute coordinates, absolute arc centres.

    ``parse(dump(tp))`` gives a tool path that :meth:`Toolpath.allclose` calls equal to ``tp``.

    Parameters
    ----------
    tp : Toolpath
    title : str, optional
        A comment for the first line.

    Returns
    -------
    str
    """
    out = [f"({title})" if title else "(written by nctwin)", "G21 G90 G90.1 G94 G17"]
    plane, feed, path = int(Plane.XY), np.nan, (int(PathMode.DEFAULT), np.nan, np.nan)
    events = tp.events
    ei = 0
    for k in range(len(tp)):
        while ei < len(events) and events["block"][ei] <= k:
            out.append(f"{events['word'][ei]}{_num(events['value'][ei])}")
            ei += 1
        mode = (int(tp.path_mode[k]), tp.blend_tol_mm[k], tp.naive_tol_mm[k])
        if not (mode[0] == path[0] and np.array_equal(mode[1:], path[1:], equal_nan=True)):
            if mode[0] == PathMode.BLEND:
                out.append(
                    "G64"
                    + "".join(
                        f" {w}{_num(v)}"
                        for w, v in zip("PQ", mode[1:], strict=True)
                        if not np.isnan(v)
                    )
                )
            elif mode[0] != PathMode.DEFAULT:
                out.append("G61" if mode[0] == PathMode.EXACT_PATH else "G61.1")
            else:
                raise ValueError("a tool path cannot return to the machine's default path mode")
            path = mode
        kind = tp.kind[k]
        words = []
        f = tp.feed_mm_s[k]
        if not np.isnan(f) and f != feed:
            words.append(f"F{_num(f * 60.0)}")
            feed = f
        if kind == MotionKind.DWELL:
            out += [*words, f"G4 P{_num(tp.dwell_s[k])}"]
            continue
        if tp.is_arc[k] and tp.plane[k] != plane:
            plane = int(tp.plane[k])
            words.append(f"G{17 + plane}")
        words.append(("G0", "G1", "G2", "G3")[kind])
        words += [f"{a}{_num(v)}" for a, v in zip("XYZ", tp.end_mm[k], strict=True)]
        if tp.is_arc[k]:
            ax = PLANE_AXES[plane]
            words += [f"{'IJK'[a]}{_num(tp.center_mm[k, a])}" for a in ax[:2]]
        out.append(" ".join(words))
    out += [f"{w}{_num(v)}" for w, v in zip(events["word"][ei:], events["value"][ei:], strict=True)]
    return "\n".join(out) + "\n"
