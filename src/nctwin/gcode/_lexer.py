"""Lexing: a program cleaned of tape markers, comments, program numbers, block-delete marks,
blanks and case, and cut into words (letter, value, line, text position) with numpy on the raw
bytes; the characters and numbers that cannot be read are reported, with why."""

from __future__ import annotations

import re

import numpy as np

from ._errors import _NEEDS_LINUXCNC, _Errors

# ---------------------------------------------------------------------------------------------
# Tables: letters, comments and bytes
# ---------------------------------------------------------------------------------------------
_LETTERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
_L = {c: i for i, c in enumerate(_LETTERS)}
_ALLOWED = np.array([c in "FGHIJKLMNPQRSTXYZ" for c in _LETTERS])
_LETTER_REASON = {
    "O": f"O-word (subroutine, loop or conditional) {_NEEDS_LINUXCNC}",
    "D": f"D word (cutter compensation) {_NEEDS_LINUXCNC}",
    "E": f"E word (threading, analog input) {_NEEDS_LINUXCNC}",
    **{a: f"axis {a} is not supported: nctwin reads 3-axis XYZ programs" for a in "ABCUVW"},
}
_CHAR_REASON = {
    "#": f"#-parameter {_NEEDS_LINUXCNC}",
    "[": f"expression [...] {_NEEDS_LINUXCNC}",
    "]": f"expression [...] {_NEEDS_LINUXCNC}",
    "=": f"parameter assignment {_NEEDS_LINUXCNC}",
    "<": f"named parameter <...> {_NEEDS_LINUXCNC}",
    ">": f"named parameter <...> {_NEEDS_LINUXCNC}",
    "@": f"polar coordinate word @ {_NEEDS_LINUXCNC}",
    "^": f"polar coordinate word ^ {_NEEDS_LINUXCNC}",
    "$": f"spindle selection $ {_NEEDS_LINUXCNC}",
    "(": "unbalanced parentheses: comments cannot nest or span lines",
    ")": "unbalanced parentheses: comments cannot nest or span lines",
    "/": "block delete '/' is only allowed at the start of a line",
}


_PAREN = re.compile(r"\([^()\n]*\)")
_SEMI = re.compile(r";[^\n]*")
_TAPE = re.compile(r"(?m)^[ \t]*%[^\n]*")
_PROGRAM_NUMBER = re.compile(r"(?im)^[ \t]*o[ \t]*[0-9]+[ \t]*$")
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


