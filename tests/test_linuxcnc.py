"""LinuxCNC as the measured machine (nctwin.kernel.linuxcnc).

The INI tests run everywhere; the live tests record short programs on LinuxCNC and are skipped
where it cannot run (``make linuxcnc`` installs it). Expected values are derived by hand: LinuxCNC
has no jerk limit, so a straight line from rest to rest with a trapezoidal feed profile takes
``L / F + F / A``.
"""

import dataclasses
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest

from nctwin.estimate import estimate
from nctwin.gcode import parse
from nctwin.kernel import linuxcnc as lc
from nctwin.machine import load_profile

PROFILE = load_profile("linuxcnc_sim")
MACHINE, PLANNER = PROFILE.machine, PROFILE.control("planner")
PERIOD_S = PLANNER.period_s
#: halsampler prints positions with 6 decimals (1 nm): speeds from differences carry up to
#: 2e-6 mm / 1 ms of rounding.
SPEED_ROUNDING_MM_S = 2e-6 / PERIOD_S

LINE = "G21 G90 G61\nG1 X60 F3000\nM2\n"  # 60 mm at 50 mm/s along X
CORNER = "G21 G90 G61\nG1 X30 F3000\nY20\nM2\n"  # exact stop at a 90 degree corner
BLENDED = "G21 G90 G64 P0.05\nG1 X20 F6000\nX30 Y5\nY20\nX0 Y0\nM2\n"

live = pytest.mark.usefixtures("linuxcnc_live")


def _ini_values(text: str) -> dict[tuple[str, str], str]:
    out, section = {}, ""
    for raw in text.splitlines():
        if raw.startswith("["):
            section = raw.strip("[]")
        elif "=" in raw and not raw.startswith("#"):
            key, value = (s.strip() for s in raw.split("=", 1))
            out[section, key] = value
    return out


def test_ini_holds_the_profile_limits():
    ini = _ini_values(lc.ini_text(MACHINE, PLANNER))
    for i, axis in enumerate("XYZ"):
        for section in (f"AXIS_{axis}", f"JOINT_{i}"):
            v = float(ini[section, "MAX_VELOCITY"])
            a = float(ini[section, "MAX_ACCELERATION"])
            assert v == MACHINE.axis_max_velocity_mm_s[i]
            assert a == MACHINE.axis_max_acceleration_mm_s2[i]
    assert float(ini["TRAJ", "MAX_LINEAR_VELOCITY"]) == 200.0 == MACHINE.max_feed_mm_s
    assert float(ini["TRAJ", "MAX_LINEAR_ACCELERATION"]) == 1000.0
    assert float(ini["TRAJ", "DEFAULT_LINEAR_VELOCITY"]) == 50.0
    assert ini["TRAJ", "NO_FORCE_HOMING"] == "1"
    assert ini["KINS", "KINEMATICS"] == "trivkins coordinates=XYZ"
    assert int(ini["EMCMOT", "SERVO_PERIOD"]) == 1_000_000
    # linuxcnc_sim's tolerance is inf: LinuxCNC runs the startup mode as a plain G64 anyway
    assert ini["RS274NGC", "RS274NGC_STARTUP_CODE"] == "G21 G90 G64"
    finite = dataclasses.replace(PLANNER, blend_tol_mm=0.0254)
    ini = _ini_values(lc.ini_text(MACHINE, finite))
    assert ini["RS274NGC", "RS274NGC_STARTUP_CODE"] == "G21 G90 G64 P0.0254 Q0"
    assert not any(key.startswith("ARC_BLEND") for _, key in ini)


def test_profile_linuxcnc_cannot_follow_is_rejected():
    from dataclasses import replace

    with pytest.raises(ValueError, match="axis_max_jerk_mm_s3"):
        lc.ini_text(replace(MACHINE, axis_max_jerk_mm_s3=(1e4, 1e4, 1e4)), PLANNER)
    with pytest.raises(ValueError, match="rapid_feed_mm_s"):
        lc.ini_text(replace(MACHINE, rapid_feed_mm_s=100.0), PLANNER)


@pytest.mark.parametrize(("kw", "name"), [({"speed": 50}, "speed"), ({"timeout_s": 0}, "timeout")])
def test_bad_run_arguments(kw, name):
    with pytest.raises(ValueError, match=name):
        lc.record(LINE, MACHINE, PLANNER, **kw)


