"""The thin-wall aerospace part of Sun et al. (2022, Fig. 7-8): eight pockets, roughed with
high-performance toolpaths.

Each pocket is a separate program with one roughing strategy, the same on every pocket: per depth
level a plunge, trochoidal loops of one radius (:data:`TROCHOID_RADIUS_MM`) along the middle, then
contour-parallel offsets cut from the inside out, joined by short G1 links; G0 retracts and
repositioning moves between levels and regions. Feeds are 3000-4000 mm/min, rapids G0. The shapes
differ in size and topology: rectangular, rounded, a circular boss, an L, a slot, and two separate
regions.

Curves and straight moves are written as G1 chords of about :data:`SEGMENT_MM` (the paper's
pocket 1 has 5383 cutter locations over a roughing path of some 16 m). Each program starts above
its first entry point at the clearance plane, as a CAM post writes it after the tool change (no
rapid from a remote position), and rapids down to 1 mm above the floor of the level before
feeding in. Pocket 1 therefore has rapids towards -X only (back to the start of each level), and
pocket 8, whose two regions are cut left to right, also one towards +X (the paper's Fig. 13).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "POCKETS",
    "SEGMENT_MM",
    "TROCHOID_RADIUS_MM",
    "PocketSpec",
    "pocket_program",
    "start_mm",
    "thinwall_programs",
]

#: Clearance plane (mm above the part's top face, Z0) the programs start at and retract to.
CLEARANCE_Z_MM = 5.0

#: Depth of one level (mm).
LEVEL_DEPTH_MM = 3.0

#: Chord length of the G1 moves (mm): CAM output of high-performance roughing is a dense point
#: sequence; the paper's pocket 1 has 5383 cutter locations over some 16 m (about 3 mm each).
SEGMENT_MM = 3.0

#: Smallest corner radius of the offsets: HPC toolpaths round every corner (mm).
MIN_CORNER_MM = 3.0


@dataclass(frozen=True)
class PocketSpec:
    """One pocket of the part.

    Parameters
    ----------
    number : int
        Pocket number (1-8).
    shape : str
        ``"rect"``, ``"rounded"``, ``"boss"`` (rectangle around a circular island), ``"L"``,
        ``"slot"`` (long and narrow) or ``"twin"`` (two regions left and right of a rib).
    center_mm : tuple of 2 floats
        Centre of the pocket on the part.
    size_mm : tuple of 2 floats
        Width (X) and height (Y) of the region the tool centre sweeps.
    corner_radius_mm : float
        Radius of the outline's corners (0: sharp).
    feed_mm_min : float
        Cutting feed.
    depth_levels : int
        Depth levels of :data:`LEVEL_DEPTH_MM`.
    """

    number: int
    shape: str
    center_mm: tuple[float, float]
    size_mm: tuple[float, float]
    corner_radius_mm: float
    feed_mm_min: float
    depth_levels: int = 2


#: The eight pockets (4 x 2 on a 560 x 240 mm part).
POCKETS = (
    PocketSpec(1, "rect", (70.0, 60.0), (110.0, 90.0), 0.0, 3500.0, 4),
    PocketSpec(2, "rounded", (200.0, 60.0), (66.0, 48.0), 12.0, 3000.0),
    PocketSpec(3, "boss", (330.0, 60.0), (96.0, 76.0), 8.0, 3500.0, 3),
    PocketSpec(4, "L", (470.0, 60.0), (114.0, 96.0), 0.0, 4000.0, 3),
    PocketSpec(5, "slot", (100.0, 180.0), (165.0, 40.0), 0.0, 3500.0, 3),
    PocketSpec(6, "rounded", (250.0, 180.0), (90.0, 60.0), 25.0, 3000.0),
    PocketSpec(7, "L", (380.0, 180.0), (86.0, 70.0), 6.0, 3500.0, 3),
    PocketSpec(8, "twin", (500.0, 180.0), (106.0, 68.0), 4.0, 4000.0, 3),
)


def _rounded_rect(cx, cy, w, h, r, seg_mm):
    """Closed counter-clockwise outline of a rectangle with corner radius ``r``, starting at the
    middle of the bottom edge; corners discretised into segments of about ``seg_mm``."""
    hw, hh = 0.5 * w, 0.5 * h
    r = min(max(r, 0.0), hw, hh)
    pts = [(cx, cy - hh)]
    for ox, oy, start in ((hw, -hh, -0.5), (hw, hh, 0.0), (-hw, hh, 0.5), (-hw, -hh, 1.0)):
        if r > 0:
            n = max(2, math.ceil(0.5 * math.pi * r / seg_mm))
            phi = math.pi * (start + np.linspace(0.0, 0.5, n + 1))
            ccx, ccy = cx + ox - math.copysign(r, ox), cy + oy - math.copysign(r, oy)
            pts += list(zip(ccx + r * np.cos(phi), ccy + r * np.sin(phi), strict=True))
        else:
            pts.append((cx + ox, cy + oy))
    pts.append(pts[0])
    return np.array(pts)


def _split_long(poly: np.ndarray, max_len: float) -> np.ndarray:
    """The polyline with every segment longer than ``max_len`` split into equal pieces."""
    seg = np.diff(poly, axis=0)
    parts = np.maximum(1, np.ceil(np.linalg.norm(seg, axis=1) / max_len).astype(np.int64))
    k = np.repeat(np.arange(len(seg)), parts)
    frac = (np.arange(len(k)) - np.repeat(np.cumsum(parts) - parts, parts)) / parts[k]
    return np.vstack([poly[k] + frac[:, None] * seg[k], poly[-1:]])


def _circle(cx, cy, r, seg_mm, start_angle=-0.5 * math.pi):
    n = max(8, math.ceil(2 * math.pi * r / seg_mm))
    phi = start_angle + np.linspace(0.0, 2 * math.pi, n + 1)
    return np.column_stack([cx + r * np.cos(phi), cy + r * np.sin(phi)])


def _l_outline(cx, cy, w, h, d):
    """Closed counter-clockwise L (the top-right quarter cut away), offset inward by ``d``."""
    x0, x1, y0, y1 = cx - 0.5 * w + d, cx + 0.5 * w - d, cy - 0.5 * h + d, cy + 0.5 * h - d
    xm, ym = cx + 0.05 * w - d, cy + 0.05 * h - d  # inner corner moves with the offset
    return np.array(
        [(cx, y0), (x1, y0), (x1, ym), (xm, ym), (xm, y1), (x0, y1), (x0, y0), (cx, y0)]
    )


def _offsets(spec: PocketSpec, stepover: float, seg_mm: float) -> list[np.ndarray]:
    """Contour-parallel offsets of a pocket, innermost first."""
    cx, cy = spec.center_mm
    w, h = spec.size_mm
    r = spec.corner_radius_mm
    out = []
    if spec.shape == "L":
        d = 0.0
        while 0.5 * min(w, h) * 0.9 - d > stepover:
            out.append(_rounded_chain(_l_outline(cx, cy, w, h, d), max(r, MIN_CORNER_MM), seg_mm))
            d += stepover
        return out[::-1]
    island = 0.16 * min(w, h) if spec.shape == "boss" else 0.0
    n = int((0.5 * min(w, h) - island - stepover) // stepover)
    for i in range(n, -1, -1):
        d = i * stepover
        corner = max(r - d, MIN_CORNER_MM)
        out.append(_rounded_rect(cx, cy, w - 2 * d, h - 2 * d, corner, seg_mm))
    if island:  # rings around the island, from the island outwards, cut first
        rings = [_circle(cx, cy, island + k * stepover, seg_mm) for k in range(1, 3)]
        out = rings + out
    return out


def _rounded_chain(poly: np.ndarray, r: float, seg_mm: float) -> np.ndarray:
    """Round the convex and concave corners of a closed polyline with radius ``r`` (0: sharp)."""
    if r <= 0:
        return poly
    pts = [poly[0]]
    for a, b, c in zip(poly[:-2], poly[1:-1], poly[2:], strict=True):
        u, v = (a - b) / np.linalg.norm(a - b), (c - b) / np.linalg.norm(c - b)
        half = 0.5 * math.acos(float(np.clip(u @ v, -1.0, 1.0)))
        t = min(r / math.tan(half), 0.45 * np.linalg.norm(a - b), 0.45 * np.linalg.norm(c - b))
        p, q = b + u * t, b + v * t
        n = max(2, math.ceil((math.pi - 2 * half) * r / seg_mm))
        s = np.linspace(0.0, 1.0, n + 1)[:, None]
        pts += list((1 - s) ** 2 * p + 2 * s * (1 - s) * b + s**2 * q)  # quadratic blend
    pts.append(poly[-1])
    return np.array(pts)


def _trochoid(
    x_from: float, x_to: float, y: float, loop_radius: float, advance: float, seg_mm: float
) -> np.ndarray:
    """Trochoidal loops (adaptive-style slotting) along ``y`` from ``x_from`` to ``x_to``,
    shape (n, 2); the first point is the start."""
    loops = max(1, int(abs(x_to - x_from) // advance))
    per_loop = max(12, math.ceil(2 * math.pi * loop_radius / seg_mm))
    t = np.linspace(0.0, loops, loops * per_loop + 1)
    phi = 2 * math.pi * t + math.pi
    x = x_from + math.copysign(advance, x_to - x_from) * t + loop_radius * (1 + np.cos(phi))
    return np.column_stack([x, y + loop_radius * np.sin(phi)])


#: Radius of the trochoidal loops, the same on every pocket (one roughing strategy), and their
#: advance per loop (mm).
TROCHOID_RADIUS_MM = 6.0
TROCHOID_ADVANCE_MM = 2.0


def _region(spec: PocketSpec, stepover: float, seg_mm: float) -> list[np.ndarray]:
    """What one depth level cuts: trochoidal loops along the middle (left to right), then the
    contour-parallel offsets; a boss has no loops (rings around its island instead)."""
    cx, cy = spec.center_mm
    w = spec.size_mm[0]
    r = TROCHOID_RADIUS_MM
    path = _offsets(spec, stepover, seg_mm)
    if spec.shape != "boss":
        half = 0.3 * w
        path.insert(0, _trochoid(cx - half, cx + half, cy, r, TROCHOID_ADVANCE_MM, seg_mm))
    return path


def _regions(spec: PocketSpec, stepover_mm: float, segment_mm: float) -> list[list[np.ndarray]]:
    """The regions of a pocket in cutting order (two either side of a rib for ``"twin"``)."""
    if spec.shape != "twin":
        return [_region(spec, stepover_mm, segment_mm)]
    cx, cy = spec.center_mm
    w, h = spec.size_mm
    return [
        _region(
            PocketSpec(0, "rounded", (cx + side * 0.275 * w, cy), (0.45 * w, h),
                       spec.corner_radius_mm, spec.feed_mm_min),
            stepover_mm,
            segment_mm,
        )
        for side in (-1.0, 1.0)
    ]  # fmt: skip


def start_mm(spec: PocketSpec, *, stepover_mm: float = 4.0) -> tuple[float, float, float]:
    """Where the program of ``spec`` starts: above its first entry point, at the clearance plane."""
    x0, y0 = _regions(spec, stepover_mm, SEGMENT_MM)[0][0][0]
    return (float(x0), float(y0), CLEARANCE_Z_MM)


def pocket_program(
    spec: PocketSpec, *, stepover_mm: float = 4.0, segment_mm: float = SEGMENT_MM
) -> str:
    """G-code of one pocket, in mm, absolute, starting at :func:`start_mm`.

    Parameters
    ----------
    spec : PocketSpec
    stepover_mm : float
        Distance between contour-parallel offsets, > 0.
    segment_mm : float
        Chord length of the G1 moves, > 0.
    """
    for name, value in (("stepover_mm", stepover_mm), ("segment_mm", segment_mm)):
        if not value > 0:
            raise ValueError(f"{name} = {value!r} is out of range: allowed > 0")
    feed = spec.feed_mm_min
    x0, y0, z0 = start_mm(spec, stepover_mm=stepover_mm)
    lines = [
        f"(nctwin thin-wall part, pocket {spec.number}: {spec.shape})",
        "G21 G90 G17",
        f"G0 X{x0:.4f} Y{y0:.4f} Z{z0:.1f}",
    ]
    for region in _regions(spec, stepover_mm, segment_mm):
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
                dense = _split_long(contour, segment_mm)
                lines += [f"G1 X{x:.4f} Y{y:.4f}" for x, y in dense[1:]]
            lines.append(f"G0 Z{CLEARANCE_Z_MM:.1f}")
    lines.append("M30")
    return "\n".join(lines) + "\n"


def thinwall_programs(**kwargs) -> dict[int, str]:
    """The programs of all eight pockets, keyed by pocket number; see :func:`pocket_program`."""
    return {spec.number: pocket_program(spec, **kwargs) for spec in POCKETS}
