"""The Hurcos' calibrations and networks on a reader's program (the real-machine chapter's
"Your program" section). Neither machine ran it, so there is no truth: the section shows what
each method predicts, and the calibrated estimate's interval from the chapter's held-out errors.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from ..controls import SequenceControl
from ..estimate import CycleTime, cycle_time
from ..gcode import parse
from ..runtimes import motion_window, timed_lines
from . import nist_learned
from .nist_hurco import MACHINES, _held_out
from .your_program import ProgramResult, block_feeds, run_program

__all__ = ["YOUR_METHODS", "your_program"]

#: The analytic methods :func:`your_program` runs, by the profile's method names (``None``:
#: each fold's calibrated choice).
YOUR_METHODS = {"calibrated": None, "block_overlap": "block_overlap", "cam": "cam"}


def _fold_times(tp, lines) -> tuple[dict[str, dict[str, list[CycleTime]]], tuple[str, ...]]:
    """Per machine and method, each fold's :class:`~nctwin.estimate.CycleTime` of ``tp`` (in
    the order of the machine's folds), and the networks' domain notes."""
    window = motion_window(tp, lines)
    out, notes = {}, ()
    for name in MACHINES:
        _, cals = _held_out(name)
        times = {label: [cycle_time(tp, cal.profile(m)) for cal in cals.values()]
                 for label, m in YOUR_METHODS.items()}  # fmt: skip
        nets, outside = nist_learned.program_times(name, tp, window)
        none = f"{name}: the learned methods not run: no move from the first cut to the M30"
        notes += outside if nets else (f"{none} for the networks to time.",)
        for method in nist_learned.METHODS if nets else ():
            times[method] = [
                _learned(ct, nets[(file, method)], window, cal.sequence, method)
                for (file, cal), ct in zip(cals.items(), times["calibrated"], strict=True)
            ]
        out[name] = times
    return out, notes


def _learned(
    ct: CycleTime, net_s: np.ndarray, window: np.ndarray, sequence: SequenceControl, method: str
) -> CycleTime:
    """The calibrated fold's ``ct`` with the networks' time of each block of the ``window``
    (``net_s``, shape (N,)) in place of its own; the window's dwells, the blocks outside it
    and the non-motion times of the fold's ``sequence`` stay, as in the chapter's table
    (:func:`~nctwin.chapters.nist_hurco.method_rows`)."""
    est = ct.estimate
    block_s = np.where(window, est.toolpath.dwell_s + net_s, est.block_times_s)
    return CycleTime.of(replace(est, method=method, block_times_s=block_s), sequence)


def _median(cts: list[CycleTime]) -> CycleTime:
    """The fold of the median cycle time (the upper middle one of an even count)."""
    cycle = np.array([ct.cycle_time_s for ct in cts])
    return cts[int(np.argsort(cycle, kind="stable")[len(cycle) // 2])]


def your_program(path, table: pd.DataFrame) -> ProgramResult:
    """A reader's program on each Hurco as the chapter's methods predict it, with the chapter's
    interval; no truth (neither machine ran it).

    Each fold of :func:`~nctwin.chapters.nist_hurco.method_rows` (a calibration on the
    machine's logs with one program held out) predicts the program as its profile does
    (:meth:`nctwin.calibrate.Calibration.profile`, :func:`nctwin.estimate.cycle_time`, rapid and
    feed at 100 %): the calibrated choice, Lee et al.'s block overlap with the fold's
    constants, and CAM. The learned methods are the fold's networks as trained for the chapter
    (:func:`nctwin.chapters.nist_learned.program_times`, the mean of the five seeds): their
    time of each block from the first cut to the M30 replaces the calibrated fold's, the rest
    (dwells, tool changes, spindle starts, the approach) stays the calibrated fold's, as in the
    chapter's table. The table shows the median over the folds of each time. The calibrated
    estimate's interval is :func:`~nctwin.chapters.nist_hurco.interval_table`'s for a program
    no fold held out: half-width the largest absolute error of the machine's held-out
    programs, nominal :math:`n/(n+1)` with :math:`n` programs (where the errors are
    exchangeable).

    Parameters
    ----------
    path : str or path-like
        A G-code file.
    table : pandas.DataFrame
        :func:`~nctwin.chapters.nist_hurco.held_out_table`, for the interval.

    Returns
    -------
    ProgramResult
        ``times``: a row per machine, time (``motion``, from the first spindle start to the
        last stop, where the program starts the spindle; ``cycle``) and method:
        ``predicted_s``, and for the calibrated estimate ``low_s``, ``high_s``,
        ``half_width_pct``, ``nominal_pct``. ``feeds``: the average feed per G-line on each
        machine of the calibrated estimate (``<machine>_mm_s``) and of each learned method
        (``<machine> <method>_mm_s``), each the fold's of the median cycle time.
    """

    def method(text: str, source: str) -> ProgramResult:
        tp = parse(text, source=source)
        folds, outside = _fold_times(tp, timed_lines(tp, text, Path(source).name))
        rows, block_s = [], {}
        for name, times in folds.items():
            held = table[(table["machine"] == name) & (table["method"] == "calibrated")]
            for label, cts in times.items():
                col = name if label == "calibrated" else f"{name} {label}"
                if label in ("calibrated", *nist_learned.METHODS):
                    block_s[f"{col}_mm_s"] = _median(cts).estimate.block_times_s
                for kind, err in (("motion", "error_pct"), ("cycle", "cycle_error_pct")):
                    values = [ct.motion_time_s if kind == "motion" else ct.cycle_time_s
                              for ct in cts]  # fmt: skip
                    if any(v is None for v in values):
                        continue
                    p = float(np.median(values))
                    row = {"machine": name, "time": kind, "method": label, "predicted_s": p}
                    if label == "calibrated":
                        w = float(held[err].abs().max())
                        row |= {"low_s": p * (1 - w / 100), "high_s": p * (1 + w / 100),
                                "half_width_pct": w,
                                "nominal_pct": 100 * len(held) / (len(held) + 1)}  # fmt: skip
                    rows.append(row)
        notes = ("No truth: neither Hurco ran this program. The learned methods' networks are "
                 "the chapter's, trained on the logs of the held-out folds, never on this "
                 "program; they time its moves from the first cut to the M30, the rest is the "
                 "calibrated fold's.",
                 *outside)  # fmt: skip
        times = pd.DataFrame(rows).sort_values(["time", "machine"], kind="stable")
        return ProgramResult(Path(source).name, times.reset_index(drop=True),
                             block_feeds(tp.lengths_mm, block_s), notes)  # fmt: skip

    return run_program(path, method)
