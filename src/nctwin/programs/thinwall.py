"""The thin-wall aerospace part of Sun et al. (2022, Fig. 7-8): eight pockets, roughed with
high-performance toolpaths, written as a CAM system writes them.

Each pocket is a separate program with one roughing strategy, the same on every pocket: per depth
level a plunge, trochoidal loops along the middle (round the island of the boss), then
contour-parallel offsets with rounded corners cut from the inside out, joined by short G1 links;
G0 retracts and repositioning moves between levels and regions. Feeds are 3000-4000 mm/min, rapids
G0. The shapes differ in size and topology: rectangular, rounded, a circular boss, an L, a slot,
and two separate regions.

The program is what a CAM post writes for a line-only control: every straight move is one G1
line, however long, and every curve (trochoid loop, rounded corner, loop round the boss) is a
sequence of G1 chords within the chordal tolerance :data:`CHORDAL_TOL_MM` of it, so short chords
where the curve is tight and long ones where it is gentle. Each program starts above its first
entry point at the clearance plane, as a CAM post writes it after the tool change (no rapid from a
remote position), and rapids down to 1 mm above the floor of the level before feeding in. Pocket
1 therefore has rapids towards -X only (back to the start of each level), and pocket 8, whose two
regions are cut left to right, also one towards +X (the paper's Fig. 13).

The pockets' lengths and trochoid loops (:data:`POCKETS`) are calibrated to the paper's
conditions by :mod:`nctwin.chapters.sun2022_part`: each pocket's CAD/CAM time and the
CAD/CAM error on the chapter's machine (Table 3), and pocket 1's cutter locations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_range

__all__ = [
    "CHORDAL_TOL_MM",
    "POCKETS",
    "SHAPES",
    "TROCHOID_ADVANCE_MM",
    "TROCHOID_RADIUS_MM",
    "PocketSpec",
    "pocket_paths",
    "pocket_program",
    "start_mm",
    "thinwall_programs",
]

#: Clearance plane (mm above the part's top face, Z0) the programs start at and retract to.
CLEARANCE_Z_MM = 5.0

#: Depth of one level (mm).
LEVEL_DEPTH_MM = 3.0

#: Chordal tolerance of the G1 chords that stand for a curve (mm): the largest distance between a
#: chord and the curve it replaces. A CAM system roughing a 20 mm cutter writes curves within a
#: few hundredths of a millimetre (CAM defaults for roughing lie between 0.01 and 0.05 mm), well
#: inside the machine's own TCP tolerance of 0.1 mm (an 840D's CYCLE832 roughing setting), so the
#: chords, not the control, carry the curve; 0.02 mm is the middle of that range.
CHORDAL_TOL_MM = 0.05

#: Smallest corner radius of the offsets: HPC toolpaths round every corner (mm).
MIN_CORNER_MM = 3.0

#: Default radius of the trochoidal loops and their advance per loop (mm): an advance of 5 % of
#: the 20 mm cutter, a common trochoidal step. :data:`POCKETS` calibrates the radius per pocket.
TROCHOID_RADIUS_MM = 6.0
TROCHOID_ADVANCE_MM = 1.0

#: The outline shapes a pocket may have.
SHAPES = ("rect", "rounded", "boss", "L", "slot", "twin")

#: Samples per millimetre (and at least per radian) of a curve before it is cut into chords.
_DENSE_PER_MM = 20.0


@dataclass(frozen=True)
class PocketSpec:
    """One pocket of the part.

    Parameters
    ----------
    number : int
        Pocket number (1-8; 0 for a region of a two-region pocket).
    shape : str
        ``"rect"``, ``"rounded"``, ``"boss"`` (rectangle around a circular island), ``"L"``,
        ``"slot"`` (long and narrow) or ``"twin"`` (two regions left and right of a rib).
    center_mm : tuple of 2 floats
        Centre of the pocket on the part (mm).
    size_mm : tuple of 2 floats
        Width (X) and height (Y) of the region the tool centre sweeps (mm), each > 0.
    corner_radius_mm : float
        Radius of the outline's corners (mm, >= 0); the offsets' corners are never tighter than
        :data:`MIN_CORNER_MM`.
    feed_mm_min : float
        Cutting feed (mm/min), > 0.
    depth_levels : int
        Depth levels of :data:`LEVEL_DEPTH_MM`, >= 1.
    trochoid_radius_mm : float
        Radius of the trochoidal loops (mm), in (0, 20].
    trochoid_advance_mm : float
        Advance of the trochoid per loop (mm), in (0, 20].
    """

    number: int
    shape: str
    center_mm: tuple[float, float]
    size_mm: tuple[float, float]
    corner_radius_mm: float
    feed_mm_min: float
    depth_levels: int = 2
    trochoid_radius_mm: float = TROCHOID_RADIUS_MM
    trochoid_advance_mm: float = TROCHOID_ADVANCE_MM

    def __post_init__(self) -> None:
        check_choice("shape", self.shape, SHAPES)
        for i, value in enumerate(self.size_mm):
            check_range(f"size_mm[{i}]", value, 0.0, 2000.0, low_open=True)
        check_range("corner_radius_mm", self.corner_radius_mm, 0.0, 500.0)
        check_range("feed_mm_min", self.feed_mm_min, 0.0, 60000.0, low_open=True)
        check_range("depth_levels", self.depth_levels, 1, 100)
        check_range("trochoid_radius_mm", self.trochoid_radius_mm, 0.0, 20.0, low_open=True)
        check_range("trochoid_advance_mm", self.trochoid_advance_mm, 0.0, 20.0, low_open=True)


#: The eight pockets, 4 x 2 on a part of about 670 x 240 mm with walls of about 3 mm between the
#: regions the cutter (20 mm) sweeps. Shape, feed, outline corner radius, depth levels and the
#: short side are the part's; the rest is calibrated before any network is trained
#: (:func:`nctwin.chapters.sun2022_part.calibrate_pocket`), against the paper's conditions
#: only: the length (the longer side; the regions' height on the two-region pocket 8) so that the
#: CAD/CAM time is Table 3's, the trochoid radius so that the machine's time over CAD/CAM's gives
#: Table 3's CAD/CAM error, and pocket 1's trochoid advance so that it has the paper's 5383 cutter
#: locations. Pockets 2 and 7 sit below the middle of their error band, where tighter loops stop
#: adding error (the loops' share of the path shrinks with their radius). Pocket 3 has two depth
#: levels: with three, the loops round its island alone take longer than its CAD/CAM time at the
#: radius its error needs. The centres follow from the sizes.
POCKETS = (
    PocketSpec(1, "rect", (84.0, 60.0), (127.4, 90.0), 0.0, 3500.0, 4, 1.91, 0.98),
    PocketSpec(2, "rounded", (224.0, 60.0), (107.1, 48.0), 12.0, 3000.0, 2, 0.47),
    PocketSpec(3, "boss", (354.0, 60.0), (107.3, 66.0), 8.0, 3500.0, 2, 2.13),
    PocketSpec(4, "L", (481.0, 60.0), (102.4, 96.0), 0.0, 4000.0, 3, 3.94),
    PocketSpec(5, "slot", (110.0, 180.0), (179.0, 40.0), 0.0, 3500.0, 3, 2.66),
    PocketSpec(6, "rounded", (287.0, 180.0), (130.0, 60.0), 25.0, 3000.0, 2, 0.8),
    PocketSpec(7, "L", (443.0, 180.0), (137.3, 70.0), 6.0, 3500.0, 3, 0.55),
    PocketSpec(8, "twin", (588.0, 180.0), (106.0, 82.2), 4.0, 4000.0, 3, 2.28),
)


# --- curves and their chords -------------------------------------------------------------------


def _arc(center: np.ndarray, r: float, a0: float, a1: float) -> np.ndarray:
    """Dense samples of the arc of radius ``r`` (mm) about ``center`` from angle ``a0`` to ``a1``
    (rad, counter-clockwise where ``a1 > a0``), shape (n, 2)."""
    n = max(16, math.ceil(abs(a1 - a0) * max(r * _DENSE_PER_MM, 8.0)))
    phi = np.linspace(a0, a1, n + 1)
    return np.column_stack([center[0] + r * np.cos(phi), center[1] + r * np.sin(phi)])


def _chords(dense: np.ndarray, tol_mm: float) -> np.ndarray:
    """The chord ends of a smooth curve sampled densely, shape (n, 2) -> (k, 2): chords of length
    ``sqrt(8 rho tol)`` for the local radius of curvature ``rho``, which keeps each chord within
    ``tol_mm`` of the curve; the first and last samples are kept."""
    step = np.diff(dense, axis=0)
    ds = np.linalg.norm(step, axis=1)
    heading = np.unwrap(np.arctan2(step[:, 1], step[:, 0]))
    turn = np.abs(np.diff(heading))  # at the interior samples
    kappa = np.concatenate([[0.0], turn / (0.5 * (ds[1:] + ds[:-1])), [0.0]])
    kappa[0], kappa[-1] = kappa[1], kappa[-2]
    density = np.sqrt(kappa / (8.0 * tol_mm))  # chords per mm
    count = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * ds)])
    n_seg = max(math.ceil(count[-1] - 1e-9), 1)
    index = np.interp(np.linspace(0.0, count[-1], n_seg + 1), count, np.arange(len(dense)))
    lo = np.minimum(index.astype(np.int64), len(dense) - 2)
    frac = (index - lo)[:, None]
    out = (1.0 - frac) * dense[lo] + frac * dense[lo + 1]
    out[0], out[-1] = dense[0], dense[-1]
    return out


def _polyline(pieces: list[np.ndarray], tol_mm: float) -> np.ndarray:
    """One contour from its pieces, shape (k, 2): a piece of two points is a straight move (one
    G1 line), a longer one a densely sampled curve (cut into chords within ``tol_mm``)."""
    out = [pieces[0][:1]]
    for piece in pieces:
        if np.linalg.norm(piece[-1] - piece[0]) < 1e-9 and len(piece) == 2:
            continue
        pts = piece if len(piece) == 2 else _chords(piece, tol_mm)
        out.append(pts[1:])
    return np.vstack(out)


def _rounded_rect(cx, cy, w, h, r) -> list[np.ndarray]:
    """Pieces of the closed counter-clockwise outline of a ``w`` x ``h`` rectangle with corner
    radius ``r``, from the middle of the bottom edge back to it."""
    hw, hh = 0.5 * w, 0.5 * h
    r = min(max(r, 0.0), hw, hh)
    pieces, at = [], np.array([cx, cy - hh])
    for ox, oy, start in ((hw, -hh, -0.5), (hw, hh, 0.0), (-hw, hh, 0.5), (-hw, -hh, 1.0)):
        corner = np.array([cx + ox - math.copysign(r, ox), cy + oy - math.copysign(r, oy)])
        arc = _arc(corner, r, math.pi * start, math.pi * (start + 0.5)) if r > 0 else None
        first = arc[0] if arc is not None else np.array([cx + ox, cy + oy])
        pieces.append(np.array([at, first]))
        if arc is not None:
            pieces.append(arc)
        at = arc[-1] if arc is not None else first
    pieces.append(np.array([at, [cx, cy - hh]]))
    return pieces


def _filleted(poly: np.ndarray, r: float) -> list[np.ndarray]:
    """Pieces of a closed polyline (first point = last, on a straight edge) with every corner
    rounded by a circular arc of radius ``r`` (smaller where an edge is too short for it)."""
    pieces, at = [], poly[0]
    for a, b, c in zip(poly[:-2], poly[1:-1], poly[2:], strict=True):
        u, v = (a - b) / np.linalg.norm(a - b), (c - b) / np.linalg.norm(c - b)
        half = 0.5 * math.acos(float(np.clip(u @ v, -1.0, 1.0)))
        t = min(r / math.tan(half), 0.45 * np.linalg.norm(a - b), 0.45 * np.linalg.norm(c - b))
        rho = t * math.tan(half)
        p, q = b + u * t, b + v * t
        bisector = (u + v) / np.linalg.norm(u + v)
        centre = b + bisector * rho / math.sin(half)
        a0 = math.atan2(p[1] - centre[1], p[0] - centre[0])
        a1 = math.atan2(q[1] - centre[1], q[0] - centre[0])
        sweep = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi  # the short way round
        pieces += [np.array([at, p]), _arc(centre, rho, a0, a0 + sweep)]
        pieces[-1][0], pieces[-1][-1] = p, q
        at = q
    pieces.append(np.array([at, poly[-1]]))
    return pieces


def _l_outline(cx, cy, w, h, d) -> np.ndarray:
    """Closed counter-clockwise L (the top-right quarter cut away), offset inward by ``d``."""
    x0, x1, y0, y1 = cx - 0.5 * w + d, cx + 0.5 * w - d, cy - 0.5 * h + d, cy + 0.5 * h - d
    xm, ym = cx + 0.05 * w - d, cy + 0.05 * h - d  # inner corner moves with the offset
    return np.array(
        [(cx, y0), (x1, y0), (x1, ym), (xm, ym), (xm, y1), (x0, y1), (x0, y0), (cx, y0)]
    )


def _offsets(spec: PocketSpec, stepover: float) -> list[list[np.ndarray]]:
    """Pieces of the contour-parallel offsets of a pocket, innermost first."""
    cx, cy = spec.center_mm
    w, h = spec.size_mm
    r, floor = spec.corner_radius_mm, MIN_CORNER_MM
    out = []
    if spec.shape == "L":
        d = 0.0
        while 0.5 * min(w, h) * 0.9 - d > stepover:
            out.append(_filleted(_l_outline(cx, cy, w, h, d), max(r, floor)))
            d += stepover
        return out[::-1]
    n = int((0.5 * min(w, h) - _island(spec) - stepover) // stepover)
    for i in range(n, -1, -1):
        d = i * stepover
        out.append(_rounded_rect(cx, cy, w - 2 * d, h - 2 * d, max(r - d, floor)))
    return out


def _trochoid(x_from: float, x_to: float, y: float, loop_radius: float, advance: float):
    """Dense samples of trochoidal loops (adaptive-style slotting) along ``y`` from ``x_from``
    to ``x_to``, shape (n, 2); the first point is the start."""
    loops = max(1, int(abs(x_to - x_from) // advance))
    per_loop = max(64, math.ceil(2 * math.pi * loop_radius * _DENSE_PER_MM))
    t = np.linspace(0.0, loops, loops * per_loop + 1)
    phi = 2 * math.pi * t + math.pi
    x = x_from + math.copysign(advance, x_to - x_from) * t + loop_radius * (1 + np.cos(phi))
    return np.column_stack([x, y + loop_radius * np.sin(phi)])


def _ring_trochoid(cx: float, cy: float, ring: float, loop_radius: float, advance: float):
    """Dense samples of trochoidal loops once round a circle of radius ``ring`` about (``cx``,
    ``cy``), counter-clockwise from below the centre, shape (n, 2): loops of ``loop_radius``
    whose centre advances about ``advance`` along the circle per loop."""
    loops = max(1, math.ceil(2 * math.pi * ring / advance))
    per_loop = max(64, math.ceil(2 * math.pi * loop_radius * _DENSE_PER_MM))
    t = np.linspace(0.0, loops, loops * per_loop + 1)
    theta = -0.5 * math.pi + 2 * math.pi * t / loops  # the loops' centre goes round the ring
    psi = 2 * math.pi * t + 0.5 * math.pi  # each loop starts on the island's side
    x = cx + ring * np.cos(theta) + loop_radius * np.cos(psi)
    return np.column_stack([x, cy + ring * np.sin(theta) + loop_radius * np.sin(psi)])


def _island(spec: PocketSpec) -> float:
    """Radius of a boss's island (mm; 0 for the other shapes)."""
    return 0.16 * min(spec.size_mm) if spec.shape == "boss" else 0.0


