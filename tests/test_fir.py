"""The FIR kernel against physics derived by hand (see nctwin.kernel.fir)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin import parse
from nctwin.controls import FirControl
from nctwin.kernel import _fir_command, fir
from nctwin.machine import Machine
from nctwin.targets import block_targets

MACHINE = Machine(
    name="fir-test",
    description="round numbers, limits far from the tests' feeds",
    axis_max_velocity_mm_s=(1000.0, 1000.0, 1000.0),
    axis_max_acceleration_mm_s2=(1e5, 1e5, 1e5),
    axis_max_jerk_mm_s3=(1e9, 1e9, 1e9),
    rapid_feed_mm_s=500.0,
    max_feed_mm_s=1000.0,
)
SETTINGS = FirControl(period_s=0.001, blend_tol_mm=0.05, t1_s=0.05, t2_s=0.01)
FILTER = fir.FirFilter.of(SETTINGS)
PERIOD_S = SETTINGS.period_s


def _corner_distance(pos: np.ndarray, corner) -> float:
    """Distance from a point to the polyline through the samples."""
    a, b = pos[:-1], pos[1:]
    ab = b - a
    t = np.einsum("ij,ij->i", corner - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    closest = a + np.clip(t, 0, 1)[:, None] * ab
    return float(np.linalg.norm(closest - corner, axis=1).min())


def test_straight_line_takes_l_over_f_plus_t1_plus_t2():
    feed, length = 80.0, 120.0
    motion = fir.run(parse(f"G1 X{length} F{feed * 60}"), MACHINE, SETTINGS)
    expected = length / feed + SETTINGS.t1_s + SETTINGS.t2_s
    assert motion.cycle_time_s == pytest.approx(expected, abs=PERIOD_S)
    np.testing.assert_array_equal(motion.pos_mm[0], [0, 0, 0])
    np.testing.assert_array_equal(motion.pos_mm[-1], [length, 0, 0])
    assert motion.speed_mm_s.max() == pytest.approx(feed, rel=1e-9)
    # acceleration F / T1 and jerk F / (T1 T2), within the rounding of differences
    acc = np.abs(motion.acc_mm_s2[:, 0]).max()
    jerk = np.abs(motion.jerk_mm_s3[:, 0]).max()
    assert acc <= feed / SETTINGS.t1_s * (1 + 1e-6)
    assert acc == pytest.approx(feed / (SETTINGS.t1_s + PERIOD_S), rel=1e-6)
    assert jerk <= feed / (SETTINGS.t1_s * SETTINGS.t2_s) * (1 + 1e-6)


def test_filter_taps_span_the_time_constants():
    n1, n2 = FILTER.taps
    assert (n1, n2) == (51, 11)
    assert FILTER.weights.sum() == pytest.approx(1.0)
    assert FILTER.length_s == pytest.approx(SETTINGS.t1_s + SETTINGS.t2_s)


@pytest.mark.parametrize("t2_s", [0.0, 0.01])
def test_filter_is_the_convolution_with_its_weights(t2_s):
    # running sums in reused buffers against a direct convolution of the held input
    flt = fir.FirFilter(0.05, t2_s, 0.001)
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(size=(3, 700)), axis=1) + np.array([[5.0], [-3.0], [100.0]])
    w = flt.weights
    held = np.concatenate(
        [np.repeat(x[:, :1], len(w) - 1, 1), x, np.repeat(x[:, -1:], len(w), 1)], 1
    )
    expected = np.array([np.convolve(row, w, mode="valid") for row in held])[
        :, : x.shape[1] + len(w) - 1
    ]
    out = flt.apply(x)
    assert out.shape == expected.shape
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 300))
def test_unique_with_index_equals_unique_and_searchsorted(seed, n):
    rng = np.random.default_rng(seed)
    x = np.round(rng.uniform(0, 50, n), int(rng.integers(0, 3)))  # repeated values
    x[: n // 2].sort()  # a sorted run, as the command's block starts
    cuts, index = _fir_command._unique_with_index(x)
    np.testing.assert_array_equal(cuts, np.unique(x))
    np.testing.assert_array_equal(index, np.searchsorted(cuts, x))


def test_corner_without_reduction_matches_the_closed_form():
    # tolerance far above the deviation: the corner is passed at the programmed feed
    feed = 40.0
    tp = parse(f"G64 P5 G1 X50 F{feed * 60}\nY50")
    assert fir.plan(tp, MACHINE, SETTINGS).junction_mm_s[1] == pytest.approx(feed)
    d = _corner_distance(fir.run(tp, MACHINE, SETTINGS).pos_mm, np.array([50.0, 0, 0]))
    # the sampled boxes average n = T/Ts + 1 samples: their continuous twins are n Ts long
    n1, n2 = FILTER.taps
    ts = PERIOD_S
    closed = fir.corner_deviation_mm(feed, math.pi / 2, n1 * ts, n2 * ts)
    assert d == pytest.approx(closed, rel=2e-3)
    assert closed == pytest.approx(
        feed * math.sin(math.pi / 4) * (3 * (n1 * ts) ** 2 + (n2 * ts) ** 2) / (12 * n1 * ts)
    )


@pytest.mark.parametrize("angle_deg", [45.0, 90.0, 135.0])
def test_reduced_corner_is_within_tolerance_at_the_highest_feed(angle_deg):
    tol, feed = 0.05, 100.0
    a = math.radians(angle_deg)
    corner = np.array([50.0, 0.0, 0.0])
    end = corner + 50.0 * np.array([math.cos(a), math.sin(a), 0.0])
    program = f"G1 X50 F{feed * 60}\nX{end[0]:.9f} Y{end[1]:.9f}"
    tp = parse(f"G64 P{tol}\n{program}")
    v = fir.plan(tp, MACHINE, SETTINGS).junction_mm_s[1]
    assert 0 < v < feed  # reduced
    assert _corner_distance(fir.run(tp, MACHINE, SETTINGS).pos_mm, corner) <= tol
    # one percent faster through the same corner breaks the tolerance
    faster = parse(f"G64 P5\nG1 X50 F{v * 1.01 * 60}\nX{end[0]:.9f} Y{end[1]:.9f}")
    assert _corner_distance(fir.run(faster, MACHINE, SETTINGS).pos_mm, corner) > tol


def test_exact_stop_and_dwell():
    tp = parse("G61 G1 X10 F600\nY10\nG4 P0.5\nX0")
    motion = fir.run(tp, MACHINE, SETTINGS)
    stops = np.flatnonzero(motion.speed_mm_s == 0)
    # the tool stands still at the corner (G61) and for the dwell
    at_corner = np.linalg.norm(motion.pos_mm - [10, 0, 0], axis=1) < 1e-9
    assert at_corner.any() and (motion.speed_mm_s[at_corner][1:] == 0).all()
    dwell = np.linalg.norm(motion.pos_mm - [10, 10, 0], axis=1) < 1e-9
    assert dwell.sum() * PERIOD_S >= 0.5
    assert len(stops) > 0
    targets = block_targets(motion, tp)
    assert targets.time_s[2] == pytest.approx(0.5, abs=2 * PERIOD_S)
    assert targets.cycle_time_s == pytest.approx(motion.cycle_time_s)


def test_exact_stop_arc_runs_at_its_feed():
    # G61 stops at every block end; along the arc the filter's shrinkage keeps to the control's
    # tolerance (not 0). Half circle r 5 at 40 mm/s between two 10 mm lines, each block from rest
    # to rest: sum(L / F) + 3 (T1 + T2). Shrink limit sqrt(2 r tol / var) = 47 mm/s > 40.
    motion = fir.run(parse("G61 G1 X10 F2400\nG2 X20 Y0 I5 J0\nG1 X30"), MACHINE, SETTINGS)
    expected = (20.0 + math.pi * 5.0) / 40.0 + 3 * (SETTINGS.t1_s + SETTINGS.t2_s)
    assert motion.cycle_time_s == pytest.approx(expected, abs=3 * PERIOD_S)


RAMP_MACHINE = dataclasses.replace(MACHINE, axis_max_acceleration_mm_s2=(2000.0, 2000.0, 2000.0))


def test_rapid_capped_at_the_filters_step_unless_ramped():
    # the step the filters allow: A T1 = 2000 * 0.05 = 100 mm/s; capped, 300 mm take 3 s + T1 + T2
    capped = fir.run(parse("G0 X300"), RAMP_MACHINE, SETTINGS)
    assert capped.cycle_time_s == pytest.approx(3.0 + 0.06, abs=PERIOD_S)
    # ramped: stairs of 100 mm/s, each held one box (T1 + Ts = 51 ms): up 100-400 and down over
    # 2 * 1000 mm/s * 0.051 s = 102 mm, 198 mm at G0's 500 mm/s; 8 stairs + 0.396 s + T1 + T2
    ramped = fir.run(parse("G0 X300"), RAMP_MACHINE, dataclasses.replace(SETTINGS, rapid_ramp=True))
    assert ramped.cycle_time_s == pytest.approx(8 * 0.051 + 198 / 500 + 0.06, abs=PERIOD_S)
    assert ramped.speed_mm_s.max() == pytest.approx(500.0)
    acc = np.abs(np.diff(ramped.speed_mm_s)) / PERIOD_S
    assert acc.max() <= 2000.0
    # a short rapid never reaches G0: 100 mm/s for 5.1 mm at both ends, 200 mm/s between
    short = fir.run(parse("G0 X20"), RAMP_MACHINE, dataclasses.replace(SETTINGS, rapid_ramp=True))
    assert short.cycle_time_s == pytest.approx(2 * 0.051 + 9.8 / 200 + 0.06, abs=PERIOD_S)
    with pytest.raises(ValueError, match="rapid_ramp = 1 is out of range"):
        dataclasses.replace(SETTINGS, rapid_ramp=1)


def test_many_ramped_rapids_each_climb_their_stairs():
    # G61: every block from rest to rest. Each 300 mm rapid as the one above (8 stairs, 198 mm at
    # 500 mm/s, T1 + T2), each 1 mm G1 at 10 mm/s in 0.1 s + T1 + T2: all 120 blocks alike
    n = 60
    tp = parse("G61\n" + "\n".join(f"G0 X{300 * (k + 1)}\nG1 Y{k + 1} F600" for k in range(n)))
    motion = fir.run(tp, RAMP_MACHINE, dataclasses.replace(SETTINGS, rapid_ramp=True))
    times = block_targets(motion, tp).time_s
    np.testing.assert_allclose(times[0::2], 8 * 0.051 + 198 / 500 + 0.06, atol=PERIOD_S)
    np.testing.assert_allclose(times[1::2], 0.1 + 0.06, atol=PERIOD_S)


def _command_of_two_moves() -> _fir_command._Command:
    """10 mm at 1000 mm/s, a 5 ms pause in block 1, 20 mm at 2000 mm/s in block 2."""
    return _fir_command._Command(
        cuts=np.array([0.0, 10.0, 30.0]),
        speed=np.array([1000.0, 2000.0]),
        block=np.array([0, 2]),
        pause=np.array([0.0, 0.005, 0.0]),
        pause_block=np.array([-1, 1, -1]),
    )


def test_a_leading_dwell_leaves_the_end_in_the_last_block():
    # the samples after the last move stay in its block, with or without a dwell first
    for text in ("G1 X10 F600\nY10", "G4 P0.25\nG1 X10 F600\nY10"):
        tp = parse(text)
        block = fir.run(tp, MACHINE, SETTINGS).block
        assert (np.diff(block) >= 0).all() and block[-1] == len(tp) - 1
    targets = block_targets(fir.run(tp, MACHINE, SETTINGS), tp)
    assert targets.time_s[0] == pytest.approx(0.25, abs=PERIOD_S)


def test_command_knot_times_and_sample_blocks():
    cmd = _command_of_two_moves()
    # arrival at and departure from each cut: 10 ms, the pause, 10 ms
    np.testing.assert_allclose(cmd.knot_times(), [0, 0, 0.01, 0.015, 0.025, 0.025], atol=1e-15)
    halved = cmd.knot_times(np.array([0.5, 1.0]))
    np.testing.assert_allclose(halved, [0, 0, 0.02, 0.025, 0.035, 0.035], atol=1e-15)
    # two samples late: the first move owns samples 0-11, the pause 12-16, the second move
    # 17-26, the last (unowned) pause takes the last move's
    kept = np.array([3, 5, 7])
    expected = np.repeat([3, 5, 7, 7], [12, 5, 10, 3])
    t_knots = cmd.knot_times()
    np.testing.assert_array_equal(cmd.sample_blocks(t_knots, PERIOD_S, 2, kept, 0, 30), expected)
    np.testing.assert_array_equal(
        cmd.sample_blocks(t_knots, PERIOD_S, 2, kept, 13, 10), expected[13:23]
    )


def test_short_segments_on_a_circle_keep_the_feed_high():
    # 1000 segments of 0.1 mm on a circle of radius 20 mm: blended globally
    r, n, feed = 20.0, 1000, 80.0
    phi = np.arange(1, n + 1) * (0.1 / r)
    pts = np.column_stack([r * np.cos(phi), r * np.sin(phi)])
    program = f"G64 P0.05\nG0 X{r} Y0\nF{feed * 60}\n" + "\n".join(
        f"G1 X{x:.6f} Y{y:.6f}" for x, y in pts
    )
    tp = parse(program)
    motion = fir.run(tp, MACHINE, SETTINGS)
    middle = (motion.block > 200) & (motion.block < 800)
    assert np.median(motion.speed_mm_s[middle]) >= 0.95 * feed
    assert motion.speed_mm_s[middle].min() >= 0.9 * feed


def test_zigzag_dips_at_every_corner():
    # 1000 segments of 2 mm turning by 120 degrees each, alternately left and right
    n, feed, seg = 1000, 80.0, 2.0
    heading = np.where(np.arange(n) % 2 == 0, math.radians(60), math.radians(-60))
    pts = np.cumsum(seg * np.column_stack([np.cos(heading), np.sin(heading)]), axis=0)
    tp = parse(
        "G64 P0.05\nF%g\n" % (feed * 60) + "\n".join(f"G1 X{x:.6f} Y{y:.6f}" for x, y in pts)
    )
    plan = fir.plan(tp, MACHINE, SETTINGS)
    assert (plan.junction_mm_s[1:n] < 0.5 * feed).all()
    motion = fir.run(tp, MACHINE, SETTINGS)
    targets = block_targets(motion, tp)
    at_corners = motion.speed_mm_s[targets.junction_sample[1:n]]
    assert (at_corners < 0.5 * feed).all()


def test_kernel_cycle_time_exceeds_cam():
    tp = parse("G1 X10 F6000\nY10\nX0\nY0")
    motion = fir.run(tp, MACHINE, SETTINGS)
    assert motion.cycle_time_s > 40.0 / 100.0 + FILTER.length_s


def test_bad_filter_constants_are_named():
    with pytest.raises(ValueError, match=r"t1_s = 0.0 is out of range: allowed \[period_s, 10\]"):
        FirControl(t1_s=0.0, t2_s=0.0)
    with pytest.raises(ValueError, match=r"t1_s = 0.0 is out of range: allowed \[0.001, 10\]"):
        fir.FirFilter(0.0, 0.0, 0.001)


# ------------------------------------------------------------------------------ properties
LIMITED = dataclasses.replace(
    MACHINE,
    axis_max_velocity_mm_s=(150.0, 120.0, 60.0),
    axis_max_acceleration_mm_s2=(2000.0, 1500.0, 1000.0),
    axis_max_jerk_mm_s3=(2e5, 1.5e5, 1e5),
    rapid_feed_mm_s=300.0,
    max_feed_mm_s=200.0,
)

_xyz = st.tuples(*(st.floats(-30, 30) for _ in range(3)))


@st.composite
def programs(draw) -> str:
    lines = [f"G64 P{draw(st.sampled_from([0.005, 0.05, 0.5, 3.0]))}"]
    scale = draw(st.sampled_from([0.02, 1.0, 10.0]))
    for _ in range(draw(st.integers(1, 30))):
        x, y, z = (v * scale / 10 for v in draw(_xyz))
        code = draw(st.sampled_from(["G1", "G1", "G0", "G4"]))
        if code == "G4":
            lines.append(f"G4 P{draw(st.floats(0, 0.2)):.3f}")
        else:
            lines.append(f"{code} X{x:.4f} Y{y:.4f} Z{z / 3:.4f} F{draw(st.integers(60, 15000))}")
    return "\n".join(lines)


@settings(max_examples=60, deadline=None)
@given(programs())
def test_kernel_invariants(program):
    tp = parse(program)
    motion = fir.run(tp, LIMITED, SETTINGS)
    np.testing.assert_array_equal(motion.pos_mm[-1], tp.end_mm[-1])
    np.testing.assert_array_equal(motion.pos_mm[0], tp.start_mm[0])
    assert np.isfinite(motion.pos_mm).all()
    # never faster than the fastest commanded feed (rapids at the rapid feed)
    top = max(LIMITED.rapid_feed_mm_s, np.nanmax(np.append(tp.feed_mm_s, 0)))
    assert motion.speed_mm_s.max() <= top * (1 + 1e-9)
    # no axis beyond its velocity, acceleration or jerk limit
    for derivative, limit in (
        (motion.vel_mm_s, LIMITED.axis_max_velocity_mm_s),
        (motion.acc_mm_s2, LIMITED.axis_max_acceleration_mm_s2),
        (motion.jerk_mm_s3, LIMITED.axis_max_jerk_mm_s3),
    ):
        assert (np.abs(derivative).max(axis=0) <= np.asarray(limit) * (1 + 1e-5)).all()
    # the per-block times add up to the cycle time (Chien et al. eq. 3)
    assert block_targets(motion, tp).cycle_time_s == pytest.approx(motion.cycle_time_s)


def test_arc_feed_is_limited_by_centripetal_acceleration():
    # r = 5 mm, A = 2000 mm/s^2 on X and Y: at most sqrt(A r) = 100 mm/s on the arc
    tight = dataclasses.replace(MACHINE, axis_max_acceleration_mm_s2=(2000.0, 2000.0, 2000.0))
    loose = dataclasses.replace(SETTINGS, blend_tol_mm=10.0)
    tp = parse("G0 X5 Y0\nG3 X5 Y0 I-5 J0 F30000")
    v_arc = math.sqrt(2000.0 * 5.0)
    assert fir.plan(tp, tight, loose).feed_mm_s[1] == pytest.approx(v_arc)
    motion = fir.run(tp, tight, loose)
    on_arc = motion.block == 1
    assert motion.speed_mm_s[on_arc].max() <= v_arc * (1 + 1e-9)
    # the tool stays on the circle within the filter's shrinkage
    r = np.hypot(motion.pos_mm[on_arc, 0], motion.pos_mm[on_arc, 1])
    shrink = v_arc**2 * FILTER.variance_s2 / (2 * 5.0)
    assert np.abs(r - 5.0).max() <= 2 * shrink + 1e-6
