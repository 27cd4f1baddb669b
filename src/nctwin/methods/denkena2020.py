r"""Denkena, Bergmann & Stoppel (2020): process forces from feed-drive signals, by a model
(Sec. 2.2, eq. 1-10) and by an LSTM (Sec. 2.3, eq. 17).

**The model.**
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

**The LSTM.** One network per force component (:data:`MODEL_CONFIG`: 3 stacked LSTM layers of 20
cells, dropout, a dense output) on the drive signals :data:`INPUT_NAMES`, scaled as the paper
scales them (:class:`InputScaling`, eq. 17), learning the low-passed measured force
(:func:`target_forces`); :func:`predict` and :func:`mc_dropout` (its uncertainty band).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from scipy import signal
from scipy.optimize import least_squares

from ..checks import check_range
from ..learn.models import ModelConfig
from ..learn.train import Trained, one_thread

__all__ = [
    "INPUT_NAMES",
    "MODEL_CONFIG",
    "POSITIVE_INPUTS",
    "AxisModel",
    "ForceModel",
    "InputScaling",
    "StribeckParams",
    "fit_masses",
    "fit_restoring",
    "fit_stribeck",
    "mc_dropout",
    "predict",
    "stribeck_n",
    "target_forces",
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
        check_range("stribeck_mm_s", self.stribeck_mm_s, 0.0, low_open=True)
        check_range("shape", self.shape, 0.0, low_open=True)


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
    check_range("bin_mm", bin_mm, 0.0, low_open=True)
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


#: The network inputs (Sec. 2.3): X, Y, Z position, velocity, acceleration, current; spindle.
INPUT_NAMES = (
    "x_mm",
    "y_mm",
    "z_mm",
    "vx_mm_s",
    "vy_mm_s",
    "vz_mm_s",
    "ax_mm_s2",
    "ay_mm_s2",
    "az_mm_s2",
    "ix_a",
    "iy_a",
    "iz_a",
    "spindle_rpm",
    "spindle_a",
)


#: Inputs scaled to [0, 1] (strictly positive); the others to [-1, 1].
POSITIVE_INPUTS = (0, 1, 2, 12, 13)


#: The paper's network: 3 stacked LSTM layers of 20 cells, dropout, one dense output.
MODEL_CONFIG = ModelConfig(
    kind="lstm", n_inputs=len(INPUT_NAMES), n_outputs=1, hidden=20, lstm_layers=3, dropout=0.2
)


def target_forces(force_n: np.ndarray, record_rate_hz: float, cutoff_hz: float = 120.0):
    """Zero-phase Butterworth low-pass of the measured forces (Sec. 2.3), shape kept."""
    b, a = signal.butter(2, cutoff_hz, fs=record_rate_hz)
    return signal.filtfilt(b, a, force_n, axis=-2)


@dataclass(frozen=True)
class InputScaling:
    """The paper's scalings, fitted on the training processes: inputs to [-1, 1] (x / max|x|)
    or, for :data:`POSITIVE_INPUTS`, to [0, 1] (min-max); forces by eq. 17,
    :math:`F^* = F / (2 |F_{max}|) + 0.5`.

    Parameters
    ----------
    offset, scale : ndarray, shape (14,)
    force_max_n : ndarray, shape (3,)
    """

    offset: np.ndarray
    scale: np.ndarray
    force_max_n: np.ndarray

    @classmethod
    def fit(cls, inputs: np.ndarray, forces: np.ndarray) -> InputScaling:
        """From training inputs (P, R, 14) and filtered forces (P, R, 3)."""
        x = inputs.reshape(-1, inputs.shape[-1])
        offset = np.zeros(x.shape[1])
        scale = np.abs(x).max(axis=0)
        pos = list(POSITIVE_INPUTS)
        offset[pos] = x[:, pos].min(axis=0)
        scale[pos] = x[:, pos].max(axis=0) - offset[pos]
        scale = np.where(scale > 0, scale, 1.0)
        return cls(offset, scale, np.abs(forces.reshape(-1, 3)).max(axis=0))

    def inputs(self, x: np.ndarray) -> np.ndarray:
        return (x - self.offset) / self.scale

    def force(self, f: np.ndarray, axis: int) -> np.ndarray:
        """Eq. 17."""
        return f / (2.0 * self.force_max_n[axis]) + 0.5

    def force_inverse(self, f_star: np.ndarray, axis: int) -> np.ndarray:
        return (f_star - 0.5) * 2.0 * self.force_max_n[axis]


def predict(nets: dict[str, Trained], scaling: InputScaling, inputs: np.ndarray) -> np.ndarray:
    """LSTM forces (R, 3) of one process; NaN in the columns of axes without a network."""
    x = scaling.inputs(inputs)
    out = np.full((len(x), 3), np.nan)
    with one_thread():
        for a, net in nets.items():
            i = "XYZ".index(a)
            out[:, i] = scaling.force_inverse(net.predict(x)[:, 0], i)
    return out


def mc_dropout(
    nets: dict[str, Trained],
    scaling: InputScaling,
    inputs: np.ndarray,
    *,
    samples: int,
    seed: int,
    axes: str = "XY",
) -> np.ndarray:
    """Monte-Carlo dropout: forces (samples, R, len(axes)) with dropout left on at prediction.

    The dropout masks come from a forked, seeded torch generator (no global state changes).
    """
    x = scaling.inputs(inputs)
    out = np.empty((samples, len(x), len(axes)))
    for j, a in enumerate(axes):
        i = "XYZ".index(a)
        model = nets[a].model
        model.train()
        try:
            with one_thread(), torch.random.fork_rng(devices=[]):
                torch.manual_seed(seed)
                for k in range(samples):
                    out[k, :, j] = scaling.force_inverse(nets[a].predict(x)[:, 0], i)
        finally:
            model.eval()
    return out
