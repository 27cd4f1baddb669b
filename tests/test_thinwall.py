"""The thin-wall part of Sun et al. (2022) and the slow controller recording."""

from __future__ import annotations

import numpy as np
import pytest

from nctwin import MotionKind, parse
from nctwin.kernel import fir
from nctwin.machine import load_machine
from nctwin.physics.measure import controller_samples, nearest_sample
from nctwin.programs.thinwall import HOME_MM, POCKETS, thinwall_programs


@pytest.fixture(scope="module")
def pockets():
    return {k: parse(text, start_mm=HOME_MM) for k, text in thinwall_programs().items()}


def _x_rapids(tp):
    rapid = tp.kind == MotionKind.RAPID
    dx = (tp.end_mm - tp.start_mm)[:, 0]
    return dx[rapid & (np.abs(dx) > 1e-9)]


def test_eight_pockets_parse_with_hpc_feeds(pockets):
    assert sorted(pockets) == list(range(1, 9))
    assert len({s.shape for s in POCKETS}) == 6
    for tp in pockets.values():
        cutting = (tp.kind == MotionKind.LINEAR) & (tp.start_mm[:, 2] == tp.end_mm[:, 2])
        feeds_mm_min = tp.feed_mm_s[cutting] * 60
        assert feeds_mm_min.min() >= 3000 - 1e-9 and feeds_mm_min.max() <= 4000 + 1e-9
        assert (tp.kind == MotionKind.RAPID).sum() >= 5


def test_rapid_directions_as_in_the_paper(pockets):
    # pocket 1 moves in X only towards -X at rapid; pocket 8 also has a rapid towards +X
    assert (_x_rapids(pockets[1]) < 0).all()
    assert (_x_rapids(pockets[8]) > 0).any()


def test_programs_are_deterministic():
    assert thinwall_programs() == thinwall_programs()


def test_controller_samples_rate_and_jitter():
    tp = parse("G1 X200 F6000")
    motion = fir.run(tp, load_machine(), fir.FirSettings.load())
    rec = controller_samples(motion, rate_hz=5.0, jitter_s=0.03, seed=1)
    nominal = np.arange(len(rec.t_s)) / 5.0
    assert len(rec.t_s) == pytest.approx(motion.cycle_time_s * 5, abs=1.5)
    assert np.abs(rec.t_s - nominal).max() <= 0.03 + motion.period_s
    np.testing.assert_array_equal(rec.vel_mm_s, motion.vel_mm_s[rec.index])
    again = controller_samples(motion, rate_hz=5.0, jitter_s=0.03, seed=1)
    np.testing.assert_array_equal(rec.index, again.index)
    with pytest.raises(ValueError, match="rate_hz = 0 is out of range"):
        controller_samples(motion, rate_hz=0)
    with pytest.raises(ValueError, match=r"jitter_s = 0\.2 is out of range"):
        controller_samples(motion, rate_hz=5.0, jitter_s=0.2)


def test_nearest_sample_ignores_a_later_pass():
    # out and back along X: the point X10 is passed twice; the pairing keeps to the first pass
    tp = parse("G1 X100 F6000\nX0")
    motion = fir.run(tp, load_machine(), fir.FirSettings.load())
    rec = controller_samples(motion, rate_hz=50.0, jitter_s=0.0)
    first_pass = np.flatnonzero(motion.pos_mm[:, 0] >= 10.0)[0] * motion.period_s
    k = nearest_sample(rec, np.array([[10.0, 0, 0]]), np.array([first_pass]), window_s=0.3)
    assert abs(rec.t_s[k[0]] - first_pass) < 0.1
    assert rec.vel_mm_s[k[0], 0] > 0  # still going out
