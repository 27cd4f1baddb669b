r"""What a machine's valid runs time (:mod:`nctwin.mtconnect`): the lines of a program that carry
time other than motion (:class:`ProgramLines`), the spans of a run between its block events
(:class:`RunTimes`) and the valid runs of one machine in its logs (:func:`machine_runs`).

The logs time a program's lines, not its motion: ``Block_Number`` names the line executing
from then on, logged on change, so a short line may never show and a line's event may lag its
start. The times are therefore read as spans between events (:func:`span_s`: from the first
event at or past one line to the first past another), never as one line's duration.
:mod:`nctwin.calibrate` turns them into the machine's non-motion times.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .gcode import parse_file
from .mtconnect import Run, Verdict, parse_program, read_log, runs, steady_feed, validate
from .paths import nist_dir
from .toolpath import Toolpath

__all__ = [
    "ProgramLines",
    "RunTimes",
    "first_changes",
    "first_m6",
    "logged_runs",
    "machine_runs",
    "motion_window",
    "program_lines",
    "rapid_plateaus",
    "run_times",
    "span_s",
]

_G28 = re.compile(r"G0*28(?![0-9.])")
_COMMENT = re.compile(r"\([^)]*\)")


@dataclass(frozen=True)
class ProgramLines:
    """The lines of one program that :mod:`nctwin.calibrate` times (1-based file lines).

    Parameters
    ----------
    file : str
    first_cut, m30 : int
        The first feed line (where ``Verdict.motion_s`` starts) and the M30 line.
    tool_changes : numpy.ndarray
        Shape (k, 2): the ``G28`` line before each ``M6`` line (the ``M6`` line itself where
        none is within 3 lines) and the ``M6`` line.
    spindle_starts : numpy.ndarray
        Shape (m, 2): each line with ``M3``/``M4`` and the next line with a block.
    spindle_rpm : numpy.ndarray
        Shape (m,): the S word in force at each spindle start (rev/min).
    optional_stops : numpy.ndarray
        Shape (j,): ``M01`` lines outside every tool change.
    """

    file: str
    first_cut: int
    m30: int
    tool_changes: np.ndarray
    spindle_starts: np.ndarray
    spindle_rpm: np.ndarray
    optional_stops: np.ndarray


def program_lines(path: str | Path) -> tuple[ProgramLines, Toolpath]:
    """Read a program (:func:`nctwin.gcode.parse_file`) and find its timed lines."""
    path = Path(path)
    tp = parse_file(path)
    return timed_lines(tp, path.read_text(), path.name), tp


def timed_lines(tp: Toolpath, text: str, name: str) -> ProgramLines:
    """The timed lines of a parsed program ``tp`` whose source is ``text``, named ``name``."""
    text = text.split("\n")
    g28 = [i for i, s in enumerate(text, 1) if _G28.search(_COMMENT.sub("", s.upper()))]
    ev = tp.events
    m = ev[ev["word"] == "M"]
    block_lines = np.unique(tp.line)
    changes = []
    for line in m["line"][m["value"] == 6]:
        before = [g for g in g28 if line - 3 <= g < line]
        changes.append((before[0] if before else line, line))
    changes_arr = np.array(changes, np.int64).reshape(-1, 2)
    s_lines, rpm = ev["line"][ev["word"] == "S"], ev["value"][ev["word"] == "S"]
    starts, speeds = [], []
    for line in np.unique(m["line"][np.isin(m["value"], (3, 4))]):
        nxt = block_lines[block_lines > line]
        starts.append((line, nxt[0] if nxt.size else line))
        speeds.append(rpm[s_lines <= line][-1] if (s_lines <= line).any() else 0.0)
    stops = m["line"][m["value"] == 1]
    inside = ((stops[:, None] >= changes_arr[:, 0]) & (stops[:, None] <= changes_arr[:, 1])).any(1)
    is_cut = np.isin(tp.kind, (1, 2, 3))
    first_cut = int(tp.line[is_cut][0]) if is_cut.any() else 0
    m30 = m["line"][np.isin(m["value"], (2, 30))]
    return ProgramLines(
        name,
        first_cut,
        int(m30[0]) if m30.size else int(tp.line.max(initial=0)) + 1,
        changes_arr,
        np.array(starts, np.int64).reshape(-1, 2),
        np.array(speeds, float),
        np.asarray(stops[~inside], np.int64),
    )


def span_s(block_t_s: np.ndarray, block: np.ndarray, first: int, last: int) -> float:
    """Time (s) from the first block event at or past line ``first`` to the first past line
    ``last`` (``block_t_s``, ``block``: shape (n,), a run's events; NaN where either is
    missing)."""
    a, b = np.flatnonzero(block >= first), np.flatnonzero(block > last)
    if not a.size or not b.size:
        return np.nan
    return float(block_t_s[b[0]] - block_t_s[a[0]])


@dataclass(frozen=True)
class RunTimes:
    """What one valid run's timeline shows (s, gross: the motion of the spans included).

    Parameters
    ----------
    log, program : str
    rapid_plateau_mm_s, rapid_override_pct : float
        ``Verdict.rapid_plateau_mm_s`` (NaN: no plateau) and ``Verdict.rapid_override_pct``
        (logged, in force from the first cut on; NaN: not logged).
    motion_s, duration_s : float
        ``Verdict.motion_s``; the run's start to its end (:attr:`Run.duration_s`).
    program_start_s, program_end_s : float
        Start to the first block event; the M30 line's event to the end.
    tool_change_s, spindle_start_s, optional_stop_s : numpy.ndarray
        One span per tool change, spindle start, optional stop of the program (NaN where the
        log shows no event for it), in :class:`ProgramLines` order.
    first_line : int
        The line of the run's first block event.
    opening_s : float
        The run's start to the first block event past the ``M6`` line of the program's first
        tool change (:func:`first_changes`); NaN where it has none.
    """

    log: str
    program: str
    rapid_plateau_mm_s: float
    rapid_override_pct: float
    motion_s: float
    duration_s: float
    program_start_s: float
    program_end_s: float
    tool_change_s: np.ndarray
    spindle_start_s: np.ndarray
    optional_stop_s: np.ndarray
    first_line: int = 0
    opening_s: float = np.nan


def run_times(run: Run, lines: ProgramLines, verdict: Verdict) -> RunTimes:
    """The :class:`RunTimes` of the valid ``run`` on the program ``lines``."""
    t, b = run.block_t_s, run.block
    m6 = first_m6(lines)
    past = np.flatnonzero(b > m6) if m6 else np.array([], int)
    opening = float(t[past[0]] - run.start_s) if past.size else np.nan
    return RunTimes(
        run.log,
        lines.file,
        verdict.rapid_plateau_mm_s,
        verdict.rapid_override_pct,
        verdict.motion_s,
        run.duration_s,
        float(t[0] - run.start_s),
        float(run.end_s - t[-1]),
        np.array([span_s(t, b, a, z) for a, z in lines.tool_changes]),
        np.array([span_s(t, b, a, z) for a, z in lines.spindle_starts]),
        np.array([span_s(t, b, a, a) for a in lines.optional_stops]),
        int(b[0]),
        opening,
    )


def first_changes(lines: ProgramLines) -> np.ndarray:
    """Mask of ``lines.tool_changes`` before the first spindle start (shape (k,))."""
    first = lines.spindle_starts[0, 0] if len(lines.spindle_starts) else np.inf
    return lines.tool_changes[:, 1] < first


def first_m6(lines: ProgramLines) -> int:
    """The ``M6`` line of the program's first tool change before any spindle start (0: none)."""
    first = lines.tool_changes[first_changes(lines)]
    return int(first[0, 1]) if len(first) else 0


