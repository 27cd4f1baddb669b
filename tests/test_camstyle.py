"""CAM-style training programs (nctwin.programs.camstyle)."""

import math
import re

import numpy as np
import pytest

from nctwin import parse
from nctwin.programs import camstyle
from nctwin.toolpath import MotionKind, PathMode


def test_same_seed_same_program_and_lines_only():
    texts = [camstyle.cam_program(seed) for seed in range(40)]
    assert texts == [camstyle.cam_program(seed) for seed in range(40)]
    modes = set()
    for text in texts:
        tp = parse(text)
        assert not tp.is_arc.any() and not (tp.kind == MotionKind.DWELL).any()
        assert (tp.kind == MotionKind.RAPID).any() and (tp.kind == MotionKind.LINEAR).any()
        modes.add(re.sub(r"P[0-9.]+", "P", text.split("\n")[2]))
    assert modes == set(camstyle.PATH_MODES)


def test_cut_time_within_max_time():
    for seed in range(20):
        tp = parse(camstyle.cam_program(seed, max_time_s=5.0))
        cut = tp.kind == MotionKind.LINEAR
        # the plunges (a third of the feed) are not counted, the cuts are
        feed = np.nanmax(tp.feed_mm_s[cut])
        cutting = cut & (tp.feed_mm_s == feed)
        assert tp.lengths_mm[cutting].sum() / feed <= 5.0 + 1e-9


def test_operations_start_with_rapids_and_a_plunge():
    tp = parse(camstyle.cam_program(3))
    lines = camstyle.cam_program(3).split("\n")
    plunges = [i for i, line in enumerate(lines) if line.startswith("G1 Z")]
    assert plunges and all(lines[i - 1].startswith("G0 X") for i in plunges)
    assert all(lines[i - 2].startswith("G0 Z") for i in plunges)
    assert tp.end_mm[-1, 2] == camstyle.SAFE_Z_MM


def test_reversals_turn_back():
    rng = np.random.default_rng(0)
    pts = camstyle._reversal(rng)
    d = np.diff(pts[:, :2], axis=0)
    u = d / np.linalg.norm(d, axis=1)[:, None]
    turn = np.degrees(np.arccos(np.clip((u[1:] * u[:-1]).sum(axis=1), -1, 1)))
    assert ((turn >= 150.0 - 1e-9) & (turn <= 179.9 + 1e-9)).all()


def test_engraving_is_closed_and_raster_is_3d():
    rng = np.random.default_rng(1)
    pts = camstyle._engrave(rng)
    np.testing.assert_allclose(pts[0], pts[-1], atol=1e-9)
    raster = camstyle._raster(rng)
    assert len(raster) <= camstyle.MAX_RASTER_POINTS + 2 * len(np.unique(raster[:, 0]))
    assert np.ptp(raster[:, 2]) > 0


def test_plain_g64_means_no_tolerance():
    text = next(t for s in range(50) if (t := camstyle.cam_program(s)).split("\n")[2] == "G64")
    tp = parse(text)
    assert (tp.path_mode == PathMode.BLEND).all()
    assert math.isinf(tp.effective_tolerance_mm(0.0254)[-1])


def test_bad_operation_count_is_named():
    with pytest.raises(ValueError, match="max_operations = 0"):
        camstyle.cam_program(0, max_operations=0)
