r"""Chien, Sencer & Ward 2023: the kinematics of the simulated machine that the paper does not
publish, calibrated on the kernel and CAM alone, before any network is trained.

Sec. 4.1 publishes the simulation's feeds, tolerances and interpolation period, not its FIR time
constants :math:`T_1, T_2` nor the axes' acceleration and jerk limits. These four are fixed here
by CAM's error :math:`(T - T_\mathrm{CAM}) / T` on the twelve rows of Tables 1-2 (toolpaths I and
II, the pocket; two feeds by two tolerances each): for every candidate machine each test path's
one generator setting is solved first for the level of its rows (the pocket's band by
:func:`nctwin.chapters.chien2023_pocket.solve_pocket`, the zig-zag share of toolpaths I and II by
:func:`nctwin.chapters.chien2023_calibrate.zigzag_share_rows`), so what the candidate is scored
on is how CAM's error changes *across* the rows, with the feed and the tolerance: the largest
absolute deviation from the paper's row over the twelve rows (:func:`machine_rows`). The
candidate with the smallest is frozen in ``data/machines/paper1_sim.toml``
(:func:`calibrate_machine`). No network enters.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..machine import Profile
from .chien2023_calibrate import best_share, zigzag_share_rows
from .chien2023_pocket import solve_pocket

__all__ = ["Kinematics", "calibrate_machine", "machine_rows", "with_kinematics"]


@dataclass(frozen=True)
class Kinematics:
    """One candidate of the simulated machine's unpublished kinematics.

    Parameters
    ----------
    t1_s, t2_s : float
        The FIR time constants (:class:`nctwin.controls.FirControl`).
    acceleration_mm_s2, jerk_mm_s3 : float
        The X and Y axes' acceleration and jerk limits; Z keeps the base profile's ratio to X.
    """

    t1_s: float
    t2_s: float
    acceleration_mm_s2: float
    jerk_mm_s3: float


def with_kinematics(base: Profile, kin: Kinematics) -> Profile:
    """``base`` with the FIR time constants and X, Y axis limits of ``kin`` (Z scaled by the
    base's Z/X ratio of each limit)."""
    m = base.machine
    acc = m.axis_max_acceleration_mm_s2
    jerk = m.axis_max_jerk_mm_s3
    a, j = kin.acceleration_mm_s2, kin.jerk_mm_s3
    machine = dataclasses.replace(
        m, axis_max_acceleration_mm_s2=(a, a, a * acc[2] / acc[0]),
        axis_max_jerk_mm_s3=(j, j, j * jerk[2] / jerk[0]),
    )  # fmt: skip
    fir = dataclasses.replace(base.control("fir"), t1_s=kin.t1_s, t2_s=kin.t2_s)
    return dataclasses.replace(base, machine=machine, fir=fir)


def machine_rows(profile: Profile, shares: Sequence[float], iterations: int) -> pd.DataFrame:
    """CAM's error on the twelve rows of Tables 1-2 on ``profile``, each test path's setting
    solved for it first.

    Parameters
    ----------
    profile : Profile
        A candidate simulated machine.
    shares : sequence of float
        The zig-zag shares toolpaths I and II choose from (:func:`best_share`).
    iterations : int
        Bisection steps of the pocket's band (:func:`solve_pocket`).

    Returns
    -------
    pandas.DataFrame
        One row per table row: ``toolpath, setting`` (the solved zig-zag share, or the pocket's
        band in mm), ``feed_mm_s, tol_mm, cam_err_pct, paper_cam_err_pct, deviation_pts``.
    """
    spec, pocket = solve_pocket("chien2023_table2", profile, iterations=iterations)
    frames = [
        pocket.assign(
            toolpath="pocketing",
            setting=spec.band_mm,
            deviation_pts=pocket.cam_err_pct - pocket.paper_cam_err_pct,
        )
    ]
    for name in ("I", "II"):
        rows = zigzag_share_rows(name, shares, profile)
        share = best_share(rows)
        frames.append(rows[rows.zigzag_share == share].assign(toolpath=name, setting=share))
    columns = ["toolpath", "setting", "feed_mm_s", "tol_mm", "cam_err_pct",
               "paper_cam_err_pct", "deviation_pts"]  # fmt: skip
    return pd.concat([f[columns] for f in frames], ignore_index=True)


def calibrate_machine(
    base: Profile, candidates: Sequence[Kinematics], shares: Sequence[float], iterations: int
) -> tuple[Kinematics, pd.DataFrame]:
    """The candidate whose largest deviation over Tables 1-2 is smallest (the first on a tie).

    Parameters
    ----------
    base : Profile
        The simulated machine whose kinematics are replaced (``paper1_sim``).
    candidates : sequence of Kinematics
        The grid.
    shares, iterations
        As :func:`machine_rows`.

    Returns
    -------
    Kinematics
        The chosen candidate.
    pandas.DataFrame
        :func:`machine_rows` of every candidate, with its ``t1_s, t2_s, acceleration_mm_s2,
        jerk_mm_s3``.
    """
    frames = [machine_rows(with_kinematics(base, k), shares, iterations)
              .assign(**dataclasses.asdict(k)) for k in candidates]  # fmt: skip
    worst = [float(np.abs(f.deviation_pts).max()) for f in frames]
    return candidates[int(np.argmin(worst))], pd.concat(frames, ignore_index=True)
