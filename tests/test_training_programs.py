"""Training and test programs of Chien et al. (2023): seeded, parseable, in the paper's ranges."""

import numpy as np
import pytest

from nctwin import gcode
from nctwin.methods.chien2023 import features as chien2023_features
from nctwin.programs.training import (
    GLOBAL_LENGTH_MM,
    LOCAL_LENGTH_MM,
    contour_program,
    global_program,
    mixed_program,
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
