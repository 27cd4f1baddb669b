"""The one position-loop model (nctwin.physics.servo), against its closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin.physics.servo import PositionLoop

TS = 0.001


def _ramp_then_hold(feed_mm_s: float, t_move_s: float, t_hold_s: float) -> np.ndarray:
    t = np.arange(round((t_move_s + t_hold_s) / TS) + 1) * TS
    return feed_mm_s * np.minimum(t, t_move_s)


@pytest.mark.parametrize("ff", [0.0, 0.5])
def test_first_order_lags_by_f_over_kp_and_decays_exponentially(ff):
    loop = PositionLoop("first_order_ff", gain_per_s=40.0, feedforward=ff)
    cmd = _ramp_then_hold(100.0, 0.5, 0.2)
    err = cmd - loop.follow(cmd, TS)
    k = round(0.5 / TS)  # the command stops here
    # steady lag (1 - ff) F / Kp = 2.5 mm (1.25 mm with half feed-forward)
    assert err[k] == pytest.approx((1 - ff) * 100.0 / 40.0, rel=1e-6)
    # then e(t) = e0 exp(-Kp t), exactly at the samples (the discretisation is exact)
    j = np.arange(1, 150)
    np.testing.assert_allclose(err[k + j], err[k] * np.exp(-40.0 * j * TS), rtol=1e-9)


def test_second_order_lags_like_kp_of_wn_over_2_zeta():
    loop = PositionLoop("second_order", natural_freq_hz=11.0, damping=0.7)
    cmd = _ramp_then_hold(60.0, 1.0, 0.0)
    err = cmd - loop.follow(cmd, TS)
    kp = 2 * math.pi * 11.0 / (2 * 0.7)
    assert err[-1] == pytest.approx(60.0 / kp, rel=1e-6)


def test_period_changes_only_the_sampling():
    loop = PositionLoop("first_order_ff", gain_per_s=30.0)
    fine = loop.follow(np.linspace(0, 10, 1001), 0.001)[::2]
    coarse = loop.follow(np.linspace(0, 10, 501), 0.002)
    np.testing.assert_allclose(fine, coarse, atol=2e-3)  # within the velocity's sampling


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"kind": "pid"}, "kind = 'pid' is not allowed"),
     ({"gain_per_s": 0.0}, r"gain_per_s = 0.0 is out of range: allowed \(0, inf\)"),
     ({"feedforward": 1.5}, r"feedforward = 1.5 is out of range: allowed \[0, 1\]")],
)  # fmt: skip
def test_bad_settings_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        PositionLoop(**kwargs)
