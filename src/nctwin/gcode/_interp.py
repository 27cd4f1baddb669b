"""The second reader: G-code through LinuxCNC's own rs274ngc interpreter, the whole language.

Why LinuxCNC's preview module
-----------------------------
LinuxCNC ships two ways to run its interpreter without a machine: the stand-alone ``rs274``
program, which prints every canonical call as text with its numbers rounded (``%.4f``), and the
``gcode`` extension module its preview (AXIS) uses, which calls a Python object back for every
canonical move with the source line (``next_line``) and the coordinates as full-precision
doubles. Rounded text would put up to 5e-5 in (1.3 um) of error into every point and arc centre
and lose the feed's digits, so this reader uses the module. It is built for the system Python
(linuxcnc-uspace installs it for ``/usr/bin/python3``, not for nctwin's venv), so it runs in a
child process, :file:`_linuxcnc_child.py`; the child appends every call to ``array('d')`` tables
and writes them as raw bytes, which are read here with :func:`numpy.frombuffer` and converted with
whole-array operations. The interpreter itself takes about 4 us a move (200,000 moves in 0.82 s
with callbacks that do nothing); end to end, child started, tables sent and converted, a move
costs about 5 us: 190,000 moves/s on 500,000 moves, 90,000-110,000 on contour.ngc's 10,000, where
the child's start (about 40 ms) counts (``benchmarks/interp_reader.py``).

What the interpreter does and what is done here
-----------------------------------------------
The interpreter does the language: parameters, expressions, O-word subroutines and loops
(subroutine files are looked up in the program's folder), canned cycles, cutter compensation,
units, planes, offsets. Its canonical moves are turned into the same
:class:`~nctwin.toolpath.Toolpath` the native reader makes:

* Lengths: the module reports inches whatever the program's units; they are multiplied by 25.4.
  Feeds (``set_feed_rate``, inches per minute) become mm/s.
* Offsets are added as LinuxCNC's canon adds them (``rotate_and_offset_pos`` in emccanon.cc):
  the G92 offset, the XY rotation (G10 L2 R), the G5x offset, the tool length offset. Work offsets
  come from a parameter file that holds only the G28 and G30 reference points
  (``g28_reference_mm``, ``g30_reference_mm``; zero by default), so they are zero; tool lengths
  and diameters come from the tool table: by default the one of nctwin's LinuxCNC configuration
  (:data:`LINUXCNC_TOOL_TABLE`, tool 1 of diameter 0 and length 0), so that compensated paths
  are the ones the live LinuxCNC runs.
* Arcs: ``arc_feed`` gives the end and centre in the plane's axis order and the signed turns;
  an arc of T turns becomes T-1 full turns then the arc, each with its share of the helix, as
  the native reader makes it.
* Path control and the line of a block: the module reports modal state only in ``next_line``,
  which it calls at the first canonical call of a line, with the state *before* that line
  (``write_settings`` runs after a block). To see the state after every line, each line of the
  program is given a comment ``(.)`` (an empty one makes no call), whose ``COMMENT`` call makes
  every executed line report (and LinuxCNC's error lines exact); the state a line's moves run
  in is the one the next line reports. ``settings[3:5]`` of the reported state are G64's P and
  Q (``write_settings``); the module does not name them, so they are read from the object's
  memory, checked against the fields it does name (feed, line, modes). Before the program the
  interpreter runs ``G64 P987654321 Q987654321``, a sentinel: a block in that state is in
  :attr:`~nctwin.toolpath.PathMode.DEFAULT` mode, as the native reader marks blocks before any
  G61/G64.
* Splines: the module draws a G5 or G5.1 spline or a G5.2/G5.3 NURBS as straight lines, where
  LinuxCNC's task runs biarcs; :mod:`nctwin.gcode._splines` puts the task's moves in their
  place.
* Canned cycles: LinuxCNC runs their moves in exact-path mode (but a first rapid up to R from
  below it); the module does not report that switch, so those blocks are marked here, as the
  native reader marks them.

What differs from the native reader (by design)
-----------------------------------------------
* ``blend_tol_mm`` and ``naive_tol_mm`` hold what LinuxCNC uses: a G64 without P gives P = 0
  (native: NaN), and Q defaults to P (native: NaN). :meth:`Toolpath.effective_tolerance_mm` and
  :meth:`Toolpath.effective_naive_tol_mm` are the same for both.
* ``events`` holds the M-words LinuxCNC's task waits for (``M0``, ``M1``, ``M3``-``M9``), read
  from the interpreter's modal M state (:mod:`nctwin.gcode._task_words`): the module's spindle,
  coolant, stop and tool-select calls are empty stubs that never reach Python. A word that
  changes no state (a second ``M8``) is not seen, and S and T words are not kept.
* Lines of blocks from a subroutine in another file are that file's lines; in such files
  (which are not instrumented) a line's state is the one the next reporting line gives.
* The tool starts at machine zero (LinuxCNC's preview starts there); ``start_mm`` is refused.
* ``M6`` puts the selected tool in the spindle, as LinuxCNC's ``iocontrol`` does on a
  non-random tool changer, so ``G41``/``G42`` without D and ``G43`` without H take its size.
  ``M61 Q`` calls nothing the child sees: in a program with ``M61`` such a line is refused
  where the tool table gives any tool a size.
* G94 sets LinuxCNC's feed to 0 (``convert_feed_mode``): the blocks after it carry NaN (no feed
  set) up to the next F, and a feed move there is LinuxCNC's error; the native reader does the
  same.

Limits: at most :data:`MAX_MOVES` canonical moves (``max_moves``), and a wall-clock limit of
:data:`TIMEOUT_BASE_S` plus :data:`TIMEOUT_S_PER_MB` per MB of program (``timeout_s``), after
which the child, or failing that the parent, stops the interpreter: an endless O-word loop is
one clear error, never a hang.

Refused, with ``file:line: reason``: spindle-synchronised motion (G33, G33.1, G76), inverse-time
and per-revolution feed (G93, G95), probing (G38.n), arcs outside the XY plane under an XY
rotation, and every error LinuxCNC reports (with its message and line).
"""