def logged_runs(
    machine_name: str,
    log_paths: Sequence[str | Path] | None = None,
    programs_dir: str | Path | None = None,
) -> tuple[list[tuple[Run, RunTimes]], dict[str, tuple[ProgramLines, Toolpath]], pd.DataFrame]:
    """:func:`machine_runs` with each valid run's events kept: (run, its times) pairs."""
    folder = nist_dir()
    nc = folder / "nc" if programs_dir is None else Path(programs_dir)
    texts = {p.name: p.read_text() for p in sorted(nc.glob("*.NC"))}
    if log_paths is None:
        log_paths = sorted((folder / "logs").glob(f"*{machine_name}*.txt.gz"))
    out, programs, why, rapids = [], {}, [], []
    for path in map(Path, log_paths):
        for run in runs(read_log(path)):
            v = validate(run, texts)
            if v.program is not None:
                rapids += rapid_plateaus(run, parse_program(v.program, texts[v.program]))
            if not v.valid:
                why.append(f"{path.name}: {v.reason} ({v.detail})")
                continue
            if v.program not in programs:
                programs[v.program] = program_lines(nc / v.program)
            out.append((run, run_times(run, programs[v.program][0], v)))
    if not out:
        first = f"; {why[0]}" if why else ""
        raise ValueError(f"no valid run of {machine_name} in {len(log_paths)} log(s){first}")
    columns = ["log", "program", "rapid_override_pct", "plateau_mm_s"]
    return out, programs, pd.DataFrame(rapids, columns=columns)


def machine_runs(
    machine_name: str,
    log_paths: Sequence[str | Path] | None = None,
    programs_dir: str | Path | None = None,
) -> tuple[list[RunTimes], dict[str, tuple[ProgramLines, Toolpath]], pd.DataFrame]:
    """The valid runs of one machine in the logs (default: the shipped ones whose name holds
    ``machine_name``) against the programs of ``programs_dir`` (``*.NC``; default the shipped
    ones, :func:`nctwin.paths.nist_dir`), and the rapid plateaus of all its runs.

    Returns
    -------
    runs : list of RunTimes
    programs : dict of str to (ProgramLines, Toolpath)
        The programs the runs ran, by file name.
    rapids : pandas.DataFrame
        A row per run of a known program (valid or not) and logged rapid override it reaches a
        plateau at: ``log``, ``program``, ``rapid_override_pct``, ``plateau_mm_s`` (the highest
        steady feed on a single-axis G0 line while that override is in force).

    Raises
    ------
    ValueError
        A file that is no log (:func:`nctwin.mtconnect.read_log`'s one line), or no valid run
        (the first run's reason: a program not in the folder is ``unknown_program``).
    """
    pairs, programs, rapids = logged_runs(machine_name, log_paths, programs_dir)
    return [t for _, t in pairs], programs, rapids


def rapid_plateaus(run: Run, program) -> list[tuple]:
    """(log, program, override, plateau) per logged rapid override > 0 that ``run`` reaches a
    single-axis G0 plateau at (:func:`machine_runs`)."""
    t, line, v = steady_feed(run, program)
    rapid = program.single_axis_rapid[line]
    pct = run.rapid_override_pct.at(t[rapid])
    return [(run.log, program.file, float(o), float(v[rapid][pct == o].max()))
            for o in np.unique(pct[np.isfinite(pct) & (pct > 0)])]  # fmt: skip


def motion_window(tp: Toolpath, lines: ProgramLines) -> np.ndarray:
    """Mask of the blocks ``Verdict.motion_s`` times: the first cut's line to the M30's."""
    return (tp.line >= lines.first_cut) & (tp.line < lines.m30)
