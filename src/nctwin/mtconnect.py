r"""NIST's MTConnect logs of two Hurco VMX 24 (``data/nist``): runs, and which are valid
measurements of which program.

:func:`read_log` reads a log, :func:`runs` splits it into :class:`Run`\ s, :func:`validate` judges
a run against the program texts (:class:`Verdict`), :func:`runs_table` does all of it for many
logs. Times are s since the Unix epoch (UTC). ``OP1-03`` is ``Box-OP1-Hurco02-03of20.txt.gz``,
``Plate-09`` is ``Plate-Op1-Hurco04-09of20.txt.gz``; "L. n" is a log's line n.

What the 80 shipped logs show (the rules rest on it):

* **Lines**: ``timestamp|item|value``, written on change, on 1/64 s ticks, in time order. 49
  lines (in 33 logs) carry the rest of the record before: the writer broke a number before the
  characters ``2017`` in it (``OP1-03`` L. 11192-11193: ``...|Block_Number|``, ``20175``;
  ``Plate-09`` L. 5867-5868: ``...|Spindle_Speed|``, ``2017.919363``). :func:`read_log` joins a
  line of digits and points that makes a number with the value before it; any other line that
  is no record is refused.
* **Units**: ``Feed_Rate`` is the actual path feed in mm/s (``Devices.xml`` L. 635, 723:
  MILLIMETER/SECOND), in steps of 1/60 mm/s: ``Plate-02`` L. 217-220 log 38.1 in block 28,
  ``N280X5.`` under ``F90.`` (90 in/min = 38.1 mm/s). Kept as logged.
* **Runs**: a cycle start logs ``Program_Status`` ACTIVE after PROGRAM_COMPLETED,
  PROGRAM_STOPPED or STOPPED (or first in a log), and ``Program_Runtime_Seconds`` restarts with
  it at 0-4 s after one stale sample (all 88 starts; ``OP1-03`` L. 2-4: 360, 0). ACTIVE after
  FEED_HOLD resumes: the counter holds (``Plate-01`` L. 88-132: 21 s through 15 holds). The run
  ends at the next status that is neither ACTIVE nor FEED_HOLD. A log may hold several runs
  (``OP3-16`` L. 2, 2232, 2235, 4453; ``Plate-08`` L. 5, 26, 30: a start stopped after 6 s, then
  the run) and begin inside one (``Plate-09`` L. 1-354: the end of the run ``Plate-08`` holds
  whole, its PROGRAM_COMPLETED logged in both; ``OP1-04`` L. 1: 1 s into a run).
* **The counter** glitches at a minute's turn, one sample 59 or 60 s off (``OP1-03`` L. 262-266:
  59, 0, 60; ``OP1-10`` L. 1831-1842: 359, 419, 360): a sample 30 s or more off the one before,
  with the one after back within 3 s, is dropped. Of its 65,906 steps while ACTIVE, 99.9 % lose
  under 0.7 s to the clock. The 14 that lose 5 s or more (5.1-2357 s) are all at M01 lines of
  Plate runs (``Plate-11`` L. 788-800: 39 min at line 259, ``N2590M01``): optional stops and
  operators' pauses, :data:`PAUSE_S` = 5 s. Below: 3.3-3.9 s after three starts, before the
  first block (the counter's latency), 2.3 s of a logging hiccup made up at once (``Plate-12``
  L. 2706-2718), 2.9 s at an M01 line of a run that pauses longer elsewhere.
* **Names**: ``Program_Name_Running`` is logged on change only; 58 of the 90 runs name nothing in
  their log (no log names OP3). The control names a file by its ``O`` line's comment, ``_`` for
  spaces, plus ``.NC``: ``O0000(NIST_MTC_CRADA_BOX_REV-A OP1)`` (``NIST_MTC_CRADA_BOX_REV-A OP1
  (Bottom).NC``) is logged ``NIST_MTC_CRADA_BOX_REV-A_OP1.NC``, ``O0000(NIST_MTC_CRADA_PLATE)``
  (``NIST_MTC_CRADA_PLATE-1.NC``) ``NIST_MTC_CRADA_PLATE.NC``. Where both are logged,
  ``Program_Name_Editing`` (the program loaded) names the run that follows. A name proves no
  text: ``Plate-05`` runs "PLATE-5" with the spindle at 6000 rev/min, which no shipped program
  asks for (``Plate-06`` runs the shipped PLATE-5); ``OP2-01``-``05`` end at lines 1209 and
  1047, the shipped OP2's M30 is line 1185. PLATE-6 and 15, 7 and 16, 19 and 20 differ only in
  their names.
* **Overrides** are logged on change only, and changed between logs: ``OP2-08``-``20`` log none,
  yet ``OP2-10`` L. 77 logs 12.8 mm/s (768/60) in an ``F30.`` block (762/60): 101 %. Steady
  samples measure the override in force to 0.1 % (:class:`FeedCheck`): the feed is 1.000 of the
  programmed where 100 % is logged, 0.990 where 99 % is (``OP1-07``, ``OP1-17``).
* **Feeds**: against its named program, no run with 10 steady samples or more (28) has over
  0.9 % of them 2 % faster than programmed x override, nor under 86 % within 1 % of its scale:
  :data:`FEED_ABOVE`, :data:`FEED_AGREE_SHARE`. Of 90 pairs of such a run and another program
  fitting its lines, 87 fail; PLATE-3 fits ``Plate-12`` (an F word apart, on a line never
  steady), PLATE-11 ``Plate-10`` at a scale of 1.33, PLATE-13 the stopped start in ``Plate-04``.
* **The start**: the adapter logs nothing for about 5 s after most starts (``OP1-06`` L. 6-7),
  and the first tool change's line is logged for 3.6-11 s: the time to the first cut varies by
  seconds between runs of one program (OP1: 4.9 s), the time from there to M30 by tenths (OP1:
  s.d. 0.32 s in 1750 s, OP3: 0.17 s in 369 s; :attr:`Verdict.motion_s`).
"""

