r"""Calibrate one real machine from its MTConnect logs (:mod:`nctwin.mtconnect`): the rapid
feed, the times that are no motion (tool changes, spindle starts, optional stops, the start and
the end of a run), and the control model that times its motion best (CAM, Lee et al.'s block
overlap, the blend-arc planner or the FIR kernel).

**The rapid feed** is read, not fitted: each axis's rapid is the plateau of the steady
``Feed_Rate`` on single-axis G0 lines (:func:`nctwin.mtconnect.steady_feed`) divided by the
``Rapid_Override`` then in force, over every run of the logs (valid or not) where that override is
logged (:func:`axis_rapid_mm_s`); the planner's three axis velocities are that rapid, and only
their accelerations are fitted. The rapid override a run ran at (:func:`run_overrides`) is the
logged one, else its plateau over the axis rapid (whole per cent, at most 100), else, where the
run shows neither, the median of the others' (``assumed``: such runs are predicted but not
fitted); every prediction of a run runs its rapids at it
(:func:`nctwin.identify.at_rapid_override`).

The logs time spans of a program's lines between block events (:mod:`nctwin.runtimes`), and
every non-motion time is *net*: a span's time minus the CAM time of the span's own blocks at the
identified rapid feed (what a motion estimator adds back when it times the same blocks).

* **Tool change** (:attr:`SequenceControl.tool_change_s`): from the ``G91 G28 Z0.`` line
  before a ``Tn M6`` line to the ``M6`` line, both included; the ``M01`` between them on every
  shipped program is in it (optional stop off: a valid run has no pause), and so is the Z
  travel to the real home above the program's ``G28`` point.
* **First tool change** (:attr:`SequenceControl.first_tool_change_s`): the ``Tn M6`` line
  before the program's first spindle start, where the spindle is at rest and no return comes
  before it. The control may start it before it logs any line (most Hurco04 runs log their
  first event past it), so it is timed from the run's start to the first event past its line,
  less the program start.
* **Spindle start**: from the ``S.. M3`` line to the line after it, both included: the control
  moves on only once the spindle is at speed. A constant where the calibration runs command
  one speed, a line in the speed where they command several
  (:attr:`SequenceControl.spindle_start_s_per_krpm`).
* **Optional stop** (:attr:`SequenceControl.optional_stop_s`): an ``M01`` line outside a tool
  change; none of the shipped programs has one, so it stays 0 ("not identified").
* **Program start / end**: the run's start to its first block event, over the runs whose
  first event is not past the first tool change; its M30 line's event to the run's end
  (PROGRAM_COMPLETED).

:func:`calibrate` fits them and the motion models on some runs, :func:`predict_runs` predicts
``Verdict.motion_s`` and the duration of others, :func:`leave_one_program_out` does both with
each program held out, :func:`write_profile` writes the machine's profile file.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd

from .controls import AccDecControl, FirControl, PlannerControl, SequenceControl
from .estimate import block_overlap, cam, kernel
from .estimate.blend_planner import blend_planner
from .identify import at_rapid_override, fit_block_overlap, fit_fir, fit_planner
from .machine import Machine, Profile, write_control
from .runner import run_tasks
from .runtimes import ProgramLines, RunTimes, first_changes, first_m6, motion_window
from .toolpath import Toolpath

__all__ = [
    "BASE_ACCELERATION_MM_S2",
    "CALIBRATE_FIR_GRID",
    "LEE_PERIOD_S",
    "METHODS",
    "Calibration",
    "axis_rapid_mm_s",
    "base_machine",
    "calibrate",
    "held_out_predictions",
    "leave_one_program_out",
    "predict_runs",
    "run_overrides",
    "sequence_s",
    "write_profile",
]

#: The motion estimators compared, by the profile's method names.
METHODS = ("cam", "block_overlap", "planner", "kernel")
#: The FIR kernel's grid here: small, as a 30-minute program takes the kernel seconds.
CALIBRATE_FIR_GRID = {"fir_t1_s": [0.03, 0.09], "fir_t2_s": [0.01],
                      "fir_acc_scale": [0.25, 0.5, 1.0, 2.0], "fir_blend_ratio": [0.25],
                      "fir_block_periods": [0]}  # fmt: skip
#: The interpolation period of Lee et al.'s estimator here (s; the Hurcos' is not published).
LEE_PERIOD_S = 0.001
#: The axis acceleration (mm/s^2) of the machine the FIR kernel scales (its ``acc_scale``).
BASE_ACCELERATION_MM_S2 = 1000.0


def axis_rapid_mm_s(rapids: pd.DataFrame | None, times: Sequence[RunTimes]) -> tuple[float, str]:
    """Each axis's rapid at 100 % (mm/s) and how it was read: the median of ``rapids``'
    plateaus over their logged overrides (:func:`nctwin.runtimes.machine_runs`), else (no
    override logged) the median plateau of ``times``, taken at 100 % (also where ``rapids`` is
    None).

    Raises
    ------
    ValueError
        Neither shows a plateau.
    """
    if rapids is not None and len(rapids):
        ratio = rapids["plateau_mm_s"] * 100.0 / rapids["rapid_override_pct"]
        return float(ratio.median()), f"{len(rapids)} plateaus at a logged rapid override"
    plateau = np.array([r.rapid_plateau_mm_s for r in times])
    if not np.isfinite(plateau).any():
        raise ValueError("no run shows a rapid plateau: the rapid feed is unknown")
    n = np.isfinite(plateau).sum()
    return float(np.nanmedian(plateau)), f"{n} plateaus, no override logged: taken at 100 %"


def run_overrides(
    times: Sequence[RunTimes], rapid_mm_s: float, assumed_pct: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The rapid override (%) each run ran at and where it comes from (``logged``; ``plateau``:
    its plateau over ``rapid_mm_s``, in whole per cent, at most 100; ``assumed``:
    ``assumed_pct``, where None the median of the others', 100 where none is known)."""
    logged = np.array([r.rapid_override_pct for r in times])
    seen = np.array([r.rapid_plateau_mm_s for r in times]) * 100.0 / rapid_mm_s
    pct = np.where(np.isfinite(logged), logged, np.minimum(np.round(seen), 100.0))
    source = np.where(np.isfinite(logged), "logged", np.where(np.isfinite(seen), "plateau", ""))
    known = np.isfinite(pct)
    if assumed_pct is None:
        assumed_pct = np.median(pct[known]) if known.any() else 100.0
    pct[~known] = assumed_pct
    return pct, np.where(known, source, "assumed")


