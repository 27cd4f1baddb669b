"""Canned cycles G73, G74, G81-G89 read natively, expanded as LinuxCNC 2.9 expands them
(interp_cycles.cc). The expected moves are worked out by hand from that source."""

from __future__ import annotations

import numpy as np
import pytest

from nctwin import GCodeError, MotionKind, dump, parse
from nctwin.toolpath import PathMode

R, F, D = MotionKind.RAPID, MotionKind.LINEAR, MotionKind.DWELL


def moves(tp, first=0):
    """(kind, x, y, z) of each block from ``first`` on."""
    return [
        (int(k), *map(float, e)) for k, e in zip(tp.kind[first:], tp.end_mm[first:], strict=True)
    ]


def test_g81_g98_retracts_to_the_initial_level():
    # the example: from Z10, G81 at X10 Y5 R2 Z-3 with G98
    tp = parse("G0 X0 Y0 Z10\nF60\nG98 G81 X10 Y5 R2 Z-3")
    assert moves(tp, 1) == [(R, 10, 5, 10), (R, 10, 5, 2), (F, 10, 5, -3), (R, 10, 5, 10)]
    assert list(tp.line) == [1, 3, 3, 3, 3]
    np.testing.assert_allclose(tp.lengths_mm[1:], [np.hypot(10, 5), 8, 5, 13])
    # the feed: 5 mm at F60 (1 mm/s) takes 5 s
    assert tp.lengths_mm[3] / tp.feed_mm_s[3] == pytest.approx(5.0)
    # LinuxCNC runs the moves of a cycle in exact-path mode (G61), then restores the mode
    assert list(tp.path_mode) == [PathMode.DEFAULT] + [PathMode.EXACT_PATH] * 4
    assert np.isnan(tp.blend_tol_mm[1:]).all()


def test_g99_retracts_to_r_and_is_the_default():
    g99 = parse("G0 X0 Y0 Z10\nF60\nG99 G81 X10 Y5 R2 Z-3")
    assert moves(g99, 1)[-1] == (R, 10, 5, 2)
    default = parse("G0 X0 Y0 Z10\nF60\nG81 X10 Y5 R2 Z-3")  # LinuxCNC's retract mode starts G99
    assert moves(default) == moves(g99)


def test_modal_cycle_repeats_on_lines_with_only_x_y():
    tp = parse("G0 X0 Y0 Z10\nF60\nG98 G81 X10 Y5 R2 Z-3\nX20\nY15\nG80\nG0 X0 Y0")
    holes = [(x, y) for k, x, y, z in moves(tp) if k == F]
    assert holes == [(10, 5), (20, 5), (20, 15)]
    assert list(tp.line[-1:]) == [7]
    assert moves(tp)[-1] == (R, 0, 0, 10)  # G80 cancels: a plain rapid at the clearance height


def test_a_later_line_after_g80_needs_a_motion():
    with pytest.raises(GCodeError, match="without an active motion mode") as info:
        parse("G0 Z10\nG81 X1 R2 Z-3 F60\nG80\nX5")
    assert info.value.line == 4


def test_below_r_the_cycle_first_rises_straight_to_r():
    # old Z 1 below R 2: a rapid straight up (in the program's own path mode), then over
    tp = parse("G64 P0.1 G0 X0 Y0 Z1\nG98 G81 X5 R2 Z-1 F60")
    assert moves(tp, 1) == [(R, 0, 0, 2), (R, 5, 0, 2), (F, 5, 0, -1), (R, 5, 0, 2)]
    assert tp.path_mode[1] == PathMode.BLEND and tp.blend_tol_mm[1] == pytest.approx(0.1)
    assert (tp.path_mode[2:] == PathMode.EXACT_PATH).all()


def test_g98_keeps_the_initial_level_of_the_first_cycle():
    # LinuxCNC's cycle_il: the Z before the first cycle of a run (10), not the Z before the line
    tp = parse("G0 X0 Y0 Z10\nF60\nG98 G81 X1 R2 Z-1\nG99 X2\nG98 X3")
    line5 = moves(tp)[-4:]
    # at Z2 (R) after the G99 hole, so the move to the hole climbs to Z10 on its way, then down
    assert line5 == [(R, 3, 0, 10), (R, 3, 0, 2), (F, 3, 0, -1), (R, 3, 0, 10)]
    # a motion other than a cycle starts a new run: the initial level is the Z then
    tp = parse("G0 X0 Y0 Z10\nF60\nG98 G81 X1 R2 Z-1\nG0 Z4\nG98 G81 X3 R2 Z-1")
    assert moves(tp)[-1] == (R, 3, 0, 4)