from __future__ import annotations

import functools
import itertools
import json
import os
import re
import subprocess
import tempfile
from os import PathLike
from pathlib import Path

import numpy as np

from ..checks import check_int, check_range
from ..toolpath import EVENT_DTYPE, PLANE_AXES, MotionKind, PathMode, Plane, Toolpath, arc_sweep
from ._errors import GCodeError, _point_mm
from ._modal import _HOMES, MM_PER_INCH
from ._splines import task_splines
from ._task_words import M_COLUMNS, task_words
from ._tools import LINUXCNC_TOOL_TABLE, ToolTable, complete_tool_table, spindle_tool_line

#: The Python that LinuxCNC's ``gcode`` module is built for (Debian's linuxcnc-uspace).
LINUXCNC_PYTHON = "/usr/bin/python3"
#: Most canonical moves one program may make; beyond it the reader stops (endless loops).
MAX_MOVES = 2_000_000
#: Wall-clock limit of the interpreter: this many seconds ...
TIMEOUT_BASE_S = 30.0
#: ... plus this many seconds per MB of program text.
TIMEOUT_S_PER_MB = 30.0
#: G64 P and Q run before the program: a state with both is "nothing set" (PathMode.DEFAULT).
PATH_SENTINEL = 987654321.0

_CHILD = Path(__file__).with_name("_linuxcnc_child.py")
#: The child stops itself (naming its last line) this long before the time limit (or at half of
#: it): LinuxCNC lets it check about every 2 s, and it is killed at the limit if it has not.
_CHILD_MARGIN_S = 2.5
_MARK = "(.)"
_MAX_LINE = 250  # LinuxCNC's LINELEN is 256: longer lines are left as they are
#: The longest line LinuxCNC 2.9's interpreter reads (characters before the newline, measured:
#: 253 gives "Command too long").
LINUXCNC_MAX_LINE = 252
_N_MOVE, _N_MODAL, _N_EVENT = 7, 15, 14
#: The modal records' causes (the child's ``CAUSES``) that are offsets, by their value in
#: :data:`~nctwin.toolpath.OFFSET_EVENTS`.
_OFFSET_CAUSES = {2: 92.0, 3: 54.0, 4: 43.0, 5: 10.0}
#: LinuxCNC's canon planes (1 XY, 2 YZ, 3 XZ) as :class:`Plane`.
_PLANE_OF_CANON = np.array([0, Plane.XY, Plane.YZ, Plane.ZX], dtype=np.int8)
_CYCLES = (730, 740, 810, 820, 830, 840, 850, 860, 870, 880, 890)
_SPINDLE_SYNC = {330: "G33", 331: "G33.1", 760: "G76"}
_FEED_MODES = {930: "inverse-time feed (G93)", 950: "feed per revolution (G95)"}
_EOF_MESSAGE = "File ended with no percent sign or program end"
_NOT_INSTALLED = "LinuxCNC's interpreter is not installed: run make linuxcnc"


