"""The ``nctwin`` command line: ``estimate``, ``simulate``, ``machines`` and ``calibrate``.

``nctwin estimate PROGRAM`` prints the cycle time of a part program (by default with the machine
profile's ``default_method``), with the non-motion times of the profile's ``[control.sequence]``,
the motion time between spindle starts and stops, a breakdown and the panel's overrides
(:mod:`nctwin.estimate.cycle`); ``nctwin simulate PROGRAM`` interpolates it on the FIR kernel
(the profile's ``[control.fir]``) and can write the feed plot and the sampled motion; ``nctwin
machines`` lists the shipped machine profiles; ``nctwin calibrate`` fits a profile's control to
its recordings, or a real machine to its MTConnect logs (:mod:`nctwin.calibrate`), and writes it
into a profile file. ``-`` reads the program from
standard input. Bad input ends with exit code 2 and one line on standard error, never a
traceback: ``file:line: reason`` for a line of the program that cannot be read (one such line
per error the reader lists), ``file: reason`` for a file that is not a program (absent, a
directory, binary, no motion), ``nctwin: reason`` for the rest (a bad machine profile or
argument, an output file that cannot be written).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from collections.abc import Sequence
from datetime import date
from pathlib import Path

import numpy as np

from . import __version__
from .estimate import METHODS, cycle_time
from .estimate.cycle import OVERRIDE_MAX_PCT
from .estimate.task_waits import pause_count
from .gcode import READERS, GCodeError, read
from .kernel import fir
from .machine import DEFAULT_MACHINE, Machine, Profile, available_machines, load_profile
from .motion import Motion
from .toolpath import MotionKind, Toolpath

__all__ = ["FEED_UNITS", "InputError", "main", "program_units"]

DESCRIPTION = """\
Cycle time and motion of a part program (G-code) on a virtual machine tool:
estimated by one of several methods (analytic, simulated, learned), or simulated
on the FIR kernel with a plot of the feed.

A program is a file, or - for standard input. Bad input ends with exit code 2 and
one line on standard error: file:line: reason for a line of the program that
cannot be read, file: reason for a file that is not a program, nctwin: reason
for the rest.

Programs are read by nctwin's own fast reader; what only LinuxCNC's interpreter
reads (O-word subroutines and loops, #parameters and expressions, cutter
compensation) goes to that interpreter where it is installed (make linuxcnc):
--reader chooses. The output says which reader read the program. On a machine
whose profile has dialect = "fanuc", programs are read as a Fanuc milling control
reads them (M29 rigid tapping, G76 fine boring, P in ms), by nctwin's reader."""

EXAMPLES = """\
examples:
  nctwin estimate part.nc                          cycle time on the default machine
  nctwin estimate part.nc --method kernel          simulated on the FIR kernel
  nctwin estimate part.nc --machine fanuc_0i_testbed --method block_overlap --json
  nctwin estimate part.nc --machine linuxcnc_sim   LinuxCNC: its chapter's best method
  cat part.nc | nctwin estimate -                  the program from standard input
  nctwin estimate part.ngc --reader native         refuse what only LinuxCNC reads
  nctwin simulate part.nc --plot feed.png --csv motion.csv
  nctwin machines"""

