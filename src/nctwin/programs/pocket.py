"""A contour-parallel pocket around an island, as a CAM system writes it: the pocketing test path
of Chien et al. (2023, Fig. 8-9, after Endo & Sencer 2022).

The part: a pocket whose outline (:data:`OUTLINE_MM`) is a polygon with sharp corners, small
corner fillets, a chamfer, a bulge of one wall and one large-radius corner, and an island that
follows the outline at a distance :data:`BAND_MM`, so the floor to clear is a band of constant
width between two walls. The tool (radius ``tool_radius_mm``) clears the band with
contour-parallel offsets:

* **Offsets.** At every level :math:`d` (the tool centre's distance from the nearest wall) there
  are two rings: the outline offset inward by :math:`d` (straight walls stay single long G-lines;
  a convex fillet of radius :math:`r` becomes :math:`r - d`, sharp once :math:`d \\ge r`) and the
  island offset outward by :math:`d` (its sharp corners become arcs of radius :math:`d`, its
  fillets grow). The levels are evenly spaced from ``tool_radius_mm`` at both walls to the middle
  of the band, at most ``stepover_mm`` apart.
* **Corner clean-up.** Where the outline has a sharp convex corner, the band is wider along the
  corner's bisector than across it: a floor region in the corner is more than half the band from
  both walls. The levels beyond the middle there are small closed loops (two offset walls and an
  arc about the island's corner); the middle ring cuts them as it passes the corner, going out
  along the bisector loop by loop and back.
* **Order and links.** Inside out, climb milling: level by level from the middle of the band to
  the walls, the island's ring clockwise and the outline's ring counter-clockwise. Every ring
  starts and ends on the bottom wall; straight G1 links across material already cleared join
  them (stay-down linking), so the program is one chain of feed moves at one depth.
* **Arcs** (fillets, the arcs of the island's offsets) are written as chords within
  ``chord_tol_mm`` of the arc, as a CAM post-processor that outputs only G1 does.

:func:`pocket_stats` gives the statistics of a path; the pockets of Chien et al. (2023)
Tables 2 and 3 are :mod:`nctwin.programs.band_pocket`.
"""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_range

__all__ = [
    "BAND_MM",
    "OUTLINE_MM",
    "pocket_program",
    "pocket_rings",
    "pocket_stats",
]

#: Outline of the pocket's wall, counter-clockwise: vertices (mm) and the fillet radius of each
#: corner (0: sharp). A 5 mm fillet bottom-left, a sharp corner bottom-right, a chamfer of two
#: sharp 135-degree corners top-right, a shallow bulge of the top wall into the pocket (6 mm
#: fillets at its foot, 15 mm at its two reflex corners), a large 70 mm round top-left and
#: a 12 mm fillet where the slanted wall meets the left side. Edge 0 (the bottom wall) is
#: horizontal: every ring starts on it.
OUTLINE_MM = (
    ((0.0, 0.0), 5.0),
    ((230.0, 0.0), 0.0),
    ((230.0, 120.0), 0.0),
    ((200.0, 150.0), 0.0),
    ((170.0, 150.0), 6.0),
    ((148.0, 140.0), 15.0),
    ((117.0, 140.0), 15.0),
    ((95.0, 150.0), 6.0),
    ((60.0, 150.0), 70.0),
    ((0.0, 100.0), 12.0),
)
#: Width of the floor between the outline and the island (mm); the island is the outline offset
#: inward by this distance (its corners sharp where the outline's fillet is smaller).
BAND_MM = 42.0


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _offset(vertices: np.ndarray, radii: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray]:
    """Offset a counter-clockwise polygon with corner fillets by ``d`` to its inside (``d < 0``:
    outside). Every edge moves by ``d``; a convex corner's fillet becomes ``r - d``, a reflex one's
    ``r + d`` (0: sharp), so a sharp corner offset outward becomes an arc of radius ``-d``.

    Returns the vertices, shape (m, 2), and radii, shape (m,), of the offset polygon.
    """
    u = _unit(np.roll(vertices, -1, axis=0) - vertices)  # edge i: vertex i -> i + 1
    n = np.column_stack([-u[:, 1], u[:, 0]])  # inward normal of a ccw polygon
    p = vertices + d * n
    u_in, p_in = np.roll(u, 1, axis=0), np.roll(p, 1, axis=0)  # the edge arriving at vertex i
    # vertex i: intersection of the offset edges i - 1 and i
    cross = u_in[:, 0] * u[:, 1] - u_in[:, 1] * u[:, 0]
    w = p - p_in
    s = (w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0]) / cross
    convex = cross > 0
    return p_in + s[:, None] * u_in, np.maximum(np.where(convex, radii - d, radii + d), 0.0)


