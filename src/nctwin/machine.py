"""Machine profiles: what a machine tool physically is, how its controls move it, and which
estimate to trust, in one file (``data/machines/*.toml``).

A profile's file has one ``[machine]`` table (:class:`Machine`: axis limits, rapid and maximum
feed), one ``[control.<kind>]`` table per control model it is described for
(:data:`nctwin.controls.CONTROLS`: ``fir``, ``accdec``, ``fanuc``, ``planner``,
``sequence``), and three
top-level keys: ``default_method``, the method ``nctwin estimate`` uses when none is named,
``recordings``, the shipped recordings of this machine the learned methods train on (if any),
``dialect``, the G-code dialect ``nctwin estimate`` and ``nctwin simulate`` read its
programs in (:data:`DIALECTS`; default ``"rs274ngc"``), and ``tool_table``, the machine's
LinuxCNC tool table (:class:`ToolTable`), a ``.tbl`` file named relative to the profile's
folder or, failing that, to the shipped profiles' (default: none, the readers' own table of
tool 1 with size 0).
No key is written twice, and an unknown or misspelt key is refused with the file, the table and
the key. Values fitted to recordings are written into the file by a command
(:func:`write_control`), never looked up elsewhere at run time, so a copy of a profile under
another name is the same machine.

::

    default_method = "cam"
    [machine]
    name = "generic_mill"
    axis_max_velocity_mm_s = [500.0, 500.0, 500.0]
    ...
    [control.fir]
    t1_s = 0.06
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import MISSING, dataclass, fields
from datetime import date
from pathlib import Path

from .checks import check_choice, check_range
from .controls import (
    CONTROLS,
    AccDecControl,
    Control,
    FanucControl,
    FirControl,
    PlannerControl,
    SequenceControl,
)
from .paths import data_dir

__all__ = [
    "DEFAULT_MACHINE",
    "DIALECTS",
    "METHOD_CONTROLS",
    "Machine",
    "Profile",
    "ToolTable",
    "available_machines",
    "load_machine",
    "load_profile",
    "profile_path",
    "read_tool_table",
    "write_control",
]

#: Profile used when none is named.
DEFAULT_MACHINE = "generic_mill"

#: G-code dialects (a profile's ``dialect``, :func:`nctwin.gcode.parse`'s ``dialect``): LinuxCNC
#: 2.9's RS274/NGC, or a Fanuc milling control's.
DIALECTS = ("rs274ngc", "fanuc")

#: The control model each estimate method runs on (None: the machine alone).
METHOD_CONTROLS: dict[str, str | None] = {
    "cam": None,
    "kernel": "fir",
    "block_overlap": "accdec",
    "planner": "planner",
    "bilstm": "planner",
    "axis_nn": "planner",
}

_XYZ = tuple[float, float, float]


@dataclass(frozen=True)
class Machine:
    """What a 3-axis machine tool physically is: its limits, apart from any control.

    Parameters
    ----------
    name : str
        Short name (a shipped profile's name; the file's stem where the file gives none).
    description : str
        What the profile stands for.
    axis_max_velocity_mm_s : tuple of 3 floats
        Velocity limit of X, Y, Z, each > 0.
    axis_max_acceleration_mm_s2 : tuple of 3 floats
        Acceleration limit of X, Y, Z, each > 0. The FIR kernel, the planner and the learned
        features keep to it (:func:`nctwin.limits.path_limits`); the acc/dec controls
        (``accdec``, ``fanuc``) accelerate as their time constants say, which a profile sets
        within it.
    axis_max_jerk_mm_s3 : tuple of 3 floats
        Jerk limit of X, Y, Z, each > 0; ``inf`` for a machine without one.
    rapid_feed_mm_s : float
        Path feed of rapid (G0) moves, > 0.
    max_feed_mm_s : float
        Highest programmable feed, > 0; a larger F is clamped to it.
    """

    name: str
    description: str
    axis_max_velocity_mm_s: _XYZ
    axis_max_acceleration_mm_s2: _XYZ
    axis_max_jerk_mm_s3: _XYZ
    rapid_feed_mm_s: float
    max_feed_mm_s: float

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"name = {self.name!r} is out of range: allowed a non-empty string")
        if not isinstance(self.description, str):
            raise ValueError(f"description = {self.description!r} is out of range: allowed text")
        for name in ("axis_max_velocity_mm_s", "axis_max_acceleration_mm_s2"):
            xyz = check_range(name, getattr(self, name), 0.0, math.inf, low_open=True,
                              high_open=True, xyz=True)  # fmt: skip
            object.__setattr__(self, name, xyz)
        jerk = check_range("axis_max_jerk_mm_s3", self.axis_max_jerk_mm_s3, 0.0, math.inf,
                           low_open=True, high_open=True, allow_inf=True, xyz=True)  # fmt: skip
        object.__setattr__(self, "axis_max_jerk_mm_s3", jerk)
        check_range(
            "rapid_feed_mm_s", self.rapid_feed_mm_s, 0.0, math.inf, low_open=True, high_open=True
        )
        check_range(
            "max_feed_mm_s", self.max_feed_mm_s, 0.0, math.inf, low_open=True, high_open=True
        )


#: The words of a LinuxCNC tool table's line (tooldata.cc): tool, pocket, offsets, diameter,
#: front and back angles, orientation.
_TABLE_WORD = re.compile(r"([TPXYZABCUVWDIJQ])\s*([-+]?(?:\d+\.?\d*|\.\d+))\s*", re.IGNORECASE)


@dataclass(frozen=True)
class ToolTable:
    """A LinuxCNC tool table (``.tbl``): each line ``T<n> P<pocket> X.. Y.. Z.. D.. ;comment``,
    lengths in the machine's units (mm on nctwin's LinuxCNC machines).

    Parameters
    ----------
    text : str
        The table as LinuxCNC reads it (written to a LinuxCNC instance's ``tool.tbl``).
    tools : tuple of int
        Tool numbers, shape (N,), in the table's order.
    offset_mm : tuple of (float, float, float)
        X, Y, Z offsets of each tool (what ``G43 H<n>`` adds), shape (N, 3).
    diameter_mm : tuple of float
        Diameter of each tool (what cutter compensation ``G41``/``G42 D<n>`` offsets by half
        of), shape (N,).
    """

    text: str
    tools: tuple[int, ...]
    offset_mm: tuple[_XYZ, ...]
    diameter_mm: tuple[float, ...]

    def offset_of(self, tool: int) -> _XYZ | None:
        """The X, Y, Z offsets of ``tool`` (mm); None if the table lacks it. Tool 0 (no tool)
        has none."""
        if tool == 0:
            return (0.0, 0.0, 0.0)
        return self.offset_mm[self.tools.index(tool)] if tool in self.tools else None


def read_tool_table(text: str, source: str = "tool.tbl") -> ToolTable:
    """Read a LinuxCNC tool table's text (see :class:`ToolTable`).

    Raises
    ------
    ValueError
        One line, ``source:line: reason``, for a line LinuxCNC would not read (a word it does
        not know, a number it cannot read, no T word, a tool listed twice).
    """
    tools, offsets, diameters = [], [], []
    for i, line in enumerate(text.splitlines(), 1):
        body = line.split(";", 1)[0].strip()
        if not body:
            continue
        words: dict[str, float] = {}
        at = 0
        while at < len(body):
            m = _TABLE_WORD.match(body, at)
            if m is None:
                raise ValueError(
                    f"{source}:{i}: cannot read {body[at:].split()[0]!r}: a tool"
                    " table line is T<n> P<pocket> X Y Z ... D<diameter> ;comment"
                )
            letter = m.group(1).upper()
            if letter in words:
                raise ValueError(f"{source}:{i}: {letter} given twice")
            words[letter], at = float(m.group(2)), m.end()
        tool = words.get("T")
        if tool is None or tool != int(tool) or tool < 1:
            raise ValueError(f"{source}:{i}: no tool number (T<n>, a whole number >= 1)")
        if int(tool) in tools:
            raise ValueError(f"{source}:{i}: tool {int(tool)} listed twice")
        if words.get("D", 0.0) < 0:
            raise ValueError(f"{source}:{i}: diameter D must be >= 0")
        tools.append(int(tool))
        offsets.append(tuple(words.get(a, 0.0) for a in "XYZ"))
        diameters.append(words.get("D", 0.0))
    return ToolTable(text, tuple(tools), tuple(offsets), tuple(diameters))


@dataclass(frozen=True)
class Profile:
    """A machine profile: the machine, its controls, and the profile's default method.

    Parameters
    ----------
    machine : Machine
    fir, accdec, fanuc, planner, sequence : control settings or None
        The control models the profile describes (:data:`nctwin.controls.CONTROLS`); None
        for a model it does not.
    default_method : str
        The method of ``nctwin estimate`` when none is named (a key of
        :data:`METHOD_CONTROLS` whose control the profile has).
    recordings : str or None
        Name of the shipped recordings of this machine (:mod:`nctwin.recordings`) the learned
        methods train on; None: the learned methods do not exist for it.
    dialect : {"rs274ngc", "fanuc"}
        The G-code dialect ``nctwin estimate`` and ``nctwin simulate`` read the machine's
        programs in (:func:`nctwin.gcode.parse`'s ``dialect``).
    tool_table : ToolTable or None
        The machine's tools, which the readers (``G43 H`` lengths, ``G41``/``G42 D``
        diameters) and the LinuxCNC kernel use for its programs; None: the readers' own.
    """

    machine: Machine
    fir: FirControl | None = None
    accdec: AccDecControl | None = None
    fanuc: FanucControl | None = None
    planner: PlannerControl | None = None
    sequence: SequenceControl | None = None
    default_method: str = "cam"
    recordings: str | None = None
    dialect: str = "rs274ngc"
    tool_table: ToolTable | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.machine, Machine):
            raise ValueError(f"machine = {self.machine!r} is out of range: allowed a Machine")
        for kind, cls in CONTROLS.items():
            control = getattr(self, kind)
            if control is not None and not isinstance(control, cls):
                raise ValueError(
                    f"{kind} = {control!r} is out of range: allowed a {cls.__name__} or None"
                )
        allowed = [m for m, kind in METHOD_CONTROLS.items() if kind is None or kind in self]
        if self.default_method not in allowed:
            raise ValueError(
                f"default_method = {self.default_method!r} is out of range: allowed "
                f"{', '.join(allowed)} (the methods whose control the profile describes)"
            )
        if self.recordings is not None and not (
            isinstance(self.recordings, str) and self.recordings
        ):
            raise ValueError(
                f"recordings = {self.recordings!r} is out of range: allowed a shipped "
                "recordings' name"
            )
        check_choice("dialect", self.dialect, DIALECTS)
        if self.tool_table is not None and not isinstance(self.tool_table, ToolTable):
            raise ValueError(
                f"tool_table = {self.tool_table!r} is out of range: allowed a ToolTable or None"
            )

    @property
    def name(self) -> str:
        """The machine's name."""
        return self.machine.name

    @property
    def controls(self) -> dict[str, Control]:
        """The control models the profile describes, by kind."""
        return {k: getattr(self, k) for k in CONTROLS if getattr(self, k) is not None}

    def __contains__(self, kind: str) -> bool:
        return kind in CONTROLS and getattr(self, kind) is not None

    def control(self, kind: str) -> Control:
        """The settings of control model ``kind``.

        Raises
        ------
        ValueError
            If the profile describes no such control, naming the table it lacks.
        """
        if kind not in CONTROLS:
            raise ValueError(f"control = {kind!r} is unknown: allowed {', '.join(CONTROLS)}")
        if kind not in self:
            have = ", ".join(f"[control.{k}]" for k in self.controls) or "none"
            raise ValueError(
                f"machine profile {self.name} has no [control.{kind}] table (it has {have})"
            )
        return getattr(self, kind)

    def control_for(self, method: str) -> Control | None:
        """The control the estimate ``method`` runs on (None for ``cam``); ValueError naming
        the method and the table if the profile lacks it."""
        if method not in METHOD_CONTROLS:
            raise ValueError(
                f"method = {method!r} is unknown: allowed {', '.join(METHOD_CONTROLS)}"
            )
        kind = METHOD_CONTROLS[method]
        if kind is None:
            return None
        try:
            return self.control(kind)
        except ValueError as err:
            raise ValueError(f"method {method!r} needs a control: {err}") from None

    @classmethod
    def from_toml(cls, path: str | Path) -> Profile:
        """Read a profile file (see the module docstring).

        Raises
        ------
        ValueError
            One line naming the file, the table and the key, for a file it cannot read, a
            missing or unknown key or table, or a value out of its range.
        """
        p = Path(path)
        data = _read_toml(p)
        top = {"machine", "control", "default_method", "recordings", "dialect", "tool_table"}
        _refuse_unknown(p, "", data, top)
        machine_table = data.get("machine")
        if not isinstance(machine_table, dict):
            raise ValueError(f"{p}: no [machine] table (the machine's limits)")
        machine_table = {"name": p.stem, "description": "", **machine_table}
        machine = _build(p, "[machine]", Machine, machine_table)
        control_tables = data.get("control", {})
        if not isinstance(control_tables, dict):
            raise ValueError(f"{p}: control must be tables ([control.<kind>])")
        _refuse_unknown(p, "[control]", control_tables, set(CONTROLS))
        controls = {}
        for kind, table in control_tables.items():
            if not isinstance(table, dict):
                raise ValueError(f"{p}: control.{kind} must be a table ([control.{kind}])")
            controls[kind] = _build(p, f"[control.{kind}]", CONTROLS[kind], table)
        tools = _profile_tools(p, data.get("tool_table"))
        try:
            return cls(
                machine,
                **controls,
                default_method=data.get("default_method", "cam"),
                recordings=data.get("recordings"),
                dialect=data.get("dialect", "rs274ngc"),
                tool_table=tools,
            )
        except ValueError as exc:
            raise ValueError(f"{p}: {exc}") from None


def _profile_tools(p: Path, name) -> ToolTable | None:
    """The tool table a profile names, read: a path relative to the profile's folder, or to
    the shipped profiles' folder (so that a copy of a shipped profile elsewhere keeps it)."""
    if name is None:
        return None
    if not (isinstance(name, str) and name):
        raise ValueError(f"{p}: tool_table = {name!r} is out of range: allowed a .tbl file's path")
    table = p.parent / name
    if not table.is_file() and (machines_dir() / name).is_file():
        table = machines_dir() / name
    try:
        text = table.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"{p}: tool_table: cannot read {table}: {exc.strerror or exc}") from None
    return read_tool_table(text, str(table))