from __future__ import annotations

import dataclasses
import functools
import gzip
import re
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .paths import nist_dir

__all__ = ["PAUSE_S", "REASONS", "FeedCheck", "Program", "Run", "Track", "Verdict",
           "feed_check", "nist_runs_table", "parse_program", "read_log", "runs", "runs_table",
           "steady_feed", "validate"]  # fmt: skip

#: A line that may carry the rest of the record before it (see the module docstring).
_FRAGMENT = re.compile(r"[0-9][0-9.]*")
_NUMBER = re.compile(r"[-+]?[0-9]*\.?[0-9]+")


def read_log(path: str | Path) -> pd.DataFrame:
    """One MTConnect log, ``timestamp|item|value`` per line, plain or gzip-compressed (read as
    gzip where its first bytes are gzip's magic number).

    Returns
    -------
    pandas.DataFrame
        A row per record, in file order: ``t_s`` (float, s since the Unix epoch, UTC, from
        ISO-8601 timestamps; exact on these logs' 1/64 s ticks), ``item`` and ``value`` (str,
        as logged), ``line`` (int, the record's 1-based line); ``attrs["source"]``: file name.

    Raises
    ------
    ValueError
        ``"{path}:{line}: reason"``, one line, for a file that is no such log: empty, binary,
        not UTF-8, a broken gzip stream, a line that is no record (nor the rest of one, see the
        module docstring), an empty item, a timestamp that is not ISO-8601 or goes back.
    """
    path = Path(path)
    raw = path.read_bytes()
    if raw[:2] == b"\x1f\x8b":
        try:
            raw = gzip.decompress(raw)
        except (OSError, EOFError, zlib.error) as exc:
            raise ValueError(f"{path}:1: a broken gzip stream ({exc})") from None
    if not raw.strip():
        raise ValueError(f"{path}:1: empty, no 'timestamp|item|value' record")
    if b"\0" in raw:
        line = raw.count(b"\n", 0, raw.index(b"\0")) + 1
        raise ValueError(f"{path}:{line}: binary data (a NUL byte)")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise ValueError(f"{path}:{line}: not UTF-8 text") from None
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    records: list[list] = []  # timestamp, item, value, line
    for n, line in enumerate(lines, 1):
        parts = line.removesuffix("\r").split("|", 2)
        if len(parts) == 3 and parts[1]:
            records.append([*parts, n])
        elif records and _FRAGMENT.fullmatch(line) and _NUMBER.fullmatch(records[-1][2] + line):
            records[-1][2] += line
        else:
            why = "an empty item" if len(parts) == 3 else "not a 'timestamp|item|value' record"
            raise ValueError(f"{path}:{n}: {why}: {line[:60]!r}")
    stamps, items, values, numbers = zip(*records, strict=True)
    t = pd.to_datetime(pd.Series(stamps), format="ISO8601", utc=True, errors="coerce")
    for k in np.flatnonzero(t.isna().to_numpy())[:1]:
        raise ValueError(f"{path}:{numbers[k]}: {stamps[k][:40]!r} is not an ISO-8601 timestamp")
    ns = t.dt.as_unit("ns").astype(np.int64).to_numpy()
    for k in np.flatnonzero(np.diff(ns) < 0)[:1]:
        raise ValueError(f"{path}:{numbers[k + 1]}: the timestamp goes back in time")
    out = pd.DataFrame({"t_s": ns / 1e9, "item": items, "value": values, "line": numbers})
    out.attrs["source"] = path.name
    return out