@functools.lru_cache(maxsize=1)
def interpreter_available() -> bool:
    """Whether LinuxCNC's interpreter can be run here (``make linuxcnc`` installs it).

    Returns
    -------
    bool
        True if ``/usr/bin/python3`` imports LinuxCNC's ``gcode`` module.
    """
    if not os.path.exists(LINUXCNC_PYTHON):
        return False
    try:
        done = subprocess.run(
            [LINUXCNC_PYTHON, "-c", "import gcode"], capture_output=True, timeout=60
        )
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done.returncode == 0


def timeout_for(n_bytes: int) -> float:
    """The interpreter's wall-clock limit for a program of ``n_bytes`` bytes, in seconds:
    :data:`TIMEOUT_BASE_S` plus :data:`TIMEOUT_S_PER_MB` per MB."""
    return TIMEOUT_BASE_S + TIMEOUT_S_PER_MB * n_bytes / 1e6


def _instrument(text: str) -> str:
    """The program with ``(.)`` at the end of each line (before a ``;`` comment), so that every
    line LinuxCNC executes makes a canonical call; and one more such line at the end, read when
    the program has no M2/M30/%. Lines with ``%``, unbalanced parentheses or near LinuxCNC's
    length limit are left as they are."""
    lines = text.split("\n")
    simple = (
        ";" not in text
        and "%" not in text
        and text.count("(") == text.count(")")
        and max(map(len, lines)) < _MAX_LINE
    )
    if simple and "\n(" not in text and not text.startswith("("):
        body = (_MARK + "\n").join(lines) + _MARK
    else:
        body = "\n".join(map(_mark_line, lines))
    return body + "\n" + _MARK + "\n"


def _mark_line(line: str) -> str:
    if line.lstrip().startswith("%") or len(line) >= _MAX_LINE:
        return line
    if line.count("(") != line.count(")") or re.search(r"\([^)]*\(", line):
        return line  # LinuxCNC reports these itself; a mark would change its message
    depth, cut = 0, len(line)
    for i, ch in enumerate(line):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif ch == ";" and depth == 0:
            cut = i
            break
    return line[:cut] + _MARK + line[cut:]