def test_program_without_motion_needs_no_linuxcnc():
    m = lc.run("G21 G90\nG1 X0 F600\nM2\n", MACHINE, PLANNER)
    assert len(m) == 1 and m.cycle_time_s == 0.0
    np.testing.assert_array_equal(m.pos_mm, [[0.0, 0.0, 0.0]])


@live
def test_straight_line_duration_end_and_feed():
    m = lc.run(LINE, MACHINE, PLANNER)
    length_mm, feed_mm_s, acc_mm_s2 = 60.0, 50.0, 1000.0
    expected_s = length_mm / feed_mm_s + feed_mm_s / acc_mm_s2  # 1.25 s
    assert abs(m.cycle_time_s - expected_s) <= 3 * PERIOD_S
    np.testing.assert_array_equal(m.pos_mm[-1], [60.0, 0.0, 0.0])
    np.testing.assert_array_equal(m.pos_mm[0], [0.0, 0.0, 0.0])
    assert m.speed_mm_s.max() <= feed_mm_s + SPEED_ROUNDING_MM_S
    # cruise at F, reached after F / A
    assert m.speed_mm_s.max() >= feed_mm_s - SPEED_ROUNDING_MM_S
    acc_rounding_mm_s2 = SPEED_ROUNDING_MM_S / PERIOD_S
    assert np.abs(m.acc_mm_s2[:, 0]).max() <= acc_mm_s2 * (1 + 1e-6) + acc_rounding_mm_s2
    assert (m.block == 0).all()


@live
def test_trace_does_not_depend_on_wall_clock_time():
    """Blended corners need the planner's look-ahead: x1 equals x5, bit for bit."""
    fast = lc.run(BLENDED, MACHINE, PLANNER, speed=5)
    slow = lc.run(BLENDED, MACHINE, PLANNER, speed=1)
    np.testing.assert_array_equal(slow.pos_mm, fast.pos_mm)
    np.testing.assert_array_equal(slow.block, fast.block)
    assert fast.block[-1] == 3 and (np.diff(fast.block) >= 0).all()


