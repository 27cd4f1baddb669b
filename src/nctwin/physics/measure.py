"""What a measuring system sees of a motion: a real control's recorded trace, and a controller's
data sampled slowly and unevenly.

A real control records its axes' actual positions, which lag its command: :class:`Recording`
adds the package's position loop (:class:`~nctwin.physics.servo.PositionLoop`, first order, no
feed-forward) (servo lag, with the wait for the in-position window at the end)
and encoder noise to a kernel's command positions (Chien et al. 2023, "machine B").

Sun et al. (2022, Sec. 4.1) read the actual axis feeds of a Siemens 840D with a slow logger: 901
samples against 5383 cutter locations, about 2.9 per second. :func:`controller_samples` samples
a kernel's Motion the same way (a nominal rate with a seeded timing jitter), and
:func:`nearest_sample` pairs each cutter location with the measured sample nearest to it, the
paper's approximation of the feed "at" a cutter location.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_range
from ..motion import Motion
from .servo import PositionLoop

__all__ = ["ControllerSamples", "Recording", "controller_samples", "nearest_sample"]


@dataclass(frozen=True)
class ControllerSamples:
    """Samples of a motion as a slow data logger records them.

    Parameters
    ----------
    index : ndarray of int64, shape (m,)
        Index of each recorded sample in the motion.
    t_s : ndarray, shape (m,)
        Times of the records.
    pos_mm, vel_mm_s : ndarray, shape (m, 3)
        Recorded positions and axis velocities (signed axis feeds).
    """

    index: np.ndarray
    t_s: np.ndarray
    pos_mm: np.ndarray
    vel_mm_s: np.ndarray


def controller_samples(
    motion: Motion, *, rate_hz: float = 5.0, jitter_s: float = 0.03, seed: int = 0
) -> ControllerSamples:
    """Record a motion at ``rate_hz`` with a uniform timing jitter of +-``jitter_s``.

    Parameters
    ----------
    motion : Motion
    rate_hz : float
        Nominal recording rate, in (0, 1 / period].
    jitter_s : float
        Half-width of the uniform jitter of each record's time, in [0, 0.5 / rate_hz).
    seed : int
        Seed of the jitter.
    """
    period = motion.period_s
    check_range("rate_hz", rate_hz, 0.0, 1.0 / period, low_open=True)
    check_range("jitter_s", jitter_s, 0.0, 0.5 / rate_hz, high_open=True)
    rng = np.random.default_rng(seed)
    nominal = np.arange(0.0, motion.cycle_time_s + 1e-12, 1.0 / rate_hz)
    t = nominal + rng.uniform(-jitter_s, jitter_s, len(nominal))
    index = np.unique(np.clip(np.rint(t / period).astype(np.int64), 0, len(motion) - 1))
    return ControllerSamples(index, motion.t_s[index], motion.pos_mm[index], motion.vel_mm_s[index])


def nearest_sample(
    samples: ControllerSamples,
    points_mm: np.ndarray,
    passage_s: np.ndarray,
    *,
    window_s: float = 2.0,
    since_s: np.ndarray | None = None,
) -> np.ndarray:
    """For each point, the record nearest to it in space among the records within ``window_s``
    of the time the tool passed it (so that a later pass over the same spot is not taken).

    Parameters
    ----------
    samples : ControllerSamples
    points_mm : ndarray, shape (N, 3)
        Cutter locations.
    passage_s : ndarray, shape (N,)
        Time the tool passes each cutter location (e.g. its junction sample's time).
    window_s : float
        Half-width of the time window searched.
    since_s : ndarray, shape (N,), optional
        Where given (finite), only the records taken from ``since_s`` to ``passage_s`` count,
        e.g. those taken while the tool was on the block that ends at the point; a point with
        no such record within the window keeps the nearest of all. NaN: no restriction.

    Returns
    -------
    ndarray of int64, shape (N,)
        Index into the records.
    """
    m = len(samples.t_s)
    span = max(1, int(np.ceil(window_s * m / max(samples.t_s[-1], 1e-9))) + 1)
    centre = np.searchsorted(samples.t_s, passage_s)
    cand = np.clip(centre[:, None] + np.arange(-span, span + 1)[None, :], 0, m - 1)
    d2 = ((samples.pos_mm[cand] - points_mm[:, None, :]) ** 2).sum(axis=2)
    t = samples.t_s[cand]
    d2[np.abs(t - passage_s[:, None]) > window_s] = np.inf
    if since_s is not None:
        outside = (t < since_s[:, None]) | (t > passage_s[:, None])
        restrict = np.isfinite(since_s) & (np.isfinite(d2) & ~outside).any(axis=1)
        d2[restrict[:, None] & outside] = np.inf
    return cand[np.arange(len(points_mm)), np.argmin(d2, axis=1)]


@dataclass(frozen=True)
class Recording:
    """What a real control's recorded trace adds to the kernel's command positions.

    Parameters
    ----------
    position_gain_1_s : float
        Gain ``Kv`` of a first-order position loop per axis (1/s,
        :class:`~nctwin.physics.servo.PositionLoop` ``first_order_ff`` without feed-forward,
        discretised exactly); the actual position lags the
        command by ``F / Kv``, in time by ``1 / Kv``, and so do the recorded block labels. 0: no
        lag (the simulation profile).
    in_position_mm : float
        The motion ends when every axis is this close to the end point.
    noise_mm : float
        Standard deviation of the encoder noise on every recorded position.
    seed : int
        Seed of the noise (combined with the program's index).
    """

    position_gain_1_s: float = 0.0
    in_position_mm: float = 0.001
    noise_mm: float = 0.0
    seed: int = 0

    def apply(self, motion: Motion, rng: np.random.Generator) -> Motion:
        """The recorded motion: lagged, extended until in position, noisy; the block labels
        delayed by the following time."""
        ts = motion.period_s
        pos = motion.pos_mm
        block = motion.block
        if self.position_gain_1_s > 0:
            loop = PositionLoop("first_order_ff", gain_per_s=self.position_gain_1_s)
            # settle: the following error decays as exp(-Kv t) from at most the largest lag
            lag_mm = np.abs(np.diff(pos, axis=0)).max(initial=0.0) / (ts * self.position_gain_1_s)
            ratio = self.in_position_mm / max(lag_mm, 1e-12)
            extra = max(int(np.ceil(-np.log(ratio) / (self.position_gain_1_s * ts))), 0)
            cmd = np.vstack([pos, np.repeat(pos[-1:], extra, axis=0)])
            # an axis the program does not move stays where it is (follow() would return it)
            pos = np.column_stack([c if np.all(c == c[0]) else loop.follow(c, ts) for c in cmd.T])
            delay = round(1.0 / (self.position_gain_1_s * ts))  # following time 1 / Kv
            block = np.concatenate([np.full(delay, block[0]), block, np.full(extra, block[-1])])
            block = block[: len(pos)]
        if self.noise_mm > 0:
            pos = pos + rng.normal(0.0, self.noise_mm, pos.shape)
        vel = np.zeros_like(pos)
        vel[1:] = np.diff(pos, axis=0) / ts
        return Motion(np.arange(len(pos)) * ts, pos, vel, block, ts)
