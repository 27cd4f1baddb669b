"""Points of a tool path by arc length.

:class:`PathGeometry` turns a :class:`~nctwin.toolpath.Toolpath` into a function of arc length
``s`` (mm from the start of the program): the position on lines, arcs and helices, evaluated for
many ``s`` at once. Kernels sample their command positions with it.
"""

from __future__ import annotations

import numpy as np

from ._geometry_loops import block_indices, path_points
from .toolpath import PLANE_AXES, Toolpath

__all__ = ["PathGeometry"]


class PathGeometry:
    """Arc-length parametrisation of a tool path.

    Parameters
    ----------
    toolpath : Toolpath

    Attributes
    ----------
    s_start_mm : ndarray, shape (N + 1,)
        Arc length at the start of each block, and the total length last.
    loop_arrays : tuple of ndarray
        What :func:`~nctwin._geometry_loops.path_points` reads of the path, in its order: for
        compiled loops that evaluate points themselves.
    """

    def __init__(self, toolpath: Toolpath) -> None:
        tp = toolpath
        self.toolpath = tp
        self.lengths_mm = tp.lengths_mm
        self.s_start_mm = np.concatenate([[0.0], np.cumsum(self.lengths_mm)])
        self.total_mm = float(self.s_start_mm[-1])
        self._arc = tp.is_arc
        self._ax = PLANE_AXES[tp.plane]
        self._chord = tp.end_mm - tp.start_mm
        self._sweep = tp.sweep_rad
        # the arcs' start angle, start and end radius and travel along the normal (0 on lines,
        # where nothing reads them)
        self._theta0, self._r0, self._r1, self._dn = (np.zeros(len(tp)) for _ in range(4))
        arc = np.flatnonzero(self._arc)
        if len(arc):
            sa, sb, _ = tp._in_plane(tp.start_mm[arc] - tp.center_mm[arc], arc)
            ea, eb, _ = tp._in_plane(tp.end_mm[arc] - tp.center_mm[arc], arc)
            self._theta0[arc] = np.arctan2(sb, sa)
            self._r0[arc] = np.hypot(sa, sb)
            self._r1[arc] = np.hypot(ea, eb)
            self._dn[arc] = self._chord[arc, self._ax[arc, 2]]
        self.loop_arrays = (
            self.s_start_mm,
            self.lengths_mm,
            tp.start_mm,
            self._chord,
            self._arc,
            self._ax,
            self._theta0,
            self._sweep,
            self._r0,
            self._r1,
            tp.center_mm,
            self._dn,
        )

    def block_at(self, s_mm: np.ndarray) -> np.ndarray:
        """Index of the block containing each arc length, shape like ``s_mm``."""
        k = np.searchsorted(self.s_start_mm, s_mm, side="right") - 1
        return np.clip(k, 0, max(len(self.lengths_mm) - 1, 0))

    def block_at_ordered(self, s_mm: np.ndarray) -> np.ndarray:
        """:meth:`block_at` of arc lengths (Q,) in increasing order, not NaN, in one compiled
        pass (:func:`nctwin._geometry_loops.block_indices`), shape (Q,)."""
        out = np.empty(len(s_mm), dtype=np.intp)
        block_indices(self.s_start_mm, np.ascontiguousarray(s_mm, dtype=np.float64), out)
        return out

    def points(self, s_mm: np.ndarray) -> np.ndarray:
        """Positions at arc lengths ``s_mm`` (clipped to the path), shape (len(s_mm), 3).

        A compiled loop (:func:`nctwin._geometry_loops.path_points`), bit for bit the numpy
        of :meth:`points_numpy`."""
        tp = self.toolpath
        s = np.ascontiguousarray(s_mm, dtype=np.float64)
        out = np.zeros((len(s), 3))
        if len(tp) == 0:
            return out
        path_points(s, *self.loop_arrays, out)
        return out

    def points_numpy(self, s_mm: np.ndarray) -> np.ndarray:
        """:meth:`points` in numpy: the definition the compiled loop reproduces."""
        tp = self.toolpath
        if len(tp) == 0:
            return np.zeros((len(s_mm), 3))
        s = np.clip(s_mm, 0.0, self.total_mm)
        k = self.block_at(s)
        length = self.lengths_mm.take(k)
        frac = np.divide(
            s - self.s_start_mm.take(k), length, out=np.zeros_like(s), where=length > 0
        )
        frac = np.clip(frac, 0.0, 1.0)
        out = np.take(tp.start_mm, k, axis=0)
        out += frac[:, None] * np.take(self._chord, k, axis=0)
        arc = self._arc[k]
        if arc.any():
            ka, fa = k[arc], frac[arc]
            ax = self._ax[ka]
            phi = self._theta0[ka] + self._sweep[ka] * fa
            r = self._r0[ka] + (self._r1[ka] - self._r0[ka]) * fa  # exact at both ends
            c = tp.center_mm[ka]
            rows = np.arange(len(ka))
            p = np.empty((len(ka), 3))
            p[rows, ax[:, 0]] = c[rows, ax[:, 0]] + r * np.cos(phi)
            p[rows, ax[:, 1]] = c[rows, ax[:, 1]] + r * np.sin(phi)
            p[rows, ax[:, 2]] = tp.start_mm[ka][rows, ax[:, 2]] + self._dn[ka] * fa
            out[arc] = p
        return out
