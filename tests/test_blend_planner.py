"""The blend-arc look-ahead planner (nctwin.estimate.blend_planner), against hand calculations
and LinuxCNC's recorded behaviour (the times in the comments were recorded on LinuxCNC; the live
test in test_linuxcnc.py checks the planner against LinuxCNC itself)."""

import math

import numpy as np
import pytest

from nctwin.estimate import estimate
from nctwin.estimate.blend_junctions import KINK_RATIO, blend_plane_acc, parabolic_directions
from nctwin.estimate.blend_limits import (
    MIN_SEGMENT_CYCLES,
    NORMAL_ACC_RATIO,
    STOP_TURN_RAD,
    junction_blends,
    move_limits,
    parabolic_junctions,
    tangent_junctions,
)
from nctwin.estimate.blend_planner import blend_planner
from nctwin.estimate.blend_speeds import OPTIMIZATION_DEPTH, optimised_end_speeds, stops_on_periods
from nctwin.gcode import parse
from nctwin.machine import load_profile

PROFILE = load_profile("linuxcnc_sim")
MACHINE = PROFILE.machine  # X/Y 1000 mm/s^2, Z 500 mm/s^2
PLANNER = PROFILE.control("planner")  # 1 ms, G64 P0.0254
A = 1000.0  # path acceleration along X or Y
AXIS_ACC = np.array([1000.0, 1000.0, 500.0])


def time_s(program: str) -> float:
    return estimate(parse(program, start_mm=(0, 0, 0)), PROFILE, "planner").cycle_time_s


def estimate_planner(tp, **kwargs):
    return blend_planner(tp, MACHINE, PLANNER, **kwargs)


def whole_periods(t: float) -> float:
    """A time from rest to rest on LinuxCNC: up to a whole number of 1 ms periods."""
    return math.ceil(t / 0.001 - 1e-9) * 0.001


def trapezoid_s(length: float, feed: float, acc: float, v0: float = 0.0, v1: float = 0.0) -> float:
    """Time of a trapezoid from v0 to v1 that reaches the feed (hand formula)."""
    ramps = (feed**2 - v0**2) / (2 * acc) + (feed**2 - v1**2) / (2 * acc)
    assert ramps <= length
    return (feed - v0) / acc + (feed - v1) / acc + (length - ramps) / feed


def test_exact_stop_line_at_full_acceleration():
    # G61: L/F + F/a = 60/50 + 50/1000 = 1.25 s, what LinuxCNC records
    assert time_s("G21 G90 G61\nG1 X60 F3000\n") == pytest.approx(1.25)


def test_last_move_of_a_blending_program_brakes_at_half_acceleration():
    # in G64 the last move keeps its parabolic end: L/F + F/(a/2) = 1.3 s (LinuxCNC: 1.301 s)
    assert time_s("G21 G90\nG1 X60 F3000\n") == pytest.approx(1.3)


def test_collinear_lines_run_at_full_acceleration_into_the_last_move():
    # 3 x 20 mm at 200 mm/s: up at a through the straight-on junction, down at a to the last
    # move's triangle speed sqrt(a / 2 * 20) = 100 mm/s, then that move at a / 2 from 100 mm/s
    # to its peak and to rest (LinuxCNC: 0.616 s)
    v1, a2 = math.sqrt(A / 2 * 20), A / 2
    cruise_mm = 40 - 200**2 / (2 * A) - (200**2 - v1**2) / (2 * A)
    first_two = 200 / A + (200 - v1) / A + cruise_mm / 200
    peak = math.sqrt((2 * a2 * 20 + v1**2) / 2)
    last = (peak - v1) / a2 + peak / a2
    program = "G21 G90 G64\nG1 X20 F12000\nX40\nX60\n"
    assert first_two + last == pytest.approx(0.616, abs=0.002)
    assert time_s(program) == pytest.approx(whole_periods(first_two + last))


