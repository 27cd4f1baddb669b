r"""CAM-style training programs: what a CAM system's output asks of a control, in lines only.

Paper 1's training programs (:mod:`nctwin.programs.training`) are one chain of G-lines at one
feed and tolerance. Part programs written by CAM systems differ in ways a learned cycle-time
model never sees in them, and these programs add exactly those:

* **operations** joined by rapids: ``G0`` up to a safe height, ``G0`` across to the next start,
  a ``G1`` plunge at a third of the feed, the cut, ``G0`` up again;
* **engraving**: a closed smooth curve (a circle with random harmonics) cut into chords of equal
  length, from a few micrometres to a few millimetres;
* **3D rasters**: parallel passes over a wavy surface, sampled every 0.05-1 mm, joined by short
  step-overs that turn the tool back (two right angles within a millimetre or so);
* **reversals**: long lines that turn back by 150-179.9 degrees at every junction;
* the path-control modes CAM posts write: a plain ``G64`` (no tolerance), ``G64 P`` without
  ``Q`` (on LinuxCNC Q = P: its naive-CAM detector merges nearly collinear lines), ``G64 P Q0``
  and ``G61`` (exact path).

Lines only: a recorded program gives targets per block, so an arc, which a learned model sees as
several chords, would have no target per chord. Every generator takes a seed or a
:class:`numpy.random.Generator`; nothing uses a global random state.
"""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_int
from .training import _log_uniform, _rng

__all__ = ["CAM_KINDS", "PATH_MODES", "cam_program"]

#: Kinds of cutting operation, drawn with equal probability.
CAM_KINDS = ("engrave", "raster", "reversal")
#: Path-control modes and their probabilities.
PATH_MODES = {"G64": 0.3, "G64 P": 0.25, "G64 P Q0": 0.3, "G61": 0.15}
#: Safe height of rapids between operations (mm).
SAFE_Z_MM = 5.0
#: Largest number of points of one raster.
MAX_RASTER_POINTS = 3000


def _engrave(rng: np.random.Generator) -> np.ndarray:
    """A closed curve of radius 2-40 mm with harmonics 2-5, chords of equal parameter step;
    shape (n + 1, 3), at a depth of 0.1-2 mm."""
    radius = _log_uniform(rng, 2.0, 40.0)
    n = round(_log_uniform(rng, 40, 4000))
    phi = np.linspace(0.0, 2.0 * math.pi, n + 1)
    k = np.arange(2, 6)
    amp = rng.uniform(0.0, 0.25, 4) / k
    r = radius * (1.0 + np.cos(np.outer(phi, k) + rng.uniform(0, 2 * math.pi, 4)) @ amp)
    depth = -rng.uniform(0.1, 2.0)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), np.full(n + 1, depth)])


def _raster(rng: np.random.Generator) -> np.ndarray:
    """Zig-zag passes along X over ``z = A sin(x / lx) cos(y / ly) - A - 0.5``; shape (m, 3)."""
    width, height = rng.uniform(10.0, 60.0, 2)
    step_mm = _log_uniform(rng, 0.05, 1.0)
    stepover = rng.uniform(0.3, 3.0)
    amp, lx, ly = rng.uniform(0.5, 5.0), rng.uniform(3.0, 30.0), rng.uniform(3.0, 30.0)
    x = np.linspace(0.0, width, max(2, round(width / step_mm)) + 1)
    rows = np.arange(0.0, height, stepover)[: max(2, MAX_RASTER_POINTS // len(x))]
    passes = []
    for i, y in enumerate(rows):
        xs = x if i % 2 == 0 else x[::-1]
        passes.append(np.column_stack([xs, np.full(len(xs), y), np.zeros(len(xs))]))
    pts = np.vstack(passes)
    pts[:, 2] = amp * np.sin(pts[:, 0] / lx) * np.cos(pts[:, 1] / ly) - amp - 0.5
    return pts


def _reversal(rng: np.random.Generator) -> np.ndarray:
    """Lines of 2-40 mm, each turning back by 150-179.9 degrees; shape (n + 1, 3)."""
    n = int(rng.integers(4, 40))
    lengths = rng.uniform(2.0, 40.0, n)
    turns = (math.pi - np.radians(rng.uniform(0.1, 30.0, n))) * rng.choice([-1.0, 1.0], n)
    heading = rng.uniform(0, 2 * math.pi) + np.cumsum(np.concatenate([[0.0], turns[1:]]))
    steps = lengths[:, None] * np.column_stack([np.cos(heading), np.sin(heading)])
    xy = np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])
    return np.column_stack([xy, np.full(n + 1, -rng.uniform(0.1, 2.0))])


