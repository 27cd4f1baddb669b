"""Sampled motion: what a kernel (virtual NC) outputs and what features and plots read.

Conventions: samples at a fixed period, starting at ``t = 0``; positions in mm; velocities in
mm/s. Velocity, acceleration and jerk at sample ``i`` are backward differences (over the period
ending at sample ``i``); they are 0 at the first sample. ``block[i]`` is the index (into the
Toolpath) of the block the interpolator executes at sample ``i``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Motion"]


@dataclass(frozen=True, eq=False)
class Motion:
    """Interpolated motion of the tool.

    Parameters
    ----------
    t_s : ndarray, shape (n,)
        Sample times, ``t_s[i] = i * period_s``.
    pos_mm : ndarray, shape (n, 3)
        Tool position.
    vel_mm_s : ndarray, shape (n, 3)
        Axis velocities.
    block : ndarray of int64, shape (n,)
        Block being executed at each sample.
    period_s : float
        Sampling (interpolation) period.
    """

    t_s: np.ndarray
    pos_mm: np.ndarray
    vel_mm_s: np.ndarray
    block: np.ndarray
    period_s: float

    def __post_init__(self) -> None:
        n = len(self.t_s)
        for name, shape in (("pos_mm", (n, 3)), ("vel_mm_s", (n, 3)), ("block", (n,))):
            a = np.asarray(getattr(self, name))
            if a.shape != shape:
                raise ValueError(f"Motion.{name} must have shape {shape}, got {a.shape}")
        for name in ("t_s", "pos_mm", "vel_mm_s", "block"):
            a = np.ascontiguousarray(getattr(self, name))
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def speed_mm_s(self) -> np.ndarray:
        """Path speed, shape (n,)."""
        return np.linalg.norm(self.vel_mm_s, axis=1)

    @property
    def acc_mm_s2(self) -> np.ndarray:
        """Axis accelerations, backward differences of the velocities, shape (n, 3)."""
        return _backward_diff(self.vel_mm_s, self.period_s)

    @property
    def jerk_mm_s3(self) -> np.ndarray:
        """Axis jerks, backward differences of the accelerations, shape (n, 3)."""
        return _backward_diff(self.acc_mm_s2, self.period_s)

    @property
    def cycle_time_s(self) -> float:
        """Duration of the motion: time of the last sample."""
        return float(self.t_s[-1]) if len(self) else 0.0

    def to_frame(self):
        """Samples as a :class:`pandas.DataFrame`, for export (``nctwin simulate --csv``)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "t_s": self.t_s,
                **{f"{a}_mm": self.pos_mm[:, i] for i, a in enumerate("xyz")},
                **{f"v{a}_mm_s": self.vel_mm_s[:, i] for i, a in enumerate("xyz")},
                "speed_mm_s": self.speed_mm_s,
                "block": self.block,
            }
        )


def _backward_diff(x: np.ndarray, dt: float) -> np.ndarray:
    out = np.zeros_like(x)
    out[1:] = np.diff(x, axis=0) / dt
    return out
