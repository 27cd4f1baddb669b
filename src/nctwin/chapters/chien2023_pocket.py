r"""Calibration of the band pockets of Chien et al. (2023) Tables 2 and 3
(:mod:`nctwin.programs.band_pocket`) against the statistics the paper publishes.

Each of a pocket's settings is fixed by one statistic, never by a network's error:

* ``outline_scale`` by the path length :math:`\sum_k l_k`: the mean over the table's rows of
  what its CAM times imply, :math:`T_\mathrm{CAM} F` (CAM runs every G-line at :math:`F`);
* ``chord_tol_mm`` by the number of G-lines of the pocketing path (the summary's
  ``pocketing_glines``; Table 3's pocket, for which the paper prints no count, takes Table 2's
  chordal tolerance: the same post-processor on another part);
* ``band_mm`` by CAM's error :math:`|T_\mathrm{CAM} - T| / T` on the table's rows, run on the
  FIR kernel of the table's machine (:func:`nctwin.chapters.chien2023.simulate_one`): the band
  where the mean difference from the paper's printed errors changes sign (a narrower band has
  shorter rows and more corners per metre, so CAM misses by more);
* ``stepover_mm`` (the paper prints none; 2 mm, a quarter of the 8 mm end mill) stays at that
  unless even the widest band a part of the table's path allows leaves CAM missing by more than
  the paper's. Then the band stays the widest and the stepover is solved for CAM's error instead,
  up to the tool's diameter :math:`2R` (beyond it the rows would leave ridges uncut): a wider
  stepover clears the same path's area with fewer rows, so the same path length belongs to a
  larger part, whose wider band has longer rows and fewer corners per metre.

:func:`solve_pocket` solves them for one pocket and :func:`cam_errors` gives the statistics; the
solved numbers are frozen in :data:`nctwin.programs.band_pocket.PAPER_POCKETS`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..machine import Profile
from ..physics.measure import Recording
from ..programs.band_pocket import (
    BAND_MAX_PER_SCALE_MM,
    PaperPocket,
    band_pocket_program,
    band_pocket_rings,
)
from ..programs.pocket import pocket_stats
from ..report.papers import load_paper_table
from .chien2023 import simulate_one

__all__ = ["MACHINE_B_RECORDING", "cam_errors", "pocket_targets", "solve_pocket"]

#: How machine B (Table 3) is recorded: the position loop, in-position window and encoder noise
#: of the chapter's machine-B runs.
MACHINE_B_RECORDING = Recording(
    position_gain_1_s=40.0, in_position_mm=0.001, noise_mm=0.002, seed=0
)


def pocket_targets(table: str) -> dict[str, float]:
    """The published statistics a pocket is solved for.

    Parameters
    ----------
    table : {"chien2023_table2", "chien2023_table3"}

    Returns
    -------
    dict
        ``path_m`` (mean of :math:`T_\\mathrm{CAM} F` over the rows), ``path_m_min``,
        ``path_m_max`` and ``lines`` (the summary's ``pocketing_glines``).
    """
    rows = load_paper_table(table)
    implied = rows.cam_s * rows.feed_mm_s / 1000.0
    summary = load_paper_table("chien2023_summary").set_index("quantity")
    return {"path_m": float(implied.mean()), "path_m_min": float(implied.min()),
            "path_m_max": float(implied.max()),
            "lines": float(summary.value["pocketing_glines"])}  # fmt: skip


def _stats(spec: PaperPocket) -> dict[str, float]:
    return pocket_stats(np.vstack(band_pocket_rings(spec)))


def _bisect(f, lo: float, hi: float, iterations: int) -> float:
    """The root of ``f`` (increasing) in [lo, hi] by bisection."""
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def _with(spec: PaperPocket, **changes: float) -> PaperPocket:
    return PaperPocket(**{**spec.__dict__, **changes})


def _smallest_scale(band_mm: float) -> float:
    """The smallest ``outline_scale`` (5 decimals) whose island stands at ``band_mm``."""
    scale = math.ceil(1e5 * band_mm / BAND_MAX_PER_SCALE_MM) / 1e5
    return scale if BAND_MAX_PER_SCALE_MM * scale >= band_mm else scale + 1e-5  # rounding


def _widest_band(targets: dict[str, float], stepover_mm: float) -> float:
    """The widest band (mm, 3 decimals) whose pocket at ``stepover_mm`` can still be as short as
    ``targets["path_m"]``: its smallest part (the island's chamfer collapsed) has that path."""

    def excess(band_mm: float) -> float:
        spec = PaperPocket(outline_scale=_smallest_scale(band_mm), band_mm=band_mm,
                           chord_tol_mm=1e-4, stepover_mm=stepover_mm)  # fmt: skip
        return _stats(spec)["path_m"] - targets["path_m"]

    low = 2 * PaperPocket.tool_radius_mm + stepover_mm
    high = BAND_MAX_PER_SCALE_MM * 5.0
    widest = high if excess(high) < 0 else _bisect(excess, low, high, 20)
    return math.floor(1e3 * widest) / 1e3


def _solve_geometry(
    band_mm: float, targets: dict[str, float], chord_tol_mm: float | None, stepover_mm: float
) -> PaperPocket:
    """``outline_scale`` for the path and (unless given) ``chord_tol_mm`` for the G-lines at
    ``band_mm`` and ``stepover_mm``; the two are solved in turn twice (the chords change the path
    a little)."""
    low_scale = _smallest_scale(band_mm)
    spec = PaperPocket(outline_scale=max(1.0, low_scale), band_mm=band_mm,
                       chord_tol_mm=chord_tol_mm or 1e-4, stepover_mm=stepover_mm)  # fmt: skip
    for _ in range(2):
        scale = _bisect(lambda s, spec=spec: _stats(_with(spec, outline_scale=s))["path_m"]
                        - targets["path_m"], low_scale, 5.0, 20)  # fmt: skip
        spec = _with(spec, outline_scale=round(scale, 5))
        if chord_tol_mm is None:  # the G-lines fall as the tolerance grows
            log_tol = _bisect(lambda x, spec=spec: targets["lines"]
                              - _stats(_with(spec, chord_tol_mm=10.0**x))["lines"],
                              -8.0, math.log10(0.1 * spec.tool_radius_mm), 24)  # fmt: skip
            spec = _with(spec, chord_tol_mm=float(f"{10.0**log_tol:.3g}"))
    return spec


def cam_errors(
    spec: PaperPocket, table: str, profile: Profile, recording: Recording | None = None
) -> pd.DataFrame:
    """CAM's error on the pocket ``spec`` at the rows of a paper table, beside the paper's.

    Returns
    -------
    pandas.DataFrame
        Per row ``feed_mm_s, tol_mm, measured_s, cam_s, cam_err_pct, ratio`` (measured over
        CAM) and the paper's ``paper_measured_s, paper_cam_s, paper_cam_err_pct, paper_ratio``.
    """
    rows = []
    for index, paper in enumerate(load_paper_table(table).itertuples()):
        text = band_pocket_program(spec, feed_mm_s=float(paper.feed_mm_s), tol_mm=paper.tol_mm)
        run = simulate_one(text, profile, recording, index)
        rows.append({"feed_mm_s": paper.feed_mm_s, "tol_mm": paper.tol_mm,
                     "measured_s": run.measured_s, "cam_s": run.cam_s,
                     "cam_err_pct": 100.0 * abs(run.cam_s - run.measured_s) / run.measured_s,
                     "ratio": run.measured_s / run.cam_s,
                     "paper_measured_s": paper.measured_s, "paper_cam_s": paper.cam_s,
                     "paper_cam_err_pct": paper.cam_err_pct,
                     "paper_ratio": paper.measured_s / paper.cam_s})  # fmt: skip
    return pd.DataFrame(rows)


def solve_pocket(
    table: str,
    profile: Profile,
    recording: Recording | None = None,
    *,
    chord_tol_mm: float | None = None,
    iterations: int = 12,
) -> tuple[PaperPocket, pd.DataFrame]:
    """Solve one pocket's settings for a paper table (see the module docstring).

    ``band_mm`` is bisected between :math:`2R` + the stepover and the widest band a pocket of the
    table's path allows, on the mean of (paper - ours) of CAM's error over the table's rows;
    each candidate first gets its scale and chordal tolerance. Where CAM misses by more than the
    paper's even on the widest band, the band stays the widest and ``stepover_mm`` is bisected
    the same way between the default and :math:`2R` (two decimals), each candidate with its own
    widest band; where CAM misses by more even at :math:`2R`, that stepover is the answer (the
    closest the part comes).

    Parameters
    ----------
    table : {"chien2023_table2", "chien2023_table3"}
    profile : Profile
        The machine the table ran on.
    recording : Recording, optional
        How that machine is recorded (Table 3: :data:`MACHINE_B_RECORDING`).
    chord_tol_mm : float, optional
        A chordal tolerance to keep (Table 3: Table 2's); none: solved for the G-lines.
    iterations : int
        Bisection steps on the band (or the stepover).

    Returns
    -------
    PaperPocket
        The solved settings.
    pandas.DataFrame
        :func:`cam_errors` of the solved pocket.
    """
    targets = pocket_targets(table)
    specs: dict[tuple[float, float], PaperPocket] = {}

    def excess(band_mm: float, stepover_mm: float) -> float:
        key = (round(band_mm, 3), stepover_mm)
        specs[key] = _solve_geometry(key[0], targets, chord_tol_mm, stepover_mm)
        errors = cam_errors(specs[key], table, profile, recording)
        return float((errors.paper_cam_err_pct - errors.cam_err_pct).mean())

    def at_widest(stepover_mm: float) -> float:
        return excess(_widest_band(targets, stepover_mm), stepover_mm)

    radius, step = PaperPocket.tool_radius_mm, PaperPocket.stepover_mm
    if at_widest(step) >= 0:  # the paper's error lies within this stepover's bands
        band = _bisect(lambda b: excess(b, step), 2 * radius + step,
                       _widest_band(targets, step), iterations)  # fmt: skip
    else:  # the widest band, and the stepover solved (a wider one: fewer corners per metre)
        if at_widest(2 * radius) < 0:
            step = 2 * radius
        else:
            step = round(_bisect(lambda s: at_widest(round(s, 2)), step, 2 * radius,
                                 iterations), 2)  # fmt: skip
        band = _widest_band(targets, step)
    key = (round(band, 3), step)
    spec = specs.get(key) or _solve_geometry(key[0], targets, chord_tol_mm, step)
    return spec, cam_errors(spec, table, profile, recording)
