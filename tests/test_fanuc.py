"""The time-domain Fanuc-like control against times, speeds and errors computed by hand."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_accdec import MACHINE

from nctwin.controls import FanucControl
from nctwin.gcode import parse
from nctwin.kernel.fanuc import (
    PAPER_SET_1,
    PAPER_SET_2,
    measure_inposition_times,
    run,
    simulate,
)
from nctwin.machine import Profile, load_profile
from nctwin.motion import Motion
from nctwin.paths import data_dir
from nctwin.toolpath import MotionKind, Toolpath

TI = 0.001
FR = 10000.0 / 60.0  # the paper's rapid feed, mm/s
A_RAPID = FR / 0.15  # rapid acceleration of set 1, mm/s^2

# the paper's rapid feed; the kernel reads rapid_feed_mm_s, max_feed_mm_s and the axis velocities
# of the machine, every control parameter is in FanucControl
assert MACHINE.rapid_feed_mm_s == MACHINE.max_feed_mm_s == FR


def sim(text: str, **changes):
    return simulate(parse(text), MACHINE, dataclasses.replace(PAPER_SET_1, **changes))


def command_speed(r) -> np.ndarray:
    """Speed of the command after acc/dec, per period (n - 1,)."""
    return np.linalg.norm(np.diff(r.command_mm, axis=0), axis=1) / TI


# ------------------------------------------------------------------------- cutting feed
def test_long_line_takes_l_over_f_plus_t_then_settles():
    # 10 mm at 10 mm/s: 1000 periods of interpolation, then the moving average of 50 periods
    # lets the command run 49 more (l/F + T within one period)
    r = sim("G1 X10 F600")
    assert r.command_end_s[0] == pytest.approx(1.0 + 0.05 - TI, abs=1e-12)
    speed = command_speed(r)
    assert speed.max() == pytest.approx(10.0, rel=1e-12)
    assert speed[24] == pytest.approx(10.0 * 25 / 50, rel=1e-12)  # ramp: F k / K
    # then the servo settles into the in-position width: the cycle ends later by that wait
    assert r.inposition_wait_s[0] > 0
    assert r.cycle_time_s == pytest.approx(r.command_end_s[0] + r.inposition_wait_s[0])
    np.testing.assert_allclose(r.command_mm[-1], [10.0, 0.0, 0.0], atol=1e-12)
    assert abs(r.motion.pos_mm[-1, 0] - 10.0) <= PAPER_SET_1.inposition_width_mm[0]


def test_set_2_time_constant():
    r = simulate(parse("G1 X10 F600"), MACHINE, PAPER_SET_2)
    assert r.command_end_s[0] == pytest.approx(1.0 + 0.1 - TI, abs=1e-12)


def test_exponential_tail_ends_below_one_increment():
    # steady state: F T = 0.5 mm inside the filter; after the input stops it decays by
    # exp(-TI / T) per period and is flushed once below 1 um
    r = sim("G1 X10 F600", cut_accdec="exponential")
    tail = math.ceil(math.log(10.0 * 0.05 / 0.001) / (TI / 0.05))
    assert r.command_end_s[0] == pytest.approx(1.0 + tail * TI, abs=1e-12)
    speed = command_speed(r)
    # the rise: 1 - exp(-t / T) of the feed, exactly (sample k covers t in ((k-1) TI, k TI])
    k = 50
    rise = 10.0 * (1 - 0.05 / TI * (1 - math.exp(-TI / 0.05)) * math.exp(-(k - 1) * TI / 0.05))
    assert speed[k - 1] == pytest.approx(rise, rel=1e-9)
    np.testing.assert_allclose(r.command_mm[-1], [10.0, 0.0, 0.0], atol=1e-12)


def test_bell_takes_the_same_time_with_twice_the_peak_acceleration():
    lin, bell = sim("G1 X10 F600"), sim("G1 X10 F600", cut_accdec="bell")
    # two boxes of 25 periods: 1000 + 24 + 24 periods
    assert bell.command_end_s[0] == pytest.approx(1.0 + 0.048, abs=1e-12)
    acc_lin = np.diff(command_speed(lin)) / TI
    acc_bell = np.diff(command_speed(bell)) / TI
    assert acc_lin.max() == pytest.approx(10.0 / 0.05, rel=1e-9)
    assert acc_bell.max() == pytest.approx(2 * 10.0 / 0.05, rel=1e-9)
    # S-shaped: the acceleration ramps up instead of jumping
    assert acc_bell[0] < 0.1 * acc_bell.max()


def test_consecutive_blocks_overlap_and_corners_are_rounded():
    r = sim("G1 X10 F600\nG1 X20")
    assert r.command_end_s[1] == pytest.approx(2.0 + 0.05 - TI, abs=1e-12)
    assert np.isnan(r.command_end_s[0])  # no stop between the two
    assert command_speed(r)[60:1990].min() == pytest.approx(10.0, rel=1e-9)
    c = sim("G1 X10 F600\nG1 Y10")
    vel = np.diff(c.command_mm, axis=0) / TI
    # 25 ms after the corner both axes move at half the feed (block overlap, Fig. 6)
    np.testing.assert_allclose(vel[1024, :2], [5.0, 5.0], rtol=1e-9)
    # the corner is cut: the command passes inside it
    assert np.hypot(c.command_mm[:, 0] - 10.0, c.command_mm[:, 1]).min() > 0.05


def test_arc_feed_is_clamped_to_sqrt_a_r():
    # full circle of R = 2 mm at F = 50 mm/s: clamp sqrt(200 * 2) = 20 mm/s
    r = sim("G17 G2 X0 Y0 I2 J0 F3000")
    assert r.block_feed_mm_s[0] == pytest.approx(20.0, rel=1e-12)
    # mid-arc the moving average of K chords, each turned by phi, has the speed
    # 2 R sin(phi / 2) / TI * sin(K phi / 2) / (K sin(phi / 2))
    k, phi = 50, 20.0 * TI / 2.0
    expect = 2.0 * 2.0 / TI * math.sin(k * phi / 2) / k
    np.testing.assert_allclose(command_speed(r)[100:500], expect, rtol=1e-9)
    # with the clamp off the feed is the programmed one
    free = sim("G17 G2 X0 Y0 I2 J0 F3000", arc_radial_acc_mm_s2=math.inf)
    assert free.block_feed_mm_s[0] == pytest.approx(50.0)
    assert free.cycle_time_s < r.cycle_time_s


def test_short_blocks_run_at_l_over_block_time():
    # 100 blocks of 0.05 mm at F = 50 mm/s; 4 ms per block caps them at 12.5 mm/s
    r = sim("G91 G1 X0.05 F3000\n" + "X0.05\n" * 99)
    np.testing.assert_allclose(r.block_feed_mm_s, 12.5, rtol=1e-12)
    assert r.command_end_s[-1] == pytest.approx(100 * 0.004 + 0.05 - TI, abs=1e-12)
    np.testing.assert_allclose(command_speed(r)[60:390], 12.5, rtol=1e-9)
    assert sim("G91 G1 X0.05 F3000\n" + "X0.05\n" * 99, block_time_s=0.0).cycle_time_s < (
        r.cycle_time_s
    )


def test_feed_is_clamped_to_what_the_axis_velocities_allow():
    # X and Y at most 5 mm/s: along X at F600 (10 mm/s) the block runs at 5 mm/s; at 45 degrees
    # in XY each axis moves at 1/sqrt(2) of the path speed, so the path runs at 5 sqrt(2) mm/s
    slow = dataclasses.replace(MACHINE, axis_max_velocity_mm_s=(5.0, 5.0, 200.0))
    r = simulate(parse("G1 X10 F600\nG1 X20 Y10"), slow, PAPER_SET_1)
    np.testing.assert_allclose(r.block_feed_mm_s, [5.0, 5.0 * math.sqrt(2.0)], rtol=1e-12)
    assert np.abs(np.diff(r.command_mm, axis=0)).max() / TI <= 5.0 * (1 + 1e-9)
    # the paper's machine allows more than the feed: the programmed F
    assert sim("G1 X10 F600").block_feed_mm_s[0] == 10.0


def test_feed_never_exceeds_f():
    text = "G1 X20 F1200\nY15\nG3 X10 Y25 R10\nG1 X-5 Y5\nG2 X0 Y0 I2.5 J-2.5\nG1 Z-3"
    r = sim(text)
    assert r.motion.speed_mm_s.max() <= 20.0 * (1 + 1e-9)
    assert command_speed(r).max() <= 20.0 * (1 + 1e-9)
    np.testing.assert_allclose(r.command_mm[-1], [0.0, 0.0, -3.0], atol=1e-9)


# ------------------------------------------------------------------------------- rapids
def test_long_rapid_takes_l_over_fr_plus_atr_plus_as():
    # within a few periods: the planner's discrete ramps and the bell's moving average of K
    # periods (it adds K - 1) each end a period early
    r = sim("G0 X100")
    assert r.command_end_s[0] == pytest.approx(100.0 / FR + 0.15 + 0.03, abs=3 * TI)
    assert command_speed(r).max() == pytest.approx(FR, rel=1e-9)
    assert r.inposition_wait_s[0] > 0
    assert r.cycle_time_s == pytest.approx(r.command_end_s[0] + r.inposition_wait_s[0])


def test_short_rapid_is_its_interpolation_smoothed_over_the_time_constant():
    # acc/dec after interpolation: 5 mm are interpolated at Fr in 30 periods, and the moving
    # average over ATR spreads them over 30 + 150 - 1 periods, never reaching Fr: a flat top at
    # l / ATR (the paper's eq. 9-12 price it as a triangle at Fr / ATR, 134 ms: shorter)
    r = sim("G0 X5", rapid_bell_s=0.0)
    assert r.command_end_s[0] == pytest.approx(5.0 / FR + 0.15 - TI, abs=1e-12)
    assert command_speed(r).max() == pytest.approx(5.0 / 0.15, rel=1e-9)
    assert r.command_end_s[0] > 2 * math.sqrt(5.0 / A_RAPID)
    bell = sim("G0 X5")
    assert bell.command_end_s[0] == pytest.approx(r.command_end_s[0] + 0.03 - TI, abs=1e-12)


def test_nonlinear_rapid_moves_each_axis_on_its_own():
    lin = sim("G0 X100 Y10")
    non = sim("G0 X100 Y10", rapid_type="nonlinear")
    assert lin.command_end_s[0] == pytest.approx(math.hypot(100, 10) / FR + 0.18, abs=3 * TI)
    assert non.command_end_s[0] == pytest.approx(100.0 / FR + 0.18, abs=3 * TI)
    off_line = np.abs(non.command_mm[:, 1] - 0.1 * non.command_mm[:, 0])
    assert off_line.max() > 5.0  # Y is done long before X: a dog-leg (Fig. 3)
    assert np.abs(lin.command_mm[:, 1] - 0.1 * lin.command_mm[:, 0]).max() < 1e-9


def test_rapid_overlap_joins_consecutive_rapids():
    off = sim("G0 X100\nG0 X200")
    on = sim("G0 X100\nG0 X200", rapid_overlap=True, rapid_overlap_percent=100.0)
    # off: two rapids with an in-position wait between them
    assert off.inposition_wait_s[0] > 0
    assert off.command_end_s[1] == pytest.approx(
        2 * off.command_end_s[0] + off.inposition_wait_s[0], abs=2 * TI
    )
    # on at 100 %: the second accelerates while the first brakes: one 200 mm rapid
    assert np.isnan(on.command_end_s[0]) and on.inposition_wait_s[0] == 0
    assert on.command_end_s[1] == pytest.approx(200.0 / FR + 0.18, abs=3 * TI)
    assert command_speed(on)[200:1150].min() == pytest.approx(FR, rel=1e-6)
    half = sim("G0 X100\nG0 X200", rapid_overlap=True)
    assert on.cycle_time_s < half.cycle_time_s < off.cycle_time_s


# ------------------------------------------------------------------------ servo, in-position
def test_inposition_wait_is_the_first_order_decay_into_the_width():
    # with FF = 0, once the command stops the error decays as e0 exp(-Kp t): the wait is the
    # first whole period with |e0| exp(-Kp t) <= width
    r = sim("G0 X100")
    i_end = round(r.command_end_s[0] / TI)
    e0 = r.following_error_mm[i_end, 0]
    kp, width = 50.0, 0.02
    periods = math.ceil(math.log(e0 / width) / (kp * TI))
    assert r.inposition_wait_s[0] == pytest.approx(periods * TI, abs=1e-12)
    decay = r.following_error_mm[i_end : i_end + periods + 1, 0]
    np.testing.assert_allclose(decay, e0 * np.exp(-kp * TI * np.arange(periods + 1)), rtol=1e-9)


def test_following_error_at_constant_feed():
    # first order, FF = 0: e = v / Kp; FF = 1: no lag; second order: e = 2 zeta / wn v
    line = "G1 X20 F600"
    assert sim(line).following_error_mm[1000, 0] == pytest.approx(10.0 / 50.0, rel=1e-6)
    assert abs(sim(line, feedforward=1.0).following_error_mm[1000, 0]) < 1e-9
    second = sim(line, servo="second_order")
    wn = 2 * math.pi * 11.0
    assert second.following_error_mm[1000, 0] == pytest.approx(2 * 0.7 / wn * 10.0, rel=1e-6)
    # underdamped: the measured position overshoots the end of a rapid (the dwell lets it be
    # seen after the in-position check), first order does not
    rap2 = sim("G0 X100\nG4 P1", servo="second_order")
    assert rap2.motion.pos_mm[:, 0].max() > 100.0 + 0.01
    assert sim("G0 X100\nG4 P1").motion.pos_mm[:, 0].max() <= 100.0 + 1e-12


def test_measure_inposition_times():
    t = measure_inposition_times(MACHINE)
    assert t.shape == (3,)
    # equal gains and widths: equal times, and the long rapids' share dominates
    np.testing.assert_allclose(t, t[0], rtol=1e-12)
    assert 0.02 < t[0] < 0.1
    slow_z = dataclasses.replace(PAPER_SET_1, position_gain_per_s=(50.0, 50.0, 25.0))
    t2 = measure_inposition_times(MACHINE, slow_z)
    assert t2[2] > 2 * t2[0]
    assert t2[0] == pytest.approx(t[0])
    with pytest.raises(ValueError, match="distances_mm"):
        measure_inposition_times(MACHINE, distances_mm=(10.0, -1.0))


def test_exact_stop_stops_and_waits_at_every_block():
    blended = sim("G1 X10 F600\nG1 X20")
    exact = sim("G61\nG1 X10 F600\nG1 X20")
    assert exact.command_end_s[0] == pytest.approx(1.0 + 0.05 - TI, abs=1e-12)
    assert exact.inposition_wait_s[0] > 0
    start_2 = exact.command_end_s[0] + exact.inposition_wait_s[0]
    assert exact.command_end_s[1] == pytest.approx(start_2 + 1.05 - TI, abs=1e-12)
    assert exact.cycle_time_s > blended.cycle_time_s + 0.05


def test_dwell_and_block_times():
    r = sim("G1 X1 F600\nG4 P0.5\nG1 X2")
    assert r.block_times_s[1] == pytest.approx(0.5, abs=1e-12)
    assert r.block_times_s.sum() == pytest.approx(r.cycle_time_s, abs=1e-9)
    # the second line starts after the first has stopped and the dwell has passed
    assert r.command_end_s[2] == pytest.approx(r.command_end_s[0] + 0.5 + 0.1 + 0.049, abs=1e-9)


def test_the_interpolator_carries_the_period_remainder_from_block_to_block():
    # ten 1.05 mm lines at 100 mm/s are 10.5 periods each: interpolated as one stream they take
    # 105 periods, where rounding each block up (the paper's eq. 2) would give 110
    text = "G1 F6000 X1.05\n" + "\n".join(f"X{1.05 * k:.2f}" for k in range(2, 11))
    r = sim(text, block_time_s=0.0)
    assert r.command_end_s[-1] == pytest.approx((105 + 50 - 1) * TI, abs=1e-12)
    assert command_speed(r).max() == pytest.approx(100.0, rel=1e-9)
    assert r.command_mm[-1, 0] == pytest.approx(10.5, abs=1e-12)


# --------------------------------------------------------------------------- the whole run
def test_run_returns_the_measured_motion_and_is_deterministic():
    text = "G0 X5 Y5\nG1 Z-1 F300\nG1 X20 F1200\nG2 X30 Y15 R10\nG0 Z5"
    m1, m2 = run(parse(text), MACHINE), run(parse(text), MACHINE)
    assert isinstance(m1, Motion)
    assert m1.period_s == TI
    np.testing.assert_array_equal(m1.pos_mm, m2.pos_mm)
    np.testing.assert_array_equal(m1.block, m2.block)
    r = simulate(parse(text), MACHINE)
    np.testing.assert_array_equal(r.motion.pos_mm, m1.pos_mm)
    np.testing.assert_allclose(m1.vel_mm_s[1:], np.diff(m1.pos_mm, axis=0) / TI)
    assert np.all(np.diff(m1.block) >= 0)
    np.testing.assert_allclose(r.command_mm[-1], [30.0, 15.0, 5.0], atol=1e-9)


def test_empty_program():
    r = simulate(Toolpath.empty(), MACHINE)
    assert len(r.motion) == 1 and r.cycle_time_s == 0.0


_RANGE = "is out of range: allowed"
_WHOLE = ".* whole multiples of period_s"


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"cut_time_constant_s": -0.1}, rf"cut_time_constant_s = -0.1 {_RANGE} \(0, 10\]"),
        ({"rapid_time_constant_s": 0.0}, rf"rapid_time_constant_s = 0.0 {_RANGE} \(0, 10\]"),
        ({"cut_time_constant_s": 0.0505}, rf"cut_time_constant_s = 0.0505 {_WHOLE}"),
        ({"period_s": 0.004}, rf"cut_time_constant_s = 0.05 {_WHOLE} = 0.004"),
        ({"rapid_bell_s": 0.0305}, rf"rapid_bell_s = 0.0305 {_WHOLE}"),
        ({"cut_accdec": "bell", "cut_time_constant_s": 0.051}, r"even multiples"),
        ({"inposition_width_mm": (0.02, 0.0, 0.02)}, rf"inposition_width_mm\[Y\] = 0.0 {_RANGE}"),
        ({"inposition_width_mm": (0.02, 0.02)}, r"inposition_width_mm = .* three numbers"),
        ({"cut_accdec": "cubic"}, rf"cut_accdec = 'cubic' {_RANGE} 'linear', 'bell'"),
        ({"servo": "pid"}, r"servo = 'pid'"),
        ({"feedforward": 1.5}, rf"feedforward = 1.5 {_RANGE} \[0, 1\]"),
        ({"block_time_s": -0.001}, rf"block_time_s = -0.001 {_RANGE} \[0, 1\)"),
        ({"rapid_overlap": 1}, r"rapid_overlap = 1"),
        ({"period_s": 0.0}, rf"period_s = 0.0 {_RANGE} \(0, 0.1\]"),
    ],
)
def test_settings_are_checked(changes, message):
    with pytest.raises(ValueError, match=message):
        FanucControl(**changes)


def _one_block(kind: MotionKind, end, feed: float, start=(0.0, 0.0, 0.0)) -> Toolpath:
    nan = np.full(1, np.nan)
    z = np.zeros(1)
    return Toolpath(np.array([start], float), np.array([end], float), np.array([kind]),
                    np.array([feed]), np.full((1, 3), np.nan), z, z, z, z, nan, nan)  # fmt: skip


def test_programs_the_kernel_cannot_run():
    with pytest.raises(ValueError, match="needs a feed F > 0"):
        simulate(_one_block(MotionKind.LINEAR, (1.0, 0.0, 0.0), np.nan), MACHINE)
    a = _one_block(MotionKind.LINEAR, (1.0, 0.0, 0.0), 10.0)
    b = _one_block(MotionKind.LINEAR, (3.0, 0.0, 0.0), 10.0, start=(2.0, 0.0, 0.0))
    jump = Toolpath(**{f: np.concatenate([getattr(a, f), getattr(b, f)]) for f in (
        "start_mm", "end_mm", "kind", "feed_mm_s", "center_mm", "plane", "dwell_s", "line",
        "path_mode", "blend_tol_mm", "naive_tol_mm")})  # fmt: skip
    with pytest.raises(ValueError, match="continuous programs only"):
        simulate(jump, MACHINE)
    with pytest.raises(ValueError, match="non-finite position"):
        simulate(_one_block(MotionKind.RAPID, (np.inf, 0.0, 0.0), np.nan), MACHINE)


def test_exponential_and_overlap_runs_fit_any_capacity():
    # a long exponential tail and overlapped rapids: the output grows until the run fits
    r = sim("G0 X50\nG0 X0\nG1 X80 F9000\nG4 P0.1", cut_accdec="exponential", rapid_overlap=True)
    np.testing.assert_allclose(r.command_mm[-1], [80.0, 0.0, 0.0], atol=1e-9)
    assert r.block_times_s.sum() == pytest.approx(r.cycle_time_s)


# ------------------------------------------------------------------------- a property test
_point = st.tuples(*(st.floats(-40.0, 40.0, allow_nan=False) for _ in range(3)))


@st.composite
def programs(draw) -> str:
    """Short programs of G0, G1, G2/G3 (XY arcs by I, J) and G4, in absolute mm."""
    lines = []
    x, y = 0.0, 0.0
    for _ in range(draw(st.integers(1, 6))):
        kind = draw(st.sampled_from(["G0", "G1", "G2", "G3", "G4"]))
        feed = draw(st.floats(30.0, 6000.0))
        if kind == "G4":
            lines.append(f"G4 P{draw(st.floats(0.0, 0.05)):.3f}")
            continue
        px, py, pz = draw(_point)
        if kind in ("G2", "G3"):
            cx, cy = x + px / 4, y + py / 4
            radius = math.hypot(x - cx, y - cy)
            if radius < 0.01:
                continue
            theta = draw(st.floats(0.0, 2 * math.pi))
            ex, ey = cx + radius * math.cos(theta), cy + radius * math.sin(theta)
            lines.append(f"{kind} X{ex:.6f} Y{ey:.6f} Z{pz:.3f} I{cx - x:.6f} J{cy - y:.6f} "
                         f"F{feed:.1f}")  # fmt: skip
            x, y = ex, ey
        else:
            lines.append(f"{kind} X{px:.3f} Y{py:.3f} Z{pz:.3f} F{feed:.1f}")
            x, y = round(px, 3), round(py, 3)
    return "\n".join(lines) or "G4 P0"


@settings(max_examples=40, deadline=None)
@given(programs(), st.sampled_from(["linear", "bell", "exponential"]))
def test_random_programs_end_on_the_program_end(text, accdec):
    tp = parse(text)
    r = simulate(tp, MACHINE, dataclasses.replace(PAPER_SET_1, cut_accdec=accdec))
    assert np.isfinite(r.motion.pos_mm).all() and np.isfinite(r.motion.vel_mm_s).all()
    np.testing.assert_allclose(r.command_mm[-1], tp.end_mm[-1], atol=1e-6)
    miss = np.abs(r.motion.pos_mm[-1] - tp.end_mm[-1])
    assert (miss <= np.asarray(PAPER_SET_1.inposition_width_mm) + 1e-9).all()
    # acc/dec averages the interpolated steps: the command's path is no longer than the program
    travelled = np.linalg.norm(np.diff(r.command_mm, axis=0), axis=1).sum()
    assert travelled <= tp.length_mm + 1e-6
    assert r.block_times_s.sum() == pytest.approx(r.cycle_time_s, abs=1e-9)


def test_settings_load_from_the_profiles_table(tmp_path):
    assert load_profile("fanuc_0i_testbed").fanuc == PAPER_SET_1
    own = tmp_path / "own.toml"
    base = (data_dir() / "machines" / "fanuc_0i_testbed.toml").read_text()
    own.write_text(base.replace("block_time_s = 0.004", "block_time_s = 0.002"))
    assert Profile.from_toml(own).fanuc.block_time_s == 0.002
    where = rf"^{re.escape(str(own))}: \[control\.fanuc\] "
    own.write_text(base.replace("block_time_s = 0.004", "block_time_ms = 4"))
    with pytest.raises(ValueError, match=rf"{where}unknown key\(s\) block_time_ms;"):
        Profile.from_toml(own)
    own.write_text(base.replace("inposition_width_mm = [0.02", "inposition_width_mm = [0.0"))
    with pytest.raises(ValueError, match=rf"{where}inposition_width_mm\[X\] = 0\.0 is out of"):
        Profile.from_toml(own)
