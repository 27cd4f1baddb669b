r"""Rapids ramped at the axes' acceleration on the FIR kernel (:mod:`nctwin.kernel.fir`).

The FIR kernel commands every block as a velocity pulse and lets its filters ramp each step of
the command over :math:`T_1`; a step of :math:`\Delta v` then accelerates at
:math:`\Delta v / T_1` and jerks at :math:`\Delta v / (T_1 T_2)`. So that no step exceeds the
axes' limits, it caps every block's feed at the largest admissible step,
:math:`\Delta v = \min(A T_1, J T_1 T_2)` along the block (:func:`step_mm_s`): with the short
filters of a high-performance machine that holds a rapid to a fraction of its programmed feed.

A control whose profile sets ``rapid_ramp`` instead commands a rapid as a staircase: from the
speed it enters at, up by :math:`\Delta v` every :math:`T_1` to the rapid feed, and down the same
way to the speed it leaves at (:func:`staircase_mm_s`). Filtered by the box of length
:math:`T_1`, each stair (held for the box's length, :math:`T_1` and one period) becomes a ramp of
:math:`\Delta v / T_1` at most, so the rapid
accelerates at the axes' limit, as an acceleration-limited rapid traverse does, and reaches the
programmed rapid feed where it is long enough.
"""

from __future__ import annotations

import numpy as np

from ..limits import PathLimits
from ..machine import Machine

__all__ = ["stair_cuts_mm", "staircase_mm_s", "step_mm_s"]


def step_mm_s(machine: Machine, limits: PathLimits, t1_s: float, t2_s: float) -> np.ndarray:
    """The largest velocity step along each block whose filtered ramp keeps every axis within
    its acceleration and jerk, :math:`\\min(A T_1, J T_1 T_2)` per axis along the block, shape
    (N,)."""
    step = np.asarray(machine.axis_max_acceleration_mm_s2) * t1_s
    if t2_s > 0:
        step = np.minimum(step, np.asarray(machine.axis_max_jerk_mm_s3) * t1_s * t2_s)
    return limits.cap(step)


def _levels(v0: float, dv: float, top: float, t1_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The stairs from ``v0`` up to ``top``: each level's speed and the distance from the
    anchor at which it ends (each is held for ``t1_s``), shapes (K,)."""
    n = max(int(np.ceil((top - v0) / dv)), 0)
    speeds = np.minimum(v0 + dv * np.arange(1, n + 1), top)
    return np.cumsum(speeds * t1_s), speeds


def stair_cuts_mm(
    s_a: float, s_b: float, v_a: float, v_b: float, top: float, dv: float, t1_s: float
) -> np.ndarray:
    """Arc lengths where the staircase of :func:`staircase_mm_s` changes level, inside
    ``(s_a, s_b)``, shape (K,)."""
    ends_a, _ = _levels(v_a, dv, top, t1_s)
    ends_b, _ = _levels(v_b, dv, top, t1_s)
    cuts = np.concatenate([s_a + ends_a, s_b - ends_b])
    return cuts[(cuts > s_a) & (cuts < s_b)]


def staircase_mm_s(
    s_mm: np.ndarray,
    s_a: float,
    s_b: float,
    v_a: float,
    v_b: float,
    top: float,
    dv: float,
    t1_s: float,
) -> np.ndarray:
    """The ramped rapid's command speed at arc lengths ``s_mm`` (M,): up from ``v_a`` at
    ``s_a`` by ``dv`` per ``t1_s``, down to ``v_b`` at ``s_b`` the same way, at most ``top``.

    Example: from rest, steps of 10 mm/s every 0.1 s to 25 mm/s: 10 mm/s over the first 1 mm,
    20 over the next 2 mm, then 25.

    >>> staircase_mm_s(np.array([0.5, 2.5, 10.0]), 0.0, 100.0, 0.0, 0.0, 25.0, 10.0, 0.1)
    array([10., 20., 25.])
    """
    ends_a, speeds_a = _levels(v_a, dv, top, t1_s)
    ends_b, speeds_b = _levels(v_b, dv, top, t1_s)
    up = np.append(speeds_a, top)[np.searchsorted(ends_a, s_mm - s_a, side="right")]
    down = np.append(speeds_b, top)[np.searchsorted(ends_b, s_b - s_mm, side="right")]
    return np.minimum(up, down)
