"""The band pocket (zig-zag across the band, then a finishing ring along each wall), checked by
hand on the part's straight bottom wall and by a property over the allowed bands."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path

from nctwin.programs import band_pocket as bp
from nctwin.programs.pocket import OUTLINE_MM, _offset, _ring, pocket_stats
from nctwin.report.papers import load_paper_table

R = 4.0
STEP = 2.0


def _rows(spec: bp.PaperPocket) -> tuple[np.ndarray, np.ndarray]:
    """Start and end points of the zig-zag's rows: its G-lines longer than the stepover (the
    links along a ring are at most a stepover of arc), shapes (n, 2), (n, 2)."""
    zigzag = bp.band_pocket_rings(spec)[0]
    seg = np.linalg.norm(np.diff(zigzag, axis=0), axis=1)
    rows = np.flatnonzero(seg > spec.stepover_mm + 1e-9)
    return zigzag[rows], zigzag[rows + 1]


@pytest.mark.parametrize("step", [STEP, 2 * R])  # Table 2's stepover and Table 3's (2R)
def test_rows_on_the_bottom_wall_by_hand(step):
    # bottom wall y = 0 from x = 0 to 230: the outline's ring runs at y = R, the island's at
    # y = band - R, between the island's sharp corners x = band and 230 - band
    band = 25.0
    spec = bp.PaperPocket(outline_scale=1.0, band_mm=band, chord_tol_mm=1e-3, stepover_mm=step)
    start, end = _rows(spec)
    assert np.allclose(start[0], [115.0, band - R])  # the middle of the island's bottom wall
    wall = (start[:, 0] > band + 1) & (start[:, 0] < 230 - band - 1) & (start[:, 1] < band)
    assert wall.sum() >= 178 / step  # 178 mm of wall, rows at most a stepover apart
    assert np.diff(np.sort(start[wall, 0])).max() <= step + 1e-9
    assert np.allclose(start[wall, 0], end[wall, 0])  # along the wall's normal
    assert np.allclose(np.sort([start[wall, 1], end[wall, 1]], axis=0), [[R], [band - R]])
    assert np.allclose(np.linalg.norm(end[wall] - start[wall], axis=1), band - 2 * R)
    # alternating: island -> outline, outline -> island
    assert np.allclose(end[0, 1], R) and np.allclose(start[1, 1], R)


@pytest.mark.parametrize("step", [STEP, 2 * R])
def test_rows_are_spaced_by_at_most_the_stepover_on_both_rings(step):
    spec = bp.PaperPocket(outline_scale=1.0, band_mm=25.0, chord_tol_mm=1e-3, stepover_mm=step)
    start, end = _rows(spec)
    feet = np.where((np.arange(len(start)) % 2 == 0)[:, None], start, end)  # island side
    tips = np.where((np.arange(len(start)) % 2 == 0)[:, None], end, start)
    gaps = [np.linalg.norm(np.diff(side, axis=0), axis=1) for side in (feet, tips)]
    assert max(g.max() for g in gaps) <= step + 1e-9
    assert np.maximum(*gaps).min() > 0.75 * step  # no crowding on both rings at once


def test_rows_in_the_sharp_corner_run_longer_than_the_band():
    # in the outline's sharp bottom-right corner the band is 25 sqrt(2) wide along the bisector
    start, end = _rows(bp.PaperPocket(outline_scale=1.0, band_mm=25.0, chord_tol_mm=1e-3))
    assert np.linalg.norm(end - start, axis=1).max() > 25.0


def test_one_connected_chain_and_g_code():
    spec = bp.PaperPocket(outline_scale=1.0, band_mm=25.0, chord_tol_mm=1e-3)
    rings = bp.band_pocket_rings(spec)
    for a, b in itertools.pairwise(rings):
        assert np.allclose(a[-1], b[0])
    # the finishing rings go once round each wall: x from R to 230 - R along the outline's,
    # from band - R to 230 - band + R along the island's
    outline_ring, island_ring = sorted((rings[1], rings[3]), key=lambda r: r[:, 0].min())
    assert np.allclose([outline_ring[:, 0].min(), outline_ring[:, 0].max()], [R, 230 - R])
    assert np.allclose([island_ring[:, 0].min(), island_ring[:, 0].max()], [21.0, 209.0])
    for ring in (outline_ring, island_ring):
        assert np.allclose(ring[0], ring[-1])
    text = bp.band_pocket_program(spec, feed_mm_s=92.0, tol_mm=0.32)
    lines = text.splitlines()
    assert "G64 P0.32" in lines and "F5520" in lines
    g1 = [line for line in lines if line.startswith("G1 X")]
    assert len(g1) == pocket_stats(np.vstack(rings))["lines"]


def test_frozen_pockets_meet_the_papers_statistics():
    summary = load_paper_table("chien2023_summary").set_index("quantity")
    lines = summary.value["pocketing_glines"]
    for name in ("table2", "table3"):
        rows = load_paper_table(f"chien2023_{name}")
        implied_m = rows.cam_s * rows.feed_mm_s / 1000.0
        stats = pocket_stats(np.vstack(bp.paper_pocket_rings(name)))
        assert implied_m.min() <= stats["path_m"] <= implied_m.max()
        assert stats["path_m"] == pytest.approx(implied_m.mean(), rel=0.01)
    stats = pocket_stats(np.vstack(bp.paper_pocket_rings("table2")))
    assert stats["lines"] == pytest.approx(lines, rel=0.02)
    assert bp.PAPER_POCKETS["table3"].chord_tol_mm == bp.PAPER_POCKETS["table2"].chord_tol_mm


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"band_mm": 9.0}, r"^band_mm = 9.0 is out of range: allowed \[10, 44\]$"),
        ({"band_mm": 50.0}, r"^band_mm = 50.0 is out of range: allowed \[10, 44\]$"),
        ({"chord_tol_mm": 0.0}, r"^chord_tol_mm = 0.0 is out of range: allowed \(0, 0.4\]$"),
        ({"stepover_mm": 9.0}, r"^stepover_mm = 9.0 is out of range: allowed \(0, 8\]$"),
        ({"outline_scale": 0.1}, r"^outline_scale = 0.1 is out of range: allowed \[0.3, 5\]$"),
    ],
)
def test_bad_settings_give_one_clear_line(changes, message):
    with pytest.raises(ValueError, match=message):
        bp.PaperPocket(**{"outline_scale": 1.0, "band_mm": 25.0, "chord_tol_mm": 1e-3, **changes})


def test_bad_names_and_feeds():
    with pytest.raises(ValueError, match=r"^name = 'table4' is unknown: allowed table2, table3$"):
        bp.paper_pocket_program("table4", feed_mm_s=92.0)
    with pytest.raises(ValueError, match=r"^feed_mm_s = 0.0 is out of range"):
        bp.paper_pocket_program("table2", feed_mm_s=0.0)


def _wall(scale: float, inset_mm: float) -> np.ndarray:
    """The outline offset inward by ``inset_mm`` as a fine closed polyline, shape (n, 2)."""
    verts = scale * np.array([p for p, _ in OUTLINE_MM])
    radii = scale * np.array([r for _, r in OUTLINE_MM])
    poly = _offset(verts, radii, inset_mm)
    return _ring(*poly, 0.5 * (poly[0][0] + poly[0][1]), 1e-4)


def _distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 2) from a polyline (m, 2), shape (n,)."""
    a, b = polyline[:-1], polyline[1:]
    d = b - a
    w = points[:, None, :] - a[None]
    f = np.clip((w * d).sum(-1) / (d * d).sum(-1), 0.0, 1.0)
    return np.linalg.norm(w - f[..., None] * d, axis=-1).min(axis=1)