def _read_toml(p: Path) -> dict:
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except OSError as exc:
        raise ValueError(f"cannot read machine profile {p}: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"machine profile {p} is not valid TOML: {exc}") from None


def _refuse_unknown(p: Path, table: str, data: dict, allowed: set[str]) -> None:
    unknown = sorted(set(data) - allowed)
    if unknown:
        where = f"{table} " if table else ""
        raise ValueError(
            f"{p}: {where}unknown key(s) {', '.join(unknown)}; allowed: "
            f"{', '.join(sorted(allowed))}"
        )


def _build(p: Path, table: str, cls: type, data: dict):
    """``cls(**data)``, refusing unknown and missing keys and bad values with the file and the
    table."""
    names = {f.name for f in fields(cls)}
    _refuse_unknown(p, table, data, names)
    missing = [f.name for f in fields(cls) if f.default is MISSING and f.name not in data]
    if missing:
        raise ValueError(f"{p}: {table} missing key(s) {', '.join(missing)}")
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
    try:
        return cls(**values)
    except ValueError as exc:
        raise ValueError(f"{p}: {table} {exc}") from None


def machines_dir() -> Path:
    """Folder of the shipped profiles."""
    return data_dir() / "machines"


def available_machines() -> list[str]:
    """Names of the shipped profiles."""
    return sorted(p.stem for p in machines_dir().glob("*.toml"))


def profile_path(name: str | Path | None = None) -> Path:
    """The file of a shipped profile by name, or a profile file by path (``.toml``).

    Parameters
    ----------
    name : str or Path, optional
        A name from :func:`available_machines`, or a path to a ``.toml`` file. Default:
        :data:`DEFAULT_MACHINE`.

    Raises
    ------
    ValueError
        If ``name`` is neither.
    """
    name = DEFAULT_MACHINE if name is None else name
    p = Path(name)
    if p.suffix == ".toml" or p.exists():
        return p
    shipped = machines_dir() / f"{name}.toml"
    if not shipped.exists():
        raise ValueError(
            f"machine = {str(name)!r} is unknown: allowed "
            f"{', '.join(available_machines())} or a path to a .toml file"
        )
    return shipped


def load_profile(name: str | Path | None = None) -> Profile:
    """Load a shipped profile by name, or a profile file by path (see :func:`profile_path`)."""
    return Profile.from_toml(profile_path(name))


def load_machine(name: str | Path | None = None) -> Machine:
    """The :class:`Machine` of a profile (see :func:`load_profile`)."""
    return load_profile(name).machine


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, tuple | list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, float):
        return "inf" if v == math.inf else repr(v)
    return repr(v)