def read_linuxcnc(
    text: str,
    *,
    source: str | None = None,
    folder: str | PathLike | None = None,
    units: str = "mm",
    block_delete: bool = False,
    tool_table: ToolTable | None = None,
    g28_reference_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    g30_reference_mm: tuple[float, float, float] = (0.0, 0.0, 0.0),
    max_moves: int = MAX_MOVES,
    timeout_s: float | None = None,
) -> Toolpath:
    """Read a program through LinuxCNC's interpreter.

    Parameters
    ----------
    text : str
        The program.
    source : str, optional
        File name used in error messages.
    folder : path, optional
        Where subroutine files (``o<name> call`` -> ``name.ngc``) are looked up: the program's
        folder (default: the current directory).
    units : {"mm", "inch"}
        Units in force before the program's own G20/G21.
    block_delete : bool
        Whether the block-delete switch is on.
    tool_table : ToolTable, optional
        The machine's LinuxCNC tool table (:func:`nctwin.machine.read_tool_table`) for tool
        lengths (G43) and diameters (G41/G42 D); default :data:`LINUXCNC_TOOL_TABLE`, the table
        of nctwin's own LinuxCNC configuration.
    g28_reference_mm, g30_reference_mm : tuple of 3 floats
        The G28 and G30 reference points in machine coordinates (mm), written to the
        interpreter's parameters #5161-#5163 and #5181-#5183; default zero, as LinuxCNC's.
    max_moves : int
        The reader stops with an error after this many canonical moves.
    timeout_s : float, optional
        Wall-clock limit; default :func:`timeout_for` the text's size. The interpreter is killed
        when it is reached.

    Returns
    -------
    Toolpath

    Raises
    ------
    GCodeError
        ``file:line: reason`` for anything LinuxCNC refuses, what this reader refuses, a limit
        reached, or LinuxCNC missing.
    ValueError
        For a bad keyword argument.
    """
    if units not in ("mm", "inch"):
        raise ValueError(f"units must be 'mm' or 'inch', got {units!r}")
    references = {
        first: _point_mm(name, point).tolist()
        for first, name, point in (
            (5161, "g28_reference_mm", g28_reference_mm),
            (5181, "g30_reference_mm", g30_reference_mm),
        )
    }
    check_int("max_moves", max_moves, 1)
    if timeout_s is None:
        timeout_s = timeout_for(len(text.encode("utf-8", "replace")))
    check_range("timeout_s", timeout_s, 0.0, low_open=True, high_open=True)
    name = source or "<string>"
    if "\0" in text:
        line = text.count("\n", 0, text.index("\0")) + 1
        raise GCodeError(line, "", "binary data (NUL bytes), not a G-code program", source)
    long = [i for i, ln in enumerate(text.split("\n")) if len(ln) > LINUXCNC_MAX_LINE]
    if long:  # LinuxCNC reports the line after it, or none if it is the last
        n = len(text.split("\n")[long[0]])
        raise GCodeError(
            long[0] + 1, "", f"a line of {n} characters: LinuxCNC reads at most "
            f"{LINUXCNC_MAX_LINE} (Command too long)", source,
        )  # fmt: skip
    if not interpreter_available():
        raise GCodeError(0, "", _NOT_INSTALLED, source)
    spindle = spindle_tool_line(tool_table, text)
    if spindle is not None:
        raise GCodeError(
            spindle, "", "G41/G42 without D and G43 without H take the size of the tool M61"
            " put in the spindle, which LinuxCNC's preview module (this reader) never sees: name"
            " the tool (G41 D<n>, G43 H<n>)", source,
        )  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="nctwin-rs274-") as tmp:
        program = Path(tmp) / "program.ngc"
        program.write_text(_instrument(text.replace("\r\n", "\n").replace("\r", "\n")))
        given = LINUXCNC_TOOL_TABLE if tool_table is None else tool_table.text
        table = Path(tmp) / "tool.tbl"
        table.write_text(complete_tool_table(given, text))
        job = {
            "program": str(program),
            "tool_table": str(table.resolve()),
            "unitcode": "G20" if units == "inch" else "G21",
            "initcode": f"G64 P{PATH_SENTINEL:.0f} Q{PATH_SENTINEL:.0f}",
            "block_delete": bool(block_delete),
            "parameters": [
                [first + a, v] for first, point in references.items() for a, v in enumerate(point)
            ],
            "max_moves": max_moves,
            "deadline_s": max(timeout_s - _CHILD_MARGIN_S, 0.5 * timeout_s),
            "home": tmp,
            "out": str(Path(tmp) / "out.bin"),
        }
        raw = _run_child(job, folder, timeout_s, source)
    header, moves, events, modal = _tables(raw)
    _raise_stop(header, events, source, max_moves, timeout_s)
    error = header["error"]
    if error is not None and error[1] != _EOF_MESSAGE:
        raise GCodeError(
            _error_line(error, events), "", _reason(error[1], name, program, folder), source
        )
    return _toolpath(moves, events, modal, source)


def _error_line(error: list, events: np.ndarray) -> int:
    """The line of LinuxCNC's error. The module returns its last reported line, plus one for an
    error in reading a line, after reporting the line the interpreter stopped on (the read
    error's line too): that last report is the line. A missing subroutine is searched for to
    the end of the file; its message names the line of the call."""
    called = re.search(r"from line: (\d+)", error[1])
    if called:
        return int(called.group(1))
    return int(events[-1, 1]) if len(events) else int(error[0])


def _run_child(job: dict, folder, timeout_s: float, source: str | None) -> bytes:
    """Run the child under the time limit; return its output file's bytes."""
    env = {"PATH": "/usr/bin:/bin", "HOME": job["home"], "LANG": "C.UTF-8"}
    cwd = str(folder) if folder is not None else None
    try:
        done = subprocess.run(
            [LINUXCNC_PYTHON, "-I", str(_CHILD), json.dumps(job)],
            capture_output=True,
            timeout=timeout_s,
            cwd=cwd,
            env=env,
        )
    except subprocess.TimeoutExpired:
        raise GCodeError(
            0,
            "",
            f"LinuxCNC's interpreter did not finish within {timeout_s:g} s and was stopped"
            f" (limit {TIMEOUT_BASE_S:g} s + {TIMEOUT_S_PER_MB:g} s per MB of program):"
            " an endless loop?",
            source,
        ) from None
    out = Path(job["out"])
    if done.returncode != 0 or not out.exists():
        tail = (done.stderr or b"").decode("utf-8", "replace").strip().splitlines()[-1:]
        why = f"exit code {done.returncode}" + (f": {tail[0]}" if tail else "")
        raise GCodeError(0, "", f"LinuxCNC's interpreter failed ({why})", source)
    return out.read_bytes()