ESTIMATE_EXAMPLES = """\
methods:
  cam            programmed feeds, no acceleration (what a CAM system prints)
  kernel         simulated on the FIR kernel, times between junction points
  block_overlap  Lee et al. 2022: acc/dec time constants and block overlap
  planner        a LinuxCNC-like look-ahead planner with blend arcs
  bilstm         Chien et al. 2023's BiLSTM, trained on LinuxCNC's recordings
  axis_nn        Sun et al. 2022's per-axis networks, trained on LinuxCNC's recordings
bilstm and axis_nn exist for linuxcnc_sim only; they never predict a move faster than its
length over its feed within the machine's limits (the physical floor), and say how many
moves they raised to it.

The cycle time is program start to end: the method's motion plus, where the profile has a
[control.sequence] table, its tool changes (M6), spindle starts (M3/M4 at the S in force),
optional stops (M1 outside a tool change) and program start and end. The motion time runs,
for each spindle start, from the first move after it to the M5 (or M6, M2, M30) that stops
it, summed; none where the program starts no spindle. The breakdown splits the cycle time.
A program pause (M0, M1) between moves stops the tool; the operator's wait that follows has no
defined time and is not counted (a "pauses" line says how many).

examples:
  nctwin estimate part.nc
  nctwin estimate part.nc --method kernel --json
  nctwin estimate part.nc --machine hurco.toml --feed-override 50 --rapid-override 25
  nctwin estimate part.nc --machine linuxcnc_sim --method bilstm
  nctwin estimate part.nc --machine own_machine.toml
  nctwin estimate part.ngc --reader linuxcnc       subroutines, #parameters, G41/G42
  nctwin estimate part.ngc --tool-table tool.tbl   the tools of its T words (LinuxCNC .tbl)
  cat part.nc | nctwin estimate -"""

CALIBRATE_EXAMPLES = """\
examples:
  nctwin calibrate Box-OP*-Hurco02-*.txt.gz --programs nc/ --output hurco02.toml
  nctwin calibrate --recordings linuxcnc --machine linuxcnc_sim \\
      --output data/machines/linuxcnc_sim.toml      (make calibrate)"""

SIMULATE_EXAMPLES = """\
The plot has two panels: the feed over time, scaled to the cutting moves (rapids
clipped), and the tool path in XY coloured by the simulated feed. Feeds are in the
program's units (mm/min after G21, in/min after G20) unless --units says otherwise.

examples:
  nctwin simulate part.nc
  nctwin simulate part.nc --plot feed.png
  nctwin simulate part.nc --plot feed.png --units mm/s --csv motion.csv
  nctwin simulate part.nc --machine paper1_sim --json"""

#: Feed units of ``nctwin simulate --units``: factor from mm/s, length unit, factor from mm.
FEED_UNITS = {
    "mm/min": (60.0, "mm", 1.0),
    "in/min": (60.0 / 25.4, "in", 1.0 / 25.4),
    "mm/s": (1.0, "mm", 1.0),
}

#: Most samples a plot draws (longer motions are thinned evenly).
PLOT_MAX_SAMPLES = 50_000

#: Feed axis of the plot: this much above the highest cutting feed.
PLOT_HEADROOM = 1.1

_UNITS_WORD = re.compile(r"(?<![A-Z])G0*2([01])(?![0-9.])", re.IGNORECASE)
_COMMENT = re.compile(r"\([^)\n]*\)|;[^\n]*")


class InputError(ValueError):
    """A program file that is not a program: absent, a directory, binary, or without motion.

    Its message starts with the file's name.
    """


