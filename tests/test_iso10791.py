"""The ISO 10791-7-style test-piece program: shipped file, geometry, length of the cycle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin import MotionKind, parse_file
from nctwin.estimate import estimate
from nctwin.machine import load_profile
from nctwin.programs import iso10791 as iso
from nctwin.programs.iso10791 import TestPieceParams, shipped_test_piece_path


def test_shipped_file_is_the_generators_output():
    assert shipped_test_piece_path().read_text(encoding="utf-8") == iso.test_piece_program()


def test_program_has_every_kind_of_block_at_its_natural_length():
    tp = parse_file(shipped_test_piece_path())
    counts = tp.kind_counts()
    p = TestPieceParams()
    assert counts["dwell"] == p.repeats * p.passes  # one dwell per bore pass
    assert counts["arc_cw"] == p.repeats * p.passes * 4 * 4  # circle quadrants + 3 x 4 corners
    assert counts["rapid"] == 15 * 3 + 3 and counts["linear"] == 306  # 3 per pass, 3 at the ends
    # one sequence, not repeated: CAM's length / feed is 7-8 minutes
    assert 420.0 < estimate(tp, load_profile("fanuc_0i_testbed"), "cam").cycle_time_s < 480.0


def _arcs_at(tp, z):
    m = tp.is_arc & np.isclose(tp.start_mm[:, 2], z)
    return tp.center_mm[m], tp.radius_mm[m]


def test_feature_geometry():
    tp = iso.test_piece()
    # circle boss D108 with a 5 mm tool: four quadrants of radius 59 around the origin
    c, r = _arcs_at(tp, -2.0)
    np.testing.assert_allclose(r, 59.0, atol=1e-4)
    np.testing.assert_allclose(c[:, :2], 0.0, atol=1e-9)
    # diamond: corner arcs of the tool radius centred on a 110 mm square turned 45 degrees
    c, r = _arcs_at(tp, -8.0)
    np.testing.assert_allclose(r, 5.0, atol=1e-3)
    np.testing.assert_allclose(np.sort(np.hypot(c[:, 0], c[:, 1])), 55 * math.sqrt(2), atol=1e-3)
    np.testing.assert_allclose(np.abs(c[:, :2]).min(axis=1), 0.0, atol=1e-3)
    # square 160: corners at (+-80, +-80)
    c, _ = _arcs_at(tp, -14.0)
    np.testing.assert_allclose(np.abs(c[:, :2]), 80.0, atol=1e-4)
    # inclined square 170 turned 3 degrees
    c, _ = _arcs_at(tp, -20.0)
    angle = np.degrees(np.arctan2(c[:, 1], c[:, 0])) % 90.0
    np.testing.assert_allclose(angle, 48.0, atol=1e-3)
    # bore D30: 72 chords with their ends on a radius of 10 mm
    bore = (tp.kind == MotionKind.LINEAR) & (np.hypot(tp.end_mm[:, 0], tp.end_mm[:, 1]) < 10.01)
    ends = tp.end_mm[bore & (np.hypot(tp.end_mm[:, 0], tp.end_mm[:, 1]) > 9.99)]
    np.testing.assert_allclose(np.hypot(ends[:, 0], ends[:, 1]), 10.0, atol=1e-4)
    assert len(ends) == 3 * (72 + 1)


def test_params_are_checked_and_the_writer_is_atomic(tmp_path):
    with pytest.raises(ValueError, match="feed_mm_min = -1 is out of range"):
        TestPieceParams(feed_mm_min=-1)
    with pytest.raises(ValueError, match="repeats = 0 is out of range"):
        TestPieceParams(repeats=0)
    with pytest.raises(ValueError, match=r"tool_radius_mm = 20\.0 is out of range"):
        TestPieceParams(tool_radius_mm=20.0)
    small = TestPieceParams(passes=1)
    path = iso.write_test_piece(tmp_path / "piece.nc", small)
    assert path.read_text() == iso.test_piece_program(small)
    assert [p.name for p in tmp_path.iterdir()] == ["piece.nc"]
    assert len(parse_file(path)) < len(iso.test_piece())