def _tables(raw: bytes):
    """The child's header and its tables: moves (M, 7), events (E, 14: the moves before each,
    then line, path mode, P, Q, units, feed mode, motion mode, the line's non-modal code, and
    the stop, spindle, tool-change, mist and flood M-codes of :mod:`._task_words`) and modal
    records (K, 15)."""
    cut = raw.index(b"\n")
    header = json.loads(raw[:cut])
    sizes = header["bytes"]
    if not sizes:
        return header, np.zeros((0, _N_MOVE)), np.zeros((0, _N_EVENT)), np.zeros((0, _N_MODAL))
    bounds = np.cumsum([cut + 1, *sizes])
    view = memoryview(raw)  # no copies: the arrays are views of the child's bytes
    part = [view[a:b] for a, b in itertools.pairwise(bounds)]
    moves = np.frombuffer(part[0], np.float64).reshape(-1, _N_MOVE)
    n_g, n_m = header["codes"] or (0, 0)
    state = np.dtype([("settings", "<f8", 5), ("gcodes", "<i4", n_g), ("mcodes", "<i4", n_m)])
    st = np.frombuffer(part[2], state)
    g = st["gcodes"].reshape(len(st), n_g)
    events = (
        np.column_stack(
            [
                np.frombuffer(part[1], np.float64),
                g[:, 0],  # line
                g[:, 11],  # path mode
                st["settings"][:, 3:5],  # G64 P, Q
                g[:, 5],  # units
                g[:, 7],  # feed mode
                g[:, 1],  # motion mode
                g[:, 2],  # the line's code of the non-modal group (G4, G28, G92, ...), or -1
                st["mcodes"][:, M_COLUMNS],
            ]
        )
        if len(st)
        else np.zeros((0, _N_EVENT))
    )
    modal = np.frombuffer(part[3], np.float64).reshape(-1, _N_MODAL)
    return header, moves, events, modal


def _raise_stop(header, events, source, max_moves, timeout_s) -> None:
    """Raise the stop the child reported (a limit, a refused call, a failure), if any, at the
    last line LinuxCNC reported."""
    stop = header["stop"]
    if stop is None:
        return
    kind, line = stop[0], int(events[-1, 1]) if len(events) else 0
    if kind == "moves":
        reason = (
            f"more than {max_moves} canonical moves (the limit, max_moves): an endless"
            " O-word loop? LinuxCNC's interpreter was stopped here"
        )
    elif kind == "time":
        reason = (
            f"LinuxCNC's interpreter reached its time limit of {timeout_s:g} s"
            f" ({TIMEOUT_BASE_S:g} s + {TIMEOUT_S_PER_MB:g} s per MB of program) and was"
            " stopped after this line: an endless O-word loop?"
        )
    elif kind == "refused":
        reason = f"{stop[1]}: not read (its path depends on the spindle or a probe)"
    else:
        reason = f"LinuxCNC's interpreter failed: {stop[1]}"
    raise GCodeError(line, "", reason, source)


def _reason(message: str, name: str, program: Path, folder) -> str:
    """LinuxCNC's message, with the instrumented copy's name replaced by the program's, and
    what it means where it is terse."""
    message = message.replace(str(program), name).replace(program.name, name)
    sub = re.search(r"seeking o-word: o<([^>]*)>", message)
    if sub:
        where = Path(folder) if folder is not None else Path.cwd()
        message = (
            f"subroutine o<{sub.group(1)}> not found: no file {sub.group(1)}.ngc in {where}"
            f" and no o<{sub.group(1)}> sub in the program (LinuxCNC: {message})"
        )
    bad = re.match(r"Bad character '([abcuvw])' used", message)
    if bad:
        message += (
            f": the {bad.group(1).upper()} axis is not on this machine (nctwin's LinuxCNC"
            " machines have the axes X, Y and Z only)"
        )
    if re.match(r"Requested tool \d+ not found in the tool table", message):
        message += (
            ", and the program's cutter compensation or length offset (G41, G42, G43) needs"
            " the sizes: give the machine's LinuxCNC tool table (tool_table=, nctwin"
            " --tool-table FILE, a profile's tool_table); nctwin's own holds T1 only, of"
            " diameter 0"
        )
    return message