class _Parser(argparse.ArgumentParser):
    """Usage errors in one line, ``nctwin: reason (see nctwin ... --help)``, exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"nctwin: {message} (see {self.prog} --help)\n")


class _Stages:
    """A progress bar over named stages on standard error, only where it is a terminal."""

    def __init__(self, stages: Sequence[str], enabled: bool) -> None:
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=len(stages), file=sys.stderr, leave=False, bar_format=(
                "{desc:<28} {bar} {n_fmt}/{total_fmt} [{elapsed}]"))  # fmt: skip
        self.started = False

    def __call__(self, stage: str) -> None:
        """Begin ``stage`` (the previous one is done)."""
        if self.bar is None:
            return
        self.bar.set_description_str(stage, refresh=False)
        if self.started:
            self.bar.update(1)
        self.started = True
        self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _parser() -> argparse.ArgumentParser:
    fmt = argparse.RawDescriptionHelpFormatter
    p = _Parser(prog="nctwin", description=DESCRIPTION, epilog=EXAMPLES, formatter_class=fmt)
    p.add_argument("--version", action="version", version=f"nctwin {__version__}")
    sub = p.add_subparsers(title="commands", dest="command", required=True, metavar="COMMAND")

    e = sub.add_parser(
        "estimate",
        help="estimate the cycle time of a part program",
        description="Estimate the cycle time of a part program.",
        epilog=ESTIMATE_EXAMPLES,
        formatter_class=fmt,
    )
    _program_args(e)
    e.add_argument(
        "--method",
        default=None,
        choices=sorted(METHODS),
        help="estimator (default: the machine profile's default_method; each needs its control "
        "table in the profile; bilstm and axis_nn need a profile with recordings: linuxcnc_sim)",
    )
    for name, what in (("rapid", "the machine's rapid feed"), ("feed", "the programmed feeds")):
        e.add_argument(
            f"--{name}-override",
            type=_percent,
            default=100.0,
            metavar="PCT",
            help=f"{name} override: scales {what}, in (0, {OVERRIDE_MAX_PCT:g}] %% (default: "
            "100; the machine's limits still hold)",
        )
    e.add_argument("--json", action="store_true", help="print machine-readable JSON")

    m = sub.add_parser(
        "simulate",
        help="interpolate a part program on the FIR kernel",
        description="Interpolate a part program on the FIR kernel: cycle time, samples,\n"
        "the feed plot and the sampled motion.",
        epilog=SIMULATE_EXAMPLES,
        formatter_class=fmt,
    )
    _program_args(m)
    m.add_argument("--plot", metavar="PNG", help="write the feed over time and over the path")
    m.add_argument("--csv", metavar="CSV", help="write the sampled motion")
    m.add_argument(
        "--units",
        choices=tuple(FEED_UNITS),
        default=None,
        help="feed units of the plot and the output (default: the program's, mm/min or in/min)",
    )
    m.add_argument("--json", action="store_true", help="print machine-readable JSON")

    sub.add_parser(
        "machines",
        help="list the shipped machine profiles",
        description="List the shipped machine profiles (names for --machine).",
        formatter_class=fmt,
    )

    c = sub.add_parser(
        "calibrate",
        help="calibrate a machine from its logs or recordings, into a profile file",
        description="Calibrate a machine into a profile file, with a comment that says what it\n"
        "was fitted to, when, and the residual.\n"
        "From MTConnect logs: the valid runs of one machine give its rapid feed, its\n"
        "non-motion times ([control.sequence]) and the motion model that fits them best.\n"
        "From shipped recordings (--recordings): the FIR kernel's [control.fir].",
        epilog=CALIBRATE_EXAMPLES,
        formatter_class=fmt,
    )
    c.add_argument("logs", nargs="*", metavar="LOG", help="MTConnect logs of one machine "
                   "(.txt or .txt.gz)")  # fmt: skip
    c.add_argument(
        "--programs",
        metavar="DIR",
        help="folder of the programs the logs ran (default: the shipped NIST programs)",
    )
    c.add_argument(
        "--recordings",
        help="instead of logs: the shipped recordings the profile names (its recordings key)",
    )
    c.add_argument(
        "--machine",
        help="with --recordings: shipped profile name or .toml path of the recorded machine",
    )
    c.add_argument(
        "--output",
        required=True,
        metavar="TOML",
        help="profile file to write (its name, without .toml, names the machine for logs)",
    )
    return p


def _percent(text: str) -> float:
    """An override of the command line (%), in (0, :data:`OVERRIDE_MAX_PCT`]."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 < value <= OVERRIDE_MAX_PCT:
        raise argparse.ArgumentTypeError(
            f"{text} is out of range: allowed (0, {OVERRIDE_MAX_PCT:g}] %"
        )
    return value


