r"""Machine constants identified from recordings: what a user of a control need not know, fitted
so that a model of it times programs as the control does.

* :func:`identified_block_overlap`: Lee et al. (2022)'s time constants from a machine's
  acceleration limits;
* :func:`fit_fir`: the FIR kernel's settings (:class:`~nctwin.controls.FirControl`) by a
  grid search on recorded cycle times; :func:`calibrate_fir` fits them to a profile's shipped
  recordings and writes them into the profile's file (``nctwin calibrate``);
* :func:`fit_block_overlap`: Lee et al. (2022)'s cutting time constant by least squares on
  recorded motion times;
* :func:`fit_planner`: the blend-arc planner's six axis limits (or its three accelerations,
  the velocities known) by least squares on recorded cycle times.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import least_squares

from .controls import AccDecControl, FirControl, PlannerControl
from .estimate.blend_planner import blend_planner
from .estimate.block_overlap import block_overlap
from .estimate.kernel import kernel
from .machine import Machine, Profile, profile_path, write_control
from .metrics import error_pct
from .runner import run_tasks
from .toolpath import MotionKind, Toolpath

__all__ = [
    "FIR_FIELDS",
    "FIR_GRID",
    "PLANNER_FIT_START",
    "PlannerFit",
    "at_rapid_override",
    "calibrate_fir",
    "fir_fields",
    "fir_fit_programs",
    "fit_block_overlap",
    "fit_fir",
    "fit_planner",
    "identified_block_overlap",
]


def identified_block_overlap(tp: Toolpath, machine: Machine, period_s: float) -> AccDecControl:
    """The acc/dec control of Lee et al.'s estimator with its time constants identified from
    ``machine``'s acceleration limits, for a control of servo period ``period_s``.

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
    ti = period_s

    def periods(t: float) -> float:
        return max(round(t / ti), 1) * ti

    return AccDecControl(
        period_s=ti,
        cut_time_constant_s=periods(main / a),
        rapid_time_constant_s=periods(machine.rapid_feed_mm_s / a),
        rapid_bell_s=0.0,
        rapid_type="linear",
        inposition_time_s=(0.0, 0.0, 0.0),
    )


#: Largest cutting time constant :func:`fit_block_overlap` tries (s).
BLOCK_OVERLAP_MAX_S = 0.5


def fit_block_overlap(
    programs: Sequence[tuple[Toolpath, float]],
    machine: Machine,
    period_s: float,
    rapid_overrides: Sequence[float] | None = None,
) -> AccDecControl:
    r"""Lee et al. (2022)'s time constants identified from recorded motion times.

    The rapid time constant is :func:`identified_block_overlap`'s, :math:`A_{TR} = F_r / a`
    at 100 % with ``machine``'s X/Y acceleration (a time constant of the control: a rapid
    override lowers the rapid feed, not :math:`A_{TR}`); the cutting time constant
    :math:`A_T`, one for every program, is the whole number of periods in
    (0, :data:`BLOCK_OVERLAP_MAX_S`] (every tenth, then every one near the best of those) of
    least squared relative error of
    :func:`nctwin.estimate.block_overlap.block_overlap`'s time against ``programs``' measured
    ones, each program's rapids at its rapid override (shares, default 1).
    """
    scales = _overrides(rapid_overrides, len(programs))
    base = identified_block_overlap(programs[0][0], machine, period_s)
    machines = [at_rapid_override(machine, k) for k in scales]

    def best(periods: np.ndarray) -> int:
        sse = np.zeros(periods.size)
        for (tp, measured), m in zip(programs, machines, strict=True):
            for i, n in enumerate(periods):
                control = dataclasses.replace(base, cut_time_constant_s=float(n * period_s))
                sse[i] += (block_overlap(tp, m, control).cycle_time_s / measured - 1.0) ** 2
        return int(periods[np.argmin(sse)])

    # every tenth period, then every period within ten of the best of those
    n_max = max(round(BLOCK_OVERLAP_MAX_S / period_s), 1)
    coarse = best(np.arange(1, n_max + 1, 10))
    n = best(np.arange(max(coarse - 9, 1), min(coarse + 9, n_max) + 1))
    return dataclasses.replace(base, cut_time_constant_s=n * period_s)


def at_rapid_override(machine: Machine, share: float) -> Machine:
    """``machine`` at a rapid override of ``share`` (1: 100 %): its rapid feed and its axis
    velocities scaled by it (the accelerations and the maximum feed kept)."""
    if share == 1.0:
        return machine
    return dataclasses.replace(
        machine,
        axis_max_velocity_mm_s=tuple(float(v) * share for v in machine.axis_max_velocity_mm_s),
        rapid_feed_mm_s=machine.rapid_feed_mm_s * share,
    )