# ---------------------------------------------------------------------------------------------
# Canonical moves -> Toolpath
# ---------------------------------------------------------------------------------------------
def _after_states(events: np.ndarray) -> np.ndarray:
    """The state each event's moves run in: the one the next event reports (see the module
    docstring), the last event's own for the last one. Shape (E, 13)."""
    if not len(events):
        return events
    return np.vstack([events[1:], events[-1:]])


def _path_control(after: np.ndarray):
    """Path mode, P and Q (mm) per event from the after-states.

    At a change of units the interpreter re-reads P and Q from the canon
    (``convert_length_units``), where LinuxCNC's keeps them in machine units, so they stay the
    same length; the preview module answers a constant 0.1 instead. A state whose units changed
    with P = Q = 0.1 keeps the previous state's P and Q (so ``G20 G64 P0.1`` on one line is read
    as ``G20``, the one case this cannot tell apart).
    """
    code, units = after[:, 1], after[:, 4]
    raw = after[:, 1:5]
    start = np.r_[True, (raw[1:] != raw[:-1]).any(axis=1)]  # runs of one state
    new_units = np.r_[False, units[1:] != units[:-1]]
    reread = new_units & (after[:, 2] == 0.1) & (after[:, 3] == 0.1)
    reread = reread[np.flatnonzero(start)][np.cumsum(start) - 1]  # the whole run
    keep = np.maximum.accumulate(np.where(reread, 0, np.arange(len(code))))
    tol, naive = after[keep, 2], after[keep, 3]
    default = (code == 640) & (tol == PATH_SENTINEL) & (naive == PATH_SENTINEL)
    mode = np.select(
        [default, code == 640, code == 610, code == 611],
        [PathMode.DEFAULT, PathMode.BLEND, PathMode.EXACT_PATH, PathMode.EXACT_STOP],
        PathMode.DEFAULT,
    ).astype(np.int8)
    # P and Q stay in the units of the G64 that set them: those in force where they changed
    key = np.stack([code, tol, naive], axis=1)
    changed = np.r_[True, (key[1:] != key[:-1]).any(axis=1)]
    idx = np.maximum.accumulate(np.where(changed, keep, 0))
    scale = np.where(units[idx] == 200, MM_PER_INCH, 1.0)
    blend = mode == PathMode.BLEND
    return mode, np.where(blend, tol * scale, np.nan), np.where(blend, naive * scale, np.nan)


def _refuse_modes(kind, ev, after, lines, source) -> None:
    """Spindle-synchronised motion and feed modes other than G94 cannot be a Toolpath."""
    motion, feed_mode = after[ev, 6], after[ev, 5]
    moving = kind != 4
    bad = moving & np.isin(motion, list(_SPINDLE_SYNC))
    if bad.any():
        k = int(np.argmax(bad))
        code = _SPINDLE_SYNC[int(motion[k])]
        raise GCodeError(
            int(lines[k]), "", f"{code} is spindle-synchronised motion: not read", source
        )
    bad = moving & (kind != 0) & np.isin(feed_mode, list(_FEED_MODES))
    if bad.any():
        k = int(np.argmax(bad))
        what = _FEED_MODES[int(feed_mode[k])]
        raise GCodeError(
            int(lines[k]), "", f"{what} is not read: a Toolpath's feeds are mm/s", source
        )


