r"""The one position-loop model of an axis: what the axis does with its control's command.

A feed axis's position loop follows the commanded position with a lag. Two forms:

* ``first_order_ff``: a P position loop of gain :math:`K_p` over an ideal velocity loop, with a
  velocity feed-forward share :math:`\alpha`: the following error :math:`e = x_c - x` obeys
  :math:`\dot e = -K_p e + (1 - \alpha) v_c`. At a constant feed :math:`F` the error settles at
  :math:`(1 - \alpha) F / K_p`; after the command stops it decays as :math:`e^{-K_p t}`.
* ``second_order``: the velocity loop too has dynamics, natural frequency :math:`\omega_n` and
  damping :math:`\zeta`: :math:`\dot e = v_c - w`, :math:`\dot w = \omega_n^2 e - 2\zeta\omega_n
  w + 2\zeta\omega_n \alpha v_c` (at constant feed it lags like the first-order loop with
  :math:`K_p = \omega_n / 2\zeta`).

The command is sampled every period and its velocity held over the period; the loop is
discretised exactly for that (the matrix exponential), so the response does not depend on the
period beyond the sampling itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from ..checks import check_range

__all__ = ["KINDS", "PositionLoop"]

#: Forms of :class:`PositionLoop`.
KINDS = ("first_order_ff", "second_order")


@dataclass(frozen=True)
class PositionLoop:
    """One axis's position loop.

    Parameters
    ----------
    kind : {"first_order_ff", "second_order"}
    gain_per_s : float
        Position-loop gain :math:`K_p` (1/s), > 0 (``first_order_ff``).
    feedforward : float
        Velocity feed-forward share :math:`\\alpha`, in [0, 1].
    natural_freq_hz : float
        :math:`\\omega_n / 2\\pi` (``second_order``), > 0.
    damping : float
        :math:`\\zeta` (``second_order``), > 0.
    """

    kind: str = "first_order_ff"
    gain_per_s: float = 30.0
    feedforward: float = 0.0
    natural_freq_hz: float = 10.0
    damping: float = 0.7

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind = {self.kind!r} is not allowed: allowed {', '.join(KINDS)}")
        for name in ("gain_per_s", "natural_freq_hz", "damping"):
            check_range(name, getattr(self, name), 0.0, math.inf, low_open=True, high_open=True)
        check_range("feedforward", self.feedforward, 0.0, 1.0)

    def matrices(self, period_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Exact discretisation for a command velocity held over ``period_s``.

        State: following error ``e`` and actual velocity ``w`` (unused by the first-order
        loop); input: the command velocity. Returns ``ad``, shape (2, 2), and ``bd``, shape (2,):
        ``state[n + 1] = ad @ state[n] + bd * v_command[n]``.
        """
        m = np.zeros((3, 3))
        if self.kind == "first_order_ff":
            m[0, 0] = -self.gain_per_s
            m[0, 2] = 1.0 - self.feedforward
        else:
            wn = 2.0 * math.pi * self.natural_freq_hz
            zeta, ff = self.damping, self.feedforward
            m[0, 1], m[0, 2] = -1.0, 1.0  # e' = v - w
            m[1, 0], m[1, 1], m[1, 2] = wn * wn, -2.0 * zeta * wn, 2.0 * zeta * wn * ff
        em = expm(m * period_s)
        return em[:2, :2], em[:2, 2]

    def follow(self, command_mm: np.ndarray, period_s: float) -> np.ndarray:
        """The actual positions of an axis that starts at rest on the first command sample.

        Parameters
        ----------
        command_mm : ndarray, shape (n,)
            Commanded positions, one per period.
        period_s : float

        Returns
        -------
        ndarray, shape (n,)
            Actual positions at the same instants.
        """
        ad, bd = self.matrices(period_s)
        cmd = np.asarray(command_mm, dtype=float)
        v = np.diff(cmd, prepend=cmd[:1]) / period_s
        state = np.zeros(2)
        err = np.empty(len(cmd))
        for n in range(len(cmd)):
            state = ad @ state + bd * v[n]
            err[n] = state[0]
        return cmd - err
