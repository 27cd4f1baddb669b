r"""What a machine's axis limits allow along a tool path: one rule for every kernel and estimator.

An axis limit :math:`L_i` (velocity, acceleration or jerk of axis :math:`i`) bounds the path's
:math:`L` along a block by :math:`\min_i L_i / s_i`, where :math:`s_i` is the largest share of
the path quantity axis :math:`i` takes on the block (toppra's idea: a constraint receives the
path). The shares (:func:`axis_shares`):

* a line or rapid of direction :math:`u`: :math:`s_i = |u_i|`;
* an arc of radius :math:`r`, sweep :math:`\phi` and length :math:`l` (a helix rises
  :math:`h` along the plane's normal, :math:`l^2 = (r\phi)^2 + h^2`): each of the plane's two
  axes takes the planar share :math:`r |\phi| / l` (an axis of the plane runs at the full
  planar speed where the arc's tangent points along it), the normal axis the helical share
  :math:`\sqrt{1 - (r\phi/l)^2} = |h|/l` (LinuxCNC's rule, canon's ``getStraightVelocity`` and
  ``getStraightAcceleration`` applied to a circle);
* a dwell or a move of zero length: 0 on every axis (no limit).

How a control splits the acceleration on an arc between its tangent and its normal is the
control's rule, not the machine's; each kernel says its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .machine import Machine
from .toolpath import Toolpath

__all__ = ["PathLimits", "axis_shares", "path_limits"]


def axis_shares(toolpath: Toolpath) -> np.ndarray:
    """Largest share of the path speed each axis takes along each block, shape (N, 3), in
    [0, 1] (see the module docstring)."""
    share = np.abs(toolpath.directions)
    arc = np.flatnonzero(toolpath.is_arc)
    if len(arc):
        ax = toolpath._plane_axes[arc]
        rows = np.arange(len(arc))
        length = toolpath.lengths_mm[arc]
        with np.errstate(divide="ignore", invalid="ignore"):
            planar = toolpath.radius_mm[arc] * np.abs(toolpath.sweep_rad[arc]) / length
        planar = np.where(length > 0, planar, 0.0)
        s = np.empty((len(arc), 3))
        s[rows, ax[:, 0]] = planar
        s[rows, ax[:, 1]] = planar
        s[rows, ax[:, 2]] = np.where(length > 0, np.sqrt(np.maximum(1.0 - planar**2, 0.0)), 0.0)
        share[arc] = s
    return share


@dataclass(frozen=True, eq=False)
class PathLimits:
    """The machine's axis limits along each of the N blocks of a tool path.

    Parameters
    ----------
    shares : ndarray, shape (N, 3)
        :func:`axis_shares` of the blocks.
    velocity_mm_s, acceleration_mm_s2, jerk_mm_s3 : ndarray, shape (N,)
        Path velocity, acceleration and jerk the axes allow along each block (``inf`` where
        no axis moves, or for an unlimited jerk).
    """

    shares: np.ndarray
    velocity_mm_s: np.ndarray
    acceleration_mm_s2: np.ndarray
    jerk_mm_s3: np.ndarray

    def cap(self, per_axis: np.ndarray) -> np.ndarray:
        """The path limit of any per-axis limit ``per_axis``, shape (3,) or (N, 3):
        :math:`\\min_i L_i / s_i` per block, shape (N,)."""
        return _cap(per_axis, self.shares)


def _cap(per_axis, shares: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return np.min(np.asarray(per_axis) / shares, axis=1, initial=np.inf)


def path_limits(toolpath: Toolpath, machine: Machine) -> PathLimits:
    """The axis limits of ``machine`` along each block of ``toolpath`` (:class:`PathLimits`)."""
    shares = axis_shares(toolpath)
    limits = (
        machine.axis_max_velocity_mm_s,
        machine.axis_max_acceleration_mm_s2,
        machine.axis_max_jerk_mm_s3,
    )
    return PathLimits(shares, *(_cap(v, shares) for v in limits))
