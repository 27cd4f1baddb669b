"""nctwin.estimate.cycle: the non-motion times, the motion time and the overrides, by hand."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nctwin import parse
from nctwin.controls import SequenceControl
from nctwin.estimate import cam, cycle_time
from nctwin.estimate.cycle import BREAKDOWN, CycleTime, apply_overrides
from nctwin.machine import Machine, Profile
from nctwin.toolpath import EVENT_DTYPE, MotionKind, Toolpath

MACHINE = Machine(
    name="hand",
    description="",
    axis_max_velocity_mm_s=(1000.0,) * 3,
    axis_max_acceleration_mm_s2=(1000.0,) * 3,
    axis_max_jerk_mm_s3=(math.inf,) * 3,
    rapid_feed_mm_s=100.0,
    max_feed_mm_s=1000.0,
)
SEQUENCE = SequenceControl(
    tool_change_s=8.0,
    spindle_start_s=2.0,
    spindle_start_s_per_krpm=1.0,
    optional_stop_s=3.0,
    program_start_s=5.0,
    program_end_s=7.0,
)
PROFILE = Profile(MACHINE, sequence=SEQUENCE)

# Two tools; an M1 while the spindle runs, one inside the tool change, one after the last M5.
PROGRAM = """G21 G90 G17
T1 M6
S1000 M3
G0 X10
G1 X20 F600
G4 P0.5
M1
G3 X30 I5 J0
M5
M1
T2 M6
S2000 M4
G1 Y10 F300
G4 P1
M5
G0 X0 Y0
M1
M30
"""
RAPIDS_S = 10 / 100 + math.hypot(30, 10) / 100
ARC_S = 5 * math.pi / 10  # a half circle of radius 5 at 10 mm/s
FEED_S = 10 / 10 + 10 / 5


def test_two_tools_by_hand():
    ct = cycle_time(parse(PROGRAM), PROFILE, "cam")
    b = ct.breakdown
    assert list(b) == list(BREAKDOWN)
    assert b["rapids"] == pytest.approx(RAPIDS_S)
    assert b["feed_lines"] == pytest.approx(FEED_S)
    assert b["arcs"] == pytest.approx(ARC_S)
    assert b["dwells"] == pytest.approx(1.5)
    assert b["tool_changes"] == 16.0
    assert b["spindle_starts"] == pytest.approx((2 + 1) + (2 + 2))  # 1000 and 2000 rev/min
    assert b["optional_stops"] == 6.0  # the M1 inside the tool change is in it
    assert b["program_start_end"] == 12.0
    assert ct.counts == {"tool_changes": 2, "spindle_starts": 2, "optional_stops": 2,
                         "spindle_runs": 2}  # fmt: skip
    blocks = RAPIDS_S + FEED_S + ARC_S + 1.5
    assert ct.estimate.cycle_time_s == pytest.approx(blocks)
    assert ct.cycle_time_s == pytest.approx(blocks + 16 + 7 + 6 + 12)
    assert sum(b.values()) == pytest.approx(ct.cycle_time_s)
    # tool 1: the X10 rapid to its M5, the M1 between included; tool 2: Y10 and the dwell
    run1 = 0.1 + 1.0 + 0.5 + 3.0 + ARC_S
    assert ct.motion_time_s == pytest.approx(run1 + 2.0 + 1.0)


def test_the_first_tool_change_before_any_spindle_start():
    seq = dataclasses.replace(SEQUENCE, first_tool_change_s=3.0)
    b = cycle_time(parse(PROGRAM), dataclasses.replace(PROFILE, sequence=seq), "cam").breakdown
    assert b["tool_changes"] == 3.0 + 8.0  # T1 at rest, T2 after the first spindle run
    # a tool change before a spindle start that follows an earlier run is no first one
    tp = parse("G21\nS900 M3\nG1 X10 F600\nM5\nT2 M6\nS900 M3\nG1 X0\n")
    profile = dataclasses.replace(PROFILE, sequence=seq)
    assert cycle_time(tp, profile, "cam").breakdown["tool_changes"] == 8.0


def test_without_a_sequence_the_cycle_time_is_the_estimates():
    tp = parse(PROGRAM)
    ct = CycleTime.of(cam(tp, MACHINE), None)
    assert ct.cycle_time_s == cam(tp, MACHINE).cycle_time_s
    assert ct.breakdown["tool_changes"] == ct.breakdown["program_start_end"] == 0.0
    assert ct.counts["tool_changes"] == 2
    assert ct.motion_time_s == pytest.approx(0.1 + 1.0 + 0.5 + ARC_S + 3.0)


def test_a_program_without_a_spindle_start_has_no_motion_time():
    ct = cycle_time(parse("G21\nG1 X10 F600\nM30\n"), PROFILE, "cam")
    assert ct.motion_time_s is None
    assert ct.cycle_time_s == pytest.approx(1.0 + 12.0)


@pytest.mark.parametrize(
    ("text", "stops"),
    [
        ("M5\nM1\nT2 M6\n", 0),  # spindle off, next is M6: inside the tool change
        ("M1\nT2 M6\n", 1),  # spindle on: an optional stop (M6 then stops it)
        ("M5\nM1\nS900 M3\nT2 M6\n", 1),  # spindle off, but the next is an M3
        ("M5\nM1\nM30\n", 1),  # spindle off, no tool change follows
    ],
)
def test_an_optional_stop_inside_a_tool_change(text, stops):
    tp = parse(f"G21\nS1000 M3\nG1 X10 F600\n{text}G1 X0\n")
    assert cycle_time(tp, PROFILE, "cam").counts["optional_stops"] == stops


def test_the_spindle_speed_in_force():
    # the S on the M3's line after it, an S given lines before, none at all (0 rev/min)
    for text, spindle_s in (("M3 S3000\n", 5.0), ("S4000\nG1 X1 F60\nM3\n", 6.0), ("M3\n", 2.0)):
        tp = parse(f"G21\n{text}G1 X10 F600\nM5\n")
        assert cycle_time(tp, PROFILE, "cam").breakdown["spindle_starts"] == spindle_s


def test_feed_override_by_hand():
    tp = parse("G21\nG0 X10\nG1 X20 F600\nG4 P1\n")
    base = cycle_time(tp, PROFILE, "cam").breakdown
    half = cycle_time(tp, PROFILE, "cam", feed_override_pct=50).breakdown
    assert half["feed_lines"] == pytest.approx(2 * base["feed_lines"]) == pytest.approx(2.0)
    assert half["rapids"] == base["rapids"] and half["dwells"] == base["dwells"] == 1.0
    fast = cycle_time(tp, PROFILE, "cam", rapid_override_pct=200).breakdown
    assert fast["rapids"] == pytest.approx(0.05) and fast["feed_lines"] == base["feed_lines"]


def test_overrides_of_100_leave_the_inputs_alone():
    tp = parse(PROGRAM)
    assert apply_overrides(tp, PROFILE) == (tp, PROFILE)
    tp50, prof50 = apply_overrides(tp, PROFILE, rapid_override_pct=50, feed_override_pct=50)
    assert prof50.machine.rapid_feed_mm_s == 50.0 and prof50.sequence == SEQUENCE
    rapid = tp.kind == MotionKind.RAPID
    np.testing.assert_array_equal(tp50.feed_mm_s[rapid], tp.feed_mm_s[rapid])
    np.testing.assert_allclose(tp50.feed_mm_s[~rapid], tp.feed_mm_s[~rapid] / 2)


@pytest.mark.parametrize("pct", [0, -5, 200.5, float("nan"), float("inf")])
@pytest.mark.parametrize("name", ["rapid_override_pct", "feed_override_pct"])
def test_overrides_out_of_range_are_refused(name, pct):
    with pytest.raises(ValueError, match=rf"^{name} = .* is out of range: allowed \(0, 200\]$"):
        apply_overrides(parse(PROGRAM), PROFILE, **{name: pct})


# ---------------------------------------------------------------- random event layouts
_WORDS = [("M", 3.0), ("M", 4.0), ("M", 5.0), ("M", 6.0), ("M", 1.0), ("M", 30.0), ("M", 8.0),
          ("S", 1500.0), ("T", 2.0)]  # fmt: skip


def _reference(items, seq: SequenceControl):
    """The cycle and motion time by walking the items one by one: a float is a dwell block,
    a (word, value) an event."""
    clock, on, rpm, motion, any_run, run_start = seq.program_start_s, False, 0.0, 0.0, False, 0.0
    pending = None  # a spindle run waits for its first block
    for j, item in enumerate(items):
        if isinstance(item, float):
            if pending:
                run_start, pending = clock, False
            clock += item
            continue
        word, value = item
        if word == "M" and value in (5.0, 6.0, 30.0) and on:  # the run ends before the word
            motion += 0.0 if pending else clock - run_start
            on = pending = False
        if word == "S":
            rpm = value
        elif value == 6.0:
            clock += seq.tool_change_s if any_run else seq.tool_change_at_s(first=True)
        elif value in (3.0, 4.0):
            clock += seq.spindle_s(rpm)
        elif value == 1.0:
            later = [v for w, v in (i for i in items[j + 1 :] if not isinstance(i, float))
                     if w == "M" and v in (3.0, 4.0, 6.0, 2.0, 30.0)]  # fmt: skip
            if on or not (later and later[0] == 6.0):
                clock += seq.optional_stop_s
        if word == "M" and value in (3.0, 4.0) and not on:
            on, pending, any_run = True, True, True
    if on and not pending:
        motion += clock - run_start
    return clock + seq.program_end_s, (motion if any_run else None)


@given(
    st.lists(st.one_of(st.floats(0.0, 10.0), st.sampled_from(_WORDS)), max_size=30),
    st.floats(0.0, 5.0),
)
def test_random_event_layouts_match_a_walk_through_them(items, spindle_per_krpm):
    seq = SequenceControl(1.5, -0.5, spindle_per_krpm, 0.7, 0.3, 0.2, first_tool_change_s=0.4)
    dwells = [i for i in items if isinstance(i, float)]
    events, n = [], 0
    for line, item in enumerate(items, 1):
        if isinstance(item, float):
            n += 1
        else:
            events.append((n, line, *item))
    zeros = np.zeros((n, 3))
    tp = Toolpath(zeros, zeros, np.full(n, MotionKind.DWELL), np.full(n, np.nan),
                  np.full((n, 3), np.nan), np.zeros(n), dwells, np.arange(n), np.zeros(n),
                  np.full(n, np.nan), np.full(n, np.nan),
                  events=np.array(events, dtype=EVENT_DTYPE))  # fmt: skip
    ct = CycleTime.of(cam(tp, MACHINE), seq)
    cycle, motion = _reference(items, seq)
    assert ct.cycle_time_s == pytest.approx(cycle, abs=1e-9)
    assert sum(ct.breakdown.values()) == pytest.approx(ct.cycle_time_s, abs=1e-9)
    if motion is None:
        assert ct.motion_time_s is None
    else:
        assert ct.motion_time_s == pytest.approx(motion, abs=1e-9)