@dataclass(frozen=True, eq=False)
class Track:
    """One numeric item within a run: ``initial``, its value in force at the start (its last
    event before, NaN where the log holds none), then ``t_s`` and ``value``, the times (s) and
    values of its events within the run, both of shape (n,)."""

    initial: float
    t_s: np.ndarray
    value: np.ndarray

    def at(self, t_s: np.ndarray) -> np.ndarray:
        """The value in force at each of ``t_s`` (shape (m,)), ``initial`` before any event."""
        return np.r_[self.initial, self.value][np.searchsorted(self.t_s, t_s, side="right")]


@dataclass(frozen=True, eq=False)
class Run:
    """One run of a program, as one log shows it (the module docstring says what a run is).

    Parameters
    ----------
    log : str
        The log's file name.
    program, editing : str or None
        ``Program_Name_Running`` in force during the run (its last event in the log up to the
        end), ``Program_Name_Editing`` in force at the start; None where the log holds none.
    start_s, end_s, start_logged : float, float, bool
        The status events that start and end the run; where the log begins inside the run
        (``start_logged`` False) or ends first, its first or last record.
    end_status : str
        PROGRAM_COMPLETED, PROGRAM_STOPPED, STOPPED, or "" where the log ends first.
    status_t_s, status : numpy.ndarray
        ``Program_Status`` events from start to end, both included: times, values; shape (k,).
    block_t_s, block : numpy.ndarray
        ``Block_Number`` events: times, and the 1-based line of the program file executing
        from then on (0: none); shape (n,).
    feed_mm_s, feed_override_pct, rapid_override_pct, spindle_rpm, tool, runtime_s : Track
        ``Feed_Rate`` (actual path feed, mm/s as logged: Devices.xml's unit), ``Feed_Override``
        and ``Rapid_Override`` (%), ``Spindle_Speed`` (actual, rev/min), ``Current_Tool`` (0
        during a change), ``Program_Runtime_Seconds`` (the run-time counter, s, glitches kept).
    """

    log: str
    program: str | None
    editing: str | None
    start_s: float
    end_s: float
    start_logged: bool
    end_status: str
    status_t_s: np.ndarray
    status: np.ndarray
    block_t_s: np.ndarray
    block: np.ndarray
    feed_mm_s: Track
    feed_override_pct: Track
    rapid_override_pct: Track
    spindle_rpm: Track
    tool: Track
    runtime_s: Track

    @property
    def duration_s(self) -> float:
        """From the start to the end (s)."""
        return self.end_s - self.start_s


#: ``Program_Status`` values that keep a run going; any other ends it.
_RUNNING = ("ACTIVE", "FEED_HOLD")
_TRACKS = {
    "feed_mm_s": "Feed_Rate",
    "feed_override_pct": "Feed_Override",
    "rapid_override_pct": "Rapid_Override",
    "spindle_rpm": "Spindle_Speed",
    "tool": "Current_Tool",
    "runtime_s": "Program_Runtime_Seconds",
}


def _events(log: pd.DataFrame, item: str, numeric: bool = False):
    """(rows, times, values) of one item's events; values as float where ``numeric``."""
    rows = np.flatnonzero((log["item"] == item).to_numpy())
    values = log["value"].to_numpy()[rows].astype(str)
    if numeric:
        number = pd.to_numeric(pd.Series(values), errors="coerce").to_numpy(float)
        if np.isnan(number).any():
            k = int(np.flatnonzero(np.isnan(number))[0])
            line = log["line"].to_numpy()[rows[k]]
            raise ValueError(f"{log.attrs.get('source', '')}:{line}: {item} is not a number")
        values = number
    return rows, log["t_s"].to_numpy()[rows], values