def test_corner_blend_arc():
    # 90 deg corner, P 0.1: theta = 45 deg, d = cos(theta) P / (1 - sin(theta)) = 0.2414 mm,
    # R = tan(theta) d, v = sqrt(0.866 * 1000 * R) = 14.46 mm/s. The first line, shortened by d,
    # runs at the full acceleration into the arc; the arc (R pi / 2 long) at v; the last line,
    # shortened by d, at a / 2 (LinuxCNC: 4.131 s)
    d = math.cos(math.pi / 4) * 0.1 / (1 - math.sin(math.pi / 4))
    radius = math.tan(math.pi / 4) * d
    v = math.sqrt(NORMAL_ACC_RATIO * A * radius)
    expected = (
        trapezoid_s(100 - d, 50.0, A, v1=v)
        + radius * math.pi / 2 / v
        + trapezoid_s(100 - d, 50.0, A / 2, v0=v)
    )
    assert v == pytest.approx(14.46, abs=0.01)
    assert expected == pytest.approx(4.131, abs=0.002)
    corner = time_s("G21 G90 G64 P0.1\nG1 X100 F3000\nY100\n")
    assert corner == pytest.approx(whole_periods(expected))


def test_exact_stop_and_dwell_stop_the_tool():
    # G61: the corner is no tangent, so both lines stop at 0.9 a (tcSetKinkProperties):
    # L/F + F/(0.9 a) each, to a whole period (LinuxCNC: 4.112 s)
    one = whole_periods(2 + 50 / 900)
    assert one == pytest.approx(2.056)
    assert time_s("G21 G90 G61\nG1 X100 F3000\nY100\n") == pytest.approx(2 * one)
    # G61.1: exact stop at the full acceleration
    assert time_s("G21 G90 G61.1\nG1 X100 F3000\nY100\n") == pytest.approx(2 * (2 + 0.05))
    # a dwell: the move before it keeps its parabolic end, so both lines brake at a / 2, and the
    # task rests the profile's dwell_wait_s (3 ms) around it (LinuxCNC: 4.704 s)
    dwell = "G21 G90 G64 P0.1\nG1 X100 F3000\nG4 P0.5\nY100\n"
    assert time_s(dwell) == pytest.approx(2 * (2 + 0.1) + 0.5 + 0.003)


def test_a_turn_close_to_a_reversal_stops():
    # four 25.4 mm moves, each turning back within STOP_TURN_RAD / 4 of a half turn: each stops
    # at its corner, the first three at the full acceleration, the last at a / 2, each to a
    # whole period (LinuxCNC, for turns within 0.002 rad: 1.519 s)
    y = 25.4 * math.tan(STOP_TURN_RAD / 8)
    program = f"G21 G90 G64\nG1 X25.4 F6000\nX0 Y{y:.6f}\nX25.4 Y{2 * y:.6f}\nX0 Y{3 * y:.6f}\n"
    length = parse(program, start_mm=(0, 0, 0)).lengths_mm  # 25.4 mm and < 1 um more
    acc = np.array([A, A, A, A / 2])
    expected = sum(whole_periods(t) for t in length / 100 + 100 / acc)  # L/F + F/a each
    assert time_s(program) == pytest.approx(expected)


def test_a_move_takes_at_least_one_period():
    # 100 moves of 0.01 mm at 200 mm/s: at least 1 ms each
    moves = "\n".join(f"X{0.01 * (i + 1):.2f}" for i in range(100))
    assert time_s(f"G21 G90 G64\nG1 F12000\n{moves}\n") >= 100 * 0.001


def test_an_item_runs_at_most_its_length_per_1_02_periods():
    # 300 collinear moves of 0.05 mm at 200 mm/s: each item holds 0.05 mm / 1.02 ms = 49.02 mm/s
    # (TP_MIN_SEGMENT_CYCLES; LinuxCNC: 0.364 s, cruising at 49.02 mm/s)
    moves = "".join(f"X{0.05 * k:.2f}\n" for k in range(1, 301))
    cruise = 0.05 / (MIN_SEGMENT_CYCLES * 0.001)
    assert cruise == pytest.approx(49.02, abs=0.01)
    assert time_s(f"G21 G90 G64\nG1 F12000\n{moves}") == pytest.approx(0.364, abs=0.002)


