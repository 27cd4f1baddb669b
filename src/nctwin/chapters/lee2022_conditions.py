"""The conditions of Lee et al. (2022)'s experiment (Sec. 3-4) beside the chapter's
(:mod:`nctwin.chapters.lee2022`): the in-position times, the test piece's run time and the
parameter sets, read from ``data/papers/lee2022_*.csv``, measured before the estimator runs."""

from __future__ import annotations

import math

import numpy as np

from ..controls import AccDecControl, FanucControl
from ..kernel.fanuc import FanucRun
from ..machine import Machine
from ..report.conditions import Condition
from ..report.papers import load_paper_table
from .lee2022 import TEST_PIECE

__all__ = ["INPOS_TOL_PCT", "RUN_TIME_TOL_PCT", "paper_conditions"]

#: Tolerance (%) of a measured in-position time or run time around the paper's, stated before
#: looking: the paper's in-position times are means of five runs, its run time one run.
INPOS_TOL_PCT = 20.0
RUN_TIME_TOL_PCT = 10.0


def paper_conditions(
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
    inpos: dict[int, np.ndarray],
    runs: dict[tuple[str, int], FanucRun],
) -> list[Condition]:
    """The paper's experiment (Sec. 3-4) beside ours, per parameter set, the paper's values read
    from ``data/papers/lee2022_*.csv``; nothing here runs the estimator.

    * ``inpos_{x,y,z}``: the in-position time of each axis measured once on the truth
      (:func:`~nctwin.chapters.lee2022.measure_inposition`, the first set) within
      :data:`INPOS_TOL_PCT` of the paper's;
    * ``test_piece_time_set<s>``: the test piece's run time on the truth within
      :data:`RUN_TIME_TOL_PCT` of the paper's measured time;
    * ``test_piece_over_30min_set<s>``: the test piece runs longer than the paper's lower bound
      (Sec. 4);
    * ``atr``, ``as``, ``at`` (``_set<s>``): the time constants of both controls, exactly the
      paper's; ``rapid_set1``, ``rapid_linear_set1``: the rapid feed and its type, set 1 only
      (set 2 restates neither).

    Parameters
    ----------
    machine : Machine
    sets : dict
        :func:`parameter_sets`.
    inpos : dict
        ``param_set -> ndarray`` (3,), s (:func:`measure_inposition`).
    runs : dict
        :func:`truth_runs`.

    Returns
    -------
    list of Condition
    """
    val = load_paper_table("lee2022_validation").set_index("param_set")
    ref_inpos = load_paper_table("lee2022_inposition").set_index("axis")["inpos_ms"]
    summary = load_paper_table("lee2022_summary").set_index("quantity")
    over_min = float(summary.loc["program_cycle_time", "value"])
    first = next(iter(sets))
    out = [Condition(f"inpos_{a.lower()}", f"Sec. 3: in-position time of {a}, measured once "
                     f"(within {INPOS_TOL_PCT:g} %)", float(ref_inpos[a]), 1000 * inpos[first][i],
                     "ms", tol_pct=INPOS_TOL_PCT) for i, a in enumerate("XYZ")]  # fmt: skip
    for s, (model, truth) in sets.items():
        row = val.loc[s]
        run_s = runs[TEST_PIECE, s].cycle_time_s
        out += [
            Condition(f"test_piece_time_set{s}", f"Sec. 3: the test piece's measured run time, set "
                      f"{s} (within {RUN_TIME_TOL_PCT:g} %)", row.measured_s, run_s, "s",
                      tol_pct=RUN_TIME_TOL_PCT),
            Condition(f"test_piece_over_30min_set{s}", f"Sec. 4: the test piece runs over "
                      f"{over_min:g} min, set {s}", over_min, run_s / 60, "min", low=over_min),
        ]  # fmt: skip
        for name, label, col, attr in (("atr", "ATR", "atr_ms", "rapid_time_constant_s"),
                                       ("as", "As", "as_ms", "rapid_bell_s"),
                                       ("at", "AT", "at_ms", "cut_time_constant_s")):  # fmt: skip
            both = {getattr(model, attr), getattr(truth, attr)}
            ours = 1000 * both.pop() if len(both) == 1 else math.nan
            out.append(Condition(f"{name}_set{s}", f"Sec. 3: {label}, set {s} "
                                 "(estimator and truth)", getattr(row, col), ours, "ms",
                                 tol_pct=0.0))  # fmt: skip
    row = val.loc[1]
    out += [
        Condition("rapid_set1", "Sec. 3: rapid feed, set 1", row.rapid_mm_min,
                  60 * machine.rapid_feed_mm_s, "mm/min", tol_pct=0.01),
        Condition("rapid_linear_set1", "Sec. 3: linear-interpolation-type rapids, set 1 (1: yes)",
                  float(row.rapid_type == "linear"), float(sets[1][1].rapid_type == "linear"),
                  low=1.0),
    ]  # fmt: skip
    return out
