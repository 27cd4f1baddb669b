"""The one rule from axis limits to path limits, against numbers derived by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin import parse
from nctwin.limits import axis_shares, path_limits
from nctwin.machine import Machine

MACHINE = Machine(
    name="hand",
    description="round numbers",
    axis_max_velocity_mm_s=(300.0, 400.0, 100.0),
    axis_max_acceleration_mm_s2=(3000.0, 4000.0, 1000.0),
    axis_max_jerk_mm_s3=(math.inf, math.inf, math.inf),
    rapid_feed_mm_s=500.0,
    max_feed_mm_s=500.0,
)


def test_a_line_takes_each_axis_at_its_share():
    # direction (3, 4, 0) / 5: X takes 0.6 of the path speed, Y 0.8
    tp = parse("G21 G90\nG1 X30 Y40 F600\n")
    lim = path_limits(tp, MACHINE)
    np.testing.assert_allclose(axis_shares(tp), [[0.6, 0.8, 0.0]])
    # min(300 / 0.6, 400 / 0.8) = min(500, 500); min(3000 / 0.6, 4000 / 0.8) = 5000
    assert lim.velocity_mm_s[0] == pytest.approx(500.0)
    assert lim.acceleration_mm_s2[0] == pytest.approx(5000.0)
    assert lim.jerk_mm_s3[0] == math.inf
    # a vertical line: Z alone
    z = path_limits(parse("G21 G90\nG1 Z5 F600\n"), MACHINE)
    assert (z.velocity_mm_s[0], z.acceleration_mm_s2[0]) == (100.0, 1000.0)


def test_a_planar_arc_takes_both_plane_axes_at_full_speed():
    # a quarter circle in XY: X and Y each run at the full path speed somewhere on a circle
    tp = parse("G21 G90 G17\nG2 X10 Y10 I10 J0 F600\n")
    np.testing.assert_array_equal(axis_shares(tp), [[1.0, 1.0, 0.0]])
    lim = path_limits(tp, MACHINE)
    assert (lim.velocity_mm_s[0], lim.acceleration_mm_s2[0]) == (300.0, 3000.0)
    # in the XZ plane (G18): X and Z
    xz = path_limits(parse("G21 G90 G18\nG2 X10 Z10 I10 K0 F600\n"), MACHINE)
    assert (xz.velocity_mm_s[0], xz.acceleration_mm_s2[0]) == (100.0, 1000.0)


def test_a_helix_shares_its_length_between_the_plane_and_its_axis():
    # a full turn of radius 10 rising 20*pi: planar length 20*pi, rise 20*pi, share 1/sqrt(2)
    rise = 20.0 * math.pi
    tp = parse(f"G21 G90 G17\nG2 X0 Y0 Z{rise!r} I10 J0 F600\n")
    share = 1.0 / math.sqrt(2.0)
    np.testing.assert_allclose(axis_shares(tp), [[share, share, share]], rtol=1e-12)
    lim = path_limits(tp, MACHINE)
    # X: 300 * sqrt 2 = 424, Y: 400 * sqrt 2, Z: 100 * sqrt 2 = 141.4
    assert lim.velocity_mm_s[0] == pytest.approx(100.0 * math.sqrt(2.0))
    assert lim.acceleration_mm_s2[0] == pytest.approx(1000.0 * math.sqrt(2.0))


def test_a_dwell_or_a_standstill_has_no_limit():
    tp = parse("G21 G90\nG4 P1\nG1 X0 F600\n")
    lim = path_limits(tp, MACHINE)
    assert np.all(axis_shares(tp) == 0.0)
    assert np.all(np.isinf(lim.velocity_mm_s)) and np.all(np.isinf(lim.acceleration_mm_s2))


@settings(max_examples=60, deadline=None)
@given(st.tuples(*[st.integers(-100_000, 100_000) for _ in range(3)]).filter(lambda d: any(d)))
def test_no_axis_exceeds_its_limit_at_the_path_limit(d):
    """At the path speed the rule allows, every axis runs within its limit, and one at it."""
    x, y, z = (f"{v / 1000:.3f}" for v in d)
    tp = parse(f"G21 G91\nG1 X{x} Y{y} Z{z} F600\n")
    lim = path_limits(tp, MACHINE)
    axis_speed = lim.velocity_mm_s[0] * np.abs(tp.directions[0])
    limits = np.array(MACHINE.axis_max_velocity_mm_s)
    assert np.all(axis_speed <= limits * (1 + 1e-12))
    assert np.isclose(axis_speed / limits, 1.0, rtol=1e-12).any()
