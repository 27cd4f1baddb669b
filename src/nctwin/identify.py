r"""Machine constants identified from recordings: what a user of a control need not know, fitted
so that a model of it times programs as the control does.

* :func:`identified_block_overlap_machine`: Lee et al. (2022)'s time constants from a machine's
  acceleration limits;
* :func:`fit_fir`: the FIR kernel's settings (:class:`~nctwin.kernel.fir.FirSettings`) by a
  grid search on recorded cycle times;
* :func:`fit_planner`: the blend-arc planner's six axis limits by least squares on recorded
  cycle times.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from .estimate.blend_planner import blend_planner
from .estimate.kernel import kernel
from .kernel.fir import FirSettings
from .machine import MachineProfile
from .report.tables import error_pct
from .runner import run_tasks
from .toolpath import MotionKind, Toolpath

__all__ = [
    "FIR_FIELDS",
    "PLANNER_FIT_START",
    "PlannerFit",
    "fir_fields",
    "fit_fir",
    "fit_planner",
    "identified_block_overlap_machine",
]


def identified_block_overlap_machine(tp: Toolpath, machine: MachineProfile) -> MachineProfile:
    """``machine`` with Lee et al.'s time constants identified from its acceleration limits.

    A linear acc/dec filter of time constant :math:`A_T` adds :math:`A_T` to a line at feed
    :math:`F`; LinuxCNC, accelerating at :math:`A`, adds :math:`F / A`. So
    :math:`A_T = F / A` with :math:`F` the program's main cutting feed (the one it cuts longest
    at) and :math:`A` the X/Y acceleration, and :math:`A_{TR} = F_r / A`, both rounded to whole
    periods; LinuxCNC has no bell stage and no in-position wait (it blends rapids too).
    """
    a = min(machine.axis_max_acceleration_mm_s2[:2])
    cut = np.isin(tp.kind, (MotionKind.LINEAR, MotionKind.ARC_CW, MotionKind.ARC_CCW))
    feed = np.minimum(tp.feed_mm_s[cut], machine.max_feed_mm_s)
    if feed.size:
        values, inverse = np.unique(feed, return_inverse=True)
        main = values[np.argmax(np.bincount(inverse, weights=tp.lengths_mm[cut]))]
    else:
        main = machine.rapid_feed_mm_s
    ti = machine.period_s

    def periods(t: float) -> float:
        return max(round(t / ti), 1) * ti

    return dataclasses.replace(
        machine,
        cut_time_constant_s=periods(main / a),
        rapid_time_constant_s=periods(machine.rapid_feed_mm_s / a),
        rapid_bell_s=0.0,
        rapid_type="linear",
        inposition_time_s=(0.0, 0.0, 0.0),
    )


#: Names of the :class:`~nctwin.kernel.fir.FirSettings` that :func:`fit_fir` fits, as its grid
#: and trials name them.
FIR_FIELDS = ("fir_t1_s", "fir_t2_s", "fir_acc_scale", "fir_blend_ratio", "fir_block_periods")


def _fir_trial(
    programs: Sequence[tuple[Toolpath, float]], machine: MachineProfile, settings: FirSettings
) -> dict:
    measured = np.array([m for _, m in programs])
    sim = np.array([kernel(tp, machine, settings).cycle_time_s for tp, _ in programs])
    err = error_pct(sim, measured)
    return {
        "score": float(np.abs(np.log(sim / measured)).mean()),
        "mean_err_pct": float(err.mean()),
        "max_err_pct": float(err.max()),
    }


def fit_fir(
    programs: Sequence[tuple[Toolpath, float]],
    machine: MachineProfile,
    grid: dict[str, Sequence[float]],
    *,
    n_jobs: int = 2,
) -> tuple[FirSettings, list[dict]]:
    """Fit the FIR kernel's settings to recorded cycle times by a grid search.

    LinuxCNC has no jerk limit and accelerates at a constant rate; the FIR kernel accelerates at
    :math:`F / T_1` with jerk :math:`F / (T_1 T_2)`, and caps an axis's feed at
    :math:`a_i T_1`. No single (T1, T2) is LinuxCNC, so the kernel's settings
    (:class:`~nctwin.kernel.fir.FirSettings`: time constants, acceleration scale, blend ratio,
    block rate; named :data:`FIR_FIELDS` in the grid and the trials) are fitted: the grid point
    with the lowest mean absolute log ratio of simulated (:func:`nctwin.estimate.kernel.kernel`)
    to recorded cycle time wins.

    Parameters
    ----------
    programs : sequence of (Toolpath, float)
        Training programs and their recorded cycle times.
    machine : MachineProfile
        The recorded machine's profile.
    grid : dict
        Values to try for each field of :data:`FIR_FIELDS`.
    n_jobs : int
        Workers of :func:`nctwin.runner.run_tasks` (one grid point each).

    Returns
    -------
    best : FirSettings
        The best grid point.
    trials : list of dict
        Every grid point with its score, mean and largest absolute error (%).
    """
    if set(grid) != set(FIR_FIELDS):
        raise ValueError(f"grid has keys {sorted(grid)}: allowed exactly {list(FIR_FIELDS)}")
    values = itertools.product(*(grid[n] for n in FIR_FIELDS))
    points = [dict(zip(FIR_FIELDS, v, strict=True)) for v in values]
    tasks = ((programs, machine, _fir_settings(p)) for p in points)
    scores = run_tasks(_fir_trial, tasks, n_jobs=n_jobs)
    trials = [p | r for p, r in zip(points, scores, strict=True)]
    return _fir_settings(min(trials, key=lambda r: r["score"])), trials


def _fir_settings(row: dict) -> FirSettings:
    """The settings of a grid point (:data:`FIR_FIELDS` are the settings' fields, prefixed)."""
    return FirSettings(**{n.removeprefix("fir_"): row[n] for n in FIR_FIELDS})


def fir_fields(settings: FirSettings) -> dict:
    """``settings`` as a grid point of :func:`fit_fir`: :data:`FIR_FIELDS` -> value."""
    return {n: getattr(settings, n.removeprefix("fir_")) for n in FIR_FIELDS}


#: Generic start of :func:`fit_planner`: every axis at this acceleration (mm/s^2) and velocity
#: (mm/s), not the profile's.
PLANNER_FIT_START = (500.0, 100.0)


@dataclass(frozen=True)
class PlannerFit:
    """What :func:`fit_planner` identified.

    Parameters
    ----------
    machine : MachineProfile
        The profile with the identified axis limits.
    limits : DataFrame
        One row per axis and limit: ``axis``, ``limit`` (``acceleration_mm_s2`` or
        ``velocity_mm_s``), ``start``, ``fitted``, ``profile`` (the value the profile had).
    mean_err_pct, max_err_pct : float
        Mean and largest absolute cycle-time error (%) of the fitted planner on the programs.
    evaluations : int
        Planner runs over the programs the fit took.
    """

    machine: MachineProfile
    limits: pd.DataFrame
    mean_err_pct: float
    max_err_pct: float
    evaluations: int


def fit_planner(
    programs: Sequence[tuple[Toolpath, float]],
    machine: MachineProfile,
    start: tuple[float, float] = PLANNER_FIT_START,
) -> PlannerFit:
    r"""Identify the blend-arc planner's axis limits from recorded cycle times.

    The planner's rules are LinuxCNC's (:mod:`nctwin.estimate.blend_planner`); its constants are
    the six axis limits it reads from the profile, :math:`a_{i,\max}` and :math:`v_{i,\max}`
    for X, Y and Z, which a user of a control need not know. They are fitted here, without the
    profile's values, by least squares on the log ratio of planned to recorded cycle time per
    program: scipy's trust-region reflective method on the logarithm of each limit, with
    finite differences of relative step 1e-3, from the generic ``start`` (every axis at the
    same acceleration and velocity). The fit plans each stop with half a servo period, not
    with the tool at rest on a whole period (``stop_periods="mean"``): whole periods make the
    planned time a step function of the limits, which finite differences cannot follow. The
    velocities are bounded by the profile's maximum feed
    (``[TRAJ] MAX_LINEAR_VELOCITY``): an axis limit above the path's is never reached, and no
    recording can tell it. Everything else in the profile (maximum and rapid feed, servo period,
    default tolerance) is kept.

    Parameters
    ----------
    programs : sequence of (Toolpath, float)
        Training programs and their recorded cycle times.
    machine : MachineProfile
        The recorded machine's profile (its axis limits are only reported, not used).
    start : (float, float)
        Acceleration (mm/s^2) and velocity (mm/s) every axis starts from.

    Returns
    -------
    PlannerFit

    Raises
    ------
    ValueError
        If there are no programs, a recorded time is not positive, or ``start`` lies outside
        the bounds (acceleration 10 to 1e5 mm/s^2, velocity 1 mm/s to the maximum feed).
    """
    if not programs:
        raise ValueError("programs is empty: the planner's limits need at least one recording")
    measured = np.array([t for _, t in programs], dtype=float)
    if not (measured > 0).all():
        raise ValueError(f"measured cycle times {measured[measured <= 0][:3]} s: allowed > 0")
    lower = np.log([10.0] * 3 + [1.0] * 3)
    upper = np.log([1e5] * 3 + [machine.max_feed_mm_s] * 3)
    x0 = np.log([start[0]] * 3 + [start[1]] * 3)
    if not ((x0 >= lower) & (x0 <= upper)).all():
        raise ValueError(
            f"start = {start!r} is out of range: allowed acceleration [10, 1e5] mm/s^2, "
            f"velocity [1, {machine.max_feed_mm_s:g}] mm/s"
        )

    def profile(x: np.ndarray) -> MachineProfile:
        e = np.exp(x)
        return dataclasses.replace(
            machine,
            axis_max_acceleration_mm_s2=tuple(float(v) for v in e[:3]),
            axis_max_velocity_mm_s=tuple(float(v) for v in e[3:]),
        )

    def planned_s(m: MachineProfile, stop_periods: str) -> np.ndarray:
        return np.array(
            [blend_planner(tp, m, stop_periods=stop_periods).cycle_time_s for tp, _ in programs]
        )

    def residual(x: np.ndarray) -> np.ndarray:
        return np.log(planned_s(profile(x), "mean") / measured)

    fit = least_squares(residual, x0, bounds=(lower, upper), diff_step=1e-3, method="trf")
    fitted = profile(fit.x)
    err = 100 * np.abs(planned_s(fitted, "whole") / measured - 1)
    limits = pd.DataFrame(
        [{"axis": axis, "limit": limit, "start": s, "fitted": getattr(fitted, field)[i],
          "profile": getattr(machine, field)[i]}
         for limit, field, s in (("acceleration_mm_s2", "axis_max_acceleration_mm_s2", start[0]),
                                 ("velocity_mm_s", "axis_max_velocity_mm_s", start[1]))
         for i, axis in enumerate("XYZ")]
    )  # fmt: skip
    return PlannerFit(fitted, limits, float(err.mean()), float(err.max()), int(fit.nfev))