def test_look_ahead_reaches_fifty_items():
    # equal collinear items, each queued move walks back through 50 of them from its own
    # triangle speed at a / 2: the end of each is v^2 = 2 a L (50 + 1/4)
    n, length = 120, 0.2
    queued = np.arange(n - 1)  # the last item before each newly queued move
    end = optimised_end_speeds(
        np.full(n, length),
        np.full(n, A),
        np.full(n, 200.0),
        np.arange(n) < n - 1,
        queued,
        np.full(n - 1, length),
        np.full(n - 1, A / 2),
        np.full(n - 1, 200.0),
    )
    assert end[0] == pytest.approx(math.sqrt(2 * A * length * (OPTIMIZATION_DEPTH + 0.25)))
    # 300 x 0.2 mm at 200 mm/s cruise at 141.8 mm/s (LinuxCNC: 0.583 s, 142 mm/s)
    moves = "".join(f"X{0.2 * k:.1f}\n" for k in range(1, 301))
    assert time_s(f"G21 G90 G64\nG1 F12000\n{moves}") == pytest.approx(0.583, abs=0.002)


def test_the_lazy_look_ahead_dips_before_a_long_line():
    # 39 moves of 0.4 mm on a quarter circle of 20 mm at 92 mm/s, then a 40 mm line: the walk
    # back from the line stops after 5 items at their peak, and the arcs before them keep the
    # end speeds of earlier walks, sqrt(12.5 (a / 2) L) = 50 mm/s (LinuxCNC: 1.497 s)
    n = round(20 * math.pi / 2 / 0.4)
    phi = np.arange(1, n + 1) * math.pi / 2 / n
    corner = "".join(f"X{50 + 20 * math.sin(p):.4f} Y{20 - 20 * math.cos(p):.4f}\n" for p in phi)
    program = f"G21 G90 G64 P0.3 Q0\nG1 X50 F5520\n{corner}Y60\n"
    assert time_s(program) == pytest.approx(1.497, abs=0.002)


def test_blend_arcs_take_the_acceleration_of_their_plane():
    s = math.sqrt(0.5)
    xy = blend_plane_acc(np.array([[s, s, 0.0]]), np.array([[s, -s, 0.0]]), AXIS_ACC)
    xz = blend_plane_acc(np.array([[s, 0.0, s]]), np.array([[s, 0.0, -s]]), AXIS_ACC)
    straight = blend_plane_acc(np.array([[1.0, 0, 0]]), np.array([[1.0, 0, 0]]), AXIS_ACC)
    # not the 1414 mm/s^2 a diagonal line may use: the X and Y limits, and Z's in a plane with Z
    assert xy[0] == pytest.approx(1000.0)
    assert xz[0] == pytest.approx(500.0)
    assert np.isinf(straight[0])
    # zigzags of 45 deg moves (LinuxCNC: 2.237 s in XY at P0.5, 1.109 s in XZ)
    h = 5 / math.sqrt(2)
    zig = "".join(f"X{h * k:.6f} Y{h * (k % 2):.6f}\n" for k in range(1, 21))
    assert time_s(f"G21 G90 G64 P0.5\nG1 F6000\n{zig}") == pytest.approx(2.237, abs=0.002)
    h = 1 / math.sqrt(2)
    zig = "".join(f"X{h * k:.6f} Z{-h * (k % 2):.6f}\n" for k in range(1, 21))
    assert time_s(f"G21 G90 G64\nG1 F6000\n{zig}") == pytest.approx(1.109, abs=0.002)


def test_a_rapid_and_a_feed_move_are_not_blended():
    # the tool stops between them (tpCheckCanonType): 10 mm rapid as a triangle at a,
    # 2 sqrt(L / a) = 0.2 s; then the last move from rest at a / 2: 2 sqrt(L / (a / 2)) = 0.283 s
    # (LinuxCNC: 0.483 s)
    rapid, feed = 2 * math.sqrt(10 / A), 2 * math.sqrt(10 / (A / 2))
    assert time_s("G21 G90 G64\nG0 X10\nG1 X20 F6000\n") == pytest.approx(
        whole_periods(rapid) + whole_periods(feed)
    )
    assert whole_periods(rapid) + whole_periods(feed) == pytest.approx(0.483)