def _toolpath(moves, events, modal, source) -> Toolpath:
    """The canonical moves as a Toolpath (mm, mm/s, machine coordinates)."""
    if not len(moves):
        return Toolpath.empty()
    moves, events, modal = task_splines(moves, events, modal, source)
    words = task_words((events[:, 0] / _N_MOVE).astype(np.int64), events[:, 1].astype(np.int64),
                       events[:, 9:])  # fmt: skip
    kind = moves[:, 0].astype(np.int8)
    index = np.arange(len(moves))
    # the event and modal record of each move: the last one made before it
    # (the child counts the moves made before an event as float64 values, 7 per move)
    ev = np.searchsorted(events[:, 0] / _N_MOVE, index, side="right") - 1
    mod = modal[np.searchsorted(modal[:, 0] / _N_MOVE, index, side="right") - 1, 1:]
    events = events[:, 1:]
    after = _after_states(events)
    lines = events[ev, 0].astype(np.int64)
    _refuse_modes(kind, ev, after, lines, source)
    no_feed = ((kind == 1) | (kind == 2)) & ~(mod[:, 0] > 0)
    if no_feed.any():  # the preview module runs it; LinuxCNC's task refuses it
        k = int(np.argmax(no_feed))
        raise GCodeError(
            int(lines[k]), "", "feed move with no feed rate set (F): LinuxCNC refuses it (Cannot"
            " do G1 with zero feed rate)", source,
        )  # fmt: skip
    n = len(moves)
    arc = kind == 2
    plane = _PLANE_OF_CANON[mod[:, 1].astype(np.int64)]
    rot_deg = mod[:, 11]
    if (arc & (plane != Plane.XY) & (rot_deg != 0)).any():
        k = int(np.argmax(arc & (plane != Plane.XY) & (rot_deg != 0)))
        raise GCodeError(
            int(lines[k]), "", "an arc outside the XY plane under an XY rotation (G10 L2 R)"
            " is not a Toolpath arc: not read", source,
        )  # fmt: skip

    # points in program coordinates (in): lines as given, arcs from their plane's order
    end = moves[:, 1:4].copy()
    center = np.full((n, 3), np.nan)
    ai = np.flatnonzero(arc)
    ax = PLANE_AXES[plane[ai]]
    end[ai[:, None], ax] = moves[ai][:, 1:4]
    center[ai, ax[:, 0]] = moves[ai, 4]
    center[ai, ax[:, 1]] = moves[ai, 5]

    # machine coordinates as LinuxCNC's canon makes them, then mm
    def to_machine(p):
        q = p + mod[:, 2:5]
        t = np.deg2rad(rot_deg)
        x, y = q[:, 0].copy(), q[:, 1].copy()
        turned = rot_deg != 0
        q[turned, 0] = (x * np.cos(t) - y * np.sin(t))[turned]
        q[turned, 1] = (x * np.sin(t) + y * np.cos(t))[turned]
        return (q + mod[:, 5:8] + mod[:, 8:11]) * MM_PER_INCH

    dwell = kind == 4
    end = to_machine(end)
    center = to_machine(center)
    # a dwell stays where the previous move ended; the tool starts at machine zero
    last = np.where(dwell, -1, np.arange(n))
    np.maximum.accumulate(last, out=last)
    end = np.where((last >= 0)[:, None], end[np.maximum(last, 0)], 0.0)
    start = np.vstack([np.zeros(3), end[:-1]])
    center[ai, ax[:, 2]] = start[ai, ax[:, 2]]
    out_kind = np.where(
        arc, np.where(moves[:, 6] > 0, MotionKind.ARC_CCW, MotionKind.ARC_CW), kind
    ).astype(np.int8)
    turns = np.where(arc, np.abs(moves[:, 6]), 1).astype(np.int64)
    mode, blend, naive = _path_control(after)
    mode, blend, naive = mode[ev], blend[ev], naive[ev]
    exact = _cycle_exact(kind, ev, after, start, end, plane)
    mode[exact], blend[exact], naive[exact] = PathMode.EXACT_PATH, np.nan, np.nan
    fields = {
        "start_mm": start,
        "end_mm": end,
        "kind": out_kind,
        # G94 sets LinuxCNC's feed to 0 (convert_feed_mode), at which only rapids and dwells
        # run: the Toolpath's "no feed set", NaN
        "feed_mm_s": np.where(mod[:, 0] == 0, np.nan, mod[:, 0] * MM_PER_INCH / 60.0),
        "center_mm": center,
        "plane": plane,
        "dwell_s": np.where(dwell, moves[:, 1], 0.0),
        "line": lines,
        "path_mode": mode,
        "blend_tol_mm": blend,
        "naive_tol_mm": naive,
    }
    if (turns > 1).any():
        fields = _expand_turns(fields, turns)
    first_block = np.concatenate([[0], np.cumsum(turns)])  # a full turn is a block
    offset = _offset_events(modal, events[:, 0].astype(np.int64))
    events = np.zeros(len(words[0]) + len(offset[0]), EVENT_DTYPE)
    events["block"] = first_block[np.concatenate([words[0], offset[0]])]
    events["line"] = np.concatenate([words[1], offset[1]])
    events["word"] = ["M"] * len(words[0]) + ["G"] * len(offset[0])
    events["value"] = np.concatenate([words[2], offset[2]])
    # in the order they ran (a subroutine's lines repeat): the M words, then the offsets
    events = events[np.argsort(events["block"], kind="stable")]
    return Toolpath(**fields, events=events)


