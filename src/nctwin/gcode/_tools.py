"""The tool table and the offsets of the native reader: the table nctwin's LinuxCNC uses where a
machine names none, the tools a program selects that the table lacks, the tool length offsets
of ``G43 H<n>``/``G49``, and the positions of a program without canned cycles and G92, which
those offsets shift.

A tool length offset works as LinuxCNC's (``convert_tool_length_offset``): it shifts the
program's coordinates, not the tool, so the tool moves by it at the next move that gives the
axis in absolute distance mode (G90); an incremental move (G91), a G53 move or a G28/G30
return to the reference point ignores it.
"""

from __future__ import annotations

import re
from os import PathLike
from pathlib import Path

import numpy as np

from ..machine import ToolTable, read_tool_table
from ._errors import _NEEDS_LINUXCNC, GCodeError, _Errors
from ._modal import _NONMODAL, _TLO, _anchored, _ffill

#: The tool table of nctwin's LinuxCNC configuration (:mod:`nctwin.kernel.linuxcnc` writes this
#: text to its instance's ``tool.tbl``): tool 1 in pocket 1, diameter 0, length 0.
LINUXCNC_TOOL_TABLE = "T1 P1 D0 Z0 ;\n"

#: Comments, ``<names>`` of parameters and subroutines, and the words of a program's text.
_NOT_WORDS = re.compile(r"\([^)]*\)|;[^\n]*|<[^>]*>")
_WORDS = re.compile(r"(?<![A-Z])([GT])\s*(\d+(?:\.\d*)?)", re.IGNORECASE)
_TABLE_TOOL = re.compile(r"^\s*T(\d+)(?:.*?\bP(\d+))?", re.IGNORECASE | re.MULTILINE)
#: The G-codes that take a tool's size from the table: cutter compensation (its diameter) and
#: tool length offsets (its length); G41.1, G42.1 and G43.1 give the size in the block.
SIZED_CODES = (41.0, 42.0, 43.0, 43.2)


def complete_tool_table(table: str, program: str) -> str:
    """``table`` with each tool the program's T words select and the table lacks, of diameter
    0 and length 0: a tool's size matters to the path only where cutter compensation or a length
    offset needs it (:data:`SIZED_CODES`). A program with one of those gets ``table`` as it is,
    and LinuxCNC refuses a tool it lacks. T0 (no tool) is never added.

    Parameters
    ----------
    table : str
        A LinuxCNC tool table's text (``T<n> P<pocket> D<diameter> Z<length> ;...`` lines).
    program : str
        The program's text: literal T and G words outside comments (T words computed from
        parameters are not seen).
    """
    words = _WORDS.findall(_NOT_WORDS.sub(" ", program))
    if any(k.upper() == "G" and float(v) in SIZED_CODES for k, v in words):
        return table
    listed = _TABLE_TOOL.findall(table)
    missing = sorted({int(float(v)) for k, v in words if k.upper() == "T"} - {0}
                     - {int(t) for t, _ in listed})  # fmt: skip
    pocket = max((int(p) for _, p in listed if p), default=0)
    added = "".join(f"T{t} P{pocket + k} D0 Z0 ;not in the table\n"
                    for k, t in enumerate(missing, 1))  # fmt: skip
    return table + ("" if not added or table.endswith("\n") else "\n") + added


#: M61 (the spindle's tool set without a tool change) and the codes that take the size of the
#: tool in the spindle when they name no tool: G41/G42 without D, G43 without H (not G41.1,
#: G42.1, G43.1, G43.2).
_CHANGE = re.compile(r"(?<![A-Z0-9.#])M0*61(?![.\d])", re.IGNORECASE)
_SPINDLE_SIZED = {
    "D": re.compile(r"(?<![A-Z0-9.#])G0*4[12](?![.\d])", re.IGNORECASE),
    "H": re.compile(r"(?<![A-Z0-9.#])G0*43(?![.\d])", re.IGNORECASE),
}