def test_an_arc_is_one_move_under_its_centripetal_limit():
    # quarter circle r = 10 in G61 at 100 mm/s: the speed stays within sqrt(0.866 a r) = 93.1
    # mm/s, the tangential acceleration is a / 2; the arc is too short to reach it: a triangle
    # 2 sqrt(L / (a / 2)) with L = 5 pi (LinuxCNC: 0.355 s)
    expected = 2 * math.sqrt(5 * math.pi / (A / 2))
    assert time_s("G21 G90 G61\nG2 X10 Y-10 I0 J-10 F6000\n") == pytest.approx(0.355)
    assert whole_periods(expected) == pytest.approx(0.355)


def test_naive_cam_merging_before_planning():
    # G64 P0.01 sets Q = P: 200 moves wiggling 0.004 mm about a line are planned as the two
    # lines LinuxCNC's canon makes of them (101 points, then 99; with Q0 nothing is merged)
    wiggle = "".join(f"X{0.05 * k:.2f} Y{0.004 * (k % 2):.3f}\n" for k in range(1, 201))
    merged = "G21 G90 G64 P0.01 Q0\nG1 F6000\nX5.05 Y0.004\nX10 Y0\n"
    assert time_s("G21 G90 G64 P0.01\nG1 F6000\n" + wiggle) == pytest.approx(time_s(merged))
    assert time_s(merged) < 0.5 * time_s("G21 G90 G64 P0.01 Q0\nG1 F6000\n" + wiggle)


def test_an_arc_entered_from_outside_its_plane_gets_a_parabolic_blend():
    # a line along Y into an arc in the XZ plane: no blend arc fits (the line is not in the
    # arc's plane), LinuxCNC blends parabolically and halves both moves' acceleration; on the
    # arc (Z: 500 mm/s^2) the speed stays within sqrt(0.866 (a / 2) r) and its tangential
    # acceleration is (a / 2) / 2 (LinuxCNC's trace: 125 mm/s^2)
    program = "G21 G90 G64 P0.1\nG0 X50 Y40 Z0\nG1 Y50 F6000\nG18 G2 X55 Z5 I5 K0\nG1 X45\n"
    tp = parse(program, start_mm=(0, 0, 0))
    moves = tp.take(np.arange(1, 4))
    tol = moves.effective_tolerance_mm(PLANNER.blend_tol_mm)
    np.testing.assert_array_equal(parabolic_junctions(moves, tol), [True, False])
    feed, acc = move_limits(moves, MACHINE, np.array([0.5, 0.5, 1.0]))
    assert feed[1] == pytest.approx(math.sqrt(NORMAL_ACC_RATIO * 250 * 5))
    assert acc[1] == pytest.approx(125.0)
    # LinuxCNC: 1.806 s (the parabolic blend is modelled as one junction speed)
    assert time_s(program) == pytest.approx(1.806, rel=0.01)


def test_tangent_junction_by_hand():
    # two lines along X, the second turned by 0.001 rad in XY, at 60 mm/s: the kink costs
    # (60 / 0.001 + 1000) * |u2 - u1| / 1000 = 61 * 0.001 = 0.061 of X's or Y's acceleration
    tp = parse("G21 G90 G61\nG1 X10 F3600\nX20 Y0.01\n", start_mm=(0, 0, 0))
    feed, acc = move_limits(tp, MACHINE)
    tangent, share = tangent_junctions(tp, feed, acc, AXIS_ACC, PLANNER.period_s)
    turn = math.atan2(0.01, 10.0)
    assert share[0] == pytest.approx(61.0 * turn, rel=1e-6)  # Y's component dominates
    assert tangent[0] and share[0] < KINK_RATIO
    # a turn twice as sharp, at twice the speed, is no longer tangent
    tp2 = parse("G21 G90 G61\nG1 X10 F7200\nX20 Y0.02\n", start_mm=(0, 0, 0))
    feed2, acc2 = move_limits(tp2, MACHINE)
    assert not tangent_junctions(tp2, feed2, acc2, AXIS_ACC, PLANNER.period_s)[0][0]
    # tangent: no stop, both lines at (1 - share) a; the last keeps its exact-path end (no a/2)
    a = A * (1 - share[0])
    total = trapezoid_s(10.0, 60.0, a, v1=60.0) + trapezoid_s(math.hypot(10, 0.01), 60.0, a, 60.0)
    assert time_s("G21 G90 G61\nG1 X10 F3600\nX20 Y0.01\n") == pytest.approx(
        whole_periods(total), rel=1e-3
    )