def _region(spec: PocketSpec, stepover: float) -> list[list[np.ndarray]]:
    """What one depth level cuts, as the pieces of each contour: trochoidal loops along the
    middle (left to right; round the island of a boss), then the contour-parallel offsets."""
    cx, cy = spec.center_mm
    path = _offsets(spec, stepover)
    r, advance = spec.trochoid_radius_mm, spec.trochoid_advance_mm
    if spec.shape == "boss":
        loops = _ring_trochoid(cx, cy, _island(spec) + stepover, r, advance)
    else:
        half = 0.3 * spec.size_mm[0]
        loops = _trochoid(cx - half, cx + half, cy, r, advance)
    return [[loops], *path]


def _regions(spec: PocketSpec, stepover: float) -> list[list[list[np.ndarray]]]:
    """The regions of a pocket in cutting order (two either side of a rib for ``"twin"``)."""
    if spec.shape != "twin":
        return [_region(spec, stepover)]
    cx, cy = spec.center_mm
    w, h = spec.size_mm
    return [
        _region(
            PocketSpec(0, "rounded", (cx + side * 0.275 * w, cy), (0.45 * w, h),
                       spec.corner_radius_mm, spec.feed_mm_min, spec.depth_levels,
                       spec.trochoid_radius_mm, spec.trochoid_advance_mm),
            stepover,
        )
        for side in (-1.0, 1.0)
    ]  # fmt: skip