def _program_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", help="G-code file, or - for standard input")
    p.add_argument(
        "--machine",
        default=DEFAULT_MACHINE,
        help=f"shipped profile name (see nctwin machines) or .toml path (default: "
        f"{DEFAULT_MACHINE})",
    )
    p.add_argument(
        "--input-units",
        default="mm",
        choices=("mm", "inch"),
        help="units before the program's own G20/G21 (default: mm)",
    )
    p.add_argument(
        "--dwell-p-unit",
        choices=("s", "ms"),
        help="unit of P in G4: s (RS274/NGC, LinuxCNC) or ms (Fanuc; native reader only); "
        'default: s, ms on a machine whose profile has dialect = "fanuc"',
    )
    p.add_argument(
        "--reader",
        default="auto",
        choices=READERS,
        help="G-code reader: native (fast, the RS274/NGC a CAM post writes), linuxcnc "
        "(LinuxCNC's own interpreter: subroutines, parameters, cutter compensation; needs make "
        "linuxcnc) or auto (native, LinuxCNC's interpreter for what only it reads; default)",
    )
    p.add_argument(
        "--tool-table",
        metavar="TBL",
        help="LinuxCNC tool table (.tbl) for tool lengths (G43 H) and diameters (G41/G42 D) "
        "(default: the machine profile's tool_table, LinuxCNC's sim table for linuxcnc_sim; "
        "without one, one tool, T1, of size 0)",
    )


def _format_duration(seconds: float) -> str:
    m, s = divmod(seconds, 60.0)
    h, m = divmod(int(m), 60)
    return f"{h}:{m:02d}:{s:04.1f}"


def _read_program(name: str) -> tuple[str, str]:
    """The text of the program named on the command line and its name for messages.

    ``-`` is standard input (``<stdin>``). Text is UTF-8, or Latin-1 where it is not.

    Raises
    ------
    InputError
        If the file cannot be read, is a directory or holds binary data (NUL bytes).
    """
    if name == "-":
        source = "<stdin>"
        stream = getattr(sys.stdin, "buffer", None)
        data = stream.read() if stream is not None else sys.stdin.read().encode()
    else:
        source, p = name, Path(name)
        if p.is_dir():
            raise InputError(f"{source}: is a directory, not a program")
        try:
            data = p.read_bytes()
        except OSError as exc:
            raise InputError(f"{source}: cannot read the file: {exc.strerror or exc}") from None
    if b"\0" in data:
        raise InputError(f"{source}: binary data (NUL bytes), not a G-code program")
    try:
        return data.decode("utf-8"), source
    except UnicodeDecodeError:
        return data.decode("latin-1"), source


def program_units(text: str, default: str = "mm") -> str:
    """``"inch"`` or ``"mm"``: the first G20 or G21 of the program outside comments, else
    ``default`` (a program that changes units is labelled by its first)."""
    match = _UNITS_WORD.search(_COMMENT.sub(" ", text))
    if match is None:
        return default
    return "inch" if match.group(1) == "0" else "mm"


def _load(args: argparse.Namespace, stage: _Stages) -> tuple[Profile, Toolpath, str, str]:
    """The machine profile, the parsed program, its text and the reader that read it (``native`` or
    ``linuxcnc``; subroutine files are looked up beside the program).

    Raises
    ------
    InputError
        If the program has no motion (no move of non-zero length and no dwell).
    """
    stage("machine")
    profile = load_profile(args.machine)
    stage("read")
    text, source = _read_program(args.program)
    stage("parse")
    kwargs = {"source": source, "units": args.input_units, "dwell_p_unit": args.dwell_p_unit}
    if profile.dialect != "rs274ngc":  # (the default keeps LinuxCNC's interpreter in reach)
        kwargs["dialect"] = profile.dialect
    if args.program != "-" and args.reader != "native":
        kwargs["folder"] = Path(args.program).resolve().parent
    if args.tool_table is not None:
        table = Path(args.tool_table)
        if not table.is_file():
            raise InputError(f"{args.tool_table}: no such tool table file")
        kwargs["tool_table"] = args.tool_table
    elif profile.tool_table is not None:
        kwargs["tool_table"] = profile.tool_table
    result = read(text, reader=args.reader, **kwargs)
    tp = result.toolpath
    if not ((tp.lengths_mm > 0).any() or (tp.dwell_s > 0).any()):
        raise InputError(f"{source}: no motion")
    return profile, tp, text, result.reader