def _ring(
    vertices: np.ndarray,
    radii: np.ndarray,
    start: np.ndarray,
    chord_tol: float,
    excursions: dict[int, list[np.ndarray]] | None = None,
) -> np.ndarray:
    """Points of a closed counter-clockwise ring, from ``start`` (a point on edge 0 -> 1) around
    and back: straight edges as one segment, fillets as chords within ``chord_tol``. At a sharp
    vertex ``i`` of ``excursions``, the tool cuts those loops (each from and back to its first
    point) and returns to the vertex.

    Raises ValueError where a fillet does not fit on its edges (the offset has collapsed)."""
    m = len(vertices)
    u = _unit(np.roll(vertices, -1, axis=0) - vertices)
    u_in = np.roll(u, 1, axis=0)
    turn = np.arctan2(u_in[:, 0] * u[:, 1] - u_in[:, 1] * u[:, 0], (u_in * u).sum(axis=1))
    tangent = radii * np.tan(0.5 * np.abs(turn))  # from the vertex to the fillet's ends
    edge = np.linalg.norm(np.roll(vertices, -1, axis=0) - vertices, axis=1)
    if (tangent + np.roll(tangent, -1) > edge + 1e-9).any():
        raise ValueError("the offset has collapsed: a fillet no longer fits on its edges")
    pts = [start]
    for i in [*range(1, m), 0]:
        v, r = vertices[i], radii[i]
        if r == 0:
            pts.append(v)
            if excursions and i in excursions:
                pts += [p for loop in excursions[i] for p in loop] + [v]
            continue
        a = v - u_in[i] * tangent[i]
        normal = np.sign(turn[i]) * np.array([-u_in[i, 1], u_in[i, 0]])
        centre = a + r * normal
        phi0 = math.atan2(a[1] - centre[1], a[0] - centre[0])
        n = max(1, math.ceil(abs(turn[i]) / (2 * math.acos(max(1 - chord_tol / r, -1.0)))))
        phi = phi0 + turn[i] * np.linspace(0.0, 1.0, n + 1)
        pts += list(centre + r * np.column_stack([np.cos(phi), np.sin(phi)]))
    pts.append(start)
    return np.array(pts)


def _corner_loop(
    vertices: np.ndarray, i: int, island_vertex: np.ndarray, d: float, chord_tol: float
) -> np.ndarray | None:
    """The clean-up loop at level ``d`` in the sharp corner ``i`` of the offset outline
    ``vertices``, or None where the level does not reach into the corner: from the corner back
    along the arriving wall, around the island's corner (an arc of radius ``d`` about it) and
    back along the leaving wall, shape (n, 2)."""
    m = len(vertices)
    corner = vertices[i]
    w = corner - island_vertex
    if np.linalg.norm(w) <= d:
        return None
    ends = []
    for other in (vertices[(i - 1) % m], vertices[(i + 1) % m]):  # each wall meets the circle
        e = _unit(other - corner)
        b = e @ w
        ends.append(corner + (-b - math.sqrt(max(b * b - (w @ w - d * d), 0.0))) * e)
    a0, a1 = (math.atan2(p[1] - island_vertex[1], p[0] - island_vertex[0]) for p in ends)
    sweep = (a0 - a1 + math.pi) % (2 * math.pi) - math.pi  # the short way round the island
    n = max(1, math.ceil(abs(sweep) / (2 * math.acos(max(1 - chord_tol / d, -1.0)))))
    phi = a0 - sweep * np.linspace(0.0, 1.0, n + 1)
    arc = island_vertex + d * np.column_stack([np.cos(phi), np.sin(phi)])
    return np.vstack([corner, arc, corner])