def test_l_repeats_in_g91_step_by_x_y():
    # G91: R from the initial level (5 - 3 = 2), Z from R (2 - 4 = -2); three holes 10 mm apart
    tp = parse("G0 X0 Y0 Z5\nG91 G81 X10 Y0 R-3 Z-4 L3 F60\nG80\nG90 G0 X0")
    expected = [(R, 10, 0, 5), (R, 10, 0, 2), (F, 10, 0, -2), (R, 10, 0, 2)]
    for x in (20, 30):
        expected += [(R, x, 0, 2), (F, x, 0, -2), (R, x, 0, 2)]
    assert moves(tp, 1)[:-1] == expected
    assert moves(tp)[-1] == (R, 0, 0, 2)  # the next line continues from the last hole, at R


def test_l_repeats_in_g90_drill_the_same_hole():
    tp = parse("G0 X0 Y0 Z5\nG98 G81 X1 R2 Z-1 L2 F60")
    assert moves(tp, 1) == [
        (R, 1, 0, 5), (R, 1, 0, 2), (F, 1, 0, -1), (R, 1, 0, 5),
        (R, 1, 0, 5), (R, 1, 0, 2), (F, 1, 0, -1), (R, 1, 0, 5),
    ]  # fmt: skip


def test_g83_pecks_back_to_r_and_down_to_just_above_the_last_depth():
    # peck Q1.5 from R1 to Z-3; LinuxCNC 2.9 comes back down to 0.010 in (0.254 mm) above
    tp = parse("G0 X0 Y0 Z5\nG83 R1 Z-3 Q1.5 F60")
    z = [round(m[3], 9) for m in moves(tp, 1)]
    kinds = [m[0] for m in moves(tp, 1)]
    assert z == [5, 1, -0.5, 1, -0.246, -2, 1, -1.746, -3, 1]
    assert kinds == [R, R, F, R, R, F, R, R, F, R]


def test_g73_breaks_chips_with_a_short_retract():
    tp = parse("G0 X0 Y0 Z5\nG73 R1 Z-3 Q1.5 F60")
    z = [round(m[3], 9) for m in moves(tp, 1)]
    assert z == [5, 1, -0.5, -0.246, -2, -1.746, -3, 1]
    assert [m[0] for m in moves(tp, 1)] == [R, R, F, R, F, R, F, R]


def test_peck_retract_is_0_010_inch_in_inch_programs_too():
    tp = parse("G20 G0 X0 Y0 Z1\nG83 R0.1 Z-0.3 Q0.25 F10")
    z_in = [round(e / 25.4, 9) for e in tp.end_mm[1:, 2]]
    assert z_in == [1, 0.1, -0.15, 0.1, -0.14, -0.3, 0.1]


@pytest.mark.parametrize(
    ("code", "expected"),
    [
        # G82: dwell at the bottom, rapid out
        ("G82", [(F, 1, 0, -1), (D, 1, 0, -1), (R, 1, 0, 5)]),
        # G85: feed out to R, then rapid to the clearance height (it has no P)
        ("G85", [(F, 1, 0, -1), (F, 1, 0, 2), (R, 1, 0, 5)]),
        # G86: dwell, spindle stop (no motion), rapid out
        ("G86", [(F, 1, 0, -1), (D, 1, 0, -1), (R, 1, 0, 5)]),
        # G89: dwell, feed out
        ("G89", [(F, 1, 0, -1), (D, 1, 0, -1), (F, 1, 0, 5)]),
        # G84: feed in, reverse the spindle, dwell, feed out to the clearance height
        ("G84", [(F, 1, 0, -1), (D, 1, 0, -1), (F, 1, 0, 5)]),
    ],
)
def test_boring_and_tapping_cycles(code, expected):
    dwell = "" if code == "G85" else "P0.5"
    tp = parse(f"M3 S500\nG0 X0 Y0 Z5\nG98 {code} X1 R2 Z-1 {dwell} F60")
    assert moves(tp, 1) == [(R, 1, 0, 5), (R, 1, 0, 2), *expected]
    assert (tp.dwell_s[tp.kind == D] == 0.5).all()


