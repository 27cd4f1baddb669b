"""Calibration of the thin-wall part (:mod:`nctwin.programs.thinwall`) to the paper's conditions.

Sun et al. (2022) publish no program, only what CAD/CAM and the machine made of it: per pocket the
CAD/CAM time and its error under the measured time (Table 3), and for pocket 1 its 5383 cutter
locations (Sec. 4.1). These are the chapter's conditions
(:func:`nctwin.chapters.sun2022_claims.paper_conditions`). Per pocket, generator inputs are set so
that the program meets them on the chapter's machine, before any network is trained and without
looking at one:

* the pocket's **length** (its longer side; the region's height for the two-region pocket 8,
  whose regions are taller than wide) for the CAD/CAM time. The length leaves the number of
  offsets unchanged, so the time moves continuously with it;
* the **trochoid radius** for the CAD/CAM error: tighter loops are slower on the machine than
  CAD/CAM's length over feed assumes, and take a different share of the path;
* for pocket 1 only, the **trochoid advance** per loop for its cutter locations (the loops carry
  most of them).

The machine (``sun2022_siemens``) is one machine for the eight pockets and is not touched here.
:func:`calibrate` re-derives :data:`nctwin.programs.thinwall.POCKETS` (a damped Newton iteration
on finite differences, a few seconds); :func:`pocket_conditions` checks the shipped pockets. Six
pockets come out in the middle of their bands. On pockets 2 and 7 the CAD/CAM error stops growing
as the loops tighten (their share of the path shrinks with their radius), so they end within
their bands but below the middle, and a new run from the shipped inputs may move them a little.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..checks import check_range
from ..estimate.cam import cam
from ..gcode import parse
from ..kernel import fir
from ..machine import Profile, load_profile
from ..metrics import error_pct
from ..programs.thinwall import POCKETS, PocketSpec, pocket_program, start_mm
from ..report.papers import load_paper_table
from .sun2022_claims import CAM_POINTS, CAM_TIME_TOL_PCT, CL_TOL_PCT

__all__ = [
    "PROFILE",
    "PocketTimes",
    "calibrate",
    "calibrate_pocket",
    "pocket_conditions",
    "pocket_times",
]

#: The chapter's machine.
PROFILE = "sun2022_siemens"

#: The calibration aims at the middle of each band: it stops once every residual is within this
#: share of its half-width.
_AIM = 0.25

#: Bounds of the calibrated inputs: trochoid radius and advance (mm), length as a factor of the
#: starting one.
_RADIUS_MM = (0.3, 10.0)
_ADVANCE_MM = (0.3, 5.0)
_LENGTH_FACTOR = (0.4, 2.5)


@dataclass(frozen=True)
class PocketTimes:
    """What CAD/CAM and the machine make of one pocket's program.

    Parameters
    ----------
    cam_s : float
        CAD/CAM time (s): length over programmed feed, rapids at the G0 feed.
    measured_s : float
        Machining time on the machine (s), the FIR kernel of the profile.
    cutter_locations : int
        G-lines of non-zero length.
    """

    cam_s: float
    measured_s: float
    cutter_locations: int

    @property
    def cam_err_pct(self) -> float:
        """CAD/CAM's unsigned error under the measured time (%)."""
        return float(error_pct(self.cam_s, self.measured_s))


def pocket_times(spec: PocketSpec, profile: Profile | None = None) -> PocketTimes:
    """CAD/CAM time, machine time and cutter locations of a pocket's program, run from its
    :func:`~nctwin.programs.thinwall.start_mm` as the chapter runs it.

    Parameters
    ----------
    spec : PocketSpec
    profile : Profile, optional
        The machine; the chapter's (:data:`PROFILE`) if None.
    """
    profile = profile or load_profile(PROFILE)
    tp = parse(pocket_program(spec), start_mm=start_mm(spec), source=f"pocket {spec.number}")
    tp = tp.take(tp.lengths_mm > 0)
    motion = fir.run(tp, profile.machine, profile.control("fir"))
    return PocketTimes(cam(tp, profile.machine).cycle_time_s, motion.cycle_time_s, len(tp))


def _targets(number: int) -> tuple[float, float, float | None]:
    """Table 3's CAD/CAM time (s) and error (%) of a pocket, and its cutter locations (pocket 1
    only; None for the others)."""
    paper = load_paper_table("sun2022_table3").set_index("pocket")
    summary = load_paper_table("sun2022_summary").set_index("quantity")["value"]
    cls = float(summary["pocket1_commanded_points"]) if number == 1 else None
    return float(paper.loc[number, "cam_s"]), float(paper.loc[number, "cam_err_pct"]), cls


def _long_axis(spec: PocketSpec) -> int:
    """Which side of ``size_mm`` the length is: the regions' longer side (Y for ``"twin"``, whose
    two regions are 0.45 of the width each)."""
    return 1 if spec.shape == "twin" else int(spec.size_mm[1] > spec.size_mm[0])


def _with(spec: PocketSpec, x: np.ndarray, length0: float) -> PocketSpec:
    """``spec`` with the inputs ``x`` (log length factor, log radius[, log advance])."""
    size = list(spec.size_mm)
    size[_long_axis(spec)] = length0 * math.exp(x[0])
    changes = {"size_mm": tuple(size), "trochoid_radius_mm": math.exp(x[1])}
    if len(x) > 2:
        changes["trochoid_advance_mm"] = math.exp(x[2])
    return dataclasses.replace(spec, **changes)


