r"""The model-based force reconstruction of Denkena et al. (2020, Sec. 2.2, eq. 1-10).

The process force on each axis is what is left of the motor force once the model's cogging,
restoring, friction and inertia forces are taken off (eq. 2),

.. math:: F = K_m I - F_{co}(s) - k (s - s_r) - F_{fr}(\dot s) - M \ddot s,

with :math:`M` the stacked masses :math:`m_x + m_z`, :math:`m_x + m_y + m_z`, :math:`m_z`. It is
fitted from air moves (no cutting) in the paper's four steps, one axis at a time:

1. :func:`fit_restoring`: the motor force of constant-velocity runs in + and - direction,
   averaged per position over both directions (friction cancels), is a straight line
   :math:`k (s - s_r)` (linear regression) plus
2. the cogging force, kept as a lookup table of the residual over position;
3. :func:`fit_stribeck`: the Stribeck curve (eq. 4, :math:`\delta = 2`) fitted to
   :math:`\tilde F_{fr} = K_m I - F_{co} - k (s - s_r)` (eq. 5) of runs at many constant
   velocities by trust-region-reflective least squares (eq. 6);
4. :func:`fit_masses`: the masses from accelerated moves, minimising eq. 8-10 on
   :math:`\tilde F_m = K_m I - F_{co} - k (s - s_r) - F_{fr}` (eq. 7).

The motor constants :math:`K_m` are taken as known (data sheet). Units: mm, s, N, A, kg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

__all__ = [
    "AxisModel",
    "ForceModel",
    "StribeckParams",
    "fit_masses",
    "fit_restoring",
    "fit_stribeck",
    "stribeck_n",
]


@dataclass(frozen=True)
class StribeckParams:
    """Parameters of eq. 4.

    Parameters
    ----------
    coulomb_n : float
        :math:`F_C`.
    breakaway_n : float
        :math:`F_{br}`.
    stribeck_mm_s : float
        :math:`v_s`, > 0.
    viscous_n_s_mm : float
        :math:`\\sigma`.
    shape : float
        :math:`\\delta` (paper: 2, after Ruderman).
    """

    coulomb_n: float
    breakaway_n: float
    stribeck_mm_s: float
    viscous_n_s_mm: float
    shape: float = 2.0

    def __post_init__(self) -> None:
        if not self.stribeck_mm_s > 0:
            raise ValueError(f"stribeck_mm_s = {self.stribeck_mm_s!r} is out of range: allowed > 0")
        if not self.shape > 0:
            raise ValueError(f"shape = {self.shape!r} is out of range: allowed > 0")


def stribeck_n(v_mm_s: np.ndarray, p: StribeckParams) -> np.ndarray:
    r"""Eq. 4: :math:`\mathrm{sgn}(v)\,(F_C + (F_{br} - F_C) e^{-|v/v_s|^\delta}) + \sigma v`.

    Parameters
    ----------
    v_mm_s : ndarray, any shape
    p : StribeckParams

    Returns
    -------
    ndarray, same shape
    """
    v = np.asarray(v_mm_s, dtype=float)
    shape = np.exp(-(np.abs(v / p.stribeck_mm_s) ** p.shape))
    return np.sign(v) * (p.coulomb_n + (p.breakaway_n - p.coulomb_n) * shape) + p.viscous_n_s_mm * v


def fit_restoring(
    pos_plus_mm: np.ndarray,
    force_plus_n: np.ndarray,
    pos_minus_mm: np.ndarray,
    force_minus_n: np.ndarray,
    *,
    bin_mm: float = 0.5,
) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Steps 1 and 2: restoring line and cogging lookup table.

    Parameters
    ----------
    pos_plus_mm, force_plus_n : ndarray, shape (N+,)
        Position and motor force :math:`K_m I` of a constant-velocity run in + direction.
    pos_minus_mm, force_minus_n : ndarray, shape (N-,)
        The same in - direction, over the same travel.
    bin_mm : float
        Width of the position bins the two directions are averaged in (> 0).

    Returns
    -------
    restoring_n_mm : float
        :math:`k`.
    rest_point_mm : float
        :math:`s_r`.
    grid_mm : ndarray, shape (G,)
        Bin centres covered by both directions.
    cogging_n : ndarray, shape (G,)
        The residual of the line: the cogging lookup table.
    """
    if not bin_mm > 0:
        raise ValueError(f"bin_mm = {bin_mm!r} is out of range: allowed > 0")
    lo = max(np.min(pos_plus_mm), np.min(pos_minus_mm))
    hi = min(np.max(pos_plus_mm), np.max(pos_minus_mm))
    if not hi - lo > 2 * bin_mm:
        raise ValueError(f"the runs overlap over {hi - lo!r} mm: allowed > 2 bin_mm = {2 * bin_mm}")
    edges = np.arange(lo, hi + bin_mm, bin_mm)
    means = []
    for s, f in ((pos_plus_mm, force_plus_n), (pos_minus_mm, force_minus_n)):
        idx = np.digitize(s, edges) - 1
        ok = (idx >= 0) & (idx < len(edges) - 1)
        total = np.bincount(idx[ok], weights=np.asarray(f)[ok], minlength=len(edges) - 1)
        count = np.bincount(idx[ok], minlength=len(edges) - 1)
        means.append(np.where(count > 0, total / np.maximum(count, 1), np.nan))
    grid = 0.5 * (edges[:-1] + edges[1:])
    mean = 0.5 * (means[0] + means[1])
    keep = np.isfinite(mean)
    grid, mean = grid[keep], mean[keep]
    k, b = np.polyfit(grid, mean, 1)
    return float(k), float(-b / k), grid, mean - (k * grid + b)