_KINDS = {"engrave": _engrave, "raster": _raster, "reversal": _reversal}


def cam_program(
    seed: int | np.random.Generator,
    *,
    feed_range_mm_s: tuple[float, float] = (5.0, 200.0),
    tol_range_mm: tuple[float, float] = (0.005, 0.5),
    max_operations: int = 4,
    max_time_s: float = 60.0,
) -> str:
    """A CAM-style program of 1 to ``max_operations`` operations (see the module docstring).

    Parameters
    ----------
    seed : int or numpy.random.Generator
    feed_range_mm_s : (float, float)
        The cutting feed is log-uniform in it; plunges run at a third of it.
    tol_range_mm : (float, float)
        The ``G64 P`` tolerance is log-uniform in it (where the mode has one).
    max_operations : int
        Largest number of operations.
    max_time_s : float
        The programmed (CAM) time of the cuts stays below it: the last cut is cut short.

    Returns
    -------
    str
        G-code text: a comment with the settings, ``G21 G90 G17``, the path-control mode,
        then per operation ``G0 Z``, ``G0 X Y``, ``G1 Z F``, ``G1 ... F`` and the cut's lines.
    """
    check_int("max_operations", max_operations, 1)
    rng = _rng(seed)
    feed = round(_log_uniform(rng, *feed_range_mm_s), 1)
    modes = list(PATH_MODES)
    mode = modes[int(rng.choice(len(modes), p=list(PATH_MODES.values())))]
    tol = round(_log_uniform(rng, *tol_range_mm), 4)
    g64 = mode.replace("P", f"P{tol:g}")
    lines = [
        f"(nctwin CAM-style training program: F {feed:g} mm/s, {g64})",
        "G21 G90 G17",
        g64,
        f"G0 Z{SAFE_Z_MM:g}",
    ]
    left_s = max_time_s
    kinds = []
    for _ in range(max_operations):
        kind = CAM_KINDS[int(rng.integers(len(CAM_KINDS)))]
        pts = _KINDS[kind](rng) + np.append(rng.uniform(-60.0, 60.0, 2), 0.0)
        pts = np.round(pts, 4)
        pts = pts[np.concatenate([[True], np.any(np.diff(pts, axis=0) != 0, axis=1)])]
        # the cut ends where its programmed time would pass what is left of max_time_s
        t = np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1)) / feed
        pts = pts[: 1 + int(np.searchsorted(t, left_s, side="right"))]
        if len(pts) < 2:
            break
        left_s -= t[len(pts) - 2]
        kinds.append(kind)
        x0, y0, z0 = pts[0]
        lines += [
            f"G0 X{x0:.4f} Y{y0:.4f}",
            f"G1 Z{z0:.4f} F{feed * 20:g}",
            f"F{feed * 60:g}",
        ]
        lines += [f"X{x:.4f} Y{y:.4f} Z{z:.4f}" for x, y, z in pts[1:]]
        lines.append(f"G0 Z{SAFE_Z_MM:g}")
    lines[0] = lines[0][:-1] + f"; {', '.join(kinds)})"
    lines.append("M30")
    return "\n".join(lines) + "\n"