def base_machine(name: str, rapid_mm_s: float) -> Machine:
    """A machine of the identified axis rapid (every axis and the rapid feed at it) and a
    generic acceleration."""
    return Machine(
        name=name,
        description=f"{name}, calibrated from its MTConnect logs (nctwin.calibrate)",
        axis_max_velocity_mm_s=(rapid_mm_s,) * 3,
        axis_max_acceleration_mm_s2=(BASE_ACCELERATION_MM_S2,) * 3,
        axis_max_jerk_mm_s3=(np.inf,) * 3,
        rapid_feed_mm_s=rapid_mm_s,
        max_feed_mm_s=rapid_mm_s,
    )


def _span_blocks(tp: Toolpath, spans: np.ndarray) -> list[np.ndarray]:
    """Per span (shape (k, 2), lines), the mask of ``tp``'s blocks within it."""
    return [(tp.line >= a) & (tp.line <= z) for a, z in spans]


@dataclass(frozen=True)
class Calibration:
    """One machine calibrated on some of its runs (:func:`calibrate`).

    Parameters
    ----------
    machine : Machine
        Every axis and the rapid at the axis rapid (:func:`axis_rapid_mm_s`), at 100 %.
    rapid_source : str
        How the axis rapid was read.
    overrides_pct, override_source : numpy.ndarray
        Shape (n,): each calibration run's rapid override and its source (:func:`run_overrides`).
    sequence : SequenceControl
        The non-motion times.
    residuals_s : dict of str to numpy.ndarray
        Measured minus fitted, per non-motion time (``tool_change``, ``first_tool_change``,
        ``spindle_start``, ``optional_stop``, ``program_start``, ``program_end``).
    planner, fir : PlannerControl, FirControl
        The fitted controls (the planner's axis limits are in ``planner_machine``).
    planner_machine : Machine
    block_overlap : AccDecControl
        Lee et al. (2022)'s time constants (:func:`nctwin.identify.fit_block_overlap`; its
        rapid time constant from ``planner_machine``'s acceleration), run on
        ``planner_machine``.
    fit_err_pct : dict of str to float
        Per method, the mean absolute error (%) of the motion time on the calibration runs of a
        known rapid override (grouped by program and override).
    best : str
        The method of the least ``fit_err_pct``.
    runs : tuple of str
        The calibration runs' logs.
    """

    machine: Machine
    rapid_source: str
    overrides_pct: np.ndarray
    override_source: np.ndarray
    sequence: SequenceControl
    residuals_s: dict
    planner: PlannerControl
    planner_machine: Machine
    block_overlap: AccDecControl
    fir: FirControl
    fit_err_pct: dict
    best: str
    runs: tuple

    def profile(self, method: str | None = None) -> Profile:
        """The profile ``nctwin estimate`` would read for ``method`` (of :data:`METHODS`;
        default :attr:`best`): the machine and the method's control as :func:`write_profile`
        writes them, and the non-motion times."""
        method = self.best if method is None else method
        if method not in METHODS:
            raise ValueError(f"method = {method!r} is out of range: allowed {', '.join(METHODS)}")
        machine = self.machine if method in ("cam", "kernel") else self.planner_machine
        control = {"planner": {"planner": self.planner}, "kernel": {"fir": self.fir},
                   "block_overlap": {"accdec": self.block_overlap}}.get(method, {})  # fmt: skip
        return Profile(machine, **control, sequence=self.sequence, default_method=method)


