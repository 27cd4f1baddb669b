"""Choosing the reader: the native one, LinuxCNC's interpreter, or the native one with LinuxCNC's
for what only it reads (``reader="auto"``); and telling the caller which one read a program."""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike
from pathlib import Path

from ..toolpath import Toolpath
from ._errors import _NEEDS_LINUXCNC, GCodeError
from ._fanuc import check_dialect
from ._interp import interpreter_available, read_linuxcnc
from ._reader import parse as parse_native
from ._reader import read_text
from ._tools import tool_table_of

#: The values of ``reader``.
READERS = ("native", "linuxcnc", "auto")
#: Keyword arguments only the native reader takes (LinuxCNC has its own rules for them).
_NATIVE_ONLY = ("dwell_p_unit", "dialect", "start_mm", "arc_tol_mm", "arc_tol_rel")
#: Keyword arguments only LinuxCNC's interpreter takes.
_LINUXCNC_ONLY = ("max_moves", "timeout_s", "folder")
_NATIVE_DEFAULTS = {
    "dwell_p_unit": "s",
    "dialect": "rs274ngc",
    "start_mm": (0.0, 0.0, 0.0),
    "arc_tol_mm": 0.005,
    "arc_tol_rel": 0.001,
}


@dataclass(frozen=True)
class ReadResult:
    """A program read, and which reader read it.

    Parameters
    ----------
    toolpath : Toolpath
    reader : {"native", "linuxcnc"}
        The native reader, or LinuxCNC's interpreter.
    """

    toolpath: Toolpath
    reader: str


def _check_reader(reader: str) -> None:
    if reader not in READERS:
        allowed = ", ".join(repr(r) for r in READERS)
        raise ValueError(f"reader = {reader!r} is not allowed: allowed {allowed}")


def _needs_interpreter(err: GCodeError) -> bool:
    """Whether the native reader refused a construct only LinuxCNC's interpreter reads."""
    return any(_NEEDS_LINUXCNC in e.reason for e in err.errors)


def read(text: str, *, reader: str = "auto", **kwargs) -> ReadResult:
    """Read a part program with the reader asked for; say which one read it.

    Parameters
    ----------
    text : str
        The program.
    reader : {"auto", "native", "linuxcnc"}
        ``"native"``: :func:`nctwin.gcode.parse`'s own reader (numpy, the RS274/NGC subset of a
        CAM post). ``"linuxcnc"``: LinuxCNC's rs274ngc interpreter, the whole language
        (:func:`read_linuxcnc`). ``"auto"``: the native reader, and where it refuses a program,
        the interpreter if it is installed (it reads what the native reader leaves to it:
        O-words, parameters, cutter compensation, and words such as ``M66 P`` the native reader
        does not know). Where both refuse, the error is the native reader's, which lists every
        error of the program, unless it names a construct only the interpreter reads: then the
        interpreter's, which read it.
    **kwargs
        ``source``, ``units``, ``block_delete``, ``tool_table`` (the machine's LinuxCNC tool
        table: a :class:`~nctwin.machine.ToolTable`, such as a profile's, or a ``.tbl`` file's
        path; default nctwin's own, tool 1 of size 0; the native reader takes the ``G43 H``
        lengths from it), ``g28_reference_mm`` and ``g30_reference_mm``
        (the points G28 and G30 return to, LinuxCNC's parameters #5161-#5163 and #5181-#5183:
        X, Y, Z in mm in the Toolpath's coordinates, which a G92 offset does not move; default
        zero, as in LinuxCNC) for both readers; ``dwell_p_unit``, ``dialect`` (``"rs274ngc"``
        or ``"fanuc"``), ``start_mm``, ``arc_tol_mm``, ``arc_tol_rel`` for the native reader
        only (with ``reader="linuxcnc"`` only their defaults are allowed; with ``"auto"`` a
        non-default one, such as ``dialect="fanuc"``, keeps the program on the native reader);
        ``max_moves``, ``timeout_s``, ``folder`` for the interpreter only.

    Returns
    -------
    ReadResult

    Raises
    ------
    GCodeError
        ``file:line: reason`` for a program that cannot be read.
    ValueError
        For a bad ``reader`` or keyword argument, naming it, its value and what is allowed;
        ``file:line: reason`` for a tool table LinuxCNC would not read.
    """
    _check_reader(reader)
    check_dialect(kwargs.get("dialect", "rs274ngc"))
    if "tool_table" in kwargs:
        kwargs["tool_table"] = tool_table_of(kwargs["tool_table"], kwargs.get("source"))
    native = {k: v for k, v in kwargs.items() if k not in _LINUXCNC_ONLY}
    interp = {k: v for k, v in kwargs.items() if k not in _NATIVE_ONLY}
    changed = [k for k in _NATIVE_ONLY if k in kwargs and _differs(kwargs[k], k)]
    given = [k for k in _LINUXCNC_ONLY if k in kwargs and k != "folder"]
    if reader == "native" and given:
        raise ValueError(
            f"{given[0]} = {kwargs[given[0]]!r} is not allowed with reader='native': it is for"
            " LinuxCNC's interpreter (reader='linuxcnc' or 'auto')"
        )
    if reader == "linuxcnc":
        if changed:
            k = changed[0]
            raise ValueError(
                f"{k} = {kwargs[k]!r} is not allowed with reader='linuxcnc': allowed its"
                f" default {_NATIVE_DEFAULTS[k]!r} (LinuxCNC has its own rules)"
            )
        return ReadResult(read_linuxcnc(text, **interp), "linuxcnc")
    try:
        return ReadResult(parse_native(text, **native), "native")
    except GCodeError as err:
        if reader == "native" or changed or not interpreter_available():
            raise
        native_error = err
    try:
        return ReadResult(read_linuxcnc(text, **interp), "linuxcnc")
    except GCodeError:
        if _needs_interpreter(native_error):
            raise
        raise native_error from None


def _differs(value, name: str) -> bool:
    default = _NATIVE_DEFAULTS[name]
    if value is None and name == "dwell_p_unit":  # the dialect's: "s" in the default one
        return False
    if name == "start_mm":
        return tuple(float(v) for v in value) != default
    return value != default


def read_file(path: str | PathLike, *, reader: str = "auto", **kwargs) -> ReadResult:
    """Read a program from a file; see :func:`read`. Subroutine files are looked up in the
    program's folder."""
    _check_reader(reader)
    text, name = read_text(path)
    kwargs.setdefault("folder", Path(path).resolve().parent)
    return read(text, reader=reader, source=name, **kwargs)


def parse(text: str, *, reader: str = "auto", **kwargs) -> Toolpath:
    """Read a part program into a :class:`~nctwin.toolpath.Toolpath`; :func:`read` without the
    name of the reader (see it for ``reader`` and the keyword arguments)."""
    return read(text, reader=reader, **kwargs).toolpath


def parse_file(path: str | PathLike, *, reader: str = "auto", **kwargs) -> Toolpath:
    """Read a program from a file; :func:`read_file` without the name of the reader."""
    return read_file(path, reader=reader, **kwargs).toolpath
