"""How the Denkena bench's compliance between tool side and slide was fixed: the model alone
(eq. 4 fitted on air moves, :func:`nctwin.chapters.denkena2020.fit_force_model`) on the paper's
one surviving Table 2 row (ramp, -y/+z) and on diagonal grooves (Figs. 4-5), beside the errors
the paper publishes for them. No LSTM is involved; the chosen setting is frozen in
:mod:`nctwin.physics.drives` (``COMPLIANCE_*``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pandas as pd

from ..methods import denkena2020 as fm
from ..physics import drives
from ..runner import run_tasks
from .denkena2020 import fit_force_model, reconstruct
from .denkena2020_bench import TOOL, Process, process_windows, run_air_moves, run_processes

__all__ = [
    "CANDIDATES",
    "calibrate_bench",
    "calibration_processes",
    "paper_ramp",
    "with_compliance",
]

#: The compliances tried, ``(mass_kg, stiffness_n_mm, damping_ratio)``: corners of 16 and 20 Hz
#: (below the spindle frequencies of Table 1), damping ratios of 0.1 and 0.3; the last is the one
#: frozen in :mod:`nctwin.physics.drives`.
CANDIDATES = ((60.0, 606.0, 0.3), (60.0, 947.0, 0.1), (60.0, 947.0, 0.3))


def paper_ramp(paper2: pd.DataFrame) -> dict:
    """The paper's ramp row of Table 2 as a process (its largest depth as ``ap_mm``), for
    :func:`nctwin.chapters.denkena2020.design_processes` (``paper_test``).

    Parameters
    ----------
    paper2 : pandas.DataFrame
        The paper table ``denkena2020_table2``.
    """
    row = paper2[paper2["process"] == "ramp milling"].iloc[0]
    return {"kind": "ramp", "feed_direction": str(row["feed_direction"]),
            "ae_mm": float(row["ae_mm"]), "ap_mm": float(row["ap_max_mm"]),
            "vf_mm_min": float(row["feed_mm_min"]), "n_rpm": float(row["spindle_rpm"])}  # fmt: skip


def calibration_processes(
    paper2: pd.DataFrame, grid: dict[str, list[float]], *, duration_s: float
) -> list[Process]:
    """The paper's ramp row and three diagonal grooves, each centred in the travel.

    Parameters
    ----------
    paper2 : pandas.DataFrame
        The paper table ``denkena2020_table2`` (its ramp row gives ae, ap, f, n).
    grid : dict
        Table 1 (the grooves take its middle ap, a low, middle and high feed and speed).
    duration_s : float
        Length of every run.

    Returns
    -------
    list of Process
        Indices 0 (ramp), 1-3 (grooves ``+x+y``, ``-x-y``, ``+x-y``).
    """
    q = paper_ramp(paper2)
    half = 0.5 * q["vf_mm_min"] / 60.0 * (duration_s - 0.6)
    procs = [Process(0, "ramp", q["feed_direction"], q["ae_mm"], q["ap_mm"], q["vf_mm_min"],
                     q["n_rpm"], (150.0, 150.0 + half, 100.0), False, 0.0, 0.0, True)]  # fmt: skip
    ap = grid["ap_mm"][len(grid["ap_mm"]) // 2]
    for k, direction in enumerate(("+x+y", "-x-y", "+x-y")):
        vf = grid["vf_mm_min"][[0, 2, -1][k]]
        n = grid["n_rpm"][[-1, 2, 0][k]]
        half = 0.5 * vf / 60.0 * (duration_s - 0.6) / np.sqrt(2.0)
        sx, sy = (-1.0 if c == "+" else 1.0 for c in direction[0::2])
        procs.append(Process(k + 1, "groove", direction, TOOL.diameter_mm, ap, vf, n,
                             (150.0 + sx * half, 150.0 + sy * half, 100.0), False, 0.0, 0.0,
                             True))  # fmt: skip
    return procs


def with_compliance(
    machine: drives.FeedDriveMachine, mass_kg: float, stiffness_n_mm: float, damping_ratio: float
) -> drives.FeedDriveMachine:
    """``machine`` with the same compliance on every axis."""
    axes = tuple(
        dataclasses.replace(a, compliance_mass_kg=mass_kg, compliance_stiffness_n_mm=stiffness_n_mm,
                            compliance_damping_ratio=damping_ratio)
        for a in machine.axes
    )  # fmt: skip
    return dataclasses.replace(machine, axes=axes)


def calibrate_bench(
    machine: drives.FeedDriveMachine,
    candidates: Sequence[tuple[float, float, float]],
    paper2: pd.DataFrame,
    figures: pd.DataFrame,
    grid: dict[str, list[float]],
    *,
    duration_s: float,
    seed: int,
    n_jobs: int = 2,
) -> pd.DataFrame:
    """The model's RMSE over the cut of :func:`calibration_processes` for each candidate
    compliance, beside the paper's.

    Parameters
    ----------
    machine : FeedDriveMachine
        Everything but the compliance.
    candidates : sequence of (float, float, float)
        ``(mass_kg, stiffness_n_mm, damping_ratio)``.
    paper2, figures : pandas.DataFrame
        The paper tables ``denkena2020_table2`` and ``denkena2020_figures``.
    grid : dict
        Table 1.
    duration_s : float
    seed : int
    n_jobs : int
        Candidates run at a time (:func:`nctwin.runner.run_tasks`).

    Returns
    -------
    pandas.DataFrame
        One row per candidate: its parameters and corner (Hz), the model's RMSE on the ramp in X
        and Y and its mean over the grooves' X and Y, the share of the ramp's cutting samples in
        which the standing X axis reads a velocity, and the paper's ramp values and groove range.
    """
    procs = calibration_processes(paper2, grid, duration_s=duration_s)
    tasks = [(machine, c, procs, duration_s, seed) for c in candidates]
    rows = pd.DataFrame(run_tasks(_candidate_row, tasks, n_jobs=n_jobs))
    ramp = paper2[paper2["process"] == "ramp milling"].set_index("axis")["model_rmse_n"]
    return rows.assign(paper_ramp_x_n=float(ramp["X"]), paper_ramp_y_n=float(ramp["Y"]),
                       paper_groove_min_n=float(figures["model_rmse_n"].min()),
                       paper_groove_max_n=float(figures["model_rmse_n"].max()))  # fmt: skip


def _candidate_row(
    machine: drives.FeedDriveMachine,
    candidate: tuple[float, float, float],
    procs: list[Process],
    duration_s: float,
    seed: int,
) -> dict:
    """One row of :func:`calibrate_bench` without the paper's columns (what a worker runs)."""
    mass, stiffness, ratio = candidate
    m = with_compliance(machine, mass, stiffness, ratio)
    rec = run_processes(procs, m, duration_s=duration_s, seed=seed, n_jobs=1)
    targets = fm.target_forces(rec.force_n, m.record_rate_hz)
    windows = process_windows(procs, m, duration_s=duration_s)
    model, _ = fit_force_model(run_air_moves(m, seed=seed), np.array([a.km_n_a for a in m.axes]))
    err = np.empty((len(procs), 2))
    for p in procs:
        cut = windows.cutting[p.index]
        diff = reconstruct(model, rec.inputs[p.index])[cut, :2] - targets[p.index, cut, :2]
        err[p.index] = np.sqrt(np.mean(diff**2, axis=0))
    cut0 = windows.cutting[0]
    reads = np.abs(rec.inputs[0, cut0, 3]) >= 0.5 * m.velocity_resolution_mm_s
    return {"mass_kg": mass, "stiffness_n_mm": stiffness, "damping_ratio": ratio,
            "corner_hz": np.sqrt(stiffness * 1e3 / mass) / (2.0 * np.pi),
            "ramp_model_rmse_x_n": err[0, 0], "ramp_model_rmse_y_n": err[0, 1],
            "groove_model_rmse_n": float(err[1:].mean()),
            "ramp_x_reads_v_pct": 100.0 * float(reads.mean())}  # fmt: skip