def spindle_tool_line(table: ToolTable | None, program: str) -> int | None:
    """The first line (1-based) of a ``program`` with ``M61`` that takes its size from the tool
    in the spindle (``G41``/``G42`` without ``D``, ``G43`` without ``H``), where ``table``
    gives some tool a size; None if there is none. LinuxCNC's preview module, which the
    interpreter reader runs, calls back on ``M6`` (the reader then loads the tool into the
    spindle, as ``iocontrol`` does) but not on ``M61 Q``, so after it such a line would be read
    with the size of the tool before, where LinuxCNC runs the new tool's size."""
    if table is None or not (any(table.diameter_mm) or any(map(any, table.offset_mm))):
        return None
    if not _CHANGE.search(_NOT_WORDS.sub(" ", program)):
        return None
    for i, line in enumerate(program.splitlines(), 1):
        words = _NOT_WORDS.sub(" ", line)
        for letter, code in _SPINDLE_SIZED.items():
            if code.search(words) and not re.search(rf"(?<![A-Z]){letter}(?![A-Z])", words, re.I):
                return i
    return None


def tool_table_of(
    tool_table: str | PathLike | ToolTable | None, source: str | None
) -> ToolTable | None:
    """``tool_table`` read: a :class:`~nctwin.machine.ToolTable` as it is, a ``.tbl`` file's
    path read (:func:`~nctwin.machine.read_tool_table`), None as it is (the readers' own).

    Raises
    ------
    GCodeError
        For a file that cannot be read.
    ValueError
        ``file:line: reason`` for a line of it LinuxCNC would not read.
    """
    if tool_table is None or isinstance(tool_table, ToolTable):
        return tool_table
    path = Path(tool_table)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise GCodeError(0, "", f"tool table {path}: {exc.strerror or exc}", source) from None
    return read_tool_table(text, str(path))


def tool_offsets(W, has, G, n: int, table: ToolTable | None, errors: _Errors) -> np.ndarray:
    """The tool length offset in force at each of ``n`` lines after its codes, shape (n, 3) mm:
    ``G43 H<n>`` the table's X, Y, Z offsets of tool n (H0: none), ``G49`` none. With no table
    (None) every offset is 0, as on nctwin's own table."""
    off = np.zeros((n, 3))
    g43 = G[_TLO] == 430
    if table is None or not g43.any() or not np.any(table.offset_mm):
        return off
    errors.at_lines(
        g43 & ~has["H"], f"G43 without H (the tool in the spindle's length) {_NEEDS_LINUXCNC}"
    )
    h = np.where(g43 & has["H"], W["H"], 0.0)
    errors.at_lines((h != np.rint(h)) | (h < 0), "H word must be a whole number >= 0")
    rows = {t: table.offset_of(t) for t in np.unique(np.rint(np.maximum(h, 0))).astype(int)}
    errors.at_lines(
        np.isin(np.rint(h), [t for t, o in rows.items() if o is None]),
        lambda i: f"G43 H{int(h[i])}: tool {int(h[i])} is not in the machine's tool table",
    )
    per_line = np.array([rows[int(t)] or (0.0, 0.0, 0.0) for t in np.rint(np.maximum(h, 0))])
    given = G[_TLO] >= 0
    return np.stack([_ffill(given, per_line[:, a], 0.0) for a in range(3)], axis=1)


def shift_by_offsets(axis_val, tlo, incremental, G) -> np.ndarray:
    """The axis words (n, 3) mm as the positions they command: plus the tool length offset
    ``tlo`` (n, 3) on lines in absolute distance mode, but on G53 lines."""
    shift = ~incremental & (G[_NONMODAL] != 530)
    return axis_val + np.where(shift[:, None], tlo, 0.0)


def plain_positions(act, axis_val, incremental, start, n):
    """Positions (n, 3) of a program with no canned cycle and no G92, and its offsets (0)."""
    off = np.zeros((n, 3))
    pos = np.empty((n, 3))
    for a in range(3):
        step = np.where(act.axis_given[:, a] & incremental, axis_val[:, a], 0.0)
        anchor = act.axis_given[:, a] & ~incremental
        value_mm = axis_val[:, a].copy()
        hl = act.home_lines
        anchor[hl], value_mm[hl] = ~np.isnan(act.home_mm[:, a]), act.home_mm[:, a]
        pos[:, a] = _anchored(anchor, value_mm, step, start[a])
    return pos, off