def test_blend_arc_is_as_small_as_its_speed_allows():
    # a 90-degree corner of two 100 mm lines, plain G64, at 10 mm/s: the tolerance would allow an
    # arc of d = 25 mm, but the arc is sized for its speed: the larger of v^2 / a_n and the arc
    # a parabolic blend would run, v t_b / phi with t_b = v / (a / 2) and phi = pi / 2;
    # d = R / tan(45 deg) = R
    tp = parse("G21 G90 G64\nG1 X100 F600\nY100\n", start_mm=(0, 0, 0))
    feed, _ = move_limits(tp, MACHINE)
    v, d, arc, _, _ = junction_blends(
        tp.lengths_mm, tp.end_tangents, tp.start_tangents, feed, np.full(2, np.inf), AXIS_ACC
    )
    r = max(10.0**2 / (NORMAL_ACC_RATIO * A), 10.0 * (10.0 / (A / 2)) / (math.pi / 2))
    assert r == pytest.approx(4 * 10.0**2 / (math.pi * A))  # the parabolic term binds
    assert d[0] == pytest.approx(r) and arc[0] == pytest.approx(r * math.pi / 2)
    assert v[0] == pytest.approx(10.0)
    # at 150 mm/s: R = 2 v^2 / (a phi) = 28.6 mm, below the largest arc (d = R = 50 mm, half a
    # line); at 200 mm/s, 2 v^2 / (a phi) = 50.9 mm > 50 mm: the largest arc
    for f, expected in ((150.0, 4 * 150.0**2 / (math.pi * A)), (200.0, 50.0)):
        feed[:] = f
        d = junction_blends(
            tp.lengths_mm, tp.end_tangents, tp.start_tangents, feed, np.full(2, np.inf), AXIS_ACC
        )[1]
        assert d[0] == pytest.approx(expected)


def test_a_blend_arc_between_two_feeds_runs_at_the_larger():
    # LinuxCNC sizes a blend arc for the larger of the two feeds and runs it as a segment of its
    # own at that speed; only its ends are held to the lines' feeds (tpGetRealFinalVel). A
    # 90-degree corner, plain G64, 100 mm at 10 mm/s then 100 mm at 80 mm/s: the arc sized for
    # 80 mm/s, R = 4 v^2 / (pi A) = 8.15 mm (as above), where sqrt(a_n R) = 84 mm/s > 80
    tp = parse("G21 G90 G64\nG1 X100 F600\nY100 F4800\n", start_mm=(0, 0, 0))
    feed, _ = move_limits(tp, MACHINE)
    v, d, _, _, v_arc = junction_blends(
        tp.lengths_mm, tp.end_tangents, tp.start_tangents, feed, np.full(2, np.inf), AXIS_ACC
    )
    r = 4 * 80.0**2 / (math.pi * A)
    assert math.sqrt(NORMAL_ACC_RATIO * A * r) > 80.0
    assert d[0] == pytest.approx(r)
    assert v[0] == pytest.approx(10.0) and v_arc[0] == pytest.approx(80.0)
    # LinuxCNC on linuxcnc_sim, live: a 8 mm plunge at 10 mm/s into an 80 mm line at 80 mm/s,
    # 1.858 s in plain G64 (2.330 s with the arc held to 10 mm/s); 1.540 s from 40 mm/s
    for plunge_feed, linuxcnc_s in ((600, 1.858), (2400, 1.540)):
        program = f"G21 G90\nG0 Z5\nG1 Z-3 F{plunge_feed}\nG1 X80 F4800\n"
        assert time_s(program) == pytest.approx(linuxcnc_s, abs=5e-4)
    # the ablation's rule: the arc at the smaller feed, 10 mm/s
    slow = estimate_planner(
        parse("G21 G90\nG0 Z5\nG1 Z-3 F600\nG1 X80 F4800\n", start_mm=(0, 0, 0)), arc_speed=False
    )
    assert slow.cycle_time_s == pytest.approx(2.330, abs=5e-4)