def _offset_events(modal: np.ndarray, line: np.ndarray):
    """The offsets LinuxCNC's task waits for the motion to set
    (:data:`~nctwin.toolpath.OFFSET_EVENTS`), one per line that sets any, from the modal records
    (K, 15) and the events' lines (E,): the moves made before each (it precedes the next), its
    line and its value."""
    cause = modal[:, 13].astype(np.int64)
    rows = np.flatnonzero(np.isin(cause, list(_OFFSET_CAUSES)) & (modal[:, 14] > 0))
    at = line[modal[rows, 14].astype(np.int64) - 1]  # the line running
    rows, at = rows[at > 0], at[at > 0]  # line 0: the start code, not the program
    moves = (modal[rows, 0] / _N_MOVE).astype(np.int64)
    # a line's first call (G55 sets the G5x and G92 offsets and the rotation: one event)
    first = np.ones(len(rows), bool)
    first[1:] = (moves[1:] != moves[:-1]) | (at[1:] != at[:-1])
    value = np.array([_OFFSET_CAUSES[c] for c in cause[rows[first]]], float)
    return moves[first], at[first], value


def _cycle_exact(kind, ev, after, start, end, plane) -> np.ndarray:
    """Moves and dwells of canned cycles, which LinuxCNC runs in exact-path mode: all but a first
    rapid straight to R from below it, made before the switch (``convert_cycle``).

    That rapid keeps the tool's place in the plane, and the move after it is the rapid over the
    hole at R's height. Without it, a first move that keeps the place in the plane (the hole
    straight below) is followed by a rapid down to R or by a feed; the one exception, a G87 back
    boring cycle under the tool with the tool exactly at R, is taken as the rapid to R. A G28
    or G30 line in a cycle's motion mode makes no cycle: its rapids keep the path mode in force.
    """
    cycle = np.isin(after[ev, 6], _CYCLES) & ~np.isin(after[ev, 7], _HOMES)
    if not cycle.any():
        return cycle
    first = np.r_[True, ev[1:] != ev[:-1]]
    ax = PLANE_AXES[plane]
    rows = np.arange(len(kind))
    d = end - start
    eps = 1e-9  # mm: the interpreter's position and the canon's differ by rounding
    still = (np.abs(d[rows, ax[:, 0]]) <= eps) & (np.abs(d[rows, ax[:, 1]]) <= eps)
    level_rapid = (kind == 0) & (np.abs(d[rows, ax[:, 2]]) <= eps)
    next_level_rapid = np.r_[level_rapid[1:] & ~first[1:], False]
    pre = first & (kind == 0) & still & next_level_rapid
    return cycle & ~pre


def _expand_turns(f: dict, turns: np.ndarray) -> dict:
    """An arc of T turns as T-1 full turns then the arc, each with its share of the travel
    along the plane's normal (as the native reader reads ``G2/G3 P``)."""
    rep = np.repeat(np.arange(len(turns)), turns)
    j = np.arange(len(rep)) - np.repeat(np.cumsum(turns) - turns, turns)  # turn of each row
    out = {k: v[rep].copy() for k, v in f.items()}
    multi = np.flatnonzero(turns[rep] > 1)
    i, jm = rep[multi], j[multi]
    s, e, c, pl = f["start_mm"][i], f["end_mm"][i], f["center_mm"][i], f["plane"][i]
    ccw = f["kind"][i] == MotionKind.ARC_CCW
    ax = PLANE_AXES[pl]
    r = np.arange(len(i))
    sweep = np.abs(arc_sweep(s, e, c, pl, ccw))
    t = turns[i]
    share = 2.0 * np.pi / (sweep + 2.0 * np.pi * (t - 1))
    sn = s[r, ax[:, 2]]
    dn = e[r, ax[:, 2]] - sn
    inner = jm < t - 1
    new_end = np.where(inner[:, None], s, e)
    new_end[r, ax[:, 2]] = np.where(inner, sn + dn * share * (jm + 1), e[r, ax[:, 2]])
    new_start = s.copy()
    new_start[r, ax[:, 2]] = sn + dn * share * jm
    c = c.copy()
    c[r, ax[:, 2]] = new_start[r, ax[:, 2]]
    out["start_mm"][multi], out["end_mm"][multi], out["center_mm"][multi] = new_start, new_end, c
    return out