def _residuals(times: PocketTimes, targets: tuple[float, float, float | None]) -> np.ndarray:
    """Distances from the conditions, each in units of its band's half-width."""
    cam_s, err, cls = targets
    out = [100 * (times.cam_s / cam_s - 1) / CAM_TIME_TOL_PCT,
           (times.cam_err_pct - err) / CAM_POINTS]  # fmt: skip
    if cls is not None:
        out.append(100 * (times.cutter_locations / cls - 1) / CL_TOL_PCT)
    return np.array(out)


def calibrate_pocket(
    spec: PocketSpec, profile: Profile | None = None, *, max_iterations: int = 15
) -> PocketSpec:
    """The pocket with its length, trochoid radius (and, for pocket 1, trochoid advance) set so
    that its CAD/CAM time, CAD/CAM error (and cutter locations) are those of the paper.

    A damped Newton iteration in the logarithms of the inputs, its Jacobian by forward
    differences, from ``spec``; the result is rounded (length to 0.1 mm, radius and advance to
    0.01 mm) as it is shipped.

    Parameters
    ----------
    spec : PocketSpec
        The pocket (number 1-8) and the starting inputs.
    profile : Profile, optional
        The machine; the chapter's (:data:`PROFILE`) if None.
    max_iterations : int
        Newton steps at most, in [1, 100].

    Returns
    -------
    PocketSpec
        The calibrated pocket (the closest one reached if the conditions cannot all be met; see
        :func:`pocket_conditions`).
    """
    check_range("spec.number", spec.number, 1, 8)
    check_range("max_iterations", max_iterations, 1, 100)
    profile = profile or load_profile(PROFILE)
    targets = _targets(spec.number)
    length0 = spec.size_mm[_long_axis(spec)]
    x = np.log([1.0, spec.trochoid_radius_mm, spec.trochoid_advance_mm])
    x = x[: 2 + (targets[2] is not None)]
    shortest = min(spec.size_mm) / length0 if spec.shape != "twin" else 0.0  # stays the longer
    lo = np.log([max(_LENGTH_FACTOR[0], shortest), _RADIUS_MM[0], _ADVANCE_MM[0]])[: len(x)]
    hi = np.log([_LENGTH_FACTOR[1], _RADIUS_MM[1], _ADVANCE_MM[1]])[: len(x)]

    def residuals(xx: np.ndarray) -> np.ndarray:
        return _residuals(pocket_times(_with(spec, xx, length0), profile), targets)

    f = residuals(x)
    for _ in range(max_iterations):
        if np.abs(f).max() <= _AIM:
            break
        h = 0.03
        jac = np.column_stack([(residuals(x + h * e) - f) / h for e in np.eye(len(x))])
        step = np.linalg.lstsq(jac, -f, rcond=None)[0]
        step *= min(1.0, 0.3 / np.abs(step).max())
        for _halving in range(5):  # halve the step until the residuals shrink
            x_new = np.clip(x + step, lo, hi)
            f_new = residuals(x_new)
            if np.linalg.norm(f_new) < np.linalg.norm(f):
                break
            step *= 0.5
        x, f = x_new, f_new
    out = _with(spec, x, length0)
    size = tuple(round(v, 1) for v in out.size_mm)
    return dataclasses.replace(
        out,
        size_mm=size,
        trochoid_radius_mm=round(out.trochoid_radius_mm, 2),
        trochoid_advance_mm=round(out.trochoid_advance_mm, 2),
    )


def calibrate(profile: Profile | None = None) -> tuple[PocketSpec, ...]:
    """:func:`calibrate_pocket` of every pocket of :data:`~nctwin.programs.thinwall.POCKETS`,
    each from its shipped inputs (a few seconds)."""
    profile = profile or load_profile(PROFILE)
    return tuple(calibrate_pocket(spec, profile) for spec in POCKETS)


def pocket_conditions(
    specs: tuple[PocketSpec, ...] = POCKETS, profile: Profile | None = None
) -> pd.DataFrame:
    """The paper's conditions on the part beside the pockets' (the chapter's machine, no logger).

    Returns
    -------
    pandas.DataFrame
        Per pocket: ``cam_s``, ``paper_cam_s``, ``cam_err_pct``, ``paper_cam_err_pct``,
        ``cutter_locations`` (``paper_cutter_locations`` for pocket 1, else NaN), the inputs
        (``length_mm``, ``trochoid_radius_mm``, ``trochoid_advance_mm``) and ``met`` (every
        condition of the pocket within its band).
    """
    profile = profile or load_profile(PROFILE)
    rows = []
    for spec in specs:
        times = pocket_times(spec, profile)
        targets = _targets(spec.number)
        rows.append({
            "pocket": spec.number, "cam_s": times.cam_s, "paper_cam_s": targets[0],
            "cam_err_pct": times.cam_err_pct, "paper_cam_err_pct": targets[1],
            "cutter_locations": times.cutter_locations,
            "paper_cutter_locations": np.nan if targets[2] is None else targets[2],
            "length_mm": spec.size_mm[_long_axis(spec)],
            "trochoid_radius_mm": spec.trochoid_radius_mm,
            "trochoid_advance_mm": spec.trochoid_advance_mm,
            "met": bool(np.all(np.abs(_residuals(times, targets)) <= 1.0)),
        })  # fmt: skip
    return pd.DataFrame(rows)