def pocket_paths(
    spec: PocketSpec, *, stepover_mm: float = 4.0, chordal_tol_mm: float = CHORDAL_TOL_MM
) -> list[list[np.ndarray]]:
    """The cutter locations of one depth level of each region of a pocket (XY), as G1 writes them.

    Parameters
    ----------
    spec : PocketSpec
    stepover_mm : float
        Distance between contour-parallel offsets (mm), in (0, 20].
    chordal_tol_mm : float
        Chordal tolerance of the chords of a curve (mm), in (0, 1].

    Returns
    -------
    list of list of ndarray
        Per region, per contour in cutting order, shape (k, 2): its start then the end of each
        G1 line (mm).
    """
    check_range("stepover_mm", stepover_mm, 0.0, 20.0, low_open=True)
    check_range("chordal_tol_mm", chordal_tol_mm, 0.0, 1.0, low_open=True)
    return [[_polyline(c, chordal_tol_mm) for c in region]
            for region in _regions(spec, stepover_mm)]  # fmt: skip


def start_mm(spec: PocketSpec, *, stepover_mm: float = 4.0) -> tuple[float, float, float]:
    """Where the program of ``spec`` starts (mm): above its first entry point, at the clearance
    plane."""
    check_range("stepover_mm", stepover_mm, 0.0, 20.0, low_open=True)
    x0, y0 = _regions(spec, stepover_mm)[0][0][0][0]
    return (round(float(x0), 4), round(float(y0), 4), CLEARANCE_Z_MM)  # as the program writes it