def test_stops_fall_on_servo_periods():
    # three items, a stop after the first: 0.2504 s from rest to rest -> 0.251; 0.1 + 0.3002 s
    # -> 0.401, the rest of the period on the item that stops
    t = stops_on_periods(np.array([0.2504, 0.1, 0.3002]), np.array([0.0, 50.0]), 0.001)
    np.testing.assert_allclose(t, [0.251, 0.1, 0.301])
    # LinuxCNC, three 7 mm moves at 37 mm/s under G61.1: 0.681 s (trapezoids: 0.6786 s)
    program = "G21 G90 G61.1\nG1 X7 F2220\nY7\nX0\n"
    assert 3 * (7 / 37 + 37 / A) == pytest.approx(0.6786, abs=1e-4)
    assert time_s(program) == pytest.approx(3 * 0.227)
    tp = parse(program, start_mm=(0, 0, 0))
    mean = estimate_planner(tp, stop_periods="mean").cycle_time_s
    assert mean == pytest.approx(3 * (7 / 37 + 37 / A + 0.0005))
    with pytest.raises(ValueError, match="stop_periods = 'all' is not allowed: allowed whole"):
        estimate_planner(tp, stop_periods="all")


def test_a_g18_circle_is_limited_by_z():
    # a full circle of r = 10 in the XZ plane at 100 mm/s under G61: canon's ARC_FEED takes the
    # smaller acceleration of the plane's axes, Z's 500 mm/s^2, so the speed stays within
    # v = sqrt(0.866 * 500 * 10) = 65.8 mm/s (not 100, Z's velocity); the circle is the last
    # move, never finalized: tangential acceleration 500 / 2 (LinuxCNC: 1.218 s)
    v = math.sqrt(NORMAL_ACC_RATIO * 500 * 10)
    program = "G21 G90 G61\nG18 G2 X0 Z0 I10 K0 F6000\n"
    feed, acc = move_limits(parse(program, start_mm=(0, 0, 0)), MACHINE)
    assert feed == pytest.approx([v])
    assert acc == pytest.approx([250.0])
    expected = 20 * math.pi / v + v / 250
    assert expected == pytest.approx(1.218, abs=0.001)
    assert time_s(program) == pytest.approx(whole_periods(expected))


def test_an_arc_splits_its_acceleration_at_its_speed_limit_not_its_feed():
    # a half circle of r = 100 in XZ at 50 mm/s between two lines, G61: the arc's speed limit is
    # Z's 100 mm/s; finalized with the kink's 0.9 of 500 mm/s^2 (a' = 450), its normal
    # acceleration at that limit is 100^2 / 100 = 100 mm/s^2, so the tangential acceleration is
    # a' sqrt(1 - (100 / a')^2) = 438.8 mm/s^2 (LinuxCNC's trace: 438.5), whatever the feed;
    # the line after it turns back (a sharp corner): a stop with no kink, 500 mm/s^2
    program = "G21 G90 G61\nG18 G1 X10 F3000\nG2 X210 Z0 I100 K0\nG1 Z-10\n"
    moves = parse(program, start_mm=(0, 0, 0))
    feed, acc = move_limits(moves, MACHINE, np.array([0.9, 0.9, 1.0]))
    assert feed[1] == pytest.approx(50.0)
    assert acc[1] == pytest.approx(450 * math.sqrt(1 - (100 / 450) ** 2))
    # at the feed instead (the rule as first written): 450 sqrt(1 - (25 / 450)^2) = 449.3
    assert move_limits(moves, MACHINE, np.array([0.9, 0.9, 1.0]), arc_ratio="feed")[1][
        1
    ] == pytest.approx(450 * math.sqrt(1 - (25 / 450) ** 2))
    assert time_s(program) == pytest.approx(6.954, abs=0.001)  # LinuxCNC: 6.954 s


