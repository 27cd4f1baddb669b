"""The Fanuc-like truth set to the conditions Lee et al. (2022) publish, before the estimator runs.

Two inputs of the truth are calibrated to the paper's experiment (Sec. 3), never to the
estimator's error:

* **In-position times.** The paper measured each axis's in-position time once (X and Y 25 ms,
  Z 120 ms; ``data/papers/lee2022_inposition.csv``) and used it for both parameter sets.
  :func:`calibrate_servo` sets the truth's servo so that the same measurement
  (:func:`nctwin.kernel.fanuc.measure_inposition_times`, with set 1) gives the paper's times:
  per axis, the in-position width (No. 1826) at the profile's position gain; where that width
  would be below the least command increment (a width the control cannot check), the axis's
  position gain (No. 1825) at the profile's width instead. The result is used for both sets.
* **The test piece's length.** The paper's test piece ran 2169 s; its drawing and pass plan
  are not published. :func:`passes_for_run_time` finishes the same features over the same
  depth in more passes, the number whose run on the truth (set 1) comes nearest the paper's
  measured time; :data:`TEST_PIECE_PASSES` is that number, and a test checks it.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.optimize import brentq

from ..controls import AccDecControl, FanucControl
from ..kernel import fanuc
from ..machine import Machine
from ..programs.iso10791 import TestPieceParams, test_piece

__all__ = [
    "TEST_PIECE_DEPTH_MM",
    "TEST_PIECE_PASSES",
    "calibrate_servo",
    "calibrated_sets",
    "passes_for_run_time",
    "test_piece_params",
]

#: Depth each feature of the test piece is finished over (the generator's 3 passes of 2 mm).
TEST_PIECE_DEPTH_MM = 6.0
#: Passes of the chapter's test piece: :func:`passes_for_run_time` for the paper's measured time
#: of set 1 on the calibrated truth (:func:`calibrate_servo`).
TEST_PIECE_PASSES = 14


def test_piece_params(passes: int = TEST_PIECE_PASSES) -> TestPieceParams:
    """The test piece's settings: ``passes`` passes over :data:`TEST_PIECE_DEPTH_MM`."""
    return TestPieceParams(passes=passes, pass_depth_mm=TEST_PIECE_DEPTH_MM / passes)


def _measured(machine: Machine, control: FanucControl, axis: int) -> float:
    """In-position time (s) of one axis, measured as the paper did."""
    return float(fanuc.measure_inposition_times(machine, control, axes=(axis,))[axis])


def calibrate_servo(machine: Machine, control: FanucControl, target_s) -> FanucControl:
    """``control`` with each axis's in-position width, or its position gain, set so that the
    in-position time measured on it is ``target_s`` (see the module's docstring).

    Parameters
    ----------
    machine : Machine
    control : FanucControl
        The truth with the parameter set the measurement is made with (the paper's set 1).
    target_s : array-like, shape (3,)
        In-position time of X, Y, Z to reach (s).

    Returns
    -------
    FanucControl
        ``control`` with new ``inposition_width_mm`` (to the least increment) and
        ``position_gain_per_s`` (to 0.01 1/s, No. 1825's unit).

    Raises
    ------
    ValueError
        If a target cannot be reached with a width in [least increment, 10] mm or a gain in
        [1, 999] 1/s.
    """
    width = list(control.inposition_width_mm)
    gain = list(control.position_gain_per_s)
    for a, target in enumerate(np.asarray(target_s, dtype=float).tolist()):

        def late(log_w: float, a: int = a, target: float = target) -> float:
            w = tuple(float(np.exp(log_w)) if i == a else width[i] for i in range(3))
            return (
                _measured(machine, dataclasses.replace(control, inposition_width_mm=w), a) - target
            )

        lo, hi = np.log(control.least_increment_mm), np.log(9.99)
        if late(lo) >= 0 >= late(hi):
            w = float(np.exp(brentq(late, lo, hi, xtol=1e-4)))  # to the detection unit
            width[a] = round(round(w / control.least_increment_mm) * control.least_increment_mm, 9)
            continue

        def slow(kp: float, a: int = a, target: float = target) -> float:
            k = tuple(kp if i == a else gain[i] for i in range(3))
            return (
                _measured(machine, dataclasses.replace(control, position_gain_per_s=k), a) - target
            )

        if not slow(1.0) >= 0 >= slow(999.0):
            raise ValueError(
                f"target_s[{a}] = {target!r} is out of range: no in-position width in "
                f"[{control.least_increment_mm:g}, 10] mm or position gain in [1, 999] 1/s "
                "reaches it"
            )
        gain[a] = round(float(brentq(slow, 1.0, 999.0, xtol=1e-3)), 2)  # No. 1825: 0.01/s
    return dataclasses.replace(
        control, inposition_width_mm=tuple(width), position_gain_per_s=tuple(gain)
    )


def calibrated_sets(
    machine: Machine, sets: dict[int, tuple[AccDecControl, FanucControl]], target_s
) -> dict[int, tuple[AccDecControl, FanucControl]]:
    """``sets`` (:func:`nctwin.chapters.lee2022.parameter_sets`) with every truth's servo set by
    :func:`calibrate_servo` on the first set's truth: one servo, as the testbed has one."""
    servo = calibrate_servo(machine, next(iter(sets.values()))[1], target_s)
    keep = {"inposition_width_mm": servo.inposition_width_mm,
            "position_gain_per_s": servo.position_gain_per_s}  # fmt: skip
    return {s: (model, dataclasses.replace(truth, **keep)) for s, (model, truth) in sets.items()}


def passes_for_run_time(
    machine: Machine, control: FanucControl, target_s: float, *, max_passes: int = 60
) -> int:
    """The number of passes whose test piece runs nearest ``target_s`` on the truth.

    The run time grows with the passes (each adds its rapids, plunge and contours), so the
    search stops at the first count whose run reaches the target.

    Parameters
    ----------
    machine : Machine
    control : FanucControl
    target_s : float
        Run time to reach (s), > 0.
    max_passes : int
        Largest count tried.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        If ``target_s`` is not a number > 0, or needs more than ``max_passes`` passes.
    """
    if not (np.isfinite(target_s) and target_s > 0):
        raise ValueError(f"target_s = {target_s!r} is out of range: allowed (0, inf) s")
    previous = 0.0
    for passes in range(1, max_passes + 1):
        run_s = fanuc.simulate(test_piece(test_piece_params(passes)), machine, control).cycle_time_s
        if run_s >= target_s:
            return passes if run_s - target_s <= target_s - previous else passes - 1
        previous = run_s
    raise ValueError(
        f"target_s = {target_s!r} is out of range: the test piece runs {previous:.0f} s "
        f"with max_passes = {max_passes}"
    )
