"""The blend-arc look-ahead planner (nctwin.estimate.blend_planner), against hand calculations
and LinuxCNC's recorded behaviour (the times in the comments were recorded on LinuxCNC; the live
test in test_linuxcnc.py checks the planner against LinuxCNC itself)."""

import math

import pytest

from nctwin.estimate import estimate
from nctwin.estimate.blend_planner import NORMAL_ACC_RATIO, STOP_TURN_RAD
from nctwin.gcode import parse
from nctwin.machine import load_machine

MACHINE = load_machine("linuxcnc_sim")  # X/Y 1000 mm/s^2, Z 500 mm/s^2, 1 ms
A = 1000.0  # path acceleration along X or Y


def time_s(program: str) -> float:
    return estimate(parse(program, start_mm=(0, 0, 0)), MACHINE, "planner").cycle_time_s


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
    assert time_s(program) == pytest.approx(first_two + last)


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
    assert time_s("G21 G90 G64 P0.1\nG1 X100 F3000\nY100\n") == pytest.approx(expected)


def test_exact_stop_and_dwell_stop_the_tool():
    # G61: two lines at the full acceleration (LinuxCNC: 4.113 s, its stop settles ~6 ms)
    assert time_s("G21 G90 G61\nG1 X100 F3000\nY100\n") == pytest.approx(2 * (2 + 0.05))
    # a dwell: the move before it keeps its parabolic end, so both lines brake at a / 2
    # (LinuxCNC: 4.704 s)
    dwell = "G21 G90 G64 P0.1\nG1 X100 F3000\nG4 P0.5\nY100\n"
    assert time_s(dwell) == pytest.approx(2 * (2 + 0.1) + 0.5)


def test_a_turn_close_to_a_reversal_stops():
    # four 25.4 mm moves, each turning back within STOP_TURN_RAD / 4 of a half turn: each stops
    # at its corner, the first three at the full acceleration, the last at a / 2
    # (LinuxCNC, for turns within 0.002 rad: 1.519 s)
    y = 25.4 * math.tan(STOP_TURN_RAD / 8)
    program = f"G21 G90 G64\nG1 X25.4 F6000\nX0 Y{y:.6f}\nX25.4 Y{2 * y:.6f}\nX0 Y{3 * y:.6f}\n"
    move = 25.4 / 100 + 100 / A  # L/F + F/a; the lengths differ from 25.4 mm by < 1 um
    last = 25.4 / 100 + 100 / (A / 2)
    assert time_s(program) == pytest.approx(3 * move + last, rel=1e-4)


def test_a_move_takes_at_least_one_period():
    # 100 moves of 0.01 mm at 200 mm/s: at least 1 ms each
    moves = "\n".join(f"X{0.01 * (i + 1):.2f}" for i in range(100))
    assert time_s(f"G21 G90 G64\nG1 F12000\n{moves}\n") >= 100 * 0.001