def _overrides(rapid_overrides: Sequence[float] | None, n: int) -> np.ndarray:
    """The rapid overrides (shares) of ``n`` programs, checked; all 1 where None."""
    scales = np.ones(n) if rapid_overrides is None else np.asarray(rapid_overrides, float)
    if scales.shape != (n,) or not ((scales > 0) & (scales <= 1)).all():
        raise ValueError(
            f"rapid_overrides {scales.tolist()[:3]}: allowed one per program, in (0, 1]"
        )
    return scales


#: Names of the :class:`~nctwin.controls.FirControl` settings that :func:`fit_fir` fits, as
#: its grid and trials name them.
FIR_FIELDS = ("fir_t1_s", "fir_t2_s", "fir_acc_scale", "fir_blend_ratio", "fir_block_periods")

#: The grid of the FIR kernel's settings :func:`calibrate_fir` searches (and the chapter
#: "Predicting a real controller").
FIR_GRID = {"fir_t1_s": [0.03, 0.045, 0.06, 0.09], "fir_t2_s": [0.003, 0.01],
            "fir_acc_scale": [2.0, 4.0, 8.0], "fir_blend_ratio": [float("inf"), 0.25],
            "fir_block_periods": [0, 2]}  # fmt: skip

#: Every how many-th training recording the fits use (:func:`fir_fit_programs`).
FIT_EVERY = 5


def _fir_trial(
    programs: Sequence[tuple[Toolpath, float]],
    machine: Machine,
    control: FirControl,
    scales: np.ndarray,
) -> dict:
    measured = np.array([m for _, m in programs])
    sim = np.array([kernel(tp, at_rapid_override(machine, k), control).cycle_time_s
                    for (tp, _), k in zip(programs, scales, strict=True)])  # fmt: skip
    err = error_pct(sim, measured)
    return {
        "score": float(np.abs(np.log(sim / measured)).mean()),
        "mean_err_pct": float(err.mean()),
        "max_err_pct": float(err.max()),
    }


def fit_fir(
    programs: Sequence[tuple[Toolpath, float]],
    machine: Machine,
    base: FirControl,
    grid: dict[str, Sequence[float]],
    *,
    n_jobs: int = 2,
    rapid_overrides: Sequence[float] | None = None,
) -> tuple[FirControl, list[dict]]:
    """Fit the FIR kernel's settings to recorded cycle times by a grid search.

    LinuxCNC has no jerk limit and accelerates at a constant rate; the FIR kernel accelerates at
    :math:`F / T_1` with jerk :math:`F / (T_1 T_2)`, and caps an axis's feed at
    :math:`a_i T_1`. No single (T1, T2) is LinuxCNC, so the kernel's settings
    (:class:`~nctwin.controls.FirControl`: time constants, acceleration scale, blend ratio,
    block rate; named :data:`FIR_FIELDS` in the grid and the trials) are fitted: the grid point
    with the lowest mean absolute log ratio of simulated (:func:`nctwin.estimate.kernel.kernel`)
    to recorded cycle time wins.

    Parameters
    ----------
    programs : sequence of (Toolpath, float)
        Training programs and their recorded cycle times.
    machine : Machine
        The recorded machine.
    base : FirControl
        The control whose period and tolerance the fit keeps.
    grid : dict
        Values to try for each field of :data:`FIR_FIELDS`.
    n_jobs : int
        Workers of :func:`nctwin.runner.run_tasks` (one grid point each).
    rapid_overrides : sequence of float, optional
        Per program, the rapid override it ran at as a share (1: 100 %, the default;
        :func:`at_rapid_override`).

    Returns
    -------
    best : FirControl
        ``base`` with the best grid point's settings.
    trials : list of dict
        Every grid point with its score, mean and largest absolute error (%).
    """
    if set(grid) != set(FIR_FIELDS):
        raise ValueError(f"grid has keys {sorted(grid)}: allowed exactly {list(FIR_FIELDS)}")
    values = itertools.product(*(grid[n] for n in FIR_FIELDS))
    points = [dict(zip(FIR_FIELDS, v, strict=True)) for v in values]
    scales = _overrides(rapid_overrides, len(programs))
    tasks = ((programs, machine, _fir_control(base, p), scales) for p in points)
    scores = run_tasks(_fir_trial, tasks, n_jobs=n_jobs)
    trials = [p | r for p, r in zip(points, scores, strict=True)]
    return _fir_control(base, min(trials, key=lambda r: r["score"])), trials