@settings(max_examples=15, deadline=None)
@given(
    scale=st.floats(0.5, 2.0),
    band_share=st.floats(0.0, 1.0),
)
def test_every_band_gives_one_chain_between_the_walls(scale, band_share):
    low, high = 2 * R + STEP, bp.BAND_MAX_PER_SCALE_MM * scale
    band = low + band_share * (high - low)
    tol = 1e-3
    spec = bp.PaperPocket(outline_scale=scale, band_mm=band, chord_tol_mm=tol)
    rings = bp.band_pocket_rings(spec)
    for a, b in itertools.pairwise(rings):
        assert np.allclose(a[-1], b[0])
    path = np.vstack(rings)
    outline, island = _wall(scale, 0.0), _wall(scale, band)
    assert Path(outline).contains_points(path).all()
    assert not Path(island).contains_points(path).any()
    assert _distance(path, outline).min() >= R - tol - 2e-4  # the walls as chords within 0.1 um
    assert _distance(path, island).min() >= R - tol - 2e-4  # the walls as chords within 0.1 um


def test_calibration_targets_are_the_papers_statistics():
    from nctwin.chapters.chien2023_pocket import pocket_targets

    rows = load_paper_table("chien2023_table3")
    targets = pocket_targets("chien2023_table3")
    implied_m = rows.cam_s * rows.feed_mm_s / 1000.0  # CAM runs every G-line at F
    assert targets["path_m"] == pytest.approx(implied_m.mean())
    assert (targets["path_m_min"], targets["path_m_max"]) == (implied_m.min(), implied_m.max())
    summary = load_paper_table("chien2023_summary").set_index("quantity")
    assert targets["lines"] == summary.value["pocketing_glines"]


@pytest.mark.parametrize("band_mm", [20.233, 50.072, 70.993])
def test_the_smallest_scale_holds_its_band(band_mm):
    # 44 mm of band per unit of scale: 50.072 / 44 = 1.138 exactly, but 44 * 1.138 falls 4e-15
    # short in floating point; the scale a band gets must hold it, and one step less must not
    from nctwin.chapters.chien2023_pocket import _smallest_scale

    scale = _smallest_scale(band_mm)
    assert bp.BAND_MAX_PER_SCALE_MM * scale >= band_mm
    assert bp.BAND_MAX_PER_SCALE_MM * (scale - 1e-5) < band_mm
    bp.PaperPocket(outline_scale=scale, band_mm=band_mm, chord_tol_mm=1e-4)  # accepted