def sequence_s(lines: ProgramLines, seq: SequenceControl, *, window: bool = True) -> float:
    """The non-motion time ``seq`` gives the motion window of a program (s), or (``window``
    False) its lines before the window, where the first approach ends."""
    after = (lines.spindle_starts[:, 0] >= lines.first_cut) == window
    tc = (lines.tool_changes[:, 0] >= lines.first_cut) == window
    first = first_changes(lines)
    spindle = sum(seq.spindle_s(rpm) for rpm in lines.spindle_rpm[after])
    stops = (lines.optional_stops >= lines.first_cut) == window
    changes = (tc & first).sum() * seq.tool_change_at_s(True)
    changes += (tc & ~first).sum() * seq.tool_change_s
    return float(changes + spindle + stops.sum() * seq.optional_stop_s)


def _motion_s(method: str, tp: Toolpath, cal: Calibration, pct: float) -> float:
    """The motion time (s) of ``tp`` by ``method`` with ``cal``'s fitted controls, its rapids at
    a rapid override of ``pct`` (%)."""
    if method == "cam":
        return cam(tp, at_rapid_override(cal.machine, pct / 100)).cycle_time_s
    if method == "planner":
        machine = at_rapid_override(cal.planner_machine, pct / 100)
        return blend_planner(tp, machine, cal.planner).cycle_time_s
    if method == "block_overlap":
        machine = at_rapid_override(cal.planner_machine, pct / 100)
        return block_overlap(tp, machine, cal.block_overlap).cycle_time_s
    return kernel(tp, at_rapid_override(cal.machine, pct / 100), cal.fir).cycle_time_s