def _report(summary: dict, rows: list[tuple[str, str]], extra: list[str], as_json: bool) -> int:
    """Print ``summary`` as JSON, or ``rows`` as an aligned table followed by ``extra`` lines."""
    if as_json:
        print(json.dumps(summary, indent=2))
        return 0
    for key, value in rows:
        print(f"{key:<12} {value}")
    for line in extra:
        print(line)
    return 0


#: How the output names a reader.
_READER_NAMES = {"native": "native", "linuxcnc": "LinuxCNC's interpreter"}


def _common_rows(summary: dict, machine_note: str = "") -> list[tuple[str, str]]:
    t = summary["cycle_time_s"]
    return [
        ("program", summary["program"]),
        ("reader", _READER_NAMES[summary["reader"]]),
        ("machine", summary["machine"] + machine_note),
        ("cycle time", f"{t:.3f} s  ({_format_duration(t)})"),
        ("path length", f"{summary['length_mm']:.3f} mm"),
        ("blocks", str(summary["blocks"])),
    ]


def _program_name(args: argparse.Namespace) -> str:
    return "<stdin>" if args.program == "-" else args.program


def _estimate(args: argparse.Namespace, enabled: bool) -> int:
    method = args.method
    stage = _Stages(["machine", "read", "parse", "estimate"], enabled)
    try:
        profile, tp, _, reader = _load(args, stage)
        method = method or profile.default_method
        profile.control_for(method)  # a profile without the method's control: one line
        learned = method in ("bilstm", "axis_nn")
        stage(f"estimate: {method}" + (" (trains on first use)" if learned else ""))
        ct = cycle_time(tp, profile, method, rapid_override_pct=args.rapid_override,
                        feed_override_pct=args.feed_override)  # fmt: skip
    finally:
        stage.close()
    result = ct.estimate
    summary = {"program": _program_name(args), "reader": reader, **result.summary()}
    summary.update(ct.summary(), rapid_override_pct=args.rapid_override,
                   feed_override_pct=args.feed_override)  # fmt: skip
    rows = _common_rows(summary)
    rows.insert(3, ("method", result.method))
    motion = ct.motion_time_s
    rows.insert(5, ("motion time", "none (no spindle start)" if motion is None else
                    f"{motion:.3f} s  ({_format_duration(motion)})"))  # fmt: skip
    pauses = pause_count(tp)
    if pauses:  # an operator ends them: no defined time
        rows.insert(6, ("pauses", f"{pauses} M0/M1 between moves: the operator's wait is not "
                                  "counted (the tool stops, then waits 0 s)"))  # fmt: skip
        summary["pauses_not_timed"] = pauses
    if (args.rapid_override, args.feed_override) != (100.0, 100.0):
        rows.insert(6, ("overrides", f"rapid {args.rapid_override:g} %, feed "
                                     f"{args.feed_override:g} %"))  # fmt: skip
    if result.floor_time_s is not None:
        rows.insert(5, ("floor", f"{result.floor_time_s:.3f} s  (every move at its feed)"))
    table = [f"\n  {'kind':<8} {'blocks':>8} {'length_mm':>12} {'time_s':>10}"] + [
        f"  {kind:<8} {r['blocks']:>8d} {r['length_mm']:>12.3f} {r['time_s']:>10.3f}"
        for kind, r in summary["by_kind"].items()
        if r["blocks"]
    ]
    n = ct.counts
    table.append(f"\n  {'breakdown':<18} {'time_s':>10}")
    table += [
        f"  {key:<18} {t:>10.3f}" + (f"  ({n[key]})" if key in n else "")
        for key, t in ct.breakdown.items()
    ]
    if result.clamped_moves:
        n = result.clamped_moves
        table.append(
            f"\n{n} move{'s' if n != 1 else ''} raised to the physical floor (length / feed): "
            f"{result.unclamped_time_s:.3f} s predicted before"
        )
    return _report(summary, rows, table, args.json)