def write_control(
    path: str | Path, kind: str, control: Control, provenance: list[str], *, today: date
) -> None:
    """Write the ``[control.<kind>]`` table of a profile's file, keeping the rest of it.

    The table's old text (its header, its keys and the comment lines right above it) is
    replaced by ``provenance`` as comments, then every field of ``control``; where the file has
    no such table it is appended. The file is written whole, then read back as a profile.

    Parameters
    ----------
    path : str or Path
        The profile's file.
    kind : str
        A key of :data:`nctwin.controls.CONTROLS`.
    control : control settings
        Of the type ``kind`` names.
    provenance : list of str
        What the values were fitted to, how, and the fit's residual: one comment line each.
    today : date
        The date written into the provenance.
    """
    p = Path(path)
    if not isinstance(control, CONTROLS.get(kind, ())):
        raise ValueError(f"control = {control!r} is out of range: allowed a {kind} control")
    lines = p.read_text().splitlines()
    header = f"[control.{kind}]"
    start = next((i for i, line in enumerate(lines) if line.strip() == header), None)
    if start is None:
        before, after = lines, []
    else:
        stop = next(
            (i for i in range(start + 1, len(lines)) if lines[i].lstrip().startswith("[")),
            len(lines),
        )
        while stop > start + 1 and (not lines[stop - 1].strip() or lines[stop - 1].startswith("#")):
            stop -= 1  # the comments above the next table are that table's
        first = start
        while first > 0 and lines[first - 1].startswith("#"):
            first -= 1
        before, after = lines[:first], lines[stop:]
    while before and not before[-1].strip():
        before.pop()
    while after and not after[0].strip():
        after.pop(0)
    table = [f"# {line}" for line in (*provenance, f"Written by nctwin on {today.isoformat()}.")]
    table.append(header)
    table += [f"{f.name} = {_toml_value(getattr(control, f.name))}" for f in fields(control)
              if getattr(control, f.name) is not None]  # None: the key left out  # fmt: skip
    text = "\n".join([*before, "", *table, *([""] if after else []), *after]) + "\n"
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(text)
    try:
        Profile.from_toml(tmp)
    except ValueError:
        tmp.unlink()
        raise
    tmp.replace(p)