def calibrate(
    name: str,
    times: Sequence[RunTimes],
    programs: dict,
    rapids: pd.DataFrame | None = None,
    *,
    n_jobs: int = 2,
) -> Calibration:
    """Identify the rapid feed, the non-motion times and the motion models from ``times``.

    The axis rapid is :func:`axis_rapid_mm_s` of ``rapids``
    (:func:`nctwin.runtimes.machine_runs`; None: no override logged), each run's rapid override
    :func:`run_overrides`. Non-motion times are medians of the net spans (the module docstring),
    the spindle start a least-squares line in the commanded speed where the runs command two
    speeds or more. The planner's three axis accelerations are fitted by
    :func:`nctwin.identify.fit_planner` (the velocities held at the axis rapid), Lee et al.'s
    cutting time constant by :func:`nctwin.identify.fit_block_overlap` (period
    :data:`LEE_PERIOD_S`, on the planner's machine), the FIR kernel by
    :func:`nctwin.identify.fit_fir` on :data:`CALIBRATE_FIR_GRID`, each on the median motion
    time (minus the non-motion times) of each program and rapid override, runs of an assumed
    override left out; the best method is the one of least mean absolute error on these same
    runs.
    """
    rapid_mm_s, rapid_source = axis_rapid_mm_s(rapids, times)
    pct, source = run_overrides(times, rapid_mm_s)
    machine = base_machine(name, rapid_mm_s)
    net: dict[str, list] = {"tool_change": [], "spindle_start": [], "optional_stop": []}
    rpm: list[float] = []
    for r, o in zip(times, pct, strict=True):
        lines, tp = programs[r.program]
        blocks = cam(tp, at_rapid_override(machine, o / 100)).block_times_s
        for key, spans, gross in (
            ("tool_change", lines.tool_changes, r.tool_change_s),
            ("spindle_start", lines.spindle_starts, r.spindle_start_s),
            ("optional_stop", np.c_[lines.optional_stops, lines.optional_stops], r.optional_stop_s),
        ):
            inside = spans[:, 0] >= lines.first_cut  # the window's: the others are the start's
            motion = np.array([blocks[m].sum() for m in _span_blocks(tp, spans[inside])])
            net[key] += list(gross[inside] - motion)
        rpm += list(lines.spindle_rpm[lines.spindle_starts[:, 0] >= lines.first_cut])
    rpm_arr = np.asarray(rpm)
    residuals = {}
    med = {k: np.array(v) for k, v in net.items()}
    ok = np.isfinite(med["spindle_start"])
    if np.unique(rpm_arr[ok]).size >= 2:
        slope, icpt = np.polyfit(rpm_arr[ok] / 1000.0, med["spindle_start"][ok], 1)
    else:
        slope, icpt = 0.0, float(np.nanmedian(med["spindle_start"]))
    residuals["spindle_start"] = med["spindle_start"][ok] - (icpt + slope * rpm_arr[ok] / 1000.0)
    fitted = {}
    for key in ("tool_change", "optional_stop"):
        v = med[key][np.isfinite(med[key])]
        fitted[key] = float(np.median(v)) if v.size else 0.0
        residuals[key] = v - fitted[key]
    early = [r for r in times if r.first_line <= (first_m6(programs[r.program][0]) or np.inf)]
    for key, runs_ in (("program_start", early or times), ("program_end", times)):
        v = np.array([getattr(r, f"{key}_s") for r in runs_])
        fitted[key] = float(np.median(v))
        residuals[key] = v - fitted[key]
    opening = np.array([r.opening_s for r in times])
    v = opening[np.isfinite(opening)] - fitted["program_start"]
    fitted["first_tool_change"] = float(np.median(v)) if v.size else None  # no motion on M6
    residuals["first_tool_change"] = v - (fitted["first_tool_change"] or 0.0)
    seq = SequenceControl(
        tool_change_s=fitted["tool_change"],
        first_tool_change_s=fitted["first_tool_change"],
        spindle_start_s=float(icpt),
        spindle_start_s_per_krpm=float(slope),
        optional_stop_s=fitted["optional_stop"],
        program_start_s=fitted["program_start"],
        program_end_s=fitted["program_end"],
    )
    logs = tuple(r.log for r in times)
    pairs, shares = [], []
    groups = {(r.program, o) for r, o, s in zip(times, pct, source, strict=True) if s != "assumed"}
    if not groups:
        raise ValueError(f"no run of {name} has a known rapid override: no motion to fit")
    for file, o in sorted(groups):
        lines, tp = programs[file]
        measured = np.median([r.motion_s for r, k in zip(times, pct, strict=True)
                              if r.program == file and k == o])  # fmt: skip
        pairs.append((tp.take(motion_window(tp, lines)), measured - sequence_s(lines, seq)))
        shares.append(o / 100)
    planner = PlannerControl(period_s=0.001, blend_tol_mm=0.0254)
    pfit = fit_planner(pairs, machine, planner, fit_velocities=False, rapid_overrides=shares)
    lee = fit_block_overlap(pairs, pfit.machine, LEE_PERIOD_S, shares)
    fir, _ = fit_fir(pairs, machine, FirControl(period_s=0.002, blend_tol_mm=0.0254),
                     CALIBRATE_FIR_GRID, n_jobs=n_jobs, rapid_overrides=shares)  # fmt: skip
    cal = Calibration(machine, rapid_source, pct, source, seq, residuals, planner,
                      pfit.machine, lee, fir, {}, "cam", logs)  # fmt: skip
    err = {}
    for method in METHODS:
        sim = np.array([_motion_s(method, tp, cal, 100 * k)
                        for (tp, _), k in zip(pairs, shares, strict=True)])  # fmt: skip
        target = np.array([t for _, t in pairs])
        err[method] = float(np.mean(np.abs(sim / target - 1)) * 100)
    best = min(err, key=err.get)
    return dataclasses.replace(cal, fit_err_pct=err, best=best)


