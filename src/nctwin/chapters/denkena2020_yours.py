"""Denkena et al.'s two reconstructions on a reader's own process (the chapter's "Your process"
section).

The reader describes a process with the fields of the chapter's :class:`Process
<nctwin.chapters.denkena2020_bench.Process>` (:data:`FIELDS`): as a dict (papermill's Python
API, ``papermill -y``) or as one string ``"kind,feed_direction,ae_mm,ap_mm,vf_mm_min,n_rpm"``,
e.g. ``"groove,+x,10,1,600,5000"`` (``papermill -p process ...``, ``python -m
nctwin.report.chapter denkena2020_force_lstm -p process ...``). :func:`your_process` runs it on
the chapter's bench as the chapter runs its own (same run length, same recording), stable (no
chatter), its path's XY extent centred on the mean start point of the training processes, at
their mean start height; the bench's force, low-passed as the LSTM's target, is the truth. The
fitted model (eq. 2) and the chapter's LSTMs (the mean of the seeds' predictions, never
retrained) reconstruct the force from the recorded drive signals, and :func:`table2
<nctwin.chapters.denkena2020.table2>` scores both as the chapter does. :func:`show_process`
displays the result.

What the bench cuts (:func:`make_process`; every bad value one line of the ``ValueError``):
the kinds and feed directions of the chapter; ``ae_mm`` the tool's diameter for a groove, below
it for side milling, up to it otherwise; ``ap_mm`` up to :data:`FLUTE_LENGTH_MM`; ``n_rpm``
such that the teeth pass below half the servo rate (the rate the bench resolves the cut at);
``vf_mm_min`` such that the tool cuts at least one diameter fully engaged within the run and
its path stays within the travel the model was fitted over (its cogging table).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from ..checks import check_range
from ..learn.train import Trained
from ..methods import denkena2020 as fm
from ..physics import drives
from .denkena2020 import _PROCESS_NAMES, reconstruct, table2
from .denkena2020_bench import (
    DIRECTIONS,
    TOOL,
    Process,
    Recorded,
    _trajectory,
    process_windows,
    run_processes,
)
from .your_program import domain_notes, show_section

__all__ = [
    "EXAMPLE_PROCESS",
    "FIELDS",
    "FLUTE_LENGTH_MM",
    "KIND_DIRECTIONS",
    "ProcessResult",
    "make_process",
    "process_fields",
    "show_process",
    "your_process",
]

#: A process' fields, in the order of the string form.
FIELDS = ("kind", "feed_direction", "ae_mm", "ap_mm", "vf_mm_min", "n_rpm")

#: The process the chapter's "Your process" section runs when the reader gives none: groove
#: milling in +x, ae 10 mm, ap 1 mm, vf 600 mm/min, n 5000 1/min.
EXAMPLE_PROCESS = "groove,+x,10,1,600,5000"

#: The feed directions of each kind, as the chapter runs them.
KIND_DIRECTIONS = {
    "side": tuple(DIRECTIONS),
    "groove": tuple(DIRECTIONS),
    "pocket": ("ccw",),
    "ramp": ("-y/+z",),
}

#: The deepest cut: the simulated end mill has no flute length, so that of a short end mill of
#: its diameter is taken, twice the diameter.
FLUTE_LENGTH_MM = 2.0 * TOOL.diameter_mm

#: Bracket of the feed search (mm/min) when the reader's feed is refused.
_FEED_SEARCH_MM_MIN = (1.0, 1e6)


@dataclass(frozen=True, eq=False)
class ProcessResult:
    """The model and the LSTM on one process of the reader's, beside the bench's force.

    Attributes
    ----------
    name : str
        A short description of the process (the text given when it was refused).
    table : pandas.DataFrame
        One row per scored axis: :func:`table2 <nctwin.chapters.denkena2020.table2>`'s scores
        (RMSE in N over the cut, the whole record, moving and standing samples; max |F| over
        the cut; RMSE / max |F|), the LSTM's being the seeds' mean. Empty when ``reason`` is set.
    notes : tuple of str
        Where the process was run, and where it lies outside the training processes.
    process : Process or None
        As run on the bench.
    axes : str
        The scored axes (those the LSTMs reconstruct), e.g. ``"XY"``.
    t_s : ndarray, shape (R,)
        Sample times.
    measured_n, model_n, lstm_n : ndarray, shape (R, len(axes))
        Bench force (low-passed, the LSTM's target), the model's and the LSTM's.
    cutting : ndarray of bool, shape (R,)
        The tool in the material.
    reason : str or None
        Why the process was not run (one line per bad value), else None.
    """

    name: str
    table: pd.DataFrame = field(default_factory=pd.DataFrame)
    notes: tuple[str, ...] = ()
    process: Process | None = None
    axes: str = ""
    t_s: np.ndarray = field(default_factory=lambda: np.empty(0))
    measured_n: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    model_n: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    lstm_n: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    cutting: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=bool))
    reason: str | None = None


def process_fields(spec: Mapping | str) -> dict:
    """The six fields of a process as given: a dict with the keys :data:`FIELDS`, or a string
    of their values joined by commas (numbers read as float).

    Raises
    ------
    ValueError
        One line per missing, unknown or non-numeric field (or one for a spec of another type).
    """
    if isinstance(spec, str):
        values = [v.strip() for v in spec.split(",")]
        if len(values) != len(FIELDS):
            raise ValueError(f"process = {spec!r}: allowed {len(FIELDS)} values separated by "
                             f"commas, {','.join(FIELDS)}")  # fmt: skip
        spec = dict(zip(FIELDS, values, strict=True))
    if not isinstance(spec, Mapping):
        raise ValueError(f"process = {spec!r}: allowed a dict with the keys {', '.join(FIELDS)} "
                         f"or a string {','.join(FIELDS)}")  # fmt: skip
    errors = [f"process has no {k}: allowed a dict with the keys {', '.join(FIELDS)}"
              for k in FIELDS if k not in spec]  # fmt: skip
    errors += [f"process has an unknown key {k!r}: allowed {', '.join(FIELDS)}"
               for k in spec if k not in FIELDS]  # fmt: skip
    out = {k: spec[k] for k in FIELDS if k in spec}
    for k in FIELDS[2:]:
        if k in out and not isinstance(out[k], bool):
            try:
                out[k] = float(out[k])
            except (TypeError, ValueError):
                errors.append(f"{k} = {out[k]!r}: allowed a number")
    if errors:
        raise ValueError("\n".join(errors))
    return out


def _errors(checks: list[tuple]) -> list[str]:
    """The messages of the failing :func:`~nctwin.checks.check_range` calls (open at ``lo``),
    each given as ``(name, value, lo, hi, keywords)``."""
    out = []
    for name, value, lo, hi, keywords in checks:
        try:
            check_range(name, value, lo, hi, low_open=True, **keywords)
        except ValueError as exc:
            out.append(str(exc))
    return out


def _placed(p: Process, machine: drives.FeedDriveMachine, duration_s: float, centre_mm):
    """``p`` started where its path's XY extent is centred on ``centre_mm`` (at its height),
    with the path (n, 3), tangent angle (n,), engagement weight (n,) and segment flag (n,) of
    :func:`_trajectory <nctwin.chapters.denkena2020_bench._trajectory>`; ValueError where the
    path does not fit in the run."""
    n, dt = round(duration_s * machine.servo_rate_hz), 1.0 / machine.servo_rate_hz
    pos, angle, weight, _, flag = _trajectory(replace(p, start_mm=(0.0, 0.0, 0.0)), n, dt)
    shift = np.array(centre_mm, dtype=float)
    shift[:2] -= 0.5 * (pos[:, :2].min(axis=0) + pos[:, :2].max(axis=0))
    return replace(p, start_mm=tuple(float(s) for s in shift)), pos + shift, angle, weight, flag


def _feed_ok(p: Process, machine, duration_s: float, centre_mm, travel_mm: np.ndarray):
    """(engaged, inside): the tool cuts at least one diameter fully engaged, forward, in the
    process' main segment (the circle of a pocket); the path stays within ``travel_mm``."""
    try:
        _, pos, angle, weight, flag = _placed(p, machine, duration_s, centre_mm)
    except ValueError:  # the path does not fit in the run
        return False, True
    main = (flag == 2) if p.kind == "pocket" else (flag > 0)
    full = main & (weight >= 1.0)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    forward = full[1:] & full[:-1] & (np.diff(angle) >= 0.0)
    inside = np.all((pos >= travel_mm[:, 0]) & (pos <= travel_mm[:, 1]))
    return float(step[forward].sum()) >= TOOL.diameter_mm, bool(inside)


def _bisect(ok, good: float, bad: float, steps: int = 40) -> float:
    """The boundary of ``ok`` between a feed where it holds and one where it does not
    (geometric bisection); the last feed where it holds."""
    for _ in range(steps):
        mid = math.sqrt(good * bad)
        good, bad = (mid, bad) if ok(mid) else (good, mid)
    return good


def make_process(
    spec: Mapping | str,
    machine: drives.FeedDriveMachine,
    *,
    duration_s: float,
    centre_mm: tuple[float, float, float],
    travel_mm: np.ndarray,
    index: int,
) -> Process:
    """The reader's process, checked against what the bench cuts (the module docstring).

    Parameters
    ----------
    spec : dict or str
        :func:`process_fields`.
    machine : FeedDriveMachine
    duration_s : float
        The chapter's run length.
    centre_mm : (float, float, float)
        Where the path's XY extent is centred, and the height it starts at.
    travel_mm : ndarray, shape (3, 2)
        Lowest and highest position of each axis.
    index : int
        The process' index (its recording noise).

    Returns
    -------
    Process
        Stable, in the test set, started where its path is centred.

    Raises
    ------
    ValueError
        One line per bad value: its name, its value, the allowed range.
    """
    f = process_fields(spec)
    kind, direction = f["kind"], f["feed_direction"]
    errors = []
    if kind not in KIND_DIRECTIONS:
        errors.append(f"kind = {kind!r}: allowed {', '.join(KIND_DIRECTIONS)}")
    elif direction not in KIND_DIRECTIONS[kind]:
        errors.append(f"feed_direction = {direction!r}: allowed for {kind} "
                      f"{', '.join(KIND_DIRECTIONS[kind])}")  # fmt: skip
    d = TOOL.diameter_mm
    ae, checks = f["ae_mm"], []
    if kind == "groove" and ae != d:
        errors.append(f"ae_mm = {ae!r}: allowed {d:g} for a groove (the tool's diameter)")
    elif kind != "groove":
        checks.append(("ae_mm", ae, 0.0, d, {"high_open": kind == "side"}))
    n_max = 60.0 * machine.servo_rate_hz / (2 * TOOL.teeth)
    errors += _errors([
        *checks,
        ("ap_mm", f["ap_mm"], 0.0, FLUTE_LENGTH_MM, {}),
        ("vf_mm_min", f["vf_mm_min"], 0.0, math.inf, {"high_open": True}),
        ("n_rpm", f["n_rpm"], 0.0, n_max, {}),
    ])  # fmt: skip
    if errors:
        raise ValueError("\n".join(errors))
    p = Process(index, kind, direction, f["ae_mm"], f["ap_mm"], f["vf_mm_min"], f["n_rpm"],
                tuple(centre_mm), False, 0.0, 0.0, True)  # fmt: skip

    def ok(which: int):  # 0: engaged, 1: inside the travel, at a feed
        return lambda vf: _feed_ok(replace(p, vf_mm_min=vf), machine, duration_s, centre_mm,
                                   travel_mm)[which]  # fmt: skip

    if not all(_feed_ok(p, machine, duration_s, centre_mm, travel_mm)):
        lo_s, hi_s = _FEED_SEARCH_MM_MIN
        lo = lo_s if ok(0)(lo_s) else _bisect(ok(0), hi_s, lo_s)
        hi = math.inf if ok(1)(hi_s) else _bisect(ok(1), lo_s, hi_s)
        raise ValueError(
            f"vf_mm_min = {p.vf_mm_min!r} is out of range: allowed [{math.ceil(lo)}, "
            f"{math.floor(hi) if hi < math.inf else 'inf'}] for this process in the "
            f"{duration_s:g} s run (the tool cuts at least {d:g} mm fully engaged; the path "
            f"stays within the model's travel, X {travel_mm[0, 0]:.0f} to {travel_mm[0, 1]:.0f} "
            f"mm, Y {travel_mm[1, 0]:.0f} to {travel_mm[1, 1]:.0f} mm)"
        )
    return _placed(p, machine, duration_s, centre_mm)[0]


def _describe(p: Process) -> str:
    return (f"{_PROCESS_NAMES[p.kind]} {p.feed_direction}, ae {p.ae_mm:g} mm, ap {p.ap_mm:g} mm, "
            f"vf {p.vf_mm_min:g} mm/min, n {p.n_rpm:g} 1/min")  # fmt: skip


def _given(spec) -> str:
    """The process as the reader gave it, in the string form where it is a dict."""
    if isinstance(spec, Mapping):
        return ",".join(str(spec.get(k, "?")) for k in FIELDS)
    return str(spec)


def your_process(
    spec: Mapping | str,
    nets: Mapping[int, Mapping[str, Trained]],
    scaling: fm.InputScaling,
    model: fm.ForceModel,
    machine: drives.FeedDriveMachine,
    recorded: Recorded,
    *,
    duration_s: float,
    seed: int,
) -> ProcessResult:
    """The model and the chapter's LSTMs on a reader's process, beside the bench's force.

    Parameters
    ----------
    spec : dict or str
        The process (:func:`process_fields`).
    nets : dict
        The chapter's networks, ``{seed: {"X": Trained, "Y": ...}}`` (:func:`train_lstms
        <nctwin.chapters.denkena2020.train_lstms>`); never retrained here.
    scaling : InputScaling
        Their scaling.
    model : ForceModel
        The fitted model; its cogging tables give the travel the process must stay within.
    machine : FeedDriveMachine
        The bench.
    recorded : Recorded
        The chapter's processes: their training processes give the start point, the training
        grid and the input ranges of the notes.
    duration_s : float
        The chapter's run length.
    seed : int
        Recording noise.

    Returns
    -------
    ProcessResult
        With ``reason`` set (and nothing else) where the process is refused.
    """
    train = [p for p in recorded.processes if not p.test]
    travel = np.array([[a.grid_mm[0], a.grid_mm[-1]] for a in model.axes])
    centre = tuple(float(c) for c in np.mean([p.start_mm for p in train], axis=0))
    try:
        p = make_process(spec, machine, duration_s=duration_s, centre_mm=centre,
                         travel_mm=travel, index=len(recorded.processes))  # fmt: skip
    except ValueError as exc:
        return ProcessResult(_given(spec), reason=str(exc))
    rec = run_processes([p], machine, duration_s=duration_s, seed=seed, n_jobs=1)
    target = fm.target_forces(rec.force_n, machine.record_rate_hz)
    windows = process_windows([p], machine, duration_s=duration_s)
    inputs = rec.inputs[0]
    lstm = np.mean([fm.predict(n, scaling, inputs) for n in nets.values()], axis=0)
    recon = reconstruct(model, inputs)
    axes = "".join(a for a in "XYZ" if a in next(iter(nets.values())))
    scored = Recorded([replace(p, index=0)], rec.t_s, rec.inputs, rec.force_n, rec.seconds)
    table = table2(scored, target, {0: lstm}, {0: recon}, windows, axes=axes)
    table = table.drop(columns=["process", "feed_direction", "ae_mm", "ap_mm", "vf_mm_min",
                                "n_rpm", "semi_stable"])  # fmt: skip
    cols = ["axis", "lstm_cutting_rmse_n", "model_cutting_rmse_n", "max_abs_force_n"]
    table = table[cols + [c for c in table.columns if c not in cols]]
    notes = [f"Run on the bench as the chapter's processes ({duration_s:g} s: air approach, cut, "
             f"air exit, stop), stable, from ({p.start_mm[0]:.1f}, {p.start_mm[1]:.1f}, "
             f"{p.start_mm[2]:.1f}) mm; RMSE against the bench's force low-passed as the "
             f"LSTM's target; the LSTM is the mean of {len(nets)} seeds' networks."]  # fmt: skip
    outside = []
    for k in FIELDS[2:]:
        lo, hi = min(getattr(q, k) for q in train), max(getattr(q, k) for q in train)
        if not lo <= getattr(p, k) <= hi:
            outside.append(f"{k} = {getattr(p, k):g} (trained {lo:g} to {hi:g})")
    if outside:
        notes.append("outside the training processes: " + ", ".join(outside))
    x_train = recorded.inputs[[not q.test for q in recorded.processes]]
    notes += domain_notes(inputs, x_train.reshape(-1, x_train.shape[-1]), fm.INPUT_NAMES,
                          rows="samples")  # fmt: skip
    idx = ["XYZ".index(a) for a in axes]
    return ProcessResult(_describe(p), table, tuple(notes), p, axes, rec.t_s,
                         target[0][:, idx], recon[:, idx], lstm[:, idx],
                         windows.cutting[0])  # fmt: skip


def show_process(result: ProcessResult) -> None:
    """Display the "Your process" section: a heading, then the reason it was not run, or the
    table, the notes and the forces over time."""
    if show_section(f"Your process: {result.name}", result.reason, result.table, result.notes):
        _plot_forces(result)


def _plot_forces(result: ProcessResult) -> None:
    import matplotlib.pyplot as plt

    _, axes = plt.subplots(1, len(result.axes), figsize=(11, 3.2), squeeze=False,
                             constrained_layout=True, sharex=True)  # fmt: skip
    for j, (ax, name) in enumerate(zip(axes[0], result.axes, strict=True)):
        t = result.t_s
        ax.fill_between(t, 0, 1, where=result.cutting, transform=ax.get_xaxis_transform(),
                        color="0.92", lw=0, label="cut")  # fmt: skip
        ax.plot(t, result.measured_n[:, j], "k", lw=0.8, label="bench, low-passed")
        ax.plot(t, result.model_n[:, j], lw=0.7, label="model")
        ax.plot(t, result.lstm_n[:, j], lw=0.8, label="LSTM")
        ax.set_title(f"{result.name}: F{name.lower()}", fontsize=9)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("force (N)")
    axes[0, 0].legend(frameon=False, fontsize=7, ncol=2)
    plt.show()