# ---------------------------------------------------------------------------------------------
# Lexing
# ---------------------------------------------------------------------------------------------
def _clean(text: str, block_delete: bool) -> np.ndarray:
    """Strip tape markers, comments, program numbers, block-delete marks, blanks and case; keep
    the lines.

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
    if "O" in text or "o" in text:
        text = _PROGRAM_NUMBER.sub("", text)
    if "/" in text:
        text = (_BLOCK_DELETE_LINE if block_delete else _BLOCK_DELETE_MARK).sub(
            "" if block_delete else r"\1", text
        )
    b = _UPPER[np.frombuffer(text.encode("utf-8"), dtype=np.uint8)]
    return b[b != 0]


def _lex(b: np.ndarray, errors: _Errors) -> dict[str, np.ndarray]:
    """Split cleaned bytes into words: letter code, value, line index and text position of each.

    Words that cannot be read are reported and left out; the other words of their line are kept.
    """
    cls = _CLASS[b]
    is_nl = cls == _NL
    is_letter = cls == _LETTER
    letters = np.flatnonzero(is_letter)
    codes = (b[letters] - 65).astype(np.int64)
    ok = _ALLOWED[codes]
    if not ok.all():
        errors.at_pos(letters[~ok], lambda pos: _letter_reason(b, letters, pos))

    # a number must follow a letter: [+-]?(digits[.digits] | .digits), nothing else
    ext = np.append(cls, _NL)  # class of each byte, and a newline past the end
    p = letters + 1
    p += ext[p] == _SIGN
    p += ext[p] == _DOT
    after = ext[p]  # where the first digit must be
    signs = np.flatnonzero(cls == _SIGN)
    dot_word = np.searchsorted(letters, np.flatnonzero(cls == _DOT))  # the word of each dot + 1
    if (
        (after != _DIGIT).any()
        or (~np.concatenate([[False], is_letter[:-1]])[signs]).any()  # a sign not after a letter
        or (dot_word[1:] == dot_word[:-1]).any()  # two dots in a word
        or (cls == _OTHER).any()
        or ((cls >= _DIGIT) & np.concatenate([[True], is_nl[:-1]])).any()  # a line's first byte
    ):
        value, readable = _lex_errors(b, cls, letters, after, errors)
        ok &= readable
    else:  # numbers are read as Python reads floats (correctly rounded)
        value = np.array(_SPACE[b].tobytes().split(), dtype=np.float64)
    big = np.isinf(value)
    if big.any():
        errors.at_pos(letters[big], "number out of range")
    ok &= ~big
    line = np.searchsorted(errors.line_starts, letters[ok], side="right") - 1
    return {"code": codes[ok], "value": value[ok], "line": line, "pos": letters[ok]}


def _lex_errors(b, cls, letters, after, errors: _Errors) -> tuple[np.ndarray, np.ndarray]:
    """Report the characters and numbers that cannot be read; the values of the other words.

    The text is cut into segments, each starting at a letter or a line start. The segment of a
    word is readable if it holds a well-formed number and nothing else; the segment before a
    line's first letter must be empty. ``after`` is the class of the byte where each word's first
    digit must be. Returns the value of each word (NaN where unreadable) and whether it is
    readable.
    """
    is_letter = cls == _LETTER
    seg = np.cumsum(is_letter | (cls == _NL))  # segment of each byte; 0 before the first line end
    word_seg = seg[letters]
    word_of_seg = np.full(int(seg[-1]) + 1, -1)
    word_of_seg[word_seg] = np.arange(len(letters))
    other = np.flatnonzero(cls == _OTHER)
    errors.at_pos(other, lambda pos: _char_reason(int(b[pos])))
    content = np.flatnonzero(~is_letter & (cls != _NL))
    at_start = content[word_of_seg[seg[content]] < 0]
    errors.at_pos(at_start[cls[at_start] != _OTHER], "number without a word letter")
    # a sign that does not follow its letter, a second dot in a number
    signs = np.flatnonzero(cls == _SIGN)
    dots = np.flatnonzero(cls == _DOT)
    stray = np.concatenate(
        [
            signs[~np.concatenate([[False], is_letter[:-1]])[signs]],
            dots[1:][seg[dots[1:]] == seg[dots[:-1]]],
        ]
    )
    stray = stray[word_of_seg[seg[stray]] >= 0]
    bad_word = after != _DIGIT
    # (a word cut short by a character that is itself an error is reported by that error)
    telling = bad_word & (after != _OTHER)
    bad_word[word_of_seg[seg[stray]]] = True
    errors.at_pos(
        np.concatenate([letters[telling], stray]),
        lambda pos: f"malformed number after word {chr(b[letters[word_of_seg[seg[pos]]]])}",
    )
    bad_seg = np.zeros(len(word_of_seg), dtype=bool)
    bad_seg[seg[other]] = True
    bad_seg[seg[at_start]] = True
    bad_seg[word_seg[bad_word]] = True
    spaced = _SPACE[b]
    spaced[bad_seg[seg]] = 32
    readable = ~bad_seg[word_seg]
    value = np.full(len(letters), np.nan)
    value[readable] = np.array(spaced.tobytes().split(), dtype=np.float64)
    return value, readable


def _letter_reason(b: np.ndarray, letters: np.ndarray, pos: int) -> str:
    """Why the word letter at ``pos`` cannot be read.

    An O right after a number (other than an N number) is a mistyped digit: blanks do not count
    in RS274/NGC, so ``X1O`` is ``X1`` then ``O``, not an O-word.
    """
    c = chr(b[pos])
    k = int(np.searchsorted(letters, pos))
    if c == "O" and k and _CLASS[b[pos - 1]] in (_DIGIT, _DOT):
        word = letters[k - 1]  # the number's word: on the same line, and not an N number
        if b[word] != 78 and not (b[word:pos] == 10).any():
            return f"malformed number after word {chr(b[word])}"
    return _LETTER_REASON.get(c, f"{c} words are not supported")


def _char_reason(c: int) -> str:
    """Why the character of byte ``c`` cannot be read outside a comment."""
    if c >= 128:
        return "non-ASCII character outside a comment"
    return _CHAR_REASON.get(chr(c), f"unexpected character {chr(c)!r}")
