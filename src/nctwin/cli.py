"""The ``nctwin`` command line.

``nctwin estimate PROGRAM [--machine NAME]
[--method cam|kernel|block_overlap|planner|bilstm|axis_nn] [--json]`` prints the cycle time of
a part program (by default with :func:`nctwin.estimate.default_method`); ``nctwin simulate
PROGRAM [--machine NAME] [--plot feed.png] [--csv motion.csv] [--json]`` interpolates it on the
FIR kernel; ``nctwin machines`` lists the shipped machine profiles. Bad input ends with exit
code 2 and one line ``file:line: reason`` on standard error, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from . import __version__
from .estimate import METHODS, default_method, estimate
from .estimate.kernel import fir_settings
from .gcode import GCodeError, parse_file
from .kernel import fir
from .machine import DEFAULT_MACHINE, available_machines, load_machine

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="nctwin", description=__doc__.split("\n\n")[0])
    p.add_argument("--version", action="version", version=f"nctwin {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    e = sub.add_parser("estimate", help="estimate the cycle time of a part program")
    _program_args(e)
    e.add_argument(
        "--method",
        default=None,
        choices=sorted(METHODS),
        help="estimator (default: the best one a chapter found for the machine, cam for most; "
        "bilstm and axis_nn need a machine with recordings: linuxcnc_sim)",
    )
    e.add_argument("--json", action="store_true", help="print machine-readable JSON")

    m = sub.add_parser("simulate", help="interpolate a part program on the FIR kernel")
    _program_args(m)
    m.add_argument("--plot", metavar="PNG", help="write commanded vs actual feed over time")
    m.add_argument("--csv", metavar="CSV", help="write the sampled motion")
    m.add_argument("--json", action="store_true", help="print machine-readable JSON")

    sub.add_parser("machines", help="list the shipped machine profiles")
    return p


def _program_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", help="G-code file")
    p.add_argument(
        "--machine",
        default=DEFAULT_MACHINE,
        help=f"shipped profile name or .toml path (default: {DEFAULT_MACHINE})",
    )
    p.add_argument(
        "--units",
        default="mm",
        choices=("mm", "inch"),
        help="units before the program's own G20/G21 (default: mm)",
    )
    p.add_argument(
        "--dwell-p-unit",
        default="s",
        choices=("s", "ms"),
        help="unit of P in G4: s (RS274/NGC, LinuxCNC) or ms (Fanuc)",
    )


def _format_duration(seconds: float) -> str:
    m, s = divmod(seconds, 60.0)
    h, m = divmod(int(m), 60)
    return f"{h}:{m:02d}:{s:04.1f}"


def _load(args: argparse.Namespace):
    """The machine and the parsed program named on the command line."""
    machine = load_machine(args.machine)
    tp = parse_file(args.program, units=args.units, dwell_p_unit=args.dwell_p_unit)
    return machine, tp


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


def _common_rows(summary: dict, machine_note: str = "") -> list[tuple[str, str]]:
    t = summary["cycle_time_s"]
    return [
        ("program", summary["program"]),
        ("machine", summary["machine"] + machine_note),
        ("cycle time", f"{t:.3f} s  ({_format_duration(t)})"),
        ("path length", f"{summary['length_mm']:.3f} mm"),
        ("blocks", str(summary["blocks"])),
    ]


def _estimate(args: argparse.Namespace) -> int:
    machine, tp = _load(args)
    result = estimate(tp, machine, args.method or default_method(machine))
    summary = {"program": args.program, **result.summary()}
    rows = _common_rows(summary)
    rows.insert(2, ("method", result.method))
    table = [f"\n  {'kind':<8} {'blocks':>8} {'length_mm':>12} {'time_s':>10}"] + [
        f"  {kind:<8} {r['blocks']:>8d} {r['length_mm']:>12.3f} {r['time_s']:>10.3f}"
        for kind, r in summary["by_kind"].items()
        if r["blocks"]
    ]
    return _report(summary, rows, table, args.json)


def _simulate(args: argparse.Namespace) -> int:
    machine, tp = _load(args)
    motion = fir.run(tp, machine, fir_settings(machine))
    summary = {
        "program": args.program,
        "machine": machine.name,
        "kernel": "fir",
        "cycle_time_s": motion.cycle_time_s,
        "length_mm": tp.length_mm,
        "blocks": len(tp),
        "samples": len(motion),
        "period_s": motion.period_s,
        "max_speed_mm_s": float(motion.speed_mm_s.max(initial=0.0)),
    }
    if args.csv:
        motion.to_frame().to_csv(args.csv, index=False, float_format="%.6f")
        summary["csv"] = args.csv
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .report.plots import feed_profile

        ax = feed_profile(motion, tp, machine, title=f"{args.program} on {machine.name}")
        ax.figure.savefig(args.plot, dpi=120)
        summary["plot"] = args.plot
    rows = _common_rows(summary, " (FIR kernel)")
    rows.append(("samples", f"{len(motion)} at {motion.period_s * 1e3:g} ms"))
    rows.append(("max speed", f"{summary['max_speed_mm_s']:.3f} mm/s"))
    rows += [("wrote", summary[key]) for key in ("csv", "plot") if key in summary]
    return _report(summary, rows, [], args.json)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "machines":
            for name in available_machines():
                print(f"{name:<16} {load_machine(name).description}")
            return 0
        if args.command == "simulate":
            return _simulate(args)
        return _estimate(args)
    except GCodeError as exc:
        where = f"{exc.source}:{exc.line}" if exc.line else f"{exc.source}"
        print(f"{where}: {exc.reason}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into a pager or head that stopped reading
        sys.stderr.close()
        return 0
    except ValueError as exc:
        print(f"nctwin: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # an output file that cannot be written
        print(f"nctwin: {exc.filename}: {exc.strerror}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
