"""Toolpath geometry, checked against numbers derived by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin import MotionKind, PathMode, parse


def test_quarter_circle_arc_length_is_pi_r_over_2():
    r = 7.5
    tp = parse(f"G17 G1 X{r} Y0 F600\nG3 X0 Y{r} I{-r} J0")
    arc = tp.lengths_mm[1]
    assert arc == pytest.approx(math.pi * r / 2, rel=1e-12)
    assert tp.sweep_rad[1] == pytest.approx(math.pi / 2)


def test_clockwise_three_quarter_circle():
    # from (10, 0) clockwise around the origin to (0, 10): 270 degrees
    tp = parse("G0 X10 Y0\nG2 X0 Y10 I-10 J0 F100")
    assert tp.sweep_rad[1] == pytest.approx(-1.5 * math.pi)
    assert tp.lengths_mm[1] == pytest.approx(1.5 * math.pi * 10)


def test_full_circle_and_helix():
    tp = parse("G0 X5 Y0 Z0\nG3 X5 Y0 Z2 I-5 J0 F100")
    assert tp.sweep_rad[1] == pytest.approx(2 * math.pi)
    assert tp.lengths_mm[1] == pytest.approx(math.hypot(2 * math.pi * 5, 2))


@pytest.mark.parametrize(
    ("program", "plane_len"),
    [
        ("G18 G0 X5 Y0 Z0\nG2 X0 Z5 I-5 K0 F100", math.pi * 5 / 2),  # ZX plane
        ("G19 G0 X0 Y5 Z0\nG3 Y0 Z5 J-5 K0 F100", math.pi * 5 / 2),  # YZ plane
    ],
)
def test_arcs_in_other_planes(program, plane_len):
    tp = parse(program)
    assert tp.lengths_mm[1] == pytest.approx(plane_len)


def test_g18_clockwise_is_seen_from_positive_y():
    # in the ZX plane (Z first, X second), G2 from X5 Z0 to X0 Z5 about the origin is a quarter
    tp = parse("G18 G0 X5 Y0 Z0\nG2 X0 Z5 I-5 K0 F100")
    assert abs(tp.sweep_rad[1]) == pytest.approx(math.pi / 2)


def test_r_arcs_both_signs():
    # R>0: the short way (90 deg); R<0: the long way (270 deg) between the same points
    short = parse("G0 X10 Y0\nG3 X0 Y10 R10 F100")
    long = parse("G0 X10 Y0\nG3 X0 Y10 R-10 F100")
    assert short.lengths_mm[1] == pytest.approx(math.pi * 10 / 2)
    assert long.lengths_mm[1] == pytest.approx(1.5 * math.pi * 10)
    np.testing.assert_allclose(short.center_mm[1], [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(long.center_mm[1], [10, 10, 0], atol=1e-12)


def test_lengths_directions_and_corner_angles():
    tp = parse("G1 X10 F600\nY10\nX0 Y0\nX0 Y0")
    np.testing.assert_allclose(tp.lengths_mm, [10, 10, math.hypot(10, 10), 0])
    np.testing.assert_allclose(tp.directions[1], [0, 1, 0])
    # corners: none at the first block, 90 deg, then 135 deg, undefined at a zero-length move
    np.testing.assert_allclose(tp.corner_angles_rad, [0, math.pi / 2, 3 * math.pi / 4, 0])


def test_tangent_continuous_arc_has_no_corner():
    tp = parse("G1 X10 Y0 F600\nG3 X20 Y10 I0 J10\nG1 Y20")
    np.testing.assert_allclose(tp.corner_angles_rad, [0, 0, 0], atol=1e-12)


def test_effective_tolerance_follows_the_program():
    tp = parse("G1 X1 F60\nG64 P0.2\nX2\nG61\nX3\nG64\nX4\nG64 P0.01 Q0.005\nX5")
    np.testing.assert_array_equal(
        tp.path_mode,
        [PathMode.DEFAULT, PathMode.BLEND, PathMode.EXACT_PATH, PathMode.BLEND, PathMode.BLEND],
    )
    np.testing.assert_allclose(tp.effective_tolerance_mm(0.05), [0.05, 0.2, 0.0, np.inf, 0.01])
    assert tp.naive_tol_mm[4] == pytest.approx(0.005)


def test_kind_counts_and_frame():
    tp = parse("G0 X1\nG1 X2 F60\nG4 P0.5\nG2 X4 I1 J0")
    assert tp.kind_counts() == {"rapid": 1, "linear": 1, "arc_cw": 1, "arc_ccw": 0, "dwell": 1}
    df = tp.to_frame()
    assert list(df["kind"]) == ["rapid", "linear", "dwell", "arc_cw"]
    assert df["length_mm"].iloc[2] == 0.0
    assert tp.dwell_s[2] == 0.5
    assert tp.kind[2] == MotionKind.DWELL


def test_arrays_are_read_only():
    tp = parse("G1 X1 F60")
    with pytest.raises(ValueError):
        tp.end_mm[0, 0] = 5.0