def runs(log: pd.DataFrame) -> list[Run]:
    """Split one log (as :func:`read_log` returns it) into its runs, in its order.

    A run starts at a ``Program_Status`` ACTIVE that follows no ACTIVE or FEED_HOLD (ACTIVE
    after FEED_HOLD resumes it) and ends at the next status that is neither, or with the log.
    Where the log's first status is not ACTIVE and the run-time counter is logged before it,
    the log begins inside a run (``start_logged`` False), which starts at its first record.
    The module docstring gives the evidence.
    """
    st_rows, st_t, st_v = _events(log, "Program_Status")
    rt_rows = _events(log, "Program_Runtime_Seconds")[0]
    spans, open_at, logged, prev = [], None, True, None
    if st_v.size and st_v[0] != "ACTIVE" and rt_rows.size and rt_rows[0] < st_rows[0]:
        open_at, logged = 0, False
    for value, row in zip(st_v, st_rows, strict=True):
        if value == "ACTIVE" and prev not in _RUNNING:
            open_at, logged = int(row), True
        elif value not in _RUNNING and open_at is not None:
            spans.append((open_at, int(row), logged, str(value)))
            open_at = None
        prev = value
    if open_at is not None:
        spans.append((open_at, len(log) - 1, logged, ""))
    bn_rows, bn_t, bn_v = _events(log, "Block_Number", numeric=True)
    run_rows, _, running = _events(log, "Program_Name_Running")
    edit_rows, _, editing = _events(log, "Program_Name_Editing")
    tracks = {field: _events(log, item, numeric=True) for field, item in _TRACKS.items()}
    t_all, source = log["t_s"].to_numpy(), str(log.attrs.get("source", ""))
    out = []
    for first, last, logged, end_status in spans:
        k_run = np.searchsorted(run_rows, last, "right") - 1
        k_edit = np.searchsorted(edit_rows, first) - 1
        st, bn = (slice(*np.searchsorted(r, (first, last + 1))) for r in (st_rows, bn_rows))
        fields = {}
        for field, (rows, t, v) in tracks.items():
            i, j = np.searchsorted(rows, (first, last + 1))
            fields[field] = Track(float(v[i - 1]) if i else np.nan, t[i:j], v[i:j])
        out.append(
            Run(
                source,
                str(running[k_run]) if k_run >= 0 else None,
                str(editing[k_edit]) if k_edit >= 0 else None,
                float(t_all[first]),
                float(t_all[last]),
                logged,
                end_status,
                st_t[st],
                st_v[st],
                bn_t[bn],
                bn_v[bn].astype(np.int64),
                **fields,
            )
        )
    return out


@dataclass(frozen=True, eq=False)
class Program:
    """What :func:`validate` reads of one program file. The arrays have an entry per 1-based
    line, shape (n_lines + 1,) (entry 0 unused), except ``spindle_rpm``.

    Parameters
    ----------
    file, name : str
        The file's name; the name the control logs: the ``O`` line's comment, ``_`` for spaces,
        plus ``.NC`` (the file's name where there is no such comment).
    n_lines, m30 : int
        Number of lines; the line of the first M30 or M2 (0: none).
    is_block, cuts, single_axis_rapid : numpy.ndarray
        The line is a block (not blank, ``%`` or a comment); feeds (G1/G2/G3 with axis words,
        or a canned cycle's); is a G0 move of one axis (bool).
    feed_mm_s : numpy.ndarray
        Programmed feed of a G1/G2/G3 line with axis words (mm/s; F in inch/min under G20,
        mm/min under G21), NaN elsewhere.
    spindle_rpm : numpy.ndarray
        The S words (> 0), in file order, shape (k,).
    """

    file: str
    name: str
    n_lines: int
    m30: int
    is_block: np.ndarray
    cuts: np.ndarray
    single_axis_rapid: np.ndarray
    feed_mm_s: np.ndarray
    spindle_rpm: np.ndarray

    @property
    def first_cut(self) -> int:
        """The first line that feeds, where the first approach ends (0: none)."""
        hits = np.flatnonzero(self.cuts)
        return int(hits[0]) if hits.size else 0


_WORD = re.compile(r"([A-Z])\s*([-+]?[0-9]*\.?[0-9]+)")
_COMMENT = re.compile(r"\([^)]*\)")
_O_NAME = re.compile(r"O\d+\s*\(([^)]*)\)")


