"""A contour-parallel pocketing program: the kind of test path of Chien et al. (2023, Fig. 8).

The pocket outline is a rectangle with two rounded and two sharp corners. The tool cuts it from
the inside out along contour-parallel offsets (one every ``stepover_mm``): straight edges are
single long G-lines (local blends at the sharp corners), rounded corners are discretised into
short G-lines of about ``segment_mm`` (global blends), and a short G1 link steps from one offset
to the next. Offsetting a rounded corner inward shrinks its radius until it becomes sharp, so the
inner offsets have more local and fewer global blends, as a real pocket does.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["pocket_program"]


def _contour(half_w: float, half_h: float, radius: float, segment: float) -> np.ndarray:
    """Closed outline, counter-clockwise from the middle of the bottom edge, shape (n, 2).

    Corners at (+w, -h) and (-w, +h) are rounded with ``radius`` (sharp when it is 0); the other
    two are sharp. The first point is repeated at the end.
    """
    pts = [(0.0, -half_h)]
    corners = [
        ((half_w, -half_h), 0.0, True),
        ((half_w, half_h), 0.5 * math.pi, False),
        ((-half_w, half_h), math.pi, True),
        ((-half_w, -half_h), 1.5 * math.pi, False),
    ]
    for (cx, cy), start, rounded in corners:
        if rounded and radius > 0:
            # centre inside the corner; the arc turns 90 degrees counter-clockwise
            ox, oy = cx - math.copysign(radius, cx), cy - math.copysign(radius, cy)
            n = max(2, math.ceil(0.5 * math.pi * radius / segment))
            phi = start - 0.5 * math.pi + np.linspace(0, 0.5 * math.pi, n + 1)
            pts += list(zip(ox + radius * np.cos(phi), oy + radius * np.sin(phi), strict=True))
        else:
            pts.append((cx, cy))
    pts.append(pts[0])
    return np.array(pts)


def pocket_program(
    *,
    width_mm: float = 260.0,
    height_mm: float = 190.0,
    corner_radius_mm: float = 85.0,
    stepover_mm: float = 2.5,
    segment_mm: float = 0.9,
    feed_mm_s: float = 92.0,
    tol_mm: float | None = None,
) -> str:
    """G-code of the pocket, in mm, absolute, from the centre outwards.

    The defaults give about 5000 G-lines and about 220 s of motion at 92 mm/s on the
    ``paper1_sim`` machine, like the pocketing path of Chien et al. (2023, Table 2).

    Parameters
    ----------
    width_mm, height_mm : float
        Outline of the pocket (the last tool-centre contour).
    corner_radius_mm : float
        Radius of the two rounded corners of the outline.
    stepover_mm : float
        Distance between consecutive contours.
    segment_mm : float
        Length of the short G-lines the rounded corners are discretised into.
    feed_mm_s : float
        Programmed feed.
    tol_mm : float, optional
        A ``G64 P`` blending tolerance for the program; none: the machine's.

    Returns
    -------
    str
    """
    for name, v in (
        ("width_mm", width_mm),
        ("height_mm", height_mm),
        ("stepover_mm", stepover_mm),
        ("segment_mm", segment_mm),
        ("feed_mm_s", feed_mm_s),
    ):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} = {v!r} is out of range: allowed (0, inf)")
    if not 0 <= corner_radius_mm <= 0.5 * min(width_mm, height_mm):
        raise ValueError(
            f"corner_radius_mm = {corner_radius_mm!r} is out of range: allowed "
            f"[0, {0.5 * min(width_mm, height_mm):g}]"
        )
    hw, hh = 0.5 * width_mm, 0.5 * height_mm
    n_offsets = int((min(hw, hh) - stepover_mm) // stepover_mm)
    lines = ["(nctwin pocket: contour-parallel offsets, inside out)", "G21 G90 G17"]
    if tol_mm is not None:
        lines.append(f"G64 P{tol_mm:g}")
    lines += [
        "G0 Z5",
        f"G0 X0 Y{-(hh - n_offsets * stepover_mm):.4f}",
        "G1 Z-2 F600",
        f"F{feed_mm_s * 60:g}",
    ]
    for i in range(n_offsets, -1, -1):
        d = i * stepover_mm
        c = _contour(hw - d, hh - d, max(corner_radius_mm - d, 0.0), segment_mm)
        if i < n_offsets:
            lines.append(f"G1 X{c[0, 0]:.4f} Y{c[0, 1]:.4f}")  # link to the next contour
        lines += [f"G1 X{x:.4f} Y{y:.4f}" for x, y in c[1:]]
    lines += ["G0 Z5", "M30"]
    return "\n".join(lines) + "\n"