def pocket_rings(
    *,
    tool_radius_mm: float = 4.0,
    stepover_mm: float = 2.0,
    chord_tol_mm: float = 0.001,
    outline_scale: float = 1.0,
) -> list[np.ndarray]:
    """The tool-centre path of the pocket as closed polylines in cutting order (island and
    outline ring per level, middle out; the first outline ring with the corner loops), each
    shape (n_i, 2).

    See the module docstring; the parameters are those of :func:`pocket_program`, and
    ``outline_scale`` scales the outline, its fillets and the band about the origin.
    """
    verts = outline_scale * np.array([p for p, _ in OUTLINE_MM])
    radii = outline_scale * np.array([r for _, r in OUTLINE_MM])
    band = outline_scale * BAND_MM
    island = _offset(verts, radii, band)
    width = band - 2 * tool_radius_mm
    n_levels = math.ceil(width / stepover_mm) + 1  # positions across the band, walls included
    step = width / (n_levels - 1)
    levels = tool_radius_mm + step * np.arange((n_levels + 1) // 2)[::-1]  # middle first
    x_start = 0.4 * verts[1, 0]
    half = 0.5 * band
    # corner loops beyond the middle, in the outline's corners where the island's is sharp
    corners = np.flatnonzero(island[1] == 0)
    loops: dict[int, list[np.ndarray]] = {int(i): [] for i in corners}
    d = levels[0] + step
    while True:
        offset = _offset(verts, radii, d)
        found = False
        for i in corners:
            loop = _corner_loop(offset[0], i, island[0][i], d, chord_tol_mm)
            if loop is not None and offset[1][i] == 0:
                loops[int(i)].append(loop)
                found = True
        if not found:
            break
        d += step
    rings = []
    for k, d in enumerate(levels):
        if d < half - 0.25 * step:  # the middle level is cut once, by the outline's ring
            poly = _offset(*island, -d)
            start = np.array([x_start, poly[0][0, 1]])
            rings.append(_ring(*poly, start, chord_tol_mm)[::-1])
        poly = _offset(verts, radii, d)
        start = np.array([x_start, poly[0][0, 1]])
        rings.append(_ring(*poly, start, chord_tol_mm, loops if k == 0 else None))
    return rings


def pocket_program(
    *,
    feed_mm_s: float = 92.0,
    tol_mm: float | None = None,
    tool_radius_mm: float = 4.0,
    stepover_mm: float = 2.0,
    chord_tol_mm: float = 0.001,
) -> str:
    """G-code of the pocket, in mm, absolute: a plunge in the middle of the band, then the
    tool-centre path of :func:`pocket_rings` as one chain of G1 moves at one depth.

    The defaults (an 8 mm end mill, a 2 mm stepover, 1 um chordal tolerance) give about 4700
    G-lines over 10.4 m, like the pocketing path of Chien et al. (2023, Table 2: about 5000).

    Parameters
    ----------
    feed_mm_s : float
        Programmed feed.
    tol_mm : float, optional
        A ``G64 P`` blending tolerance for the program; none: the machine's.
    tool_radius_mm : float
        Radius of the end mill: the outermost rings run this far from the walls.
    stepover_mm : float
        Largest distance between neighbouring rings.
    chord_tol_mm : float
        Largest distance between an arc and its chords.

    Returns
    -------
    str
    """
    check_range("feed_mm_s", feed_mm_s, 0.0, 1000.0, low_open=True)
    check_range("tool_radius_mm", tool_radius_mm, 0.0, 0.25 * BAND_MM, low_open=True)
    check_range("stepover_mm", stepover_mm, 0.0, 2.0 * tool_radius_mm, low_open=True)
    check_range("chord_tol_mm", chord_tol_mm, 0.0, 0.1 * tool_radius_mm, low_open=True)
    if tol_mm is not None:
        check_range("tol_mm", tol_mm, 0.0, math.inf, low_open=True)
    path = np.vstack(
        pocket_rings(
            tool_radius_mm=tool_radius_mm, stepover_mm=stepover_mm, chord_tol_mm=chord_tol_mm
        )
    )
    return _program_text(path, feed_mm_s, tol_mm)


def _program_text(
    path_mm: np.ndarray,
    feed_mm_s: float,
    tol_mm: float | None,
    title: str = "contour-parallel offsets around an island, middle out",
) -> str:
    """G-code of a tool-centre path, shape (n, 2): rounded to 0.1 um, repeated points dropped,
    a plunge at its first point, then one G1 per point; ``title`` is its first comment.

    Raises ValueError unless ``feed_mm_s`` is in (0, 1000] and ``tol_mm`` (if given) positive."""
    check_range("feed_mm_s", feed_mm_s, 0.0, 1000.0, low_open=True)
    if tol_mm is not None:
        check_range("tol_mm", tol_mm, 0.0, math.inf, low_open=True)
    path = np.round(path_mm, 4)
    keep = np.append(True, (np.diff(path, axis=0) != 0).any(axis=1))
    path = path[keep]
    lines = [f"(nctwin pocket: {title})", "G21 G90 G17"]
    if tol_mm is not None:
        lines.append(f"G64 P{tol_mm:g}")
    lines += [
        "G0 Z5",
        f"G0 X{path[0, 0]:.4f} Y{path[0, 1]:.4f}",
        "G1 Z-3 F600",
        f"F{feed_mm_s * 60:g}",
    ]
    lines += [f"G1 X{x:.4f} Y{y:.4f}" for x, y in path[1:]]
    lines += ["G0 Z5", "M30"]
    return "\n".join(lines) + "\n"


def pocket_stats(path_mm: np.ndarray, *, short_mm: float = 1.0) -> dict[str, float]:
    """Statistics of a tool-centre path, shape (n, 2), as :func:`_program_text` writes it.

    Returns
    -------
    dict
        ``lines`` (G1 moves), ``path_m``, the segment-length quantiles ``seg_p10_mm``,
        ``seg_p50_mm``, ``seg_p90_mm``, ``seg_max_mm``, the share of G-lines shorter than
        ``short_mm`` (``short_share_pct``) and of the path on them (``short_length_pct``).
    """
    path = np.round(path_mm, 4)
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    seg = seg[seg > 0]
    short = seg < short_mm
    p10, p50, p90 = np.percentile(seg, [10, 50, 90])
    return {"lines": len(seg), "path_m": seg.sum() / 1000.0, "seg_p10_mm": p10,
            "seg_p50_mm": p50, "seg_p90_mm": p90, "seg_max_mm": seg.max(),
            "short_share_pct": 100.0 * short.mean(),
            "short_length_pct": 100.0 * seg[short].sum() / seg.sum()}  # fmt: skip