def _feed_plot(motion: Motion, tp: Toolpath, machine: Machine, feed_unit: str, title: str):
    """The :class:`~nctwin.report.plots.FeedPlot` of a simulated program, in ``feed_unit``
    (a key of :data:`FEED_UNITS`), thinned to at most :data:`PLOT_MAX_SAMPLES` samples."""
    from .report.plots import FeedPlot

    per_mm_s, length_unit, per_mm = FEED_UNITS[feed_unit]
    step = max(1, math.ceil(len(motion) / PLOT_MAX_SAMPLES))
    idx = np.arange(0, len(motion), step)
    if idx[-1] != len(motion) - 1:
        idx = np.append(idx, len(motion) - 1)
    block = motion.block[idx]
    kind = tp.kind[block]
    rapid = kind == MotionKind.RAPID
    commanded = np.minimum(tp.feed_mm_s[block], machine.max_feed_mm_s)
    commanded = np.where(kind == MotionKind.DWELL, np.nan, commanded)
    actual = motion.speed_mm_s[idx]
    cutting = (tp.kind != MotionKind.RAPID) & (tp.kind != MotionKind.DWELL)
    cutting_feeds = np.minimum(tp.feed_mm_s[cutting], machine.max_feed_mm_s)
    if len(cutting_feeds):
        top_mm_s = float(cutting_feeds.max())
    else:  # only rapids (and dwells): scale to them
        top_mm_s = float(actual.max(initial=0.0)) or machine.rapid_feed_mm_s
    xy_len = np.hypot(*(tp.end_mm[:, :2] - tp.start_mm[:, :2]).T)
    moves = (tp.kind == MotionKind.RAPID) & (xy_len > 0)  # what shows in XY
    rapid_xy = np.stack([tp.start_mm[moves, :2], tp.end_mm[moves, :2]], axis=1) * per_mm
    return FeedPlot(
        t_s=motion.t_s[idx],
        commanded=commanded * per_mm_s,
        actual=actual * per_mm_s,
        rapid=rapid,
        xy=motion.pos_mm[idx, :2] * per_mm,
        rapid_xy=rapid_xy,
        feed_top=PLOT_HEADROOM * top_mm_s * per_mm_s,
        rapid_feed=machine.rapid_feed_mm_s * per_mm_s,
        feed_unit=feed_unit,
        length_unit=length_unit,
        title=title,
    )


def _simulate(args: argparse.Namespace, enabled: bool) -> int:
    stages = ["machine", "read", "parse", "simulate (FIR kernel)"]
    stages += ["plot"] * bool(args.plot) + ["csv"] * bool(args.csv)
    stage = _Stages(stages, enabled)
    try:
        profile, tp, text, reader = _load(args, stage)
        machine = profile.machine
        stage("simulate (FIR kernel)")
        motion = fir.run(tp, machine, profile.control("fir"))
        feed_unit = args.units or (
            "in/min" if program_units(text, args.input_units) == "inch" else "mm/min"
        )
        summary = {
            "program": _program_name(args),
            "reader": reader,
            "machine": machine.name,
            "kernel": "fir",
            "cycle_time_s": motion.cycle_time_s,
            "length_mm": tp.length_mm,
            "blocks": len(tp),
            "samples": len(motion),
            "period_s": motion.period_s,
            "max_speed_mm_s": float(motion.speed_mm_s.max(initial=0.0)),
        }
        if args.plot:
            stage("plot")
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            from .report import plots

            title = f"{_program_name(args)} on {machine.name} (FIR kernel)"
            fig = plots.feed_figure(_feed_plot(motion, tp, machine, feed_unit, title))
            try:
                fig.savefig(args.plot, dpi=120)
            finally:
                plt.close(fig)
            summary["plot"] = args.plot
        if args.csv:
            stage("csv")
            motion.to_frame().to_csv(args.csv, index=False, float_format="%.6f")
            summary["csv"] = args.csv
    finally:
        stage.close()
    per_mm_s = FEED_UNITS[feed_unit][0]
    rows = _common_rows(summary, " (FIR kernel)")
    rows.append(("samples", f"{len(motion)} at {motion.period_s * 1e3:g} ms"))
    rows.append(("max speed", f"{summary['max_speed_mm_s'] * per_mm_s:.1f} {feed_unit}"))
    rows += [("wrote", summary[key]) for key in ("csv", "plot") if key in summary]
    return _report(summary, rows, [], args.json)