@functools.lru_cache(maxsize=64)
def parse_program(file: str, text: str) -> Program:
    """Read the lines of one ISO/Fanuc-style program (as Mastercam posts them here) for
    :class:`Program`: modal G0/G1/G2/G3 and canned cycles (G73-G89, G80), F under G20/G21, S,
    M30/M2; lines under G28/G30/G53/G58/G91 (home, other frames) are neither cuts nor rapids."""
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    n = len(lines)
    is_block, cuts, single = (np.zeros(n + 1, bool) for _ in range(3))
    feed = np.full(n + 1, np.nan)
    spindle: list[float] = []
    name, m30, motion, mm_per_unit, f_mm_s = "", 0, -1, 25.4, np.nan
    for i, raw in enumerate(lines, 1):
        line = raw.strip().upper()
        o_name = _O_NAME.match(line)
        if o_name and not name:
            name = o_name.group(1).strip().replace(" ", "_") + ".NC"
        code = _COMMENT.sub("", line).strip()
        if not code or code == "%":
            continue
        is_block[i] = True
        words = [(w, float(v)) for w, v in _WORD.findall(code)]
        axes = {w for w, _ in words if w in "XYZ"}
        other_frame = False
        for w, v in words:
            if w == "G":
                g = int(v)
                if g in (0, 1, 2, 3):
                    motion = g
                elif g == 80:
                    motion = -1
                elif 73 <= g <= 89:
                    motion = 81
                elif g in (20, 21):
                    mm_per_unit = 25.4 if g == 20 else 1.0
                other_frame |= g in (28, 30, 53, 58, 91)
            elif w == "F":
                f_mm_s = v * mm_per_unit / 60.0
            elif w == "S" and v > 0:
                spindle.append(v)
            elif w == "M" and int(v) in (2, 30) and not m30:
                m30 = i
        if axes and not other_frame:
            feed[i] = f_mm_s if motion in (1, 2, 3) else np.nan
            cuts[i] = motion in (1, 2, 3, 81)
            single[i] = motion == 0 and len(axes) == 1
    return Program(file, name or file, n, m30, is_block, cuts, single, feed, np.asarray(spindle))


REASONS = tuple(  # why a run is not a valid measurement, in the order validate checks
    "not_completed unknown_program other_version restart feed_hold pause feed_override "
    "rapid_override_changed".split()
)
#: The run-time counter falling this far behind the clock (s) while ACTIVE is a pause.
PAUSE_S = 5.0
#: Feed checks (:class:`FeedCheck`): a sample faster than the programmed feed x override by
#: more than FEED_ABOVE contradicts the program, and at most that share may; at least
#: FEED_AGREE_SHARE of them lie within FEED_AGREE of the scale; fewer than FEED_MIN_SAMPLES
#: samples tell no version apart; the scale may miss 1 by FEED_SCALE_TOL (half a 1 % step).
FEED_ABOVE, FEED_AGREE, FEED_AGREE_SHARE, FEED_MIN_SAMPLES = 0.02, 0.01, 0.8, 10
FEED_SCALE_TOL = 0.005
#: A spindle speed held 1 s or more lies within this share of an S word of the program.
SPINDLE_TOL = 0.03


def steady_feed(run: Run, program: Program) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(time, program line, feed) of the run's steady ``Feed_Rate`` samples: in the same block
    as the sample before and within 0.5 % of it, > 0; line 0 where past the program's end."""
    f = run.feed_mm_s
    k = np.searchsorted(run.block_t_s, f.t_s, side="right") - 1
    line = np.r_[run.block, 0][k]
    line = np.where(line <= program.n_lines, line, 0)
    v = f.value
    ok = np.r_[False, (k[1:] == k[:-1]) & (np.abs(np.diff(v)) <= 0.005 * v[1:]) & (v[1:] > 0)]
    return f.t_s[ok], line[ok], v[ok]


@dataclass(frozen=True)
class FeedCheck:
    """A run's steady feed samples (:func:`feed_check`) on G1/G2/G3 lines of a program, as
    ratios to the line's programmed feed x the feed override in force (100 % where none is
    logged): ``n`` samples, their median ``scale`` (NaN where none: 1 where the override in
    force is the one logged, 1.01 under an unlogged 101 %), the share ``agree`` within
    :data:`FEED_AGREE` of it and the share ``above`` faster than it by :data:`FEED_ABOVE`."""

    n: int
    scale: float
    agree: float
    above: float

    @property
    def consistent(self) -> bool:
        """Whether the feeds fit the program (too few samples to tell: they do)."""
        return self.n < FEED_MIN_SAMPLES or (
            self.above <= FEED_ABOVE and self.agree >= FEED_AGREE_SHARE
        )