def fit_stribeck(
    v_mm_s: np.ndarray, friction_n: np.ndarray, *, shape: float = 2.0
) -> StribeckParams:
    """Step 3: eq. 6 by trust-region-reflective least squares.

    Parameters
    ----------
    v_mm_s : ndarray, shape (M,)
        Constant velocities (both signs).
    friction_n : ndarray, shape (M,)
        :math:`\\tilde F_{fr}` (eq. 5) at those velocities.
    shape : float
        :math:`\\delta`, held fixed (paper: 2).

    Returns
    -------
    StribeckParams
    """
    v = np.asarray(v_mm_s, dtype=float)
    f = np.asarray(friction_n, dtype=float)
    if v.shape != f.shape or v.size < 4:
        raise ValueError(
            f"v_mm_s and friction_n shapes = {v.shape}, {f.shape}: allowed equal, >= 4"
        )
    slow = np.abs(v) <= np.quantile(np.abs(v), 0.5)
    fast = ~slow
    f_c0 = float(np.median(np.abs(f[fast])))
    f_br0 = float(max(np.abs(f[slow]).max(), f_c0))
    x0 = [f_c0 * 0.8, f_br0, float(np.median(np.abs(v[slow])) + 1e-3), 0.0]

    def residual(x):
        return stribeck_n(v, StribeckParams(*x, shape=shape)) - f

    scale = max(np.abs(f).max(), 1.0)
    upper = [10 * scale, 10 * scale, 10 * np.abs(v).max(), 10 * scale / np.abs(v).max()]
    fit = least_squares(residual, x0, bounds=([0, 0, 1e-4, 0], upper), method="trf")
    return StribeckParams(*(float(x) for x in fit.x), shape=shape)


def fit_masses(force_n: list[np.ndarray], acc_mm_s2: list[np.ndarray]) -> np.ndarray:
    r"""Step 4: eq. 8-10, the moved masses of X, Y, Z by linear least squares, then the own masses.

    Parameters
    ----------
    force_n, acc_mm_s2 : list of three ndarray, each shape (N_a,)
        :math:`\tilde F_{m}` (eq. 7) and acceleration of the accelerated moves of X, Y, Z.

    Returns
    -------
    ndarray, shape (3,)
        :math:`m_x, m_y, m_z` (kg), from the moved masses :math:`M_x = m_x + m_z`,
        :math:`M_y = m_x + m_y + m_z`, :math:`M_z = m_z`.
    """
    moved = np.array(
        [1e3 * np.dot(f, a) / np.dot(a, a) for f, a in zip(force_n, acc_mm_s2, strict=True)]
    )
    m_z = moved[2]
    m_x = moved[0] - m_z
    return np.array([m_x, moved[1] - moved[0], m_z])


@dataclass(frozen=True, eq=False)
class AxisModel:
    """The fitted model of one axis.

    Parameters
    ----------
    km_n_a : float
    restoring_n_mm, rest_point_mm : float
    grid_mm, cogging_n : ndarray, shape (G,)
        Cogging lookup table (linear interpolation, held at its ends).
    friction : StribeckParams
    """

    km_n_a: float
    restoring_n_mm: float
    rest_point_mm: float
    grid_mm: np.ndarray
    cogging_n: np.ndarray
    friction: StribeckParams

    def position_force_n(self, s_mm: np.ndarray) -> np.ndarray:
        """:math:`F_{co}(s) + k (s - s_r)`."""
        cog = np.interp(s_mm, self.grid_mm, self.cogging_n)
        return cog + self.restoring_n_mm * (np.asarray(s_mm) - self.rest_point_mm)


@dataclass(frozen=True, eq=False)
class ForceModel:
    """The fitted reconstruction, eq. 2.

    Parameters
    ----------
    axes : tuple of three AxisModel
    own_mass_kg : ndarray, shape (3,)
        :math:`m_x, m_y, m_z`.
    """

    axes: tuple[AxisModel, AxisModel, AxisModel]
    own_mass_kg: np.ndarray

    @property
    def moved_mass_kg(self) -> np.ndarray:
        """Eq. 2's mass matrix diagonal: :math:`m_x + m_z, m_x + m_y + m_z, m_z`."""
        mx, my, mz = self.own_mass_kg
        return np.array([mx + mz, mx + my + mz, mz])

    def reconstruct(
        self, pos_mm: np.ndarray, vel_mm_s: np.ndarray, acc_mm_s2: np.ndarray, current_a: np.ndarray
    ) -> np.ndarray:
        """Process forces from the drive signals (eq. 2).

        Parameters
        ----------
        pos_mm, vel_mm_s, acc_mm_s2, current_a : ndarray, shape (R, 3)

        Returns
        -------
        ndarray, shape (R, 3)
        """
        out = np.empty(np.shape(current_a))
        for i, a in enumerate(self.axes):
            out[:, i] = (
                a.km_n_a * current_a[:, i]
                - a.position_force_n(pos_mm[:, i])
                - stribeck_n(vel_mm_s[:, i], a.friction)
                - self.moved_mass_kg[i] * acc_mm_s2[:, i] * 1e-3
            )
        return out
