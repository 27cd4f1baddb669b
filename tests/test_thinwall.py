"""The thin-wall part of Sun et al. (2022) and the slow controller recording."""

from __future__ import annotations

import numpy as np
import pytest

from nctwin import MotionKind, parse
from nctwin.estimate import estimate
from nctwin.kernel import fir
from nctwin.machine import load_profile
from nctwin.physics.measure import ControllerSamples, controller_samples, nearest_sample
from nctwin.programs.thinwall import (
    POCKETS,
    SEGMENT_MM,
    pocket_program,
    start_mm,
    thinwall_programs,
)
from nctwin.report.tables import load_paper_table


@pytest.fixture(scope="module")
def pockets():
    parsed = {s.number: parse(pocket_program(s), start_mm=start_mm(s)) for s in POCKETS}
    return {k: tp.take(tp.lengths_mm > 0) for k, tp in parsed.items()}


GENERIC = load_profile()  # the default profile


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


def test_entry_as_a_cam_post_writes_it(pockets):
    # each program starts above its first entry point: no rapid longer than the part's pocket
    # spacing, and the first move is the rapid down towards the first level
    for spec in POCKETS:
        tp = pockets[spec.number]
        rapid = tp.kind == MotionKind.RAPID
        assert tp.lengths_mm[rapid].max() < 150.0
        np.testing.assert_allclose(tp.start_mm[0], start_mm(spec))
        assert tp.kind[0] == MotionKind.RAPID and tp.end_mm[0, 2] == pytest.approx(1.0)


def test_cl_spacing_and_cam_times_as_the_papers(pockets):
    # the paper's pocket 1: 5383 cutter locations; CAD/CAM times of Table 3 (frozen: within 10 %)
    summary = load_paper_table("sun2022_summary").set_index("quantity")["value"]
    assert len(pockets[1]) == pytest.approx(summary["pocket1_commanded_points"], rel=0.1)
    paper = load_paper_table("sun2022_table3").set_index("pocket")["cam_s"]
    machine = load_profile("sun2022_siemens")
    for k, tp in pockets.items():
        assert tp.length_mm / len(tp) == pytest.approx(SEGMENT_MM, rel=0.15)
        assert estimate(tp, machine, "cam").cycle_time_s == pytest.approx(paper[k], rel=0.1)


def test_bad_stepover_is_refused():
    with pytest.raises(ValueError, match="stepover_mm = 0 is out of range"):
        pocket_program(POCKETS[0], stepover_mm=0)


def test_controller_samples_rate_and_jitter():
    tp = parse("G1 X200 F6000")
    motion = fir.run(tp, GENERIC.machine, GENERIC.control("fir"))
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
    motion = fir.run(tp, GENERIC.machine, GENERIC.control("fir"))
    rec = controller_samples(motion, rate_hz=50.0, jitter_s=0.0)
    first_pass = np.flatnonzero(motion.pos_mm[:, 0] >= 10.0)[0] * motion.period_s
    k = nearest_sample(rec, np.array([[10.0, 0, 0]]), np.array([first_pass]), window_s=0.3)
    assert abs(rec.t_s[k[0]] - first_pass) < 0.1
    assert rec.vel_mm_s[k[0], 0] > 0  # still going out


def test_nearest_sample_since_keeps_to_the_block():
    # records at 0.5, 0.9 and 1.05 s at X 5, 9.5 and 10; the tool passes X10 at 1.0 s
    pos = np.array([[5.0, 0, 0], [9.5, 0, 0], [10.0, 0, 0]])
    rec = ControllerSamples(np.arange(3), np.array([0.5, 0.9, 1.05]), pos, np.ones((3, 3)))
    point, passage = np.array([[10.0, 0, 0]]), np.array([1.0])
    assert nearest_sample(rec, point, passage)[0] == 2  # the nearest of all, after the passage
    assert nearest_sample(rec, point, passage, since_s=np.array([0.5]))[0] == 1  # on the block
    assert nearest_sample(rec, point, passage, since_s=np.array([np.nan]))[0] == 2
    assert nearest_sample(rec, point, passage, since_s=np.array([0.95]))[0] == 2  # none: all
