"""PathGeometry: points by arc length, and its compiled loop against the numpy definition."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_gcode import programs

from nctwin import parse, parse_file
from nctwin._geometry_loops import block_indices
from nctwin.geometry import PathGeometry


def _queries(geo: PathGeometry, rng: np.random.Generator) -> np.ndarray:
    """Arc lengths to ask for: random ones, every block start and end, and beyond both ends."""
    total = geo.total_mm
    return np.concatenate(
        [rng.uniform(-0.1 * total - 1, 1.1 * total + 1, 500), geo.s_start_mm, [0.0, total]]
    )


@settings(max_examples=100, deadline=None)
@given(programs(), st.integers(0, 2**32 - 1))
def test_compiled_points_equal_numpy_bit_for_bit(text, seed):
    geo = PathGeometry(parse(text))
    s = _queries(geo, np.random.default_rng(seed))
    np.testing.assert_array_equal(geo.points(s), geo.points_numpy(s))


def test_compiled_points_equal_numpy_on_public_programs(shared_programs):
    rng = np.random.default_rng(0)
    for path in sorted(shared_programs.iterdir()):
        try:
            tp = parse_file(path)
        except Exception:  # rejected programs are the parser's tests' business
            continue
        geo = PathGeometry(tp)
        s = _queries(geo, rng)
        np.testing.assert_array_equal(geo.points(s), geo.points_numpy(s), err_msg=path.name)


def test_points_by_hand():
    # a 10 mm line along X, then a quarter circle of radius 10 about (10, 10) in XY, rising 2 mm
    geo = PathGeometry(parse("G1 X10 F600\nG3 X20 Y10 Z2 I0 J10"))
    quarter = math.hypot(10 * math.pi / 2, 2.0)  # helix length
    s = np.array([-5.0, 0.0, 4.0, 10.0, 10.0 + quarter / 2, 10.0 + quarter, 1e6])
    mid = 10 + 10 * math.sqrt(0.5)
    expected = [
        [0, 0, 0],
        [0, 0, 0],
        [4, 0, 0],
        [10, 0, 0],
        [mid, 10 - 10 * math.sqrt(0.5), 1.0],
        [20, 10, 2],
        [20, 10, 2],
    ]
    np.testing.assert_allclose(geo.points(s), expected, atol=1e-12)
    assert geo.total_mm == pytest.approx(10.0 + quarter)


def test_empty_path_has_points_at_the_origin():
    geo = PathGeometry(parse("G4 P0.1"))
    np.testing.assert_array_equal(geo.points(np.array([0.0, 1.0])), np.zeros((2, 3)))


@settings(max_examples=100, deadline=None)
@given(programs(), st.integers(0, 2**32 - 1), st.booleans())
def test_compiled_block_indices_equal_block_at(text, seed, ordered):
    geo = PathGeometry(parse(text))
    if not len(geo.lengths_mm):
        return
    s = _queries(geo, np.random.default_rng(seed))
    s = np.sort(s) if ordered else s
    out = np.empty(len(s), dtype=np.intp)
    block_indices(geo.s_start_mm, s, out)
    np.testing.assert_array_equal(out, geo.block_at(s))