def test_a_helix_takes_linuxcncs_effective_radius():
    # a full turn of r = 5 in YZ rising 20 mm along X, between lines: length
    # l = sqrt((10 pi)^2 + 20^2); canon's speed limit sqrt(0.866 * 500 * 5) l / (10 pi) (Z's
    # acceleration, the planar share), the path acceleration min(500 l / (10 pi), 1000 l / 20);
    # finalized with the effective radius r + h^2 / r = 85 mm (pmCircleEffectiveMinRadius)
    program = "G21 G90 G61\nG19 G1 Y10 F6000\nG3 Y10 Z0 X20 J5 K0\nG1 Z-10\n"
    moves = parse(program, start_mm=(0, 0, 0))
    length = math.hypot(10 * math.pi, 20)
    v_max = math.sqrt(NORMAL_ACC_RATIO * 500 * 5) * length / (10 * math.pi)
    a = min(500 * length / (10 * math.pi), 1000 * length / 20)
    feed, acc = move_limits(moves, MACHINE)
    assert moves.lengths_mm[1] == pytest.approx(length)
    assert feed[1] == pytest.approx(v_max)
    assert acc[1] == pytest.approx(a * math.sqrt(1 - (v_max**2 / 85 / a) ** 2))


def test_a_helix_into_a_line_along_its_plane_blends_straight_on():
    # the YZ helix above ends running along -Z in its plane (and along +X); the line after runs
    # along -Z: tpComputeBlendVelocity takes the arc's planar tangent, so the parabolic blend
    # sees no turn and no tolerance limit; its start leans towards the centre by (F / 2)^2 / r
    moves = parse(
        "G21 G90 G64 P0.01\nG19 G1 Y10 F3000\nG3 Y10 Z0 X20 J5 K0\nG1 Z-10\n", start_mm=(0, 0, 0)
    )
    end, start = parabolic_directions(moves, np.full(3, 300.0), np.full(3, 50.0))
    np.testing.assert_allclose(end[1], [0, 0, -1], atol=1e-12)
    lean = 25.0**2 / 5
    np.testing.assert_allclose(start[1], np.array([0, lean, -300]) / math.hypot(lean, 300))
    np.testing.assert_allclose(end[0], moves.end_tangents[0])
    # LinuxCNC: 1.431 s (the 3D tangents: a 33 degree turn held to 5 mm/s, 1.560 s)
    assert time_s("G21 G90 G64 P0.01\nG19 G1 Y10 F3000\nG3 Y10 Z0 X20 J5 K0\nG1 Z-10\n") == (
        pytest.approx(1.431, rel=0.005)
    )


def test_g61_stops_without_a_kink_at_a_reversal_and_between_rapid_and_feed():
    # a reversal (tpSetupTangent's sharp corner) and a change between rapid and feed
    # (handleModeChange) stop the tool before any kink is set: the moves keep their full
    # acceleration. 10 mm at 50 mm/s and back at 1000 mm/s^2 (0.25 s each), then 10 mm along Y
    # after a 90 degree kink, the last two at 0.9 a (LinuxCNC: 0.762 s)
    turn = 0.25 + whole_periods(0.2 + 50 / 900)
    assert time_s("G21 G90 G61\nG1 X10 F3000\nX0\nY10\n") == pytest.approx(0.25 + 2 * (turn - 0.25))
    assert 0.25 + 2 * (turn - 0.25) == pytest.approx(0.762)
    # 5 mm rapid along Z (triangle at 500 mm/s^2), a stop, 5 mm at 5 mm/s (LinuxCNC: 1.210 s)
    expected = 2 * math.sqrt(5 / 500) + 5 / 5 + 5 / 500
    assert time_s("G21 G90 G61\nG0 Z-5\nG1 Z-10 F300\n") == pytest.approx(expected, abs=0.001)
    assert expected == pytest.approx(1.210)


def test_a_junction_takes_the_mode_of_the_move_before_it():
    # LinuxCNC gives each move the term condition in force when it is queued, and the junction
    # after it uses that move's (tcSetupState): G61 then G64 stops at the first corner, G64
    # then G61 blends it; the second corner the other way round. Swapping the modes changes
    # the time only through that (LinuxCNC: 1.397 s and 1.356 s)
    stop_first = time_s("G21 G90 G61\nG1 X20 F3000\nG64 P0.05\nG1 Y20\nG1 X0\n")
    blend_first = time_s("G21 G90 G64 P0.05\nG1 X20 F3000\nG61\nG1 Y20\nG1 X0\n")
    assert stop_first == pytest.approx(1.397, abs=0.001)
    assert blend_first == pytest.approx(1.356, abs=0.001)