def test_dwell_p_in_milliseconds_applies_to_cycles():
    tp = parse("G0 Z5\nG82 X1 R2 Z-1 P500 F60", dwell_p_unit="ms")
    assert tp.dwell_s[tp.kind == D].tolist() == [0.5]


def test_g84_without_p_dwells_zero_and_g74_needs_the_spindle_reversed():
    tp = parse("M3\nG0 Z5\nG84 X1 R2 Z-1 F60")
    assert tp.dwell_s[tp.kind == D].tolist() == [0.0]
    assert moves(parse("M4\nG0 Z5\nG74 X1 R2 Z-1 F60")) == moves(tp)
    with pytest.raises(GCodeError, match="spindle turning counterclockwise in G84"):
        parse("M4\nG0 Z5\nG84 X1 R2 Z-1 F60")
    with pytest.raises(GCodeError, match="spindle turning clockwise in G74"):
        parse("M3\nG0 Z5\nG74 X1 R2 Z-1 F60")


@pytest.mark.parametrize("code", ["G84", "G86 P1", "G87 I1 J0 K0", "G88 P1"])
def test_cycles_that_stop_the_spindle_need_it_turning(code):
    with pytest.raises(GCodeError, match="spindle not turning"):
        parse(f"G0 Z5\n{code} X1 R2 Z-1 F60")
    parse(f"M3\nG0 Z5\n{code} X1 R2 Z-1 F60")
    with pytest.raises(GCodeError, match="spindle not turning"):
        parse(f"M3\nM5\nG0 Z5\n{code} X1 R2 Z-1 F60")


def test_g88_leaves_the_tool_at_the_bottom():
    # the operator retracts by hand at a program stop; LinuxCNC's coordinates continue from
    # the clearance height, the next move starts where the tool is
    tp = parse("M3\nG0 X0 Y0 Z5\nG98 G88 X1 R2 Z-1 P0.5 F60\nG80\nG0 X4")
    assert moves(tp, 1) == [(R, 1, 0, 5), (R, 1, 0, 2), (F, 1, 0, -1), (D, 1, 0, -1), (R, 4, 0, 5)]
    np.testing.assert_array_equal(tp.start_mm[-1], [1, 0, -1])


def test_g87_back_boring():
    # in through the hole off centre (I1 J0) with the spindle oriented, counterbore up to K-6
    tp = parse("M3\nG0 X0 Y0 Z2\nF60\nG87 X5 Y5 R-5 Z-8 I1 J0 K-6")
    assert moves(tp, 1) == [
        (R, 5, 5, 2), (R, 5, 5, -5),  # to the hole, down to R (G99: the clearance)
        (R, 6, 5, -5), (R, 6, 5, -8), (R, 5, 5, -8),  # off centre, through, back on centre
        (F, 5, 5, -6), (F, 5, 5, -8),  # the counterbore
        (R, 6, 5, -8), (R, 6, 5, -5), (R, 5, 5, -5),  # off centre, out, back on centre
    ]  # fmt: skip


def test_cycles_in_the_zx_and_yz_planes_drill_along_y_and_x():
    tp = parse("G18 G0 X0 Y10 Z0\nG81 X5 Z5 R2 Y-3 F60")
    assert moves(tp, 1) == [(R, 5, 10, 5), (R, 5, 2, 5), (F, 5, -3, 5), (R, 5, 2, 5)]
    tp = parse("G19 G0 X10 Y0 Z0\nG98 G81 Y5 Z5 R2 X-3 F60")
    assert moves(tp, 1) == [(R, 10, 5, 5), (R, 2, 5, 5), (F, -3, 5, 5), (R, 10, 5, 5)]


def test_g84_outside_g17_is_left_to_linuxcnc():
    # LinuxCNC 2.9's convert_cycle_g74_g84 maps the plane's axes twice there
    with pytest.raises(GCodeError, match=r"G84 in the G18 plane .* needs LinuxCNC's interpreter"):
        parse("M3\nG18 G0 Y10\nG84 X1 R2 Y-1 F60", reader="native")