def pocket_program(
    spec: PocketSpec, *, stepover_mm: float = 4.0, chordal_tol_mm: float = CHORDAL_TOL_MM
) -> str:
    """G-code of one pocket, in mm, absolute, starting at :func:`start_mm`.

    Parameters
    ----------
    spec : PocketSpec
    stepover_mm : float
        Distance between contour-parallel offsets (mm), in (0, 20].
    chordal_tol_mm : float
        Chordal tolerance of the chords of a curve (mm), in (0, 1].
    """
    feed = spec.feed_mm_min
    paths = pocket_paths(spec, stepover_mm=stepover_mm, chordal_tol_mm=chordal_tol_mm)
    x0, y0, z0 = start_mm(spec, stepover_mm=stepover_mm)
    lines = [
        f"(nctwin thin-wall part, pocket {spec.number}: {spec.shape})",
        "G21 G90 G17",
        f"G0 X{x0:.4f} Y{y0:.4f} Z{z0:.1f}",
    ]
    for region in paths:
        for level in range(1, spec.depth_levels + 1):
            x, y = region[0][0]
            lines += [
                f"G0 X{x:.4f} Y{y:.4f}",
                f"G0 Z{1.0 - LEVEL_DEPTH_MM * (level - 1):.1f}",
                f"G1 Z{-LEVEL_DEPTH_MM * level:.1f} F{0.3 * feed:g}",
                f"F{feed:g}",
            ]
            for i, contour in enumerate(region):
                if i:
                    lines.append(f"G1 X{contour[0, 0]:.4f} Y{contour[0, 1]:.4f}")  # link
                lines += [f"G1 X{x:.4f} Y{y:.4f}" for x, y in contour[1:]]
            lines.append(f"G0 Z{CLEARANCE_Z_MM:.1f}")
    lines.append("M30")
    return "\n".join(lines) + "\n"


def thinwall_programs(**kwargs) -> dict[int, str]:
    """The programs of all eight pockets, keyed by pocket number; see :func:`pocket_program`."""
    return {spec.number: pocket_program(spec, **kwargs) for spec in POCKETS}