def feed_check(run: Run, program: Program) -> FeedCheck:
    """The run's logged feed against ``program``'s (:class:`FeedCheck`)."""
    t, line, v = steady_feed(run, program)
    override = run.feed_override_pct.at(t)
    override = np.where(np.isnan(override), 100.0, override)
    planned = program.feed_mm_s[line] * override / 100.0
    use = np.isfinite(planned) & (planned > 0)
    ratio = v[use] / planned[use]
    if not ratio.size:
        return FeedCheck(0, np.nan, np.nan, np.nan)
    scale = float(np.median(ratio))
    agree = float(np.mean(np.abs(ratio - scale) <= FEED_AGREE * scale))
    return FeedCheck(ratio.size, scale, agree, float(np.mean(ratio > scale * (1 + FEED_ABOVE))))


def _mismatch(run: Run, program: Program, feeds: bool = True) -> str:
    """Why ``run`` is not a run of ``program``'s text ("" where it may be): a line it does not
    have, an end off its M30 line, a spindle speed or (``feeds``) feeds it does not program."""
    blocks = run.block[run.block > 0]
    if blocks.size and blocks.max() > program.n_lines:
        return f"visits line {blocks.max()}; {program.file} has {program.n_lines}"
    if not program.is_block[blocks].all():
        return f"visits line {blocks[~program.is_block[blocks]][0]}, no block of {program.file}"
    if run.end_status == "PROGRAM_COMPLETED" and blocks.size and blocks[-1] != program.m30:
        return f"ends at line {blocks[-1]}, not at {program.file}'s M30 (line {program.m30})"
    s = run.spindle_rpm
    held = s.value[(np.diff(np.r_[s.t_s, run.end_s]) >= 1.0) & (s.value > 0)]
    near = np.abs(held[:, None] - program.spindle_rpm) <= SPINDLE_TOL * program.spindle_rpm
    if not near.any(axis=1).all():
        rpm = held[~near.any(axis=1)][0]
        return f"holds the spindle at {rpm:.0f} rev/min, no S word of {program.file}"
    feed = feed_check(run, program) if feeds else None
    if feed is not None and not feed.consistent:
        return (
            f"its feed fits {program.file} in {feed.agree:.0%} of {feed.n} steady samples, "
            f"{feed.above:.0%} faster than programmed"
        )
    return ""


def _identify(run: Run, programs: dict[str, Program]) -> tuple[Program | None, str, str]:
    """(program, "name" or "content", why not): by the logged name, else by content."""
    logged = run.program or run.editing
    if logged:
        program = programs.get(logged)
        if program is None:
            return None, "", f"{logged} is none of the programs"
        return program, "name", _mismatch(run, program)
    fits = [p for p in programs.values() if not _mismatch(run, p, feeds=False)]
    if len(fits) > 1:  # feeds tell the variants apart, then an unlogged override of 100 %
        fits = [p for p in fits if feed_check(run, p).consistent]
    if len(fits) > 1:
        fits = [p for p in fits if abs(feed_check(run, p).scale - 1) <= FEED_SCALE_TOL] or fits
    if len(fits) == 1:
        return fits[0], "content", _mismatch(run, fits[0])
    files = ", ".join(sorted(p.file for p in fits)) if len(fits) < 4 else f"{len(fits)} programs"
    return None, "", f"no name logged, and its content fits {files or 'no program'}"


def _pause_s(run: Run) -> float:
    """The longest time (s) the run-time counter fell behind the clock between two of its
    samples while ACTIVE throughout; glitch samples dropped (module docstring)."""
    t, v = run.runtime_s.t_s, run.runtime_s.value
    glitch = np.zeros(v.shape, bool)
    glitch[1:-1] = (np.abs(v[1:-1] - v[:-2]) >= 30) & (np.abs(v[2:] - v[:-2]) <= 3)
    t, v = t[~glitch], v[~glitch]
    not_active = run.status != "ACTIVE"
    k = np.searchsorted(run.status_t_s, t, side="right")
    stops = np.r_[0, np.cumsum(not_active)][k]  # status events other than ACTIVE so far
    active = np.r_[not run.start_logged, ~not_active][k]
    ok = (np.diff(v) >= 0) & (np.diff(stops) == 0) & active[:-1]
    return float(np.max(np.diff(t) - np.diff(v), where=ok, initial=0.0))