def predict_runs(
    cal: Calibration, times: Sequence[RunTimes], programs: dict, methods: Sequence[str] = METHODS
) -> pd.DataFrame:
    """Predicted ``motion_s`` and duration of each run by each of ``methods`` (of
    :data:`METHODS`), its rapids at
    its rapid override (:func:`run_overrides` with ``cal``'s axis rapid; where assumed, the
    median of ``cal``'s runs of a known override).

    Returns
    -------
    pandas.DataFrame
        A row per run and method: ``log``, ``program``, ``method``, ``override_pct``,
        ``override_source``, ``measured_s``, ``predicted_s`` (the motion window's motion plus
        ``cal.sequence``), ``error_pct``, ``measured_cycle_s`` (the run's duration),
        ``predicted_cycle_s`` (the window, plus the motion and the non-motion times before it,
        plus the program start and end).
    """
    assumed = float(np.median(cal.overrides_pct[cal.override_source != "assumed"]))
    pct, source = run_overrides(times, cal.machine.rapid_feed_mm_s, assumed)
    seq = cal.sequence
    rows = []
    cache: dict = {}
    for r, o, s in zip(times, pct, source, strict=True):
        lines, tp = programs[r.program]
        for method in methods:
            key = (r.program, method, o)
            if key not in cache:
                window = motion_window(tp, lines)
                before = tp.line < lines.first_cut
                motion = _motion_s(method, tp.take(window), cal, o) + sequence_s(lines, seq)
                start = _motion_s(method, tp.take(before), cal, o) if before.any() else 0.0
                start += sequence_s(lines, seq, window=False)
                cache[key] = motion, motion + start + seq.program_start_s + seq.program_end_s
            motion, cycle = cache[key]
            rows.append({"log": r.log, "program": r.program, "method": method,
                         "override_pct": o, "override_source": s, "measured_s": r.motion_s,
                         "predicted_s": motion, "error_pct": 100 * (motion / r.motion_s - 1),
                         "measured_cycle_s": r.duration_s,
                         "predicted_cycle_s": cycle})  # fmt: skip
    return pd.DataFrame(rows)


def held_out_predictions(
    name: str,
    times: Sequence[RunTimes],
    programs: dict,
    rapids: pd.DataFrame | None = None,
    *,
    n_jobs: int = 2,
) -> tuple[pd.DataFrame, dict[str, Calibration]]:
    """Each program's runs predicted (:func:`predict_runs`) by a calibration on the other
    programs' runs (and on the other programs' rows of ``rapids``), ``n_jobs`` calibrations at
    a time (:func:`nctwin.runner.run_tasks`).

    Returns
    -------
    rows : pandas.DataFrame
        :func:`predict_runs`' rows of every held-out run, plus ``chosen`` (the method is the
        one its calibration picked on its own runs).
    calibrations : dict of str to Calibration
        The calibration each program was predicted by, by file name.
    """
    files = sorted({r.program for r in times})
    tasks = [
        (name, [r for r in times if r.program != file], programs,
         None if rapids is None else rapids[rapids["program"] != file])
        for file in files
    ]  # fmt: skip
    # a fold per worker, its grid search in series: the planner's fit is serial, the folds not
    cals = dict(zip(files, run_tasks(_calibrate_fold, tasks, n_jobs=n_jobs), strict=True))
    parts = []
    for file, cal in cals.items():
        pred = predict_runs(cal, [r for r in times if r.program == file], programs)
        parts.append(pred.assign(chosen=pred["method"] == cal.best))
    return pd.concat(parts, ignore_index=True), cals


def _calibrate_fold(name, times, programs, rapids) -> Calibration:
    """:func:`calibrate` in one process (what a worker of :func:`held_out_predictions` runs)."""
    return calibrate(name, times, programs, rapids, n_jobs=1)


