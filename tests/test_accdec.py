"""The ideal acc/dec kernel (nctwin.kernel.accdec) against times and speeds computed by hand."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nctwin import parse
from nctwin.controls import AccDecControl
from nctwin.kernel.accdec import measure_inposition_times, run, simulate
from nctwin.machine import Machine
from nctwin.physics.servo import PositionLoop

TI = 0.001
FR = 10000.0 / 60.0  # rapid feed, mm/s

MACHINE = Machine(
    name="hand",
    description="the paper's testbed: rapid feed 10,000 mm/min",
    axis_max_velocity_mm_s=(200.0, 200.0, 200.0),
    axis_max_acceleration_mm_s2=(2000.0, 2000.0, 2000.0),
    axis_max_jerk_mm_s3=(math.inf,) * 3,
    rapid_feed_mm_s=FR,
    max_feed_mm_s=FR,
)
#: paper set 1 with round servo numbers
CONTROL = AccDecControl(
    period_s=TI,
    cut_time_constant_s=0.05,
    rapid_time_constant_s=0.15,
    rapid_bell_s=0.03,
    position_gain_per_s=(80.0, 80.0, 35.0),
    inposition_width_mm=(0.01, 0.01, 0.01),
)


def test_one_normal_block_takes_l_over_f_plus_at():
    # 10 mm at 10 mm/s: 1 s of interpolation + AT = 50 ms of acc/dec (eq. 3)
    r = simulate(parse("G1 X10 F600"), MACHINE, CONTROL)
    assert r.cycle_time_s == pytest.approx(1.05, abs=1e-12)
    speed = r.motion.speed_mm_s
    assert speed.max() == pytest.approx(10.0, rel=1e-9)
    # linear acc/dec: sample i holds the mean speed over the period ending at i ms,
    # F (i - 0.5) / 50 on the ramp; full feed after AT
    assert speed[25] == pytest.approx(10.0 * 24.5 / 50.0, rel=1e-9)
    assert speed[51] == pytest.approx(10.0, rel=1e-9)
    np.testing.assert_allclose(r.motion.pos_mm[-1], [10.0, 0.0, 0.0], atol=1e-9)


def test_short_block_never_reaches_the_feed():
    # 0.3 mm at 10 mm/s: 30 ms < AT; a trapezoid of 30 + 50 ms peaking at F * 30 / 50 (eq. 4-5)
    r = simulate(parse("G1 X0.3 F600"), MACHINE, CONTROL)
    assert r.cycle_time_s == pytest.approx(0.08, abs=1e-12)
    assert r.motion.speed_mm_s.max() == pytest.approx(6.0, rel=1e-9)


def test_two_cutting_blocks_overlap_by_at():
    r = simulate(parse("G1 X10 F600\nG1 X20"), MACHINE, CONTROL)
    assert r.cycle_time_s == pytest.approx(1.0 + 1.0 + 0.05, abs=1e-12)
    # collinear blocks overlap seamlessly: no dip in speed at the junction
    speed = r.motion.speed_mm_s
    assert speed[60:2000].min() == pytest.approx(10.0, rel=1e-9)
    np.testing.assert_allclose(r.block_times_s, [1.0, 1.05], atol=1e-12)


def test_corner_blends_both_axes_during_at():
    r = simulate(parse("G1 X10 F600\nG1 Y10"), MACHINE, CONTROL)
    vel = r.motion.vel_mm_s
    # 25 ms after the corner both axes move at about half the feed (overlap, Fig. 6)
    assert vel[1025, 0] == pytest.approx(10.0 * (1 - 24.5 / 50.0), rel=1e-9)
    assert vel[1025, 1] == pytest.approx(10.0 * 24.5 / 50.0, rel=1e-9)


def test_long_rapid_command_and_inposition():
    # 100 mm at Fr: ceil(0.6 s) + ATR 150 ms + As 30 ms (eq. 13), then in-position
    r = simulate(parse("G0 X100"), MACHINE, CONTROL)
    assert r.command_end_s[0] == pytest.approx(0.6 + 0.15 + 0.03, abs=1e-12)
    wait = r.inposition_wait_s[0]
    assert 0 < wait < 0.2
    assert r.cycle_time_s == pytest.approx(0.78 + wait, abs=1e-12)
    err = np.abs(r.following_error_mm)
    assert np.all(err[-1] <= 0.01)  # in position at the end
    assert err[-2, 0] > 0.01  # and not one period earlier


def test_short_rapid_is_a_triangle():
    # 1 mm: a = Fr / ATR = 1111.1 mm/s^2, Ta = ceil(sqrt(1 / a)) = 30 ms, T = 2 Ta + As (eq. 15)
    r = simulate(parse("G0 X1"), MACHINE, CONTROL)
    assert r.command_end_s[0] == pytest.approx(0.06 + 0.03, abs=1e-12)
    assert np.abs(r.motion.acc_mm_s2[:, 0]).max() <= FR / 0.15 * (1 + 1e-6)


def test_nonlinear_rapid_moves_each_axis_at_the_rapid_feed():
    c = dataclasses.replace(CONTROL, rapid_type="nonlinear")
    r = simulate(parse("G0 X100 Y10"), MACHINE, c)
    # the longest axis decides (eq. 14): X 100 mm as if alone
    assert r.command_end_s[0] == pytest.approx(0.6 + 0.15 + 0.03, abs=1e-12)
    # Y (10 mm) is a short rapid on its own: Ta = ceil(sqrt(10 / 1111.1)) = 95 ms, then As
    y_end = round((2 * 0.095 + 0.03) / TI)
    assert r.motion.pos_mm[y_end, 1] == pytest.approx(10.0, abs=1e-9)
    assert r.motion.pos_mm[y_end - 1, 1] < 10.0 - 1e-6
    assert r.motion.pos_mm[y_end, 0] < 50.0  # X is far from done: the path is not straight
    linear = simulate(parse("G0 X100 Y10"), MACHINE, CONTROL)
    assert linear.command_end_s[0] == pytest.approx(0.603 + 0.18, abs=1e-12)  # 100.499 mm


def test_dwell_stops_the_motion():
    r = simulate(parse("G1 X10 F600\nG4 X0.5\nG1 X20"), MACHINE, CONTROL)
    assert r.cycle_time_s == pytest.approx(1.05 + 0.5 + 1.05, abs=1e-12)
    dwell = r.motion.block == 1
    assert dwell.sum() == 500
    assert np.all(r.motion.speed_mm_s[dwell] == 0.0)


def test_feed_is_clamped_to_what_the_axis_velocities_allow():
    # X at most 5 mm/s: 10 mm along X at F600 (10 mm/s) takes 2 s + AT; at 45 degrees in XY
    # each axis moves at 1/sqrt(2) of the path speed, so the path runs at 5 sqrt(2) mm/s
    slow = dataclasses.replace(MACHINE, axis_max_velocity_mm_s=(5.0, 5.0, 200.0))
    r = simulate(parse("G1 X10 F600"), slow, CONTROL)
    assert r.cycle_time_s == pytest.approx(2.0 + 0.05, abs=1e-12)
    assert r.motion.speed_mm_s.max() == pytest.approx(5.0, rel=1e-9)
    diagonal = simulate(parse("G1 X10 Y10 F600"), slow, CONTROL)
    assert diagonal.motion.speed_mm_s.max() == pytest.approx(5.0 * math.sqrt(2.0), rel=1e-9)
    assert np.abs(diagonal.motion.vel_mm_s).max() == pytest.approx(5.0, rel=1e-9)


def test_position_loop_lags_by_f_over_kp():
    r = simulate(parse("G1 X10 F600"), MACHINE, CONTROL)
    # first-order loop at constant velocity: e = v / Kp = 10 / 80 mm
    assert r.following_error_mm[800, 0] == pytest.approx(10.0 / 80.0, rel=1e-6)


def test_inposition_measurement_is_seeded_and_z_is_slowest():
    a = measure_inposition_times(MACHINE, CONTROL, seed=3)
    b = measure_inposition_times(MACHINE, CONTROL, seed=3)
    np.testing.assert_array_equal(a.samples_s, b.samples_s)
    assert a.samples_s.shape == (3, 5)
    assert a.mean_s[2] > 3 * a.mean_s[0] > 0
    assert a.mean_s[0] == pytest.approx(a.mean_s[1])


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"cut_time_constant_s": 0.0505}, r"cut_time_constant_s = 0\.0505 is out of range"),
        ({"rapid_bell_s": 0.0305}, r"rapid_bell_s = 0\.0305 is out of range"),
    ],
)
def test_time_constants_must_be_whole_periods(changes, message):
    with pytest.raises(ValueError, match=message):
        simulate(parse("G1 X1 F60"), MACHINE, dataclasses.replace(CONTROL, **changes))


def test_bad_arguments_are_named():
    no_feed = dataclasses.replace(parse("G1 X1 F60"), feed_mm_s=np.array([np.nan]))
    with pytest.raises(ValueError, match="feed_mm_s = nan of block 0"):
        simulate(no_feed, MACHINE, CONTROL)
    with pytest.raises(ValueError, match="repeats = 0 is out of range"):
        measure_inposition_times(MACHINE, CONTROL, repeats=0)
    with pytest.raises(ValueError, match="rapid_type = 'curved'"):
        dataclasses.replace(CONTROL, rapid_type="curved")


segment = st.tuples(
    st.sampled_from(["G1", "G2", "G3"]),
    st.floats(-30, 30),
    st.floats(-30, 30),
    st.floats(-3, 3),
    st.integers(60, 6000),
)


def _program(segments) -> tuple[str, float]:
    """G-code of random lines and arcs (centre offset (a, b) / 3, sweep of a + b degrees * 6)."""
    lines, fmax = [], 0.0
    p = np.zeros(2)
    for g, a, b, z, f in segments:
        if g == "G1" or math.hypot(a, b) < 1.5:
            end = np.array([a, b])
            lines.append(f"G1 X{end[0]:.4f} Y{end[1]:.4f} Z{z:.4f} F{f}")
        else:
            off = np.array([a, b]) / 3.0
            c = p + off
            phi = math.atan2(-off[1], -off[0]) + math.radians(6 * (a + b))
            r = math.hypot(*off)
            end = c + r * np.array([math.cos(phi), math.sin(phi)])
            lines.append(
                f"{g} X{end[0]:.4f} Y{end[1]:.4f} Z{z:.4f} I{off[0]:.4f} J{off[1]:.4f} F{f}"
            )
        p = np.round(end, 4)
        fmax = max(fmax, f / 60.0)
    return "\n".join(lines), fmax


@given(st.lists(segment, min_size=1, max_size=6), st.sampled_from([0.01, 0.05, 0.1]))
def test_kernel_ends_at_the_program_end_and_never_exceeds_f(segments, at_s):
    text, fmax = _program(segments)
    tp = parse(text)
    c = dataclasses.replace(CONTROL, cut_time_constant_s=at_s)
    motion = run(tp, MACHINE, c)
    np.testing.assert_allclose(motion.pos_mm[-1], tp.end_mm[-1], atol=1e-6)
    assert np.all(np.isfinite(motion.pos_mm))
    # arcs written with 4 decimals have start and end radii that differ by up to 1e-4 mm; the
    # kernel moves along that spiral at F over the arc's nominal length, hence the 1e-4 slack
    assert motion.speed_mm_s.max() <= fmax * (1 + 1e-4)


def test_servo_is_the_packages_one_position_loop():
    # the kernel's following error is what nctwin.physics.servo.PositionLoop makes of the
    # command: X with Kp 80, Z with Kp 35, through a rapid, its in-position wait and a line
    r = simulate(parse("G0 X30 Z-20\nG1 X40 Y5 F1200"), MACHINE, CONTROL)
    cmd = r.motion.pos_mm
    for axis, kp in enumerate(CONTROL.position_gain_per_s):
        actual = PositionLoop("first_order_ff", kp).follow(cmd[:, axis], TI)
        np.testing.assert_allclose(r.following_error_mm[:, axis], cmd[:, axis] - actual,
                                   atol=1e-12)  # fmt: skip