@live
def test_parallel_instances_do_not_interfere():
    """Three instances at once (private lock file, shared memory, NML port, HOME each)."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(3) as pool:
        line, a, b = pool.map(lambda p: lc.run(p, MACHINE, PLANNER), [LINE, BLENDED, BLENDED])
    np.testing.assert_array_equal(a.pos_mm, b.pos_mm)
    assert abs(line.cycle_time_s - (60.0 / 50.0 + 50.0 / 1000.0)) <= 3 * PERIOD_S
    np.testing.assert_array_equal(line.pos_mm[-1], [60.0, 0.0, 0.0])


@live
def test_program_longer_than_the_planner_queue():
    """2400 chords of 0.05 mm (the queue holds about 1800 moves): nothing lost, repeatable."""
    from concurrent.futures import ThreadPoolExecutor

    phi = np.arange(1, 2401) * 0.05 / 20.0  # chords on a circle of radius 20 mm
    xy = np.round(20.0 * np.column_stack([np.sin(phi), 1.0 - np.cos(phi)]), 4)
    program = "G21 G90 G64 P0.01 Q0\nG1 F6000\n" + "".join(f"X{x} Y{y}\n" for x, y in xy)
    with ThreadPoolExecutor(2) as pool:
        a, b = pool.map(lambda p: lc.run(p, MACHINE, PLANNER), [program, program])
    np.testing.assert_array_equal(a.pos_mm, b.pos_mm)
    np.testing.assert_array_equal(a.pos_mm[-1], [xy[-1, 0], xy[-1, 1], 0.0])
    assert a.block[-1] == len(xy) - 1
    assert a.speed_mm_s.max() <= 100.0 + SPEED_ROUNDING_MM_S
    assert a.cycle_time_s >= len(xy) * 0.05 / 100.0


@live
def test_exact_stop_at_corner():
    tp = parse(CORNER)
    m = lc.run(tp, MACHINE, PLANNER)
    corner = np.flatnonzero((m.pos_mm[:, 0] == 30.0) & (m.pos_mm[:, 1] == 0.0))
    assert len(corner) >= 1  # the tool reaches the corner itself: no blend
    k = corner[0]
    # one servo period at the axis acceleration is 1 mm/s: the speed passes through ~0
    assert m.speed_mm_s[k - 1 : k + 2].min() <= 1000.0 * PERIOD_S
    assert (m.block[: k - 5] == 0).all() and (m.block[k + 5 :] == 1).all()
    np.testing.assert_array_equal(m.pos_mm[-1], [30.0, 20.0, 0.0])
    assert m.speed_mm_s.max() <= 50.0 + SPEED_ROUNDING_MM_S


#: Programs whose LinuxCNC cycle time the blend-arc planner (nctwin.estimate.blend_planner)
#: must match: collinear lines at the full acceleration into a last move at a / 2, a blend arc
#: with the full acceleration on the line before it, a chain of short blended lines, moves
#: that turn back within 0.002 rad and stop, 300 moves of 0.2 mm held back by the look-ahead's
#: depth, a zigzag whose blend arcs lie in the XZ plane (Z's acceleration), a rapid followed
#: by a feed move (no blend between them), a corner of short moves before a long line (the
#: lazy look-ahead's dip), slow reversals whose blend arcs are as small as their speed allows,
#: G61 chords of a circle that LinuxCNC passes as tangent (R 500 mm) or stops at (R 20 mm),
#: small kinks next to a programmed arc (nctwin.estimate.blend_junctions), and arcs and a helix
#: outside the XY plane.
PLANNER_PROGRAMS = {
    "collinear": "G21 G90 G64\nG1 F12000\n" + "".join(f"X{5 * k}\n" for k in range(1, 11)) + "M2\n",
    "corner": "G21 G90 G64 P0.1\nG1 X100 F3000\nY100\nM2\n",
    "short_corners": "G21 G90 G64 P0.1\nG1 X10 F6000\nY10\nX20\nY20\nX30\nY30\nM2\n",
    "reversals": "G21 G90 G64\nG1 X25.4 F6000\nX0 Y0.0254\nX25.4 Y0.0508\nX0 Y0.0762\nM2\n",
    "depth": "G21 G90 G64\nG1 F12000\n"
    + "".join(f"X{0.2 * k:.1f}\n" for k in range(1, 301))
    + "M2\n",
    "xz_zigzag": "G21 G90 G64\nG1 F6000\n"
    + "".join(f"X{k / 2**0.5:.6f} Z{-(k % 2) / 2**0.5:.6f}\n" for k in range(1, 21))
    + "M2\n",
    "rapid_feed": "G21 G90 G64\nG0 X10\nG1 X20 F6000\nM2\n",
    "lazy_corner": "G21 G90 G64 P0.3 Q0\nG1 X50 F5520\n"
    + "".join(
        f"X{50 + 20 * math.sin(p):.4f} Y{20 - 20 * math.cos(p):.4f}\n"
        for p in np.arange(1, 80) * math.pi / 158
    )
    + "Y60\nM2\n",
    "slow_reversals": "G21 G90 G64\nG1 F1200\n"
    + "".join(
        f"X{x:.4f} Y{y:.4f}\n"
        for x, y in np.cumsum(
            [[10 * math.cos(h), 10 * math.sin(h)] for h in np.radians([0, 140, 0, 140, 0, 140])],
            axis=0,
        )
    )
    + "M2\n",
    "g61_tangent": "G21 G90 G61\nG1 F1800\n"
    + "".join(
        f"X{500 * math.sin(k / 500):.4f} Y{500 - 500 * math.cos(k / 500):.4f}\n"
        for k in range(1, 21)
    )
    + "M2\n",
    # a turn 0.03 rad short of a reversal: within tpSetupTangent's 2 degrees, a stop
    "sharp_reversal": "G21 G90 G64\nG1 X13.654 F774\n"
    + f"X{13.654 - 33.302 * math.cos(0.03):.4f} Y{33.302 * math.sin(0.03):.4f}\n"
    + f"X{23.654 - 33.302 * math.cos(0.03):.4f}\nM2\n",
    # G61 stops at each of 100 chords, each on a whole servo period (52 ms more than trapezoids)
    "g61_circle": "G21 G90 G61\nG1 F3000\n"
    + "".join(
        f"X{5 * math.sin(k * math.pi / 50):.4f} Y{5 - 5 * math.cos(k * math.pi / 50):.4f}\n"
        for k in range(1, 101)
    )
    + "M2\n",
    # an arc into a 0.126 mm line that turns 1 degree towards its centre: the blend arc as
    # LinuxCNC makes it is 0.004 mm long, passed at 4 mm/s (its length per servo period)
    "arc_kink_xy": "G21 G90 G64 P0.0254 Q0\nG0 X-5 Y5\nG1 F12000\nG17 G3 X0 Y0 I5 J0\n"
    "G1 X0.126 Y0.0022\nX10.1123 Y0.5256\nM2\n",
    "arc_kink_yz": "G21 G90 G64 P0.0254 Q0\nG0 Y-5 Z5\nG1 F12000\nG19 G3 Y0 Z0 J5 K0\n"
    "G1 Y0.126 Z0.0022\nY10.1123 Z0.5256\nM2\n",
    # a 0.5 degree kink into an arc: the 0.004 mm blend arc alone is slower than the kink speed,
    # but the line's rest it consumes makes it faster (blendCheckConsume before the choice)
    "line_kink_arc": "G21 G90 G64 P0.0254 Q0\nG0 X10.1226 Y0.2629\nG1 F12000\n"
    "X0.126 Y0.0011\nX0 Y0\nG17 G2 X-5 Y5 I0 J5\nM2\n",
    # two arcs with a 3.2 degree kink, and an arc into a last line with a 6 degree kink
    "arc_kink_arc": "G21 G90 G64 P0.0254 Q0\nG0 X-5 Y5\nG1 F12000\nG17 G3 X0 Y0 I5 J0\n"
    "G2 X5.2713 Y-4.7131 I0.2791 J-4.9922\nG1 Y-14.7131\nM2\n",
    "arc_kink_last": "G21 G90 G64 P0.0254 Q0\nG0 Y-5 Z5\nG1 F12000\nG19 G3 Y0 Z0 J5 K0\n"
    "G1 Y9.9452 Z1.0453\nM2\n",
    # arcs outside XY: a slow G18 half circle as the last move (a / 4 on it), a G18 half
    # circle of 100 mm between lines under G61 (its acceleration split at Z's 100 mm/s, and a
    # reversal after it that sets no kink), a G19 helical turn between lines (its parabolic
    # blends on the planar tangent)
    "g18_half_last": "G21 G90 G64 P0.01\nG18 G1 X10 F1200\nG2 X30 Z0 I10 K0\nM2\n",
    "g18_r100_g61": "G21 G90 G61\nG18 G1 X10 F3000\nG2 X210 Z0 I100 K0\nG1 Z-10\nM2\n",
    "g19_helix": "G21 G90 G64 P0.01\nG19 G1 Y10 F3000\nG3 Y10 Z0 X20 J5 K0\nG1 Z-10\nM2\n",
    # a change of path-control mode: the junction takes the mode of the move before it
    "g61_then_g64": "G21 G90 G61\nG1 X20 F3000\nG64 P0.05\nG1 Y20\nG1 X0\nM2\n",
    "g64_then_g61": "G21 G90 G64 P0.05\nG1 X20 F3000\nG61\nG1 Y20\nG1 X0\nM2\n",
    "g61_stops": "G21 G90 G61\nG1 F1800\n"
    + "".join(
        f"X{20 * math.sin(k / 20):.4f} Y{20 - 20 * math.cos(k / 20):.4f}\n" for k in range(1, 11)
    )
    + "M2\n",
}


@live
@pytest.mark.parametrize("name", sorted(PLANNER_PROGRAMS))
def test_blend_planner_times_what_linuxcnc_records(name):
    program = PLANNER_PROGRAMS[name]
    recorded = lc.run(program, MACHINE, PLANNER).cycle_time_s
    planned = estimate(parse(program, start_mm=(0, 0, 0)), PROFILE, "planner").cycle_time_s
    assert planned == pytest.approx(recorded, abs=5 * PERIOD_S)


@live
def test_rejected_program_carries_linuxcnc_message():
    with pytest.raises(lc.LinuxCNCError, match="exceed X's positive limit") as info:
        lc.run("G21 G90\nG1 X20000 F600\nM2\n", MACHINE, PLANNER)
    assert info.value.line == 2
    assert isinstance(info.value, ValueError)


@live
def test_timeout_kills_the_instance_and_leaves_nothing(monkeypatch):
    # the instance's own folder, not every nctwin-linuxcnc-* (other runs may be going on)
    made, original = [], tempfile.mkdtemp

    def mkdtemp(**kwargs):
        made.append(original(**kwargs))
        return made[-1]

    monkeypatch.setattr(lc.tempfile, "mkdtemp", mkdtemp)
    with pytest.raises(TimeoutError, match="timeout_s"):
        lc.record("G21\nG4 P60\nM2\n", MACHINE, PLANNER, timeout_s=4.0)
    assert len(made) == 1 and Path(made[0]).name.startswith("nctwin-linuxcnc-")
    assert not Path(made[0]).exists()


def test_samples_follow_a_subroutine_whose_lines_repeat():
    """Blocks of lines 5, 6 (a subroutine) called twice from lines 9 and 10, with line 6
    holding two blocks: samples reporting 5, 6, 9 (no motion), 5, 6 follow the program forward,
    a repeated line goes to its next run, and a line with two blocks to its last block."""
    block_line = np.array([2, 5, 6, 6, 5, 6, 6, 11])
    sample_line = np.array([2, 2, 5, 6, 6, 9, 5, 5, 6, 11, 11])
    rec = lc.Recording(
        pos_mm=np.zeros((len(sample_line), 3)),
        current_vel_mm_s=np.zeros(len(sample_line)),
        program_line=sample_line,
        in_position=np.ones(len(sample_line), bool),
        period_s=PERIOD_S,
        log="",
    )
    tp = dataclasses.replace(parse("G1 X1 F600\n" * 8), line=block_line)
    assert lc.motion_of(rec, tp).block.tolist() == [0, 0, 1, 3, 3, 3, 4, 4, 6, 7, 7]


def test_experiment_conditions_by_hand():
    from types import SimpleNamespace

    from nctwin.chapters import linuxcnc as rk

    profile = load_profile("linuxcnc_sim")
    # 1 s at the 1 ms servo period: 1001 samples; a 10 ms trace holds 101
    rec = SimpleNamespace(n_samples=1001, feed_mm_s=np.full(101, 150.0))
    recordings = {f"train_{i}": rec for i in range(60)} | {"public_a": rec}
    programs = {"startup": ("public", parse("G1 X1 F100\nG64\nG1 X2"), None),
                "set": ("public", parse("G64 P0.1\nG1 X1 F100"), None)}  # fmt: skip
    conds = {c.id: c for c in rk.experiment_conditions(recordings, programs, profile)}
    assert conds["recordings_train"].met and conds["recordings_public"].ours == 1.0
    assert not conds["recordings_public"].met and not conds["recordings_broad"].met
    assert conds["trace_period"].ours == pytest.approx(10.0) and conds["trace_period"].met
    assert conds["feed_within_ini"].ours == 150.0 and conds["feed_within_ini"].met
    # the profile gives the startup mode LinuxCNC's plain G64: met; a finite tolerance is not
    assert conds["startup_mode_programs"].ours == 0.0 and conds["startup_mode_programs"].met
    finite = dataclasses.replace(
        profile, planner=dataclasses.replace(profile.planner, blend_tol_mm=0.0254)
    )
    conds = {c.id: c for c in rk.experiment_conditions(recordings, programs, finite)}
    assert conds["startup_mode_programs"].ours == 1.0 and not conds["startup_mode_programs"].met


@live
def test_the_sims_tool_table_offsets_the_live_tool():
    # G43 H1 with LinuxCNC's sim table (T1 0.511 mm long): the Z move ends 0.511 mm higher, as
    # the native reader reads it; with nctwin's own table (T1 of length 0) at the programmed Z
    text = "G21 G90 G61\nG43 H1\nG1 Z5 F3000\nG1 X10\nM2\n"
    m = lc.run(text, MACHINE, PLANNER, tool_table=PROFILE.tool_table)
    np.testing.assert_allclose(m.pos_mm[-1], [10.0, 0.0, 5.511], atol=1e-6)
    tp = parse(text, tool_table=PROFILE.tool_table)
    np.testing.assert_allclose(tp.end_mm[-1], m.pos_mm[-1], atol=1e-6)
    np.testing.assert_allclose(lc.run(text, MACHINE, PLANNER).pos_mm[-1], [10, 0, 5], atol=1e-6)
