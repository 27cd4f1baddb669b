"""The native reader's order of execution within a line (LinuxCNC's), full circles and arcs of
several turns, and G92 offsets. Numbers worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nctwin import GCodeError, MotionKind, dump, parse

R, F, D = MotionKind.RAPID, MotionKind.LINEAR, MotionKind.DWELL


# ------------------------------------------------------------------ order of execution
def test_dwell_runs_before_the_motion_of_its_line():
    tp = parse("G0 X0 Y0\nG4 P.001 G0 X1 Y1")
    assert list(tp.kind) == [R, D, R]
    assert list(tp.line) == [1, 2, 2]
    assert tp.dwell_s.tolist() == [0.0, 0.001, 0.0]
    np.testing.assert_array_equal(tp.end_mm[1], [0, 0, 0])  # dwells where it was
    np.testing.assert_array_equal(tp.end_mm[2], [1, 1, 0])
    # with a modal motion: the axis words (X included) move after the dwell
    tp = parse("G1 X5 F60\nG4 P2 X7")
    assert list(tp.kind) == [F, D, F] and tp.end_mm[2, 0] == 7 and tp.dwell_s[1] == 2


def test_a_g4_with_x_and_no_p_is_a_fanuc_dwell_alone_on_its_line():
    assert parse("G0 X3\nG4 X2").dwell_s[1] == 2.0
    with pytest.raises(GCodeError, match="give the dwell time with P"):
        parse("G0 X3\nG4 X2 Y1")
    with pytest.raises(GCodeError, match="both use P"):
        parse("G4 P1 G2 X1 I1 F60")


def test_f_runs_before_g20_and_a_1_inch_move_at_f6_mm_min_takes_254_s():
    tp = parse("G21\nG20 F6 G1 X1")
    assert tp.feed_mm_s[0] == pytest.approx(0.1)  # 6 mm/min
    assert tp.lengths_mm[0] / tp.feed_mm_s[0] == pytest.approx(254.0)


def test_stops_run_after_the_motion_of_their_line():
    tp = parse("M3 S100 G1 X1 F60 M0\nG1 X2 M30")
    words = [(str(e["word"]), float(e["value"]), int(e["block"])) for e in tp.events]
    # M3 and S before block 0; M0 after it (before block 1); M30 after block 1
    assert words == [("M", 3.0, 0), ("S", 100.0, 0), ("M", 0.0, 1), ("M", 30.0, 2)]


def test_g80_gives_way_to_another_motion_code_of_its_line():
    # LinuxCNC's read_g: "G80 G0 X0", common in CAM output, is "G0 X0"
    tp = parse("G0 Z5\nG81 X1 R2 Z-1 F60\nG80 G0 X0")
    assert tp.kind[-1] == R and tp.end_mm[-1].tolist() == [0, 0, 2]
    with pytest.raises(GCodeError, match="two G-codes of the motion group"):
        parse("G0 G1 X1 F60")


def test_distance_mode_and_plane_of_a_line_apply_to_its_motion():
    tp = parse("G0 X1\nG91 G0 X1\nG18 G2 X2 Z0 I1 K0 F60")
    assert tp.end_mm[1, 0] == 2
    assert tp.plane[2] == 1 and tp.end_mm[2, 0] == 4  # G91 still in force: X2 is a step
    assert tp.center_mm[2].tolist() == [3, 0, 0]


# ------------------------------------------------------------------ full circles and turns
def test_full_circle_without_end_point_words():
    tp = parse("G0 X10 Y0\nG2 I-10 F600")
    assert tp.kind[1] == MotionKind.ARC_CW
    np.testing.assert_array_equal(tp.end_mm[1], tp.start_mm[1])
    np.testing.assert_array_equal(tp.center_mm[1], [0, 0, 0])
    assert tp.lengths_mm[1] == pytest.approx(2 * math.pi * 10)
    assert tp.sweep_rad[1] == pytest.approx(-2 * math.pi)
    # 62.83 mm at 10 mm/s
    assert tp.lengths_mm[1] / tp.feed_mm_s[1] == pytest.approx(2 * math.pi)
    # a line with only I/J in arc mode is a full circle too
    tp = parse("G0 X10 Y0\nG3 I-10 F600\nJ5")
    assert len(tp) == 3 and tp.center_mm[2].tolist() == [10, 5, 0]


def test_p_turns_of_a_full_circle():
    tp = parse("G0 X10 Y0\nG2 I-10 P3 F600")
    assert len(tp) == 4 and list(tp.line) == [1, 2, 2, 2]
    assert tp.length_mm - tp.lengths_mm[0] == pytest.approx(3 * 2 * math.pi * 10)


def test_p_turns_of_a_helix_share_the_travel_along_the_normal():
    # half a turn plus one full turn: 3 pi rad for 6 mm down, 4 mm in the full turn
    tp = parse("G0 X10 Y0 Z0\nG3 X-10 Y0 Z-6 I-10 J0 P2 F600")
    np.testing.assert_allclose(tp.end_mm[1:], [[10, 0, -4], [-10, 0, -6]], atol=1e-12)
    np.testing.assert_allclose(tp.center_mm[1:, 2], [0, -4], atol=1e-12)
    expected = math.hypot(2 * math.pi * 10, 4) + math.hypot(math.pi * 10, 2)
    assert tp.length_mm == pytest.approx(10 + expected)
    np.testing.assert_array_equal(tp.start_mm[2], tp.end_mm[1])


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("G2 I1 P0 F60", "P value should be 1 or greater with G2 or G3"),
        ("G2 I1 P1.5 F60", "P value not an integer with G2 or G3"),
        ("G0 X1\nG2 R5 F60", "without an arc"),
    ],
)
def test_arc_turn_errors(text, reason):
    with pytest.raises(GCodeError, match=reason):
        parse(text)


# ------------------------------------------------------------------ G92 offsets
def x_ends(text: str) -> list[float]:
    return [float(x) for x in parse(text).end_mm[:, 0]]


def test_g92_gives_the_current_point_new_coordinates():
    tp = parse("G0 X10 Y5\nG92 X0 Y0\nG0 X1 Y1")
    np.testing.assert_array_equal(tp.end_mm[-1], [11, 6, 0])  # positions are machine positions


def test_g92_1_g92_2_g92_3():
    # G92 X10 at X0: offset -10. G92.2 clears it but keeps the parameters, G92.3 brings them
    # back; G92.1 clears it and zeros the parameters, so a later G92.3 restores nothing
    text = "G0 X0\nG92 X10\nG0 X0\nG92.2\nG0 X1\nG92.3\nG0 X2\nG92.1\nG0 X3\nG92.3\nG0 X4"
    assert x_ends(text) == [0, -10, 1, -8, 3, 4]


def test_g92_ignores_the_distance_mode_and_keeps_its_offset_across_units():
    assert x_ends("G91 G0 X5\nG92 X0\nG0 X1") == [5, 6]
    assert x_ends("G20 G0 X1\nG92 X0\nG21 G90 G0 X10") == pytest.approx([25.4, 35.4])


def test_g53_ignores_g92():
    assert x_ends("G0 X5\nG92 X0\nG53 G0 X1\nG0 X1") == [5, 1, 6]


def test_g92_moves_absolute_arc_centres():
    tp = parse("G0 X10 Y0\nG92 X5 Y0\nG90.1 G3 X-5 Y0 I0 J0 F60")
    np.testing.assert_array_equal(tp.center_mm[-1], [5, 0, 0])
    np.testing.assert_array_equal(tp.end_mm[-1], [0, 0, 0])


def test_g92_1_runs_before_the_motion_of_its_line():
    assert x_ends("G0 X2\nG92 X0\nG92.1 G0 X1") == [2, 1]
    assert x_ends("G0 X2\nG92 X0\nG92.1 G91 G0 X1") == [2, 3]


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("G92", "G92 without an axis word"),
        ("G92 G1 X1 F60", "G92 and G1 cannot share a line"),
    ],
)
def test_g92_errors(text, reason):
    with pytest.raises(GCodeError, match=reason):
        parse(text)


def test_dump_round_trips_the_new_constructs():
    text = "G0 X10 Y0\nG4 P1\nG92 X0\nG3 I-10 P2 F600\nG92.1\nG4 P.5 G1 X3 Y4\nG2 X3 Y4 I1 J0"
    tp = parse(text)
    assert parse(dump(tp)).allclose(tp)


# ------------------------------------------------------------------ properties
_num = st.floats(-50, 50, allow_nan=False).map(lambda v: f"{v:.3f}")
_line = st.one_of(
    st.builds(lambda x, y: f"G0 X{x} Y{y}", _num, _num),
    st.builds(lambda x, z: f"G1 X{x} Z{z} F300", _num, _num),
    st.builds(lambda i, j, p: f"G2 I{i} J{j} P{p} F300", _num, _num, st.integers(1, 3)),
    st.builds(lambda p, x: f"G4 P{abs(float(p)):.3f} G0 X{x}", _num, _num),
    st.builds(lambda x: f"G92 X{x}", _num),
    st.sampled_from(["G92.1", "G92.2", "G92.3", "G91", "G90", "G20", "G21", "G80", "M3", "M5"]),
    st.builds(
        lambda c, x, r, z: f"G98 {c} X{x} R{r} Z{z} P0.1 Q1 F300",
        st.sampled_from(["G81", "G82", "G83", "G73", "G85", "G86", "G89"]),
        _num,
        _num,
        _num,
    ),
    st.builds(lambda x, y: f"X{x} Y{y}", _num, _num),
)


@given(st.lists(_line, max_size=15))
def test_programs_of_the_new_constructs_parse_or_raise_gcode_error(lines):
    try:
        tp = parse("\n".join(lines))
    except GCodeError as err:
        assert err.line >= 1 and err.reason
    else:
        assert np.isfinite(tp.end_mm).all() and np.isfinite(tp.lengths_mm).all()
        np.testing.assert_array_equal(tp.start_mm[1:], tp.end_mm[:-1])  # contiguous
