"""The blend-arc look-ahead planner (nctwin.estimate.blend_planner), against hand calculations
and LinuxCNC's recorded behaviour."""

import math

import pytest

from nctwin.estimate import estimate
from nctwin.estimate.blend_planner import NORMAL_ACC_RATIO
from nctwin.gcode import parse
from nctwin.machine import load_machine

MACHINE = load_machine("linuxcnc_sim")  # X/Y 1000 mm/s^2, Z 500 mm/s^2, 1 ms


def time_s(program: str) -> float:
    return estimate(parse(program, start_mm=(0, 0, 0)), MACHINE, "planner").cycle_time_s


def test_single_line_rest_to_rest():
    # L/F + F/a = 60/50 + 50/1000 = 1.25 s: what LinuxCNC recorded for this line
    assert time_s("G21 G90\nG1 X60 F3000\n") == pytest.approx(1.25)


def test_collinear_lines_do_not_slow_down():
    assert time_s("G21 G90\nG1 X30 F3000\nX60\n") == pytest.approx(1.25)


def test_corner_speed_from_the_blend_arc():
    # 90 deg corner, P 0.1: theta = 45 deg, d = cos(theta) P / (1 - sin(theta)) = 0.2414 mm,
    # R = tan(theta) d = 0.2414 mm, v = sqrt(0.866 * 1000 * R) = 14.46 mm/s; each 100 mm line
    # is blended at one end, so it accelerates at a / 2 = 500 mm/s^2
    d = math.cos(math.pi / 4) * 0.1 / (1 - math.sin(math.pi / 4))
    v = math.sqrt(NORMAL_ACC_RATIO * 1000 * math.tan(math.pi / 4) * d)
    a, f, length = 500.0, 50.0, 100.0
    line = (f / a) + (f - v) / a + (length - f**2 / (2 * a) - (f**2 - v**2) / (2 * a)) / f
    assert v == pytest.approx(14.46, abs=0.01)
    assert time_s("G21 G90 G64 P0.1\nG1 X100 F3000\nY100\n") == pytest.approx(2 * line)


def test_exact_stop_and_dwell_stop_the_tool():
    stop = 2 * (100 / 50 + 50 / 1000)  # two lines rest to rest at the full acceleration
    assert time_s("G21 G90 G61\nG1 X100 F3000\nY100\n") == pytest.approx(stop)
    assert time_s("G21 G90 G64 P0.1\nG1 X100 F3000\nG4 P0.5\nY100\n") == pytest.approx(stop + 0.5)


def test_a_move_takes_at_least_one_period():
    # 100 moves of 0.01 mm at 200 mm/s: at least 1 ms each
    moves = "\n".join(f"X{0.01 * (i + 1):.2f}" for i in range(100))
    assert time_s(f"G21 G90 G64\nG1 F12000\n{moves}\n") >= 100 * 0.001