def _fir_control(base: FirControl, row: dict) -> FirControl:
    """``base`` with the settings of a grid point (:data:`FIR_FIELDS` are the control's
    fields, prefixed)."""
    return dataclasses.replace(base, **{n.removeprefix("fir_"): row[n] for n in FIR_FIELDS})


def fir_fields(control: FirControl) -> dict:
    """``control`` as a grid point of :func:`fit_fir`: :data:`FIR_FIELDS` -> value."""
    return {n: getattr(control, n.removeprefix("fir_")) for n in FIR_FIELDS}


def fir_fit_programs(training: Sequence) -> list[tuple[Toolpath, float]]:
    """The recordings the fits use: every :data:`FIT_EVERY`-th of ``training`` (the
    :class:`~nctwin.estimate.learned.MoveData` of the training sets, in their order), as
    (moves, recorded cycle time)."""
    return [(x.moves, x.measured_s) for x in training[::FIT_EVERY]]


def calibrate_fir(
    profile: str | Path, output: str | Path, *, today: date, n_jobs: int = 2
) -> tuple[FirControl, list[dict], list[str]]:
    """Fit the FIR kernel to a profile's shipped recordings and write it into a profile file.

    The programs are :func:`fir_fit_programs` of the profile's training recordings
    (:func:`nctwin.estimate.learned.training_data`), the grid :data:`FIR_GRID`, the period and
    the tolerance those of the profile's ``[control.fir]`` (else of its ``[control.planner]``).
    The best control is written as the ``[control.fir]`` table of ``output`` (a copy of the
    profile's file where ``output`` is another file), with a comment that says which
    recordings, when, and the fit's residual.

    Parameters
    ----------
    profile : str or Path
        A shipped profile's name or a profile file with a ``recordings`` key.
    output : str or Path
        The profile file to write.
    today : date
        Written into the provenance comment.
    n_jobs : int
        Workers of the grid search.

    Returns
    -------
    control : FirControl
    trials : list of dict
        Every grid point (:func:`fit_fir`).
    provenance : list of str
        The comment written above the table.
    """
    from .estimate.learned import training_data

    source = profile_path(profile)
    loaded = Profile.from_toml(source)
    base = loaded.fir
    if base is None:
        planner = loaded.control("planner")
        base = FirControl(period_s=planner.period_s, blend_tol_mm=planner.blend_tol_mm)
    training = training_data(loaded)
    programs = fir_fit_programs(training)
    best, trials = fit_fir(programs, loaded.machine, base, FIR_GRID, n_jobs=n_jobs)
    row = min(trials, key=lambda r: r["score"])
    names = [x.name for x in training[::FIT_EVERY]]
    provenance = [
        "The FIR kernel fitted to the recorded cycle times of this machine: `nctwin calibrate",
        f"--recordings {loaded.recordings}` (nctwin.identify.calibrate_fir), a grid search of "
        f"{np.prod([len(v) for v in FIR_GRID.values()])} points",
        f"(nctwin.identify.FIR_GRID) on {len(programs)} recordings, every {FIT_EVERY}th of the "
        "training sets",
        f"({names[0]} ... {names[-1]}). Residual: cycle time off by "
        f"{row['mean_err_pct']:.2f} % on average, {row['max_err_pct']:.2f} % at worst.",
    ]
    out = Path(output)
    if out.resolve() != source.resolve():
        out.write_text(source.read_text())
    write_control(out, "fir", best, provenance, today=today)
    return best, trials, provenance


#: Generic start of :func:`fit_planner`: every axis at this acceleration (mm/s^2) and velocity
#: (mm/s), not the profile's.
PLANNER_FIT_START = (500.0, 100.0)


@dataclass(frozen=True)
class PlannerFit:
    """What :func:`fit_planner` identified.

    Parameters
    ----------
    machine : Machine
        The machine with the identified axis limits.
    limits : DataFrame
        One row per axis and limit: ``axis``, ``limit`` (``acceleration_mm_s2`` or
        ``velocity_mm_s``), ``start``, ``fitted``, ``profile`` (the value the profile had; a
        velocity held fixed starts, and stays, at it).
    mean_err_pct, max_err_pct : float
        Mean and largest absolute cycle-time error (%) of the fitted planner on the programs.
    evaluations : int
        Planner runs over the programs the fit took.
    """

    machine: Machine
    limits: pd.DataFrame
    mean_err_pct: float
    max_err_pct: float
    evaluations: int