def leave_one_program_out(
    name: str,
    times: Sequence[RunTimes],
    programs: dict,
    rapids: pd.DataFrame | None = None,
    *,
    n_jobs: int = 2,
) -> pd.DataFrame:
    """:func:`held_out_predictions` by held-out program and method, medians over its runs.

    Returns
    -------
    pandas.DataFrame
        A row per held-out program and method: ``program``, ``method``, ``runs``,
        ``override`` (the runs' rapid overrides and sources, e.g. ``"57 % plateau"``),
        ``median_measured_s``, ``predicted_s`` (the median over the runs), ``error_pct``
        (signed, against the median of the program's runs), ``median_cycle_s``,
        ``predicted_cycle_s``, ``cycle_error_pct`` (the same for the run's duration),
        ``chosen`` (the method the calibration picked on its own runs).
    """
    rows = []
    pred, _ = held_out_predictions(name, times, programs, rapids, n_jobs=n_jobs)
    for (file, method), g in pred.groupby(["program", "method"], sort=False):
        measured = float(g["measured_s"].median())
        predicted = float(g["predicted_s"].median())
        cycle = float(g["measured_cycle_s"].median())
        predicted_cycle = float(g["predicted_cycle_s"].median())
        used = zip(g["override_pct"], g["override_source"], strict=True)
        override = sorted({f"{o:g} % {s}" for o, s in used})
        rows.append({"program": file, "method": method, "runs": len(g),
                     "override": ", ".join(override), "median_measured_s": measured,
                     "predicted_s": predicted, "error_pct": 100 * (predicted / measured - 1),
                     "median_cycle_s": cycle, "predicted_cycle_s": predicted_cycle,
                     "cycle_error_pct": 100 * (predicted_cycle / cycle - 1),
                     "chosen": bool(g["chosen"].iloc[0])})  # fmt: skip
    return pd.DataFrame(rows)


def _residual_text(res: np.ndarray) -> str:
    if not res.size:
        return "none"
    return f"{res.size} spans, s.d. {np.std(res):.2f} s, worst {np.max(np.abs(res)):.2f} s"


def _vec(v) -> str:
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def write_profile(cal: Calibration, output: str | Path, *, today: date) -> None:
    """Write ``cal`` as a profile file: ``[machine]``, ``default_method`` (``cal.best``), the
    best method's control table and ``[control.sequence]``, each with its provenance."""
    m = cal.profile().machine
    out = Path(output)
    out.write_text(
        f"# {m.name}, calibrated from {len(cal.runs)} valid runs of its MTConnect logs\n"
        f"# (nctwin.calibrate): axis velocities and rapid feed the median single-axis rapid\n"
        f"# plateau over its rapid override ({cal.rapid_source}).\n"
        f'default_method = "{cal.best}"\n\n[machine]\n'
        f'name = "{m.name}"\ndescription = "{m.description}"\n'
        f"axis_max_velocity_mm_s = {_vec(m.axis_max_velocity_mm_s)}\n"
        f"axis_max_acceleration_mm_s2 = {_vec(m.axis_max_acceleration_mm_s2)}\n"
        "axis_max_jerk_mm_s3 = [inf, inf, inf]\n"
        f"rapid_feed_mm_s = {m.rapid_feed_mm_s!r}\nmax_feed_mm_s = {m.max_feed_mm_s!r}\n"
    )
    runs_text = f"{len(cal.runs)} runs ({cal.runs[0]} ... {cal.runs[-1]})"
    fit = ", ".join(f"{k} {v:.2f} %" for k, v in cal.fit_err_pct.items())
    if cal.best != "cam":
        kind, control, what = {
            "planner": ("planner", cal.planner,
                        "The axis accelerations (the velocities: the rapid plateau)"),
            "block_overlap": ("accdec", cal.block_overlap,
                              "The cutting time constant (the rapid one from the planner's fit)"),
            "kernel": ("fir", cal.fir, "The FIR kernel's settings"),
        }[cal.best]  # fmt: skip
        write_control(out, kind, control, [
            f"{what} fitted by nctwin.calibrate on the", f"motion times of {runs_text}.",
            f"Mean absolute motion-time error on them: {fit}."], today=today)  # fmt: skip
    res = cal.residuals_s
    write_control(out, "sequence", cal.sequence, [
        "Non-motion times (nctwin.calibrate) from the block events of",
        f"{runs_text}.",
        f"Residuals: tool change {_residual_text(res['tool_change'])};",
        f"first tool change {_residual_text(res['first_tool_change'])};",
        f"spindle start {_residual_text(res['spindle_start'])};",
        f"program start {_residual_text(res['program_start'])};",
        f"program end {_residual_text(res['program_end'])}; optional stop "
        f"{_residual_text(res['optional_stop'])}."], today=today)  # fmt: skip
