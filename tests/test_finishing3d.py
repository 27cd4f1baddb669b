"""The 3D ball-end finishing program: reproducible, CAM-like and within its tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin.gcode import parse
from nctwin.paths import data_dir
from nctwin.programs import finishing3d as f3
from nctwin.programs.finishing3d import (
    FinishingParams,
    finishing3d,
    finishing3d_program,
    program_statistics,
    write_finishing3d,
)
from nctwin.toolpath import MotionKind, Plane

SMALL = FinishingParams(width_mm=30.0, length_mm=4.0, stepover_mm=1.0)
PUBLIC = data_dir() / "programs" / "public"
#: The real CAM 3D ball-end finishing programs whose chord lengths the defaults follow.
REAL_CAM = ("LHchips4.ngc", "camotics_bear.nc")


def test_seeded_and_deterministic():
    assert finishing3d_program(3, SMALL) == finishing3d_program(3, SMALL)
    assert finishing3d_program(3, SMALL) != finishing3d_program(4, SMALL)


def test_structure_of_the_passes():
    tp = finishing3d(1, SMALL)
    passes = 5  # y = 0, 1, 2, 3, 4
    counts = tp.kind_counts()
    # zigzag: G2 leads on the passes along +X (3), G3 on those back (2)
    assert counts["arc_cw"] == 2 * 3 and counts["arc_ccw"] == 2 * 2
    # the safe height, across and down to the first lead-in; up and home at the end
    assert counts["rapid"] == 5
    assert counts["dwell"] == 0
    assert (tp.plane[tp.is_arc] == Plane.ZX).all()
    # each pass at its own Y; only the 4 links across move in Y
    cut = tp.kind != MotionKind.RAPID
    moves_y = cut & (tp.start_mm[:, 1] != tp.end_mm[:, 1])
    assert moves_y.sum() == passes - 1
    np.testing.assert_allclose(tp.end_mm[moves_y, 1] - tp.start_mm[moves_y, 1], 1.0)
    np.testing.assert_array_equal(np.unique(tp.end_mm[cut, 1]), np.arange(passes, dtype=float))
    # the leads start beyond X = 0 on passes along +X and beyond X = width on those back
    lead_in = np.flatnonzero(tp.is_arc)[::2]
    assert (tp.start_mm[lead_in[::2], 0] < 0).all()
    assert (tp.start_mm[lead_in[1::2], 0] > SMALL.width_mm).all()
    # feeds: LHchips4's F1300, F800 on chords descending more steeply than 45 degrees
    feeds = tp.feed_mm_s[cut] * 60
    assert set(np.unique(np.round(feeds))) <= {800.0, 1300.0}
    d = tp.end_mm[cut] - tp.start_mm[cut]
    steep = (tp.kind[cut] == MotionKind.LINEAR) & (-d[:, 2] > np.abs(d[:, 0])) & (d[:, 0] != 0)
    np.testing.assert_allclose(feeds[steep], 800.0)
    np.testing.assert_allclose(feeds[~steep & (d[:, 0] != 0)], 1300.0)


def test_steep_chords_take_the_steep_feed():
    # a steep angle of 1 degree makes most descending chords steep: F written where it changes
    p = FinishingParams(width_mm=30.0, length_mm=2.0, stepover_mm=1.0, steep_angle_deg=1.0)
    text = finishing3d_program(1, p)
    tp = parse(text)
    d = tp.end_mm - tp.start_mm
    chord = (tp.kind == MotionKind.LINEAR) & (d[:, 0] != 0)
    steep = chord & (-d[:, 2] > math.tan(math.radians(1.0)) * np.abs(d[:, 0]))
    assert steep.sum() > 10
    np.testing.assert_allclose(tp.feed_mm_s[steep] * 60, 800.0)
    np.testing.assert_allclose(tp.feed_mm_s[chord & ~steep] * 60, 1300.0)
    assert text.count(" F") < chord.sum()  # modal, not on every block


def test_lead_arcs_are_tangent_and_vertical_at_their_free_ends():
    tp = finishing3d(2, SMALL)
    arcs = np.flatnonzero(tp.is_arc)
    lead_in, lead_out = arcs[::2], arcs[1::2]
    # tangent to the pass at both ends: the corner left is the angle between the tangent and
    # the first or last chord, L kappa / 2 <= sqrt(2 kappa tol) for a chord within tol
    assert np.degrees(tp.corner_angles_rad[lead_in + 1]).max() < 5.0
    assert np.degrees(tp.corner_angles_rad[lead_out]).max() < 5.0
    # the descent before a lead-in is straight down, as the arc starts; the lead-out ends
    # straight up, as the rapid after it
    np.testing.assert_allclose(tp.start_tangents[lead_in], [[0, 0, -1]] * len(lead_in), atol=1e-3)
    np.testing.assert_allclose(tp.end_tangents[lead_out], [[0, 0, 1]] * len(lead_out), atol=1e-3)
    np.testing.assert_allclose(tp.radius_mm[arcs], SMALL.lead_radius_mm, atol=2e-3)


def test_chords_stay_within_the_cam_tolerance():
    p = SMALL
    text = finishing3d_program(5, p)
    tp = parse(text)
    surf = f3._Surface(np.random.default_rng(5), p)
    # the chords, not the links across (which move in Y); passes 2 and 4 run back along -X
    chords = (tp.kind == MotionKind.LINEAR) & (tp.end_mm[:, 0] != tp.start_mm[:, 0])
    chords &= tp.end_mm[:, 1] == tp.start_mm[:, 1]
    for y in (0.0, 1.0, 2.0, 4.0):
        mine = np.flatnonzero(chords & (tp.end_mm[:, 1] == y))
        pts = np.concatenate([tp.start_mm[mine[:1]], tp.end_mm[mine]])
        pts = pts[np.argsort(pts[:, 0])]
        xs, zs = pts[:, 0], pts[:, 2]
        fine = np.linspace(xs[0], xs[-1], 20001)
        true = surf.tip(fine, np.full(len(fine), y), p.tool_radius_mm)
        # vertical distance bounds the normal one; coordinates are rounded to 0.5 um
        assert np.abs(np.interp(fine, xs, zs) - true).max() <= p.tolerance_mm + 1e-3
        lengths = np.hypot(np.diff(xs), np.diff(zs))
        assert lengths.max() <= p.max_segment_mm + 2e-3


def test_the_ball_touches_the_surface_and_never_cuts_into_it():
    # drop cutter: over the tip at (x, y), the ball's lower surface is z_tip + r - sqrt(r^2 - d^2)
    # at a distance d; it must be above the surface everywhere under it and touch it once
    p = SMALL
    surf = f3._Surface(np.random.default_rng(7), p)
    r = p.tool_radius_mm
    rng = np.random.default_rng(0)
    x, y = rng.uniform(0, p.width_mm, 200), rng.uniform(0, p.length_mm, 200)
    tip = surf.tip(x, y, r)
    rho = np.linspace(0.0, r, 61)[:, None] * np.ones((1, 120))
    phi = np.linspace(0.0, 2 * math.pi, 120, endpoint=False)[None, :] * np.ones((61, 1))
    du, dv = (rho * np.cos(phi)).ravel(), (rho * np.sin(phi)).ravel()
    ball = r - np.sqrt(np.maximum(r * r - du * du - dv * dv, 0.0))
    gap = np.empty(len(x))
    for i in range(len(x)):
        f = surf.eval(x[i] + du, y[i] + dv)[0]
        gap[i] = (tip[i] + ball - f).min()
    assert gap.min() >= -1e-9
    assert gap.max() < 2e-3  # touches (within the footprint grid's resolution)


def test_default_program_matches_its_documented_statistics():
    stats = program_statistics(finishing3d_program(0))
    assert stats["lines"] == 22626
    assert stats["blocks"] == 22497
    assert (stats["g0"], stats["g1"], stats["g2"], stats["g3"]) == (5, 22250, 122, 120)
    assert stats["chords"] == 22126
    assert stats["cut_length_mm"] == pytest.approx(12042, abs=1)
    assert stats["arc_length_mm"] == pytest.approx(1908, abs=1)
    assert stats["rapid_length_mm"] == pytest.approx(159, abs=1)
    assert stats["chord_min_mm"] == pytest.approx(0.085, abs=1e-3)
    assert stats["chord_median_mm"] == pytest.approx(0.426, abs=1e-3)
    assert stats["chord_max_mm"] <= 1.001 + 1e-9
    assert stats["chord_share_below_0_5mm"] == pytest.approx(0.626, abs=1e-3)
    assert stats["feed_main_mm_min"] == 1300 and stats["feed_min_mm_min"] == 800
    assert stats["arc_radius_median_mm"] == pytest.approx(5.0, abs=1e-3)
    assert f"{stats['lines']:,.0f}" in f3.__doc__


def test_leads_feeds_and_rapids_are_the_real_programs():
    """LHchips4's F words are written F999...; restored, its arcs are all R 5 and it cuts most
    of its length at F1300; the bear has no arcs, one feed and 7 rapids; ours: R 5 leads,
    F1300, fewer rapids than either (no pass is far from the one before)."""
    lh = program_statistics(f3.real_cam_text(PUBLIC / "LHchips4.ngc"))
    bear = program_statistics(f3.real_cam_text(PUBLIC / "camotics_bear.nc"))
    ours = program_statistics(finishing3d_program(0))
    np.testing.assert_allclose([lh["arc_radius_min_mm"], lh["arc_radius_max_mm"]], 5.0, atol=1e-3)
    assert lh["feed_main_mm_min"] == 1300.0 and lh["feed_main_share"] > 0.75
    assert (lh["feed_min_mm_min"], lh["feed_max_mm_min"]) == (750.0, 5000.0)
    assert lh["g0"] == 71 and bear["g0"] == 7
    assert math.isnan(bear["arc_radius_median_mm"]) and bear["feed_main_mm_min"] == 6000.0
    assert ours["arc_radius_median_mm"] == pytest.approx(lh["arc_radius_median_mm"], abs=1e-3)
    assert ours["feed_main_mm_min"] == lh["feed_main_mm_min"]
    assert ours["g0"] <= min(lh["g0"], bear["g0"])
    # the restoration only touches a text that holds the post-processor's mark
    assert (
        f3.real_cam_text(PUBLIC / "camotics_bear.nc") == (PUBLIC / "camotics_bear.nc").read_text()
    )
    assert "F999" not in f3.real_cam_text(PUBLIC / "LHchips4.ngc")


def test_chords_are_as_short_as_real_cam_finishing_output():
    """The defaults' reason: the chord lengths of the real CAM finishing programs shipped
    (median 0.29 and 0.53 mm, 62 % and 47 % below 0.5 mm); the tip path over a convex region
    curves at least at the ball's radius r, so a 0.01 mm tolerance could not give chords below
    sqrt(8 r 0.01) = 0.49 mm there."""
    ours = program_statistics(finishing3d_program(0))
    real = [program_statistics((PUBLIC / name).read_text()) for name in REAL_CAM]
    lo = min(r["chord_median_mm"] for r in real)
    hi = max(r["chord_median_mm"] for r in real)
    assert lo <= ours["chord_median_mm"] <= hi
    share = [r["chord_share_below_0_5mm"] for r in real]
    assert min(share) - 0.05 <= ours["chord_share_below_0_5mm"] <= max(share) + 0.05
    old = FinishingParams(tolerance_mm=0.01, max_segment_mm=2.0)
    coarse = program_statistics(finishing3d_program(0, old))
    assert coarse["chord_median_mm"] > 2 * hi


def test_write_and_parse(tmp_path):
    path = write_finishing3d(tmp_path / "sub" / "f3d.nc", 1, SMALL)
    assert path.read_text() == finishing3d_program(1, SMALL)
    assert finishing3d(1, SMALL).allclose(parse(path.read_text()))
    assert not list(path.parent.glob(".*.tmp"))


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"stepover_mm": 0.0}, r"stepover_mm = 0.0 is out of range: allowed \(0, 100\]"),
        ({"tolerance_mm": -0.01}, r"tolerance_mm = -0.01 is out of range"),
        ({"bumps": -1}, r"bumps = -1 is out of range: allowed integers >= 0"),
        ({"max_segment_mm": 0.005}, r"max_segment_mm = 0.005 is out of range: allowed >= 10"),
        ({"steep_angle_deg": 91.0}, r"steep_angle_deg = 91.0 is out of range: allowed \(0, 90\]"),
    ],
)
def test_params_are_checked(changes, message):
    with pytest.raises(ValueError, match=message):
        FinishingParams(**changes)
