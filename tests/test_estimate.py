"""The CAM baseline against a program timed by hand."""

from __future__ import annotations

import math

import pytest

from nctwin import parse
from nctwin.estimate import estimate
from nctwin.machine import Machine, Profile

MACHINE = Machine(
    name="hand",
    description="round numbers",
    axis_max_velocity_mm_s=(500.0, 500.0, 500.0),
    axis_max_acceleration_mm_s2=(1000.0, 1000.0, 1000.0),
    axis_max_jerk_mm_s3=(1e5, 1e5, 1e5),
    rapid_feed_mm_s=500.0,
    max_feed_mm_s=1000.0,
)
PROFILE = Profile(MACHINE)  # CAM needs no control

PROGRAM = """
G21 G90 G17
G0 Z10            (10 mm rapid at 500 mm/s: 0.02 s)
G1 Z0 F600        (10 mm at 10 mm/s: 1 s)
X30               (30 mm: 3 s)
G3 X30 Y20 I0 J10 F1200  (half circle, r 10: 10 pi mm at 20 mm/s: pi/2 s)
G4 P2             (2 s)
M30
"""


def test_cam_time_of_a_hand_computed_program():
    result = estimate(parse(PROGRAM), PROFILE, "cam")
    expected = 0.02 + 1.0 + 3.0 + math.pi / 2 + 2.0
    assert result.cycle_time_s == pytest.approx(expected, rel=1e-12)
    by_kind = result.by_kind()
    assert by_kind["rapid"]["time_s"] == pytest.approx(0.02)
    assert by_kind["arc_ccw"]["length_mm"] == pytest.approx(10 * math.pi)
    assert by_kind["dwell"]["time_s"] == 2.0
    summary = result.summary()
    assert summary["blocks"] == 5
    assert summary["length_mm"] == pytest.approx(10 + 10 + 30 + 10 * math.pi)


def test_cam_clamps_feed_to_the_machine_maximum():
    result = estimate(parse("G1 X100 F120000"), PROFILE, "cam")  # 2000 mm/s asked, 1000 allowed
    assert result.cycle_time_s == pytest.approx(0.1)


def test_inch_program_time():
    # 1 in at 60 in/min takes 1 s whatever the units
    result = estimate(parse("G20\nG1 X1 F60"), PROFILE, "cam")
    assert result.cycle_time_s == pytest.approx(1.0)
    # on one line LinuxCNC sets F (60 mm/min, the program starts in mm) before it changes the
    # units, and keeps the physical feed: 25.4 mm at 60 mm/min take 25.4 s
    result = estimate(parse("G20 G1 X1 F60"), PROFILE, "cam")
    assert result.cycle_time_s == pytest.approx(25.4)


def test_unknown_method_is_named():
    with pytest.raises(ValueError, match="method = 'magic' is unknown: allowed cam"):
        estimate(parse("G1 X1 F60"), PROFILE, "magic")