@dataclass(frozen=True)
class Verdict:
    """Whether a run is a valid measurement of a program, and why not.

    Parameters
    ----------
    valid : bool
    reason, reasons, detail : str, tuple of str, str
        The first of :data:`REASONS` that holds ("" where valid), all that hold, and one
        sentence on the first.
    program, matched_by : str or None, str
        The matched program's file name; how: ``"name"`` (``Program_Name_Running`` logged,
        else ``Program_Name_Editing``), ``"content"`` (no name logged: the one program its
        content fits) or "".
    feed_override_pct, rapid_override_pct : float
        Logged, in force when the first approach ended (NaN: not logged in the log).
    feed_scale, feed_samples : float, int
        :class:`FeedCheck` ``scale`` and ``n`` against the matched program (NaN, 0: none).
    rapid_plateau_mm_s : float
        The highest steady ``Feed_Rate`` on a single-axis G0 line of the matched program
        (mm/s; NaN: none): an axis's rapid feed x the rapid override, where a move reaches it.
    motion_s : float
        Where valid, from the first ``Block_Number`` event at or past the program's first feed
        line (where the first approach ends) to the event of its M30 line; else NaN.
    """

    valid: bool
    reason: str
    reasons: tuple[str, ...]
    detail: str
    program: str | None
    matched_by: str
    feed_override_pct: float
    rapid_override_pct: float
    feed_scale: float
    feed_samples: int
    rapid_plateau_mm_s: float
    motion_s: float


def _parsed(programs: dict[str, str]) -> dict[str, Program]:
    """The programs by logged name; two files of one name are refused."""
    out: dict[str, Program] = {}
    for file, text in programs.items():
        p = parse_program(file, text)
        if p.name in out:
            raise ValueError(f"{file} and {out[p.name].file} are both logged as {p.name}")
        out[p.name] = p
    return out


def validate(run: Run, programs: dict[str, str]) -> Verdict:
    """Judge ``run`` against ``programs`` (texts by file name). The checks, in :data:`REASONS`
    order (the module docstring gives the evidence):

    * ``not_completed``: the run did not end PROGRAM_COMPLETED.
    * ``unknown_program``: the logged name is no program's, or no name is logged and not
      exactly one program fits the content (lines, M30, spindle, then feeds and a scale of 1).
    * ``other_version``: the matched program does not fit: a line it lacks or that is no
      block, an end off its M30 line, a spindle speed held 1 s that no S word asks for
      (:data:`SPINDLE_TOL`), feeds it does not program (:attr:`FeedCheck.consistent`).
    * ``restart``: no start logged, block numbers going back, or a first block logged past the
      program's first feed line.
    * ``feed_hold``: a FEED_HOLD status. ``pause``: the run-time counter falls more than
      :data:`PAUSE_S` behind the clock while ACTIVE (an M01 optional stop, an operator).
    * ``feed_override``: a logged ``Feed_Override`` other than 100 % from the first feed line
      on, a feed scale off 1 by more than :data:`FEED_SCALE_TOL`, or neither to tell it.
    * ``rapid_override_changed``: a ``Rapid_Override`` event after the first feed line that
      differs from the value then in force (the value itself is an input of the run).
    """
    program, how, mismatch = _identify(run, _parsed(programs))
    found: dict[str, str] = {}
    if run.end_status != "PROGRAM_COMPLETED":
        found["not_completed"] = f"ended {run.end_status or 'with the log'}"
    if program is None:
        found["unknown_program"] = mismatch
    elif mismatch:
        found["other_version"] = f"{run.program or run.editing or how}: {mismatch}"
    blocks = run.block[run.block > 0]
    back = np.flatnonzero(np.diff(blocks) < 0)
    if not run.start_logged:
        found["restart"] = "the log begins inside the run"
    elif back.size:
        found["restart"] = f"line {blocks[back[0]]} is followed by line {blocks[back[0] + 1]}"
    elif program is not None and blocks.size and blocks[0] > program.first_cut > 0:
        found["restart"] = f"starts at line {blocks[0]}, past the first cut {program.first_cut}"
    if np.any(run.status == "FEED_HOLD"):
        found["feed_hold"] = f"{np.sum(run.status == 'FEED_HOLD')} FEED_HOLD events"
    lag_s = _pause_s(run)
    if lag_s > PAUSE_S:
        found["pause"] = f"the run-time counter stops for {lag_s:.0f} s while ACTIVE"
    feed = FeedCheck(0, np.nan, np.nan, np.nan)
    fo_pct = ro_pct = rapid_mm_s = motion_s = np.nan
    if program is not None:
        cut = np.flatnonzero(run.block >= max(program.first_cut, 1))
        cut_t = run.block_t_s[cut[0]] if cut.size else run.end_s
        feed = feed_check(run, program)
        fo, ro = run.feed_override_pct, run.rapid_override_pct
        fo_pct, ro_pct = float(fo.at(cut_t)), float(ro.at(cut_t))
        feeding = np.r_[fo_pct, fo.value[fo.t_s > cut_t]]
        other = feeding[np.isfinite(feeding) & (feeding != 100)]
        if other.size:
            found["feed_override"] = f"Feed_Override {other[0]:g} % while feeding"
        elif feed.n and abs(feed.scale - 1) > FEED_SCALE_TOL:
            found["feed_override"] = (
                f"its feed runs at {feed.scale:.1%} of the programmed x logged override "
                f"({feed.n} steady samples)"
            )
        elif not feed.n and np.isnan(feeding).all():
            found["feed_override"] = "no Feed_Override logged and no steady feed to tell it"
        later = ro.value[ro.t_s > cut_t]
        if np.any(later != ro_pct):
            was = f"{ro_pct:g} %" if np.isfinite(ro_pct) else "not logged"
            found["rapid_override_changed"] = (
                f"Rapid_Override {was} at the first cut, then {later.min():g}-{later.max():g} %"
            )
        if cut.size:
            motion_s = float(run.block_t_s[-1] - run.block_t_s[cut[0]])
        _, line, v = steady_feed(run, program)
        rapid = v[program.single_axis_rapid[line]]
        rapid_mm_s = float(rapid.max()) if rapid.size else np.nan
    reasons = tuple(r for r in REASONS if r in found)
    return Verdict(
        valid=not reasons,
        reason=reasons[0] if reasons else "",
        reasons=reasons,
        detail=found[reasons[0]] if reasons else "",
        program=program.file if program is not None else None,
        matched_by=how if program is not None else "",
        feed_override_pct=fo_pct,
        rapid_override_pct=ro_pct,
        feed_scale=feed.scale,
        feed_samples=feed.n,
        rapid_plateau_mm_s=rapid_mm_s,
        motion_s=motion_s if not reasons else np.nan,
    )


