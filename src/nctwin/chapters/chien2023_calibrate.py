"""Chien, Sencer & Ward 2023: the test toolpaths' settings, fixed by the paper's published
conditions on the kernel alone, before any network is trained.

Toolpaths I and II of Table 1 (:func:`nctwin.programs.training.contour_program`) are chains of
straights, sharp zig-zags and curves; their *zig-zag share* is the one generator setting fixed
here, by CAM's error on the paper's four rows of each (:func:`zigzag_share_rows`): the share
whose largest deviation from the paper's rows is smallest is frozen in
:data:`nctwin.programs.training.PAPER_ZIGZAG_SHARE`. No network enters.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from ..machine import Profile
from ..programs.training import contour_program
from ..report.papers import load_paper_table
from .chien2023 import simulate_one

__all__ = ["best_share", "zigzag_share_rows"]


def zigzag_share_rows(name: str, shares: Sequence[float], profile: Profile) -> pd.DataFrame:
    """CAM's error on Table 1's rows of toolpath ``name`` for each zig-zag share.

    Parameters
    ----------
    name : {"I", "II"}
    shares : sequence of float
        Zig-zag shares to try, each in [0, 1].
    profile : Profile
        The simulation's machine (``paper1_sim``).

    Returns
    -------
    pandas.DataFrame
        One row per share and table row: ``zigzag_share, feed_mm_s, tol_mm, measured_s, cam_s,
        cam_err_pct, paper_cam_err_pct, deviation_pts``.
    """
    paper = load_paper_table("chien2023_table1")
    paper = paper[paper.toolpath == name]
    rows = []
    for share in shares:
        for r in paper.itertuples():
            text = contour_program(name, feed_mm_s=r.feed_mm_s, tol_mm=r.tol_mm, zigzag_share=share)
            run = simulate_one(text, profile)
            err = 100.0 * (run.measured_s - run.cam_s) / run.measured_s
            rows.append({"zigzag_share": share, "feed_mm_s": r.feed_mm_s, "tol_mm": r.tol_mm,
                         "measured_s": run.measured_s, "cam_s": run.cam_s, "cam_err_pct": err,
                         "paper_cam_err_pct": r.cam_err_pct,
                         "deviation_pts": err - r.cam_err_pct})  # fmt: skip
    return pd.DataFrame(rows)


def best_share(rows: pd.DataFrame) -> float:
    """The share of :func:`zigzag_share_rows` whose largest absolute deviation is smallest (the
    smallest such share on a tie)."""
    worst = rows.assign(dev=np.abs(rows.deviation_pts)).groupby("zigzag_share").dev.max()
    return float(worst.idxmin())