def test_words_carry_over_between_lines_of_the_same_cycle_only():
    tp = parse("G0 Z5\nG82 X1 R2 Z-1 P0.5 F60\nX2")
    assert tp.dwell_s[tp.kind == D].tolist() == [0.5, 0.5]
    with pytest.raises(GCodeError, match="R clearance plane unspecified in G83") as info:
        parse("G0 Z5\nG81 X1 R2 Z-1 F60\nG83 X2 Z-1 Q1")
    assert info.value.line == 3


def test_g91_r_is_from_the_initial_level_and_z_from_r():
    tp = parse("G0 X1 Y1 Z10\nG91 G98 G81 R-8 Z-5 X0 F60")
    assert moves(tp, 1) == [(R, 1, 1, 10), (R, 1, 1, 2), (F, 1, 1, -3), (R, 1, 1, 10)]


def test_cycles_read_inch_words():
    tp = parse("G20 G0 X0 Y0 Z1\nG98 G81 X1 R0.1 Z-0.2 F10")
    np.testing.assert_allclose(tp.end_mm[-2], [25.4, 0, -0.2 * 25.4])
    assert tp.feed_mm_s[-2] == pytest.approx(10 * 25.4 / 60)


def test_events_of_a_cycle_line_come_before_its_moves():
    tp = parse("G0 Z5\nM3 S800 G81 X1 R2 Z-1 F60")
    assert list(tp.events["block"]) == [1, 1]


def test_dump_round_trips_cycles_in_a_set_path_mode():
    tp = parse("G64 P0.01 G0 X0 Y0 Z5\nG83 X1 R1 Z-3 Q1.5 F60\nG80\nG0 X0")
    assert parse(dump(tp)).allclose(tp)
    # (in the machine's default mode it cannot: no G-code returns to it after the cycle's G61)
    with pytest.raises(ValueError, match="default path mode"):
        dump(parse("G0 Z5\nG81 X1 R1 Z-3 F60\nG80\nG0 X0"))


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("G0 Z5\nG81 X1 Z-1 F60", 2, "R clearance plane unspecified in G81"),
        ("G0 Z5\nG81 X1 R1 F60", 2, "Z value unspecified in G81"),
        ("G0 Z5\nG81 X1 R-2 Z-1 F60", 2, "R less than Z in G81"),
        ("G0 Z5\nG83 X1 R1 Z-1 F60", 2, "Q word missing with G83"),
        ("G0 Z5\nG83 X1 R1 Z-1 Q0 F60", 2, "negative or zero Q value used in G83"),
        ("G0 Z5\nG82 X1 R1 Z-1 F60", 2, "dwell time P word missing with G82"),
        ("G0 Z5\nG87 X1 R1 Z-1 I1 J1 K0 F60", 2, "spindle not turning in G87"),
        ("M3\nG0 Z5\nG87 X1 R1 Z-1 I1 J1 F60", 3, "K word missing with G87"),
        ("G0 Z5\nG81 X1 R1 Z-1 L0 F60", 2, "cannot do zero repeats"),
        ("G0 Z5\nG81 X1 R1 Z-1 L1.5 F60", 2, "L word must be a whole number"),
        ("G0 X1 L2", 1, "L word without a canned cycle"),
        ("G0 Z5\nG81 R1 F60", 2, "G81 without an axis word"),
        ("G0 Z5\nG81 X1 R1 Z-1", 2, "G81 with no feed rate set (F)"),
        ("G0 Z5\nG53 G81 X1 R1 Z-1 F60", 2, "G53 can only be used with G0 or G1"),
        ("G0 Z5\nG81 X1 R1 Z-1 Q1 F60", 2, "Q word without G64, G73 or G83"),
        ("G0 Z5\nG81 X1 R1 Z-1 P1 F60", 2, "P word without"),
        ("G0 Z5\nG83 X1 R100 Z-100 Q0.0001 F60", 2, "would make more than"),
    ],
)
def test_cycle_errors(text, line, reason):
    with pytest.raises(GCodeError) as info:
        parse(text)
    assert info.value.line == line
    assert reason in info.value.reason