def runs_table(log_paths, programs: dict[str, str]) -> pd.DataFrame:
    """One row per run of every log, with its :class:`Verdict`.

    Parameters
    ----------
    log_paths : iterable of str or Path
        MTConnect logs; the machine is the ``HurcoNN`` in a file's name.
    programs : dict of str to str
        Program texts by file name.

    Returns
    -------
    pandas.DataFrame
        Sorted by machine, start, log and run: ``log``, ``machine``, ``run`` (index in the
        log), ``logged_name`` (:attr:`Run.program`, else :attr:`Run.editing`, else ""),
        ``start`` (UTC), ``end_status``, ``duration_s`` (start to end), ``first_block`` and
        ``last_block`` (> 0), then the :class:`Verdict`'s fields (``program``: the matched
        file, else the logged name; ``reasons`` space-separated).
    """
    rows = []
    for path in map(Path, log_paths):
        machine = re.search(r"Hurco\d+", path.name)
        for k, run in enumerate(runs(read_log(path))):
            verdict = dataclasses.asdict(validate(run, programs))
            b = run.block[run.block > 0]
            rows.append(
                {
                    "log": path.name,
                    "machine": machine.group(0) if machine else "",
                    "run": k,
                    "logged_name": run.program or run.editing or "",
                    "start": pd.Timestamp(run.start_s, unit="s", tz="UTC"),
                    "end_status": run.end_status,
                    "duration_s": run.duration_s,
                    "first_block": int(b[0]) if b.size else 0,
                    "last_block": int(b[-1]) if b.size else 0,
                    **verdict,
                    "program": verdict["program"] or run.program or run.editing or "",
                    "reasons": " ".join(verdict["reasons"]),
                }
            )
    table = pd.DataFrame(rows)
    return table.sort_values(["machine", "start", "log", "run"], ignore_index=True)


def nist_runs_table() -> pd.DataFrame:
    """:func:`runs_table` of the 80 shipped logs against the 23 shipped programs
    (:func:`nctwin.paths.nist_dir`)."""
    folder = nist_dir()
    programs = {p.name: p.read_text() for p in sorted((folder / "nc").glob("*.NC"))}
    return runs_table(sorted((folder / "logs").glob("*.txt.gz")), programs)