def _one_line(message: str) -> str:
    return "; ".join(part.strip() for part in str(message).splitlines() if part.strip())


def _gcode_lines(exc: GCodeError) -> list[str]:
    """One ``file:line: reason`` line per error the reader lists (``file: reason`` without a
    line), then ``... and N more``."""
    out = []
    for e in getattr(exc, "errors", None) or (exc,):
        where = f"{e.source or '<string>'}:{e.line}" if e.line else f"{e.source or '<string>'}"
        out.append(f"{where}: {_one_line(e.reason)}")
    n_more = getattr(exc, "n_more", 0)
    if n_more:
        out.append(f"... and {n_more} more")
    return out


def _calibrate(args: argparse.Namespace) -> int:
    if args.logs and args.recordings:
        raise ValueError("give MTConnect logs or --recordings, not both")
    if args.logs:
        return _calibrate_logs(args)
    if not (args.recordings and args.machine):
        raise ValueError("give MTConnect logs, or --recordings NAME --machine PROFILE")
    from .identify import calibrate_fir

    profile = load_profile(args.machine)
    if profile.recordings != args.recordings:
        raise ValueError(
            f"recordings = {args.recordings!r} is not the machine's: allowed "
            f"{profile.recordings!r} (the recordings key of {args.machine})"
        )
    control, _, provenance = calibrate_fir(args.machine, args.output, today=date.today())
    for line in provenance:
        print(line)
    print(f"[control.fir] of {args.output}: {control}")
    return 0


def _calibrate_logs(args: argparse.Namespace) -> int:
    from .calibrate import calibrate, write_profile
    from .runtimes import machine_runs

    for log in args.logs:
        if not Path(log).is_file():
            raise ValueError(f"{log}: no such log file")
    if args.programs is not None and not Path(args.programs).is_dir():
        raise ValueError(f"--programs {args.programs}: no such folder")
    name = Path(args.output).stem
    times, programs, rapids = machine_runs(name, args.logs, args.programs)
    cal = calibrate(name, times, programs, rapids)
    write_profile(cal, args.output, today=date.today())
    seq = cal.sequence
    print(f"{name}: {len(times)} valid runs of {len(programs)} programs")
    print(f"rapid feed {cal.machine.rapid_feed_mm_s:.2f} mm/s; tool change "
          f"{seq.tool_change_s:.2f} s (first {seq.tool_change_at_s(True):.2f} s); spindle start "
          f"{seq.spindle_start_s:.2f} s + "
          f"{seq.spindle_start_s_per_krpm:.3f} s per 1000 rev/min")  # fmt: skip
    errs = ", ".join(f"{k} {v:.2f} %" for k, v in cal.fit_err_pct.items())
    print(f"motion-time error on these runs: {errs}; best {cal.best}; wrote {args.output}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return exc.code if isinstance(exc.code, int) else 2
    enabled = sys.stderr.isatty() and not getattr(args, "json", False)
    try:
        if args.command == "machines":
            for name in available_machines():
                print(f"{name:<16} {load_profile(name).machine.description}")
            return 0
        if args.command == "simulate":
            return _simulate(args, enabled)
        if args.command == "calibrate":
            return _calibrate(args)
        return _estimate(args, enabled)
    except GCodeError as exc:
        print("\n".join(_gcode_lines(exc)), file=sys.stderr)
        return 2
    except InputError as exc:
        print(_one_line(str(exc)), file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into a pager or head that stopped reading
        sys.stderr.close()
        return 0
    except ValueError as exc:
        print(f"nctwin: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except OSError as exc:  # an output file that cannot be written
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"nctwin: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("nctwin: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
