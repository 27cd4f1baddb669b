"""LinuxCNC's junctions with a programmed arc (nctwin.estimate.blend_junctions), against hand
calculations; the times in the comments were recorded on LinuxCNC (the live planner test in
test_linuxcnc.py runs them)."""

import math

import numpy as np
import pytest

from nctwin.estimate import estimate
from nctwin.estimate.blend_junctions import (
    ARC_BLEND,
    KINK_RATIO,
    PARABOLIC_BLEND,
    TANGENT_BLEND,
    arc_junction_blends,
    choose_blends,
    parabolic_performance,
)
from nctwin.gcode import parse
from nctwin.machine import load_profile

PROFILE = load_profile("linuxcnc_sim")
MACHINE = PROFILE.machine
A_N = math.sqrt(0.75) * 1000.0  # normal acceleration of a blend arc in XY
R = 5.0  # the arc's radius
KINK = math.radians(1.0)


def arc_into_line(kink_rad: float, line_mm: float = 0.126, sweep: float = math.pi / 2):
    """A G3 arc of radius 5 ending at the origin heading +X (centre (0, 5)), then a line
    turning by ``kink_rad`` (positive: towards the centre), as arc_junction_blends' inputs."""
    one = np.ones(1)
    u2 = np.array([[math.cos(kink_rad), math.sin(kink_rad), 0.0]])
    return dict(
        point=np.zeros((1, 3)),
        u1=np.array([[1.0, 0.0, 0.0]]),
        u2=u2,
        arc1=np.array([True]),
        arc2=np.array([False]),
        centre1=np.array([[0.0, R, 0.0]]),
        centre2=np.zeros((1, 3)),
        normal1=np.array([[0.0, 0.0, 1.0]]),
        normal2=np.array([[0.0, 0.0, 1.0]]),
        sweep1=sweep * one,
        sweep2=0.0 * one,
        length1=R * sweep * one,
        length2=line_mm * one,
        speed1=math.sqrt(A_N * R) * one,  # the arc's centripetal limit, 65.8 mm/s
        speed2=line_mm / 0.001 * one,
        tol_mm=0.0254 * one,
        plane_acc=1000.0 * one,
        plane_vel=200.0 * one,
    )


def test_convex_arc_lowers_the_blend_angle_and_the_line_limits_its_size():
    # the line turns towards the centre: convex; phi_max = min(2/3 sweep, theta_t) = pi/3, so
    # theta = theta_t - pi/12; the line offers half its length, d = 0.063 mm (the tolerance
    # would allow more), R = tan(theta) d, v = sqrt(a_n R) (the goal 126 mm/s is higher)
    out = arc_junction_blends(**arc_into_line(KINK))
    theta = (math.pi - KINK) / 2 - math.pi / 12
    radius = math.tan(theta) * 0.063
    assert out["made"][0]
    assert out["radius"][0] == pytest.approx(radius)
    assert out["v_plan"][0] == pytest.approx(math.sqrt(A_N * radius))


def test_blend_circle_is_tangent_to_the_line_and_inside_the_arc():
    # the circle as made touches the line d_L from the junction and the arc's circle from
    # inside (its centre r - R from the arc's); for a small kink alpha the arc loses about
    # s = alpha r (sqrt(r / (r - R)) - 1), the blend turns by beta = alpha + s / r, and the
    # line loses R beta - s
    out = arc_junction_blends(**arc_into_line(KINK))
    radius, d_line, d_arc = out["radius"][0], out["trim2"][0], out["trim1"][0]
    u = np.array([math.cos(KINK), math.sin(KINK)])
    centre = d_line * u + radius * np.array([-u[1], u[0]])
    assert np.hypot(centre[0], centre[1] - R) == pytest.approx(R - radius, rel=1e-9)
    small = KINK * R * (math.sqrt(R / (R - radius)) - 1.0)
    assert d_arc == pytest.approx(small, rel=0.02)
    assert d_line == pytest.approx(radius * (KINK + small / R) - small, rel=0.02)
    assert out["length"][0] == pytest.approx(radius * (KINK + d_arc / R), rel=1e-6)
    assert out["length"][0] < 0.01 < radius * KINK * 10  # far below the planned R (pi - 2 theta)


def test_blend_fails_out_of_the_arcs_plane():
    tilted = arc_into_line(KINK)
    tilted["u2"] = np.array([[math.cos(KINK), 0.0, math.sin(KINK)]])  # turns in XZ
    out = arc_junction_blends(**tilted)
    assert not out["made"][0] and out["length"][0] == 0.0


def test_concave_arc_keeps_the_blend_angle():
    # the line turns away from the centre: not convex, theta = theta_t, R = tan(theta) d
    out = arc_junction_blends(**arc_into_line(-KINK))
    assert out["radius"][0] == pytest.approx(math.tan((math.pi - KINK) / 2) * 0.063)


def test_choose_blends_takes_the_fastest_and_the_first_of_equals():
    arc = np.array([4.0, 1.0, 2.0, 3.0, 0.0])
    kink = np.array([3.0, 5.0, 2.0, 3.0, 1.0])
    para = np.array([1.0, 2.0, 2.0, 1.0, 1.0])
    assert choose_blends(arc, kink, para).tolist() == [
        ARC_BLEND,
        TANGENT_BLEND,
        PARABOLIC_BLEND,
        TANGENT_BLEND,
        PARABOLIC_BLEND,
    ]


def test_parabolic_performance_by_hand():
    # 10 mm and 1 mm lines, a = 200 and 400 mm/s^2, 90 degree turn, no tolerance: reachable
    # speeds sqrt(a L / 2) = 31.62 and 14.14, t_b = min(10/31.62, 1/14.14, max(0.158, 0.035))
    # = 0.0707 s, speeds min(vr, a t_b) = 14.14 and 14.14; net sin(45 deg) 28.28 / 4
    one = np.ones(1)
    perf = parabolic_performance(
        10 * one, one, 100 * one, 100 * one, 200 * one, 400 * one, 0 * one, 0 * one
    )
    v = min(math.sqrt(200 * 5), 200 * 1 / math.sqrt(400 * 0.5))
    assert perf[0] == pytest.approx(math.sin(math.pi / 4) * (v + math.sqrt(200)) / 4)


def test_kink_speed_is_the_share_of_the_move_speed():
    # tpSetupTangent: v_k = v_max r_k / k, here k = 2 r_k: half the speed
    assert 65.8 * KINK_RATIO / (2 * KINK_RATIO) == pytest.approx(32.9)


@pytest.mark.parametrize(
    ("program", "recorded_s"),
    [
        # XY arc, a 0.126 mm line turning 1 degree in, a 10 mm line 2 degrees more (0.663 s)
        ("G17 G3 X0 Y0 I5 J0\nG1 X0.126 Y0.0022\nX10.1123 Y0.5256\n", 0.663),
        # the same in YZ (0.829 s)
        ("G19 G3 Y0 Z0 J5 K0\nG1 Y0.126 Z0.0022\nY10.1123 Z0.5256\n", 0.829),
    ],
)
def test_arc_into_a_kinked_short_line_runs_through_the_tiny_blend_arc(program, recorded_s):
    start = "G21 G90 G64 P0.0254 Q0\nG0 X-5 Y5\nG1 F12000\n"
    if "G19" in program:
        start = "G21 G90 G64 P0.0254 Q0\nG0 Y-5 Z5\nG1 F12000\n"
    tp = parse(start + program + "M2\n", start_mm=(0, 0, 0))
    assert estimate(tp, PROFILE, "planner").cycle_time_s == pytest.approx(recorded_s, abs=0.002)
