"""Training and test programs of Chien et al. (2023): seeded, parseable, in the paper's ranges."""

import numpy as np
import pytest

from nctwin import gcode
from nctwin.methods.chien2023 import features as chien2023_features
from nctwin.programs.training import (
    GLOBAL_LENGTH_MM,
    LOCAL_LENGTH_MM,
    PAPER_ZIGZAG_SHARE,
    ProgramSpec,
    contour_program,
    global_program,
    mixed_program,
    paper_contour_program,
    paper_global_program,
    paper_mixed_program,
    training_specs,
)


def test_same_seed_same_program_other_seed_other_program():
    a = global_program(3, n_lines=200, feed_mm_s=80, tol_mm=0.4)
    assert a == global_program(np.random.default_rng(3), n_lines=200, feed_mm_s=80, tol_mm=0.4)
    assert a != global_program(4, n_lines=200, feed_mm_s=80, tol_mm=0.4)


def test_global_program_lines_short_and_tolerance_from_g64():
    tp = gcode.parse(global_program(1, n_lines=500, feed_mm_s=92, tol_mm=0.35))
    assert 495 <= len(tp) <= 500  # rounding to 4 decimals may merge a point
    assert tp.lengths_mm.max() < GLOBAL_LENGTH_MM[1] + 1e-3
    assert tp.lengths_mm.min() > 0
    np.testing.assert_allclose(tp.feed_mm_s, 92.0)
    np.testing.assert_allclose(tp.effective_tolerance_mm(1.0), 0.35)


def test_mixed_program_local_share():
    tp = gcode.parse(mixed_program(2, n_lines=4000, feed_mm_s=70, tol_mm=0.3))
    long = tp.lengths_mm > GLOBAL_LENGTH_MM[1] + 1e-3
    # local lines are log-uniform in (0.5, 1000) mm: 1 - log(2)/log(2000) of them exceed 1 mm
    expected = 0.75 * (1 - np.log(1 / 0.5) / np.log(LOCAL_LENGTH_MM[1] / LOCAL_LENGTH_MM[0]))
    assert abs(long.mean() - expected) < 0.1
    assert tp.lengths_mm.max() <= LOCAL_LENGTH_MM[1]


def test_training_specs_ranges_and_families():
    specs = training_specs(0, n_programs=40, n_lines=100, feed_range_mm_s=(65, 100),
                           tol_range_mm=(0.3, 0.5))  # fmt: skip
    assert len(specs) == 40
    assert sum(s.family == "mixed" for s in specs) == 20
    assert all(65 <= s.feed_mm_s <= 100 and 0.3 <= s.tol_mm <= 0.5 for s in specs)
    assert len({s.seed for s in specs}) == 40
    assert specs == training_specs(0, n_programs=40, n_lines=100, feed_range_mm_s=(65, 100),
                                   tol_range_mm=(0.3, 0.5))  # fmt: skip


def test_contours_fixed_and_ii_longer_than_i():
    one = gcode.parse(contour_program("I", feed_mm_s=75, tol_mm=0.3))
    two = gcode.parse(contour_program("II", feed_mm_s=75, tol_mm=0.3))
    assert contour_program("I", feed_mm_s=75, tol_mm=0.3) == contour_program(
        "I", feed_mm_s=75, tol_mm=0.3
    )
    assert 4 < two.length_mm / one.length_mm < 9
    # sharp and smooth sections: both large and small corner angles
    angles = one.corner_angles_rad
    assert (angles > np.pi / 3).sum() > 20 and (angles[angles > 0] < 0.1).sum() > 100
    with pytest.raises(ValueError, match="unknown"):
        contour_program("III", feed_mm_s=75, tol_mm=0.3)


def test_features_rows_match_the_program():
    tp = gcode.parse("G21 G90 G64 P0.2\nG1 F6000 X10\nY10\nX0\n")
    x = chien2023_features(tp, machine_tol_mm=0.5)
    assert x.shape == (3, 5)
    np.testing.assert_allclose(x[:, 0], 100.0)
    np.testing.assert_allclose(x[:, 1], 10.0)
    np.testing.assert_allclose(x[:, 2], [np.pi, np.pi / 2, np.pi / 2])
    np.testing.assert_allclose(x[:, 3], [np.pi / 2, np.pi / 2, np.pi])
    np.testing.assert_allclose(x[:, 4], 0.2)


def test_cam_blend_program_seeded_and_in_range():
    from nctwin.programs.camblend import LINE_MM, cam_blend_program

    a = cam_blend_program(5, n_lines=4000, feed_mm_s=70.0, tol_mm=0.075)
    assert a == cam_blend_program(5, n_lines=4000, feed_mm_s=70.0, tol_mm=0.075)
    assert a != cam_blend_program(6, n_lines=4000, feed_mm_s=70.0, tol_mm=0.075)
    tp = gcode.parse(a)
    assert 3900 <= len(tp) <= 4000  # points that round onto their predecessor are dropped
    assert tp.lengths_mm.max() <= LINE_MM[1] + 1e-3
    np.testing.assert_allclose(tp.effective_tolerance_mm(1.0), 0.075)
    x = chien2023_features(tp, 1.0)
    long = x[:, 1] > 10.0
    # lines leave and meet arcs tangentially (the turn onto a chord is half the chord's angle)
    tangent_both = long & (x[:, 2] < 0.1) & (x[:, 3] < 0.1)
    assert tangent_both.sum() >= 5
    assert (x[:, 1] < 1.0).mean() > 0.4  # the arcs' chords
    assert (x[:, 2] > np.radians(149)).sum() >= 5  # reversals