def fit_planner(
    programs: Sequence[tuple[Toolpath, float]],
    machine: Machine,
    control: PlannerControl,
    start: tuple[float, float] = PLANNER_FIT_START,
    *,
    fit_velocities: bool = True,
    rapid_overrides: Sequence[float] | None = None,
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
    recording can tell it. Everything else (the machine's maximum and rapid feed, the control's
    servo period and default tolerance) is kept.

    With ``fit_velocities=False`` only the three accelerations are fitted and the velocities are
    ``machine``'s: a real machine's axis velocities show in its logs (the rapid plateaus,
    :mod:`nctwin.calibrate`), and a least-squares fit of a few cycle times trades them against
    the accelerations. ``rapid_overrides`` gives each program the rapid override it ran at:
    its planner runs with the rapid feed and the axis velocities scaled by it.

    Parameters
    ----------
    programs : sequence of (Toolpath, float)
        Training programs and their recorded cycle times.
    machine : Machine
        The recorded machine (its axis limits are only reported, not used).
    control : PlannerControl
        The planner's period and default tolerance.
    start : (float, float)
        Acceleration (mm/s^2) and velocity (mm/s) every axis starts from (the velocity unused
        with ``fit_velocities=False``).
    fit_velocities : bool
        Fit the three axis velocities too (the default), else keep ``machine``'s.
    rapid_overrides : sequence of float, optional
        Per program, the rapid override in force as a share (1: 100 %, the default).

    Returns
    -------
    PlannerFit

    Raises
    ------
    ValueError
        If there are no programs, a recorded time is not positive, ``start`` lies outside
        the bounds (acceleration 10 to 1e5 mm/s^2, velocity 1 mm/s to the maximum feed), or a
        rapid override is not in (0, 1] or not one per program.
    """
    if not programs:
        raise ValueError("programs is empty: the planner's limits need at least one recording")
    measured = np.array([t for _, t in programs], dtype=float)
    if not (measured > 0).all():
        raise ValueError(f"measured cycle times {measured[measured <= 0][:3]} s: allowed > 0")
    scales = _overrides(rapid_overrides, len(programs))
    n = 6 if fit_velocities else 3
    lower = np.log([10.0] * 3 + [1.0] * 3)[:n]
    upper = np.log([1e5] * 3 + [machine.max_feed_mm_s] * 3)[:n]
    x0 = np.log([start[0]] * 3 + [start[1]] * 3)[:n]
    if not ((x0 >= lower) & (x0 <= upper)).all():
        raise ValueError(
            f"start = {start!r} is out of range: allowed acceleration [10, 1e5] mm/s^2, "
            f"velocity [1, {machine.max_feed_mm_s:g}] mm/s"
        )

    def profile(x: np.ndarray) -> Machine:
        e = np.exp(x)
        velocity = e[3:] if fit_velocities else machine.axis_max_velocity_mm_s
        return dataclasses.replace(
            machine,
            axis_max_acceleration_mm_s2=tuple(float(v) for v in e[:3]),
            axis_max_velocity_mm_s=tuple(float(v) for v in velocity),
        )

    def planned_s(m: Machine, stop_periods: str) -> np.ndarray:
        return np.array(
            [blend_planner(tp, at_rapid_override(m, k), control,
                           stop_periods=stop_periods).cycle_time_s
             for (tp, _), k in zip(programs, scales, strict=True)]
        )  # fmt: skip

    def residual(x: np.ndarray) -> np.ndarray:
        return np.log(planned_s(profile(x), "mean") / measured)

    fit = least_squares(residual, x0, bounds=(lower, upper), diff_step=1e-3, method="trf")
    fitted = profile(fit.x)
    err = 100 * np.abs(planned_s(fitted, "whole") / measured - 1)
    limits = pd.DataFrame(
        [{"axis": axis, "limit": limit, "start": s[i], "fitted": getattr(fitted, field)[i],
          "profile": getattr(machine, field)[i]}
         for limit, field, s in (("acceleration_mm_s2", "axis_max_acceleration_mm_s2",
                                  (start[0],) * 3),
                                 ("velocity_mm_s", "axis_max_velocity_mm_s",
                                  (start[1],) * 3 if fit_velocities
                                  else machine.axis_max_velocity_mm_s))
         for i, axis in enumerate("XYZ")]
    )  # fmt: skip
    return PlannerFit(fitted, limits, float(err.mean()), float(err.max()), int(fit.nfev))
