"""The pocketing test program of Chien et al. (2023): a contour-parallel pocket around an island,
checked by facts a machinist can check on a drawing of it."""

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from nctwin import gcode
from nctwin.chapters import chien2023 as ch
from nctwin.programs.pocket import BAND_MM, OUTLINE_MM, pocket_program, pocket_rings

TOOL_R = 4.0


def _wall(step_mm: float = 0.1) -> np.ndarray:
    """The outline with its fillets as dense points (independent of the generator's offsets)."""
    v = np.array([p for p, _ in OUTLINE_MM])
    r = np.array([q for _, q in OUTLINE_MM])
    m = len(v)
    arcs = []
    for i in range(m):
        a, b, c = v[i - 1], v[i], v[(i + 1) % m]
        u1, u2 = (b - a) / np.linalg.norm(b - a), (c - b) / np.linalg.norm(c - b)
        turn = math.atan2(u1[0] * u2[1] - u1[1] * u2[0], u1 @ u2)
        start = b - u1 * r[i] * math.tan(abs(turn) / 2)
        centre = start + r[i] * math.copysign(1, turn) * np.array([-u1[1], u1[0]])
        phi = math.atan2(*(start - centre)[::-1]) + turn * np.linspace(0, 1, 200)
        arcs.append(centre + r[i] * np.column_stack([np.cos(phi), np.sin(phi)]))
    pts = []
    for i in range(m):  # the fillet at vertex i, then the straight wall to fillet i + 1
        end, nxt = arcs[i][-1], arcs[(i + 1) % m][0]
        n = max(2, int(np.linalg.norm(nxt - end) / step_mm))
        pts += [arcs[i], end + np.linspace(0, 1, n)[:, None] * (nxt - end)]
    pts = np.vstack(pts)
    return pts[np.append(True, (np.diff(pts, axis=0) != 0).any(axis=1))]


@pytest.fixture(scope="module")
def path():
    tp = ch.cutting_blocks(gcode.parse(pocket_program(feed_mm_s=92.0, tol_mm=0.32)))
    return np.vstack([tp.start_mm[:1, :2], tp.end_mm[:, :2]]), tp


def _dense(points: np.ndarray, step_mm: float = 0.1) -> np.ndarray:
    seg = np.diff(points, axis=0)
    n = np.maximum(1, np.ceil(np.linalg.norm(seg, axis=1) / step_mm).astype(int))
    k = np.repeat(np.arange(len(seg)), n)
    frac = (np.arange(len(k)) - np.repeat(np.cumsum(n) - n, n)) / n[k]
    return points[k] + frac[:, None] * seg[k]


def test_about_5000_short_and_long_g1_lines_at_one_depth(path):
    _, tp = path
    assert 4000 <= len(tp) <= 6000
    np.testing.assert_allclose(tp.feed_mm_s, 92.0)
    np.testing.assert_allclose(tp.effective_tolerance_mm(1.0), 0.32)
    assert np.ptp(tp.end_mm[:, 2]) == 0  # one depth
    np.testing.assert_array_equal(tp.start_mm[1:], tp.end_mm[:-1])  # one chain
    lengths = tp.lengths_mm
    assert (lengths < 1.0).mean() > 0.5  # arcs in short chords
    assert (lengths > 50.0).sum() >= 50  # long straight walls, several per ring


def test_rings_closed_outline_ccw_island_cw():
    rings = pocket_rings()
    for ring in rings:
        np.testing.assert_allclose(ring[0], ring[-1], atol=1e-9)
    area = [0.5 * np.sum(r[:-1, 0] * r[1:, 1] - r[1:, 0] * r[:-1, 1]) for r in rings]
    # climb milling: counter-clockwise along the outline, clockwise around the island
    assert area[-1] > 0 and area[-2] < 0  # the finishing passes along the wall and the island
    assert abs(sum(a > 0 for a in area) - sum(a < 0 for a in area)) <= 1


def test_every_level_one_stepover_apart_on_the_bottom_wall(path):
    p, _ = path
    # the horizontal passes of the bottom region cross x = 150: one per ring
    seg_a, seg_b = p[:-1], p[1:]
    horizontal = (
        (seg_a[:, 1] == seg_b[:, 1])
        & (np.minimum(seg_a[:, 0], seg_b[:, 0]) < 150)
        & (np.maximum(seg_a[:, 0], seg_b[:, 0]) > 150)
    )
    y = np.unique(np.round(seg_a[horizontal, 1], 3))
    y = y[y < BAND_MM]
    assert y[0] == pytest.approx(TOOL_R, abs=1e-3)  # the last pass along the wall
    assert y[-1] == pytest.approx(BAND_MM - TOOL_R, abs=1e-3)  # the last pass along the island
    gaps = np.diff(y)
    np.testing.assert_allclose(gaps, gaps[0], atol=2e-3)
    assert gaps[0] <= 2.0 + 1e-9


def test_no_gouge_and_the_whole_floor_is_cut(path):
    p, _ = path
    wall = _wall()
    tangent = np.gradient(wall, axis=0)
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])  # inward: the wall runs ccw
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    wall_tree = cKDTree(wall)

    def inside_and_depth(points):
        d, i = wall_tree.query(points)
        return ((points - wall[i]) * normal[i]).sum(axis=1) > 0, d

    dense = _dense(p)
    inside, d_path = inside_and_depth(dense)
    assert inside.all() and d_path.min() > TOOL_R - 0.01  # the tool's edge spares the wall
    # the island is the outline offset inward by BAND_MM: its edge is where the wall's inward
    # normals at that distance are no nearer to another part of the wall
    offset = wall + BAND_MM * normal
    island_edge = offset[inside_and_depth(offset)[1] > BAND_MM - 1e-6]
    assert cKDTree(island_edge).query(dense)[0].min() > TOOL_R - 0.01  # and the island
    # every point the tool can reach (its centre at least its radius from both) is cut
    gx, gy = np.meshgrid(np.arange(0.25, 230, 0.5), np.arange(0.25, 150, 0.5))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    inside, d = inside_and_depth(grid)
    reachable = grid[inside & (d >= TOOL_R) & (d <= BAND_MM - TOOL_R)]
    assert cKDTree(dense).query(reachable)[0].max() < TOOL_R


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"feed_mm_s": 0.0}, "feed_mm_s"), ({"stepover_mm": 9.0}, "stepover_mm"),
     ({"chord_tol_mm": float("nan")}, "chord_tol_mm"), ({"tol_mm": -0.1}, "tol_mm")],
)  # fmt: skip
def test_bad_parameters_named(kwargs, name):
    with pytest.raises(ValueError, match=name):
        pocket_program(**kwargs)


def test_pocket_stats_by_hand():
    from nctwin.programs.pocket import pocket_stats

    s = pocket_stats(np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 4.5], [3.0, 4.5], [3.0, 4.0]]))
    assert s["lines"] == 3  # the repeated point is no G-line
    assert s["path_m"] == pytest.approx(6.0e-3)
    assert s["short_share_pct"] == pytest.approx(200 / 3)
    assert s["short_length_pct"] == pytest.approx(100 * 1.0 / 6.0)
    assert s["seg_max_mm"] == 5.0
