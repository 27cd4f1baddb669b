"""LinuxCNC's naive-CAM detector (G64 Q), checked against cases derived by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin import MotionKind, parse
from nctwin.naivecam import MAX_CHAIN, merge_naive_cam, small_arc_points


def _merge(program: str):
    tp = parse(program)
    merged, source = merge_naive_cam(tp)
    return tp, merged, source


def test_collinear_points_merge_into_one_line():
    tp, merged, source = _merge("G64 P0.01\nG1 X1 F600\nX2\nX3\nX4\n")
    assert len(merged) == 1
    np.testing.assert_array_equal(merged.start_mm[0], [0, 0, 0])
    np.testing.assert_array_equal(merged.end_mm[0], [4, 0, 0])
    assert merged.kind[0] == MotionKind.LINEAR
    # LinuxCNC reports the line of the chain's last point
    assert source.tolist() == [3]
    assert merged.line[0] == tp.line[3]


def test_point_off_the_line_by_more_than_q_splits():
    # (2, 0.02) is 0.02 from the line (0,0)-(4,0): beyond Q = 0.01, within Q = 0.03
    program = "G1 X1 F600\nX2 Y0.02\nX3 Y0\nX4\n"
    _, merged, source = _merge("G64 P0.01\n" + program)
    # (1,0) and (2,0.02) chain; (3,0) would leave (2,0.02) 0.02 from (0,0)-(3,0): split
    assert source.tolist() == [1, 3]
    np.testing.assert_array_equal(merged.end_mm[:, :2], [[2, 0.02], [4, 0]])
    np.testing.assert_array_equal(merged.start_mm[1, :2], [2, 0.02])
    _, wide, _ = _merge("G64 P0.03\n" + program)
    assert len(wide) == 1


def test_projection_is_clamped_to_the_segment():
    # (-1, 0) lies on the infinite line through (0,0)-(5,0) but 1 mm before the segment
    _, merged, _ = _merge("G64 P0.01\nG1 X-1 F600\nX5\n")
    assert len(merged) == 2


def test_chain_holds_at_most_101_points():
    program = "G64 P0.01\nG1 F600\n" + "".join(f"X{i}\n" for i in range(1, 251))
    _, merged, source = _merge(program)
    assert MAX_CHAIN == 101
    assert len(merged) == 3
    np.testing.assert_array_equal(merged.end_mm[:, 0], [101, 202, 250])
    np.testing.assert_array_equal(np.diff(np.r_[-1, source]), [101, 101, 48])


def test_q_zero_leaves_the_path_unchanged():
    for header in ("G64 P0.01 Q0", "G64", "G61", "G64 P0", ""):
        tp, merged, source = _merge(header + "\nG1 X1 F600\nX2\nX3\n")
        assert merged is tp
        np.testing.assert_array_equal(source, np.arange(len(tp)))


def test_q_without_p_and_p_without_q_both_merge():
    for header in ("G64 Q0.01", "G64 P0.01"):
        _, merged, _ = _merge(header + "\nG1 X1 F600\nX2\n")
        assert len(merged) == 1


@pytest.mark.parametrize(
    ("between", "n_merged"),
    [
        ("X3", 1),  # nothing between: one line
        ("G0 X3\nG1", 3),  # a rapid flushes the chain and stays itself
        ("G4 P0.5", 3),  # a dwell flushes the chain and stays itself
        ("X3 F700", 2),  # a new feed flushes before its own move
        ("X3 F600", 1),  # the same feed again does not
        ("X3 S1000", 2),  # an S word flushes (SET_SPINDLE_SPEED)
        ("M8", 2),  # an M word flushes, also on a line of its own
        ("X3 T1", 1),  # a T word does not (SELECT_POCKET)
        ("G64 P0.02\nX3", 2),  # any G64 flushes (SET_MOTION_CONTROL_MODE)
        ("G61\nX3", 4),  # G61 turns the detector off: X3, X4, X5 stay
        ("G2 X3 Y-1 I0.5 J-0.5\nG1", 3),  # an arc with a large sagitta flushes and stays an arc
    ],
)
def test_what_breaks_the_chain(between, n_merged):
    tp, merged, source = _merge(f"G64 P0.01\nG1 X1 F600\nX2\n{between}\nX4\nX5\n")
    assert len(merged) == n_merged
    np.testing.assert_array_equal(merged.start_mm[0], tp.start_mm[0])
    np.testing.assert_array_equal(merged.end_mm[-1], tp.end_mm[-1])
    assert source[-1] == len(tp) - 1
    assert np.all(np.diff(source) > 0)
    np.testing.assert_array_equal(merged.kind, tp.kind[source])


def test_small_arc_becomes_two_chain_points():
    # a 2-degree arc of radius 10: sagitta 10 (1 - cos 1 deg) = 0.0015 < Q = 0.01
    a = math.radians(2)
    x, y = 10 * math.sin(a), 10 - 10 * math.cos(a)
    program = f"G17 G64 P0.01\nG1 X0 Y0 F600\nG3 X{x!r} Y{y!r} I0 J10\nG1 X{x + 1!r}\n"
    tp = parse(program)
    small, mid = small_arc_points(tp, tp.effective_naive_tol_mm())
    assert small.tolist() == [False, True, False]
    np.testing.assert_allclose(mid[1, :2], [10 * math.sin(a / 2), 10 - 10 * math.cos(a / 2)])
    merged, source = merge_naive_cam(tp)
    # mid point and end of the arc: the end is 0.0015 off the chord to the next line's end,
    # so the chain is (arc middle, arc end) and then the line
    assert merged.kind.tolist() == [MotionKind.LINEAR] * len(merged)
    np.testing.assert_array_equal(merged.end_mm[-1], tp.end_mm[-1])
    np.testing.assert_array_equal(merged.start_mm[0], tp.start_mm[0])
    assert set(source.tolist()) <= {0, 1, 2}
    # under Q = 0 the arc stays an arc
    kept, _ = merge_naive_cam(parse(program.replace("P0.01", "P0.01 Q0")))
    assert kept.is_arc.sum() == 1


def test_small_arc_outside_the_xy_plane_stays_an_arc():
    # the same 2-degree arc in the ZX plane (G18): chord_deviation is only tried in XY
    a = math.radians(2)
    x, z = 10 - 10 * math.cos(a), 10 * math.sin(a)
    tp = parse(f"G18 G64 P0.01\nG1 X0 Z0 F600\nG3 X{x!r} Z{z!r} I10 K0\nG1 Z{z + 1!r}\n")
    assert abs(tp.sweep_rad[1]) == pytest.approx(a)
    merged, _ = merge_naive_cam(tp)
    assert merged.is_arc.sum() == 1


def test_closing_the_loop_flushes():
    # a point back at the chain's start is never linkable (zero-length chord)
    _, merged, _ = _merge("G64 P0.01\nG1 X1 F600\nX0\nX1\n")
    assert len(merged) >= 2


def test_start_and_end_points_are_kept_bit_for_bit():
    pts = np.cumsum(np.full((20, 2), [0.1, 0.0003]), axis=0) + np.array([1 / 3, 2 / 7])
    body = "".join(f"X{x!r} Y{y!r}\n" for x, y in pts.tolist())
    tp, merged, source = _merge(f"G64 P0.01\nG0 X{1 / 3!r} Y{2 / 7!r}\nG1 F600\n{body}")
    assert len(merged) == 2
    np.testing.assert_array_equal(merged.start_mm[1], tp.start_mm[1])
    np.testing.assert_array_equal(merged.end_mm[1], tp.end_mm[-1])
    assert source.tolist() == [0, len(tp) - 1]


def _polyline_program(steps, q):
    lines = [f"G64 P{q}", "G1 F600"]
    x = y = 0.0
    for dx, dy in steps:
        x, y = x + dx, y + dy
        lines.append(f"X{x:.4f} Y{y:.4f}")
    return "\n".join(lines) + "\n"


def _distance_to_polyline(p: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> float:
    m = ends - starts
    mm = np.einsum("ij,ij->i", m, m)
    t = np.clip(np.einsum("ij,ij->i", p - starts, m) / np.where(mm > 0, mm, 1.0), 0, 1)
    return float(np.min(np.linalg.norm(p - (starts + t[:, None] * m), axis=1)))


@settings(max_examples=60, deadline=None)
@given(
    steps=st.lists(
        st.tuples(st.floats(-0.2, 0.2, allow_nan=False), st.floats(-0.2, 0.2, allow_nan=False)),
        min_size=1,
        max_size=250,
    ),
    q=st.sampled_from([0.001, 0.01, 0.05]),
)
def test_merged_path_stays_within_q(steps, q):
    tp = parse(_polyline_program(steps, q))
    merged, source = merge_naive_cam(tp)
    assert len(merged) <= len(tp)
    np.testing.assert_array_equal(merged.start_mm[0], tp.start_mm[0])
    np.testing.assert_array_equal(merged.end_mm[-1], tp.end_mm[-1])
    np.testing.assert_array_equal(merged.start_mm[1:], merged.end_mm[:-1])
    assert np.all(np.diff(source) > 0)
    for p in tp.end_mm:
        assert _distance_to_polyline(p, merged.start_mm, merged.end_mm) <= q + 1e-12
    # each merged line ends on an original end point, that of its source block
    np.testing.assert_array_equal(merged.end_mm, tp.end_mm[source])