def test_cam_blend_arc_chords_within_the_chord_tolerance():
    from nctwin.programs.camblend import CHORD_TOL_MM, RADIUS_MM, _arc

    rng = np.random.default_rng(0)
    for _ in range(200):
        turn = rng.uniform(-np.pi, np.pi)
        lengths, turns, rest = _arc(rng, turn)
        assert turns.sum() + rest == pytest.approx(turn)  # the arc turns the path by `turn`
        phi = abs(turns[1]) if len(turns) > 1 else 2 * abs(turns[0])
        radius = lengths[0] / (2 * np.sin(phi / 2))  # all chords of one circle
        np.testing.assert_allclose(lengths, lengths[0])
        assert RADIUS_MM[0] - 1e-9 <= radius <= RADIUS_MM[1] + 1e-9
        sagitta = radius * (1 - np.cos(phi / 2))
        assert sagitta <= max(CHORD_TOL_MM[1], radius * (1 - np.cos(abs(turn) / 300))) + 1e-12


def test_cam_blend_specs_shares_and_ranges():
    from nctwin.programs.camblend import cam_blend_specs

    specs = cam_blend_specs(1, n_programs=30, n_lines=2000, feed_range_mm_s=(60, 80),
                            tol_range_mm=(0.05, 0.1),
                            shares={"global": 0.1, "mixed": 1 / 30, "cam": 26 / 30})  # fmt: skip
    assert [s.family for s in specs].count("global") == 3
    assert [s.family for s in specs].count("mixed") == 1
    assert [s.family for s in specs].count("cam") == 26
    assert all(60 <= s.feed_mm_s <= 80 and 0.05 <= s.tol_mm <= 0.1 for s in specs)
    assert len({s.seed for s in specs}) == 30
    with pytest.raises(ValueError, match="shares"):
        cam_blend_specs(1, n_programs=3, n_lines=10, feed_range_mm_s=(60, 80),
                        tol_range_mm=(0.05, 0.1), shares={"cam": 0.5})  # fmt: skip


def test_paper_global_program_turns_at_random_at_every_junction():
    tp = gcode.parse(paper_global_program(5, n_lines=4000, feed_mm_s=80, tol_mm=0.4))
    d = tp.end_mm[:, :2] - tp.start_mm[:, :2]
    heading = np.arctan2(d[:, 1], d[:, 0])
    turn = np.abs((np.diff(heading) + np.pi) % (2 * np.pi) - np.pi)
    # a direction change uniform in (0, 2 pi) turns by more than 90 degrees half the time
    assert abs((turn > np.pi / 2).mean() - 0.5) < 0.03
    assert tp.lengths_mm.max() < GLOBAL_LENGTH_MM[1] + 1e-3
    # the curve sections of the older family turn that much at few junctions
    tp_old = gcode.parse(global_program(5, n_lines=4000, feed_mm_s=80, tol_mm=0.4))
    d = tp_old.end_mm[:, :2] - tp_old.start_mm[:, :2]
    heading = np.arctan2(d[:, 1], d[:, 0])
    assert (np.abs((np.diff(heading) + np.pi) % (2 * np.pi) - np.pi) > np.pi / 2).mean() < 0.05


def test_paper_mixed_program_local_share_and_spec_families():
    tp = gcode.parse(paper_mixed_program(2, n_lines=4000, feed_mm_s=70, tol_mm=0.3))
    long = tp.lengths_mm > GLOBAL_LENGTH_MM[1] + 1e-3
    expected = 0.75 * (1 - np.log(1 / 0.5) / np.log(LOCAL_LENGTH_MM[1] / LOCAL_LENGTH_MM[0]))
    assert abs(long.mean() - expected) < 0.1
    spec = ProgramSpec("paper_mixed", 4000, 70.0, 0.3, 2)
    assert spec.text() == paper_mixed_program(2, n_lines=4000, feed_mm_s=70.0, tol_mm=0.3)


def test_paper_contour_program_zigzag_share():
    # the share sets how many sections are zig-zags: none at 0, more at 0.6 than at 0.1
    def corners(share):
        tp = gcode.parse(contour_program("I", feed_mm_s=75, tol_mm=0.3, zigzag_share=share))
        d = tp.end_mm[:, :2] - tp.start_mm[:, :2]
        heading = np.arctan2(d[:, 1], d[:, 0])
        return (np.abs((np.diff(heading) + np.pi) % (2 * np.pi) - np.pi) > 0.6 * np.pi).sum()

    assert corners(0.0) < corners(0.1) < corners(0.6)
    assert paper_contour_program("II", feed_mm_s=75, tol_mm=0.3) == contour_program(
        "II", feed_mm_s=75, tol_mm=0.3, zigzag_share=PAPER_ZIGZAG_SHARE["II"]
    )
    with pytest.raises(ValueError, match="zigzag_share"):
        contour_program("I", feed_mm_s=75, tol_mm=0.3, zigzag_share=1.5)
    with pytest.raises(ValueError, match="allowed I, II"):
        paper_contour_program("III", feed_mm_s=75, tol_mm=0.3)
