"""Tool paths as arrays of blocks.

A :class:`Toolpath` is what a part program means once its text has been read: one row per
motion block (rapid, linear, circular, dwell), with the geometry in millimetres and the feed in
millimetres per second. It holds no parsing and no physics; kernels and estimators read it.

Conventions
-----------
* Units: mm, s, mm/s, rad.
* ``N`` is the number of blocks. Every array has ``N`` rows; all arrays are read-only.
* Arcs are given by start, end, centre and plane. The centre's coordinate along the plane's
  normal equals the start's. A helical arc moves along the normal from start to end at a constant
  rate. An arc whose start and end coincide in the plane is a full circle.
* Planes follow RS274/NGC: G17 = XY (normal Z), G18 = ZX (normal Y), G19 = YZ (normal X).
  Clockwise (G2) is clockwise when looking from the positive normal axis down onto the plane,
  with the plane axes taken in the order (X, Y), (Z, X), (Y, Z).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ._rows import row_norm

__all__ = ["EVENT_DTYPE", "OFFSET_EVENTS", "PLANE_AXES", "MotionKind", "PathMode", "Plane",
           "Toolpath"]  # fmt: skip


class MotionKind(enum.IntEnum):
    """Kind of a block."""

    RAPID = 0
    LINEAR = 1
    ARC_CW = 2
    ARC_CCW = 3
    DWELL = 4


class Plane(enum.IntEnum):
    """Arc plane: G17, G18, G19."""

    XY = 0
    ZX = 1
    YZ = 2


class PathMode(enum.IntEnum):
    """Path-control mode in force at a block (modal group 13 of RS274/NGC)."""

    DEFAULT = 0  #: the program set nothing: the machine's own blending tolerance applies
    BLEND = 1  #: G64 (with or without P)
    EXACT_PATH = 2  #: G61
    EXACT_STOP = 3  #: G61.1


#: For each plane, the indices of its first axis, second axis and normal axis. Shape (3, 3).
PLANE_AXES = np.array([[0, 1, 2], [2, 0, 1], [1, 2, 0]], dtype=np.intp)

EVENT_DTYPE = np.dtype([("block", np.int64), ("line", np.int64), ("word", "U1"), ("value", "f8")])
#: The events of word ``G``: a line that sets an offset, which LinuxCNC's task sets only once
#: the motion has stopped (``emcTaskCheckPreconditions``), by the first it sets: 43 a tool
#: length offset (G43, G43.1, G43.2, G49), 54 the work offset (a change of G54-G59.3, or G10
#: L2/L20 of the system in force), 92 the G92 offset (G92, G92.1, G92.2, G92.3), 10 the XY
#: rotation.
OFFSET_EVENTS = {43.0: "tool length offset", 54.0: "work offset", 92.0: "G92 offset",
                 10.0: "XY rotation"}  # fmt: skip


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Toolpath:
    """A part program as arrays of blocks.

    Parameters
    ----------
    start_mm, end_mm : ndarray, shape (N, 3)
        Start and end point of each block. For a dwell both are the tool's position.
    kind : ndarray of int8, shape (N,)
        :class:`MotionKind` of each block.
    feed_mm_s : ndarray, shape (N,)
        Programmed feed in force at the block (modal F). NaN before any F was given; rapids carry
        the modal F too but move at the machine's rapid feed.
    center_mm : ndarray, shape (N, 3)
        Arc centre; NaN for blocks that are not arcs.
    plane : ndarray of int8, shape (N,)
        :class:`Plane` in force at the block.
    dwell_s : ndarray, shape (N,)
        Dwell time; 0 for blocks that are not dwells.
    line : ndarray of int64, shape (N,)
        1-based source line of each block (0 for blocks not read from a file).
    path_mode : ndarray of int8, shape (N,)
        :class:`PathMode` in force at the block.
    blend_tol_mm : ndarray, shape (N,)
        The P of the G64 in force (NaN where G64 had no P or no G64 is in force).
    naive_tol_mm : ndarray, shape (N,)
        The Q of the G64 in force (naive CAM detector tolerance), NaN where not given.
    events : structured ndarray, shape (E,)
        Non-motion words kept in program order (M, S, T, and G for the offsets of
        :data:`OFFSET_EVENTS`): fields ``block`` (index of the block they precede), ``line``,
        ``word`` (letter) and ``value``.
    """

    start_mm: np.ndarray
    end_mm: np.ndarray
    kind: np.ndarray
    feed_mm_s: np.ndarray
    center_mm: np.ndarray
    plane: np.ndarray
    dwell_s: np.ndarray
    line: np.ndarray
    path_mode: np.ndarray
    blend_tol_mm: np.ndarray
    naive_tol_mm: np.ndarray
    events: np.ndarray = field(default_factory=lambda: np.zeros(0, EVENT_DTYPE))

    def __post_init__(self) -> None:
        n = len(np.asarray(self.kind))
        specs = {
            "start_mm": (np.float64, (n, 3)),
            "end_mm": (np.float64, (n, 3)),
            "kind": (np.int8, (n,)),
            "feed_mm_s": (np.float64, (n,)),
            "center_mm": (np.float64, (n, 3)),
            "plane": (np.int8, (n,)),
            "dwell_s": (np.float64, (n,)),
            "line": (np.int64, (n,)),
            "path_mode": (np.int8, (n,)),
            "blend_tol_mm": (np.float64, (n,)),
            "naive_tol_mm": (np.float64, (n,)),
        }
        for name, (dtype, shape) in specs.items():
            a = np.asarray(getattr(self, name), dtype=dtype)
            if a.shape != shape:
                raise ValueError(f"Toolpath.{name} must have shape {shape}, got {a.shape}")
            object.__setattr__(self, name, _readonly(a))
        events = np.asarray(self.events)
        if events.dtype != EVENT_DTYPE:
            events = np.array([tuple(e) for e in events], dtype=EVENT_DTYPE)
        object.__setattr__(self, "events", _readonly(events))
        if n and (self.kind.min() < 0 or self.kind.max() > MotionKind.DWELL):
            raise ValueError("Toolpath.kind must hold MotionKind values 0..4")
        if n and (self.plane.min() < 0 or self.plane.max() > Plane.YZ):
            raise ValueError("Toolpath.plane must hold Plane values 0..2")

    @classmethod
    def empty(cls) -> Toolpath:
        """A tool path with no blocks."""
        z3, z1 = np.zeros((0, 3)), np.zeros(0)
        return cls(z3, z3, z1, z1, z3, z1, z1, z1, z1, z1, z1)

    def __len__(self) -> int:
        return len(self.kind)

    # ------------------------------------------------------------------ arcs
    @cached_property
    def is_arc(self) -> np.ndarray:
        """Boolean mask of arc blocks, shape (N,)."""
        return (self.kind == MotionKind.ARC_CW) | (self.kind == MotionKind.ARC_CCW)

    @cached_property
    def _plane_axes(self) -> np.ndarray:
        return PLANE_AXES[self.plane]

    def _in_plane(
        self, p: np.ndarray, blocks: np.ndarray | slice = slice(None)
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Coordinates of points ``p`` (B, 3), one per block of ``blocks`` (default: all), along
        each block's first, second and normal axis."""
        ax = self._plane_axes[blocks]
        rows = np.arange(len(ax))
        return p[rows, ax[:, 0]], p[rows, ax[:, 1]], p[rows, ax[:, 2]]

    @cached_property
    def radius_mm(self) -> np.ndarray:
        """Arc radius (mean of start and end radius), shape (N,); NaN for other blocks."""
        sa, sb, _ = self._in_plane(self.start_mm - self.center_mm)
        ea, eb, _ = self._in_plane(self.end_mm - self.center_mm)
        return 0.5 * (np.hypot(sa, sb) + np.hypot(ea, eb))

    @cached_property
    def sweep_rad(self) -> np.ndarray:
        """Signed swept angle of arcs (positive counter-clockwise), shape (N,); 0 for others."""
        sweep = np.zeros(len(self))
        arc = self.is_arc
        if arc.any():
            with np.errstate(invalid="ignore"):
                sweep[arc] = arc_sweep(
                    self.start_mm[arc],
                    self.end_mm[arc],
                    self.center_mm[arc],
                    self.plane[arc],
                    self.kind[arc] == MotionKind.ARC_CCW,
                )
        return sweep

    # --------------------------------------------------------------- lengths
    @cached_property
    def lengths_mm(self) -> np.ndarray:
        """Path length of each block (arc length for arcs, helix included), shape (N,)."""
        out = row_norm(self.end_mm - self.start_mm)  # the chord of lines
        arc = np.flatnonzero(self.is_arc)
        if len(arc):
            _, _, dn = self._in_plane(self.end_mm[arc] - self.start_mm[arc], arc)
            with np.errstate(invalid="ignore"):
                out[arc] = np.hypot(self.radius_mm[arc] * self.sweep_rad[arc], dn)
        out[self.kind == MotionKind.DWELL] = 0.0
        return out

    @property
    def length_mm(self) -> float:
        """Total path length of all motion blocks."""
        return float(self.lengths_mm.sum())

    @cached_property
    def directions(self) -> np.ndarray:
        """Unit chord direction (end - start) of each block, shape (N, 3); zeros where the chord
        is zero (dwells, full circles, zero-length moves)."""
        d = self.end_mm - self.start_mm
        n = row_norm(d)[:, None]
        return np.divide(d, n, out=np.zeros_like(d), where=n > 0)

    def _tangents(self, at_end: bool) -> np.ndarray:
        """Unit tangent of each block at its start or end, shape (N, 3): the chord direction of
        lines, the arc's tangent (helix included) of arcs; zeros where undefined."""
        t = self.directions.copy()
        arc = np.flatnonzero(self.is_arc)
        if len(arc):
            point = (self.end_mm if at_end else self.start_mm)[arc]
            ra, rb, _ = self._in_plane(point - self.center_mm[arc], arc)
            r = np.hypot(ra, rb)
            ccw = np.where(self.kind[arc] == MotionKind.ARC_CCW, 1.0, -1.0)
            with np.errstate(invalid="ignore", divide="ignore"):
                ua, ub = -rb / r * ccw, ra / r * ccw
                _, _, dn = self._in_plane(self.end_mm[arc] - self.start_mm[arc], arc)
                planar = r * np.abs(self.sweep_rad[arc])
                total = np.hypot(planar, dn)
                ax = self._plane_axes[arc]
                t[arc, ax[:, 0]] = ua * planar / total
                t[arc, ax[:, 1]] = ub * planar / total
                t[arc, ax[:, 2]] = dn / total
        return np.nan_to_num(t, nan=0.0)

    @cached_property
    def start_tangents(self) -> np.ndarray:
        """Unit tangent at the start of each block, shape (N, 3); zeros where undefined."""
        return self._tangents(at_end=False)

    @cached_property
    def end_tangents(self) -> np.ndarray:
        """Unit tangent at the end of each block, shape (N, 3); zeros where undefined."""
        return self._tangents(at_end=True)

    @cached_property
    def corner_angles_rad(self) -> np.ndarray:
        """Corner angle at the start of each block, shape (N,).

        The angle between the previous block's end tangent and this block's start tangent: 0 for
        a straight continuation, pi for a reversal. It is 0 for the first block and wherever a
        tangent is undefined (dwells, zero-length moves).
        """
        out = np.zeros(len(self))
        if len(self) > 1:
            cos = np.einsum("ij,ij->i", self.end_tangents[:-1], self.start_tangents[1:])
            out[1:] = np.arccos(np.clip(cos, -1.0, 1.0))
            defined = (np.abs(self.end_tangents[:-1]).sum(1) > 0) & (
                np.abs(self.start_tangents[1:]).sum(1) > 0
            )
            out[1:][~defined] = 0.0
        return out

    # -------------------------------------------------------------- summaries
    def effective_tolerance_mm(self, machine_tol_mm: float) -> np.ndarray:
        """Blending tolerance each block is executed with, shape (N,).

        A program's own G64 P overrides the machine's tolerance from that block on, as on a real
        control. G61 and G61.1 give 0 (exact path / exact stop). G64 without P, or with P0, means
        "no tolerance" and gives ``inf`` (LinuxCNC semantics). Where the program set nothing, the
        machine's tolerance applies.
        """
        tol = np.full(len(self), float(machine_tol_mm))
        blend = self.path_mode == PathMode.BLEND
        p = self.blend_tol_mm
        tol[blend] = np.where(np.isfinite(p[blend]) & (p[blend] > 0), p[blend], np.inf)
        tol[self.path_mode >= PathMode.EXACT_PATH] = 0.0
        return tol

    def effective_naive_tol_mm(self) -> np.ndarray:
        """Naive-CAM tolerance (``G64 Q``) each block is executed with, LinuxCNC's rules, (N,).

        ``G64 P`` without Q sets Q = P; a plain ``G64`` or ``G61``/``G61.1`` gives 0 (off); where
        the program set nothing, 0 (LinuxCNC starts with ``Q0`` in nctwin's profiles).
        """
        q = np.zeros(len(self))
        blend = self.path_mode == PathMode.BLEND
        given = np.isfinite(self.naive_tol_mm)
        p = np.nan_to_num(self.blend_tol_mm, nan=0.0)
        q[blend] = np.where(given[blend], self.naive_tol_mm[blend], p[blend])
        return q

    def take(self, blocks: np.ndarray) -> Toolpath:
        """The tool path of the given blocks (indices or mask, in order); events are kept and
        re-pointed to the next kept block."""
        idx = np.arange(len(self))[blocks]
        ev = self.events.copy()
        ev["block"] = np.searchsorted(idx, ev["block"], side="left")
        names = ("start_mm", "end_mm", "kind", "feed_mm_s", "center_mm", "plane", "dwell_s",
                 "line", "path_mode", "blend_tol_mm", "naive_tol_mm")  # fmt: skip
        return Toolpath(**{n: getattr(self, n)[idx] for n in names}, events=ev)

    def kind_counts(self) -> dict[str, int]:
        """Number of blocks per kind, keyed by lower-case kind name."""
        counts = np.bincount(self.kind, minlength=len(MotionKind))
        return {k.name.lower(): int(counts[k]) for k in MotionKind}

    def allclose(self, other: Toolpath, *, rtol: float = 1e-12, atol: float = 1e-9) -> bool:
        """Whether two tool paths have the same blocks (source lines are not compared).

        Geometry, feeds, dwell times and tolerances are compared with ``rtol`` and ``atol``
        (mm, mm/s, s); kinds, planes and path modes exactly; NaNs compare equal.
        """
        if len(self) != len(other):
            return False
        exact = ("kind", "path_mode")
        close = ("start_mm", "end_mm", "feed_mm_s", "dwell_s", "blend_tol_mm", "naive_tol_mm")
        if not all(np.array_equal(getattr(self, n), getattr(other, n)) for n in exact):
            return False
        if not all(
            np.allclose(getattr(self, n), getattr(other, n), rtol=rtol, atol=atol, equal_nan=True)
            for n in close
        ):
            return False
        arcs = self.is_arc
        return bool(
            np.array_equal(self.plane[arcs], other.plane[arcs])
            and np.allclose(self.center_mm[arcs], other.center_mm[arcs], rtol=rtol, atol=atol)
        )

    def to_frame(self):
        """The blocks as a :class:`pandas.DataFrame` (one row per block), for inspection."""
        import pandas as pd

        return pd.DataFrame(
            {
                "line": self.line,
                "kind": [MotionKind(k).name.lower() for k in self.kind],
                **{f"{a}_start_mm": self.start_mm[:, i] for i, a in enumerate("xyz")},
                **{f"{a}_end_mm": self.end_mm[:, i] for i, a in enumerate("xyz")},
                "length_mm": self.lengths_mm,
                "feed_mm_s": self.feed_mm_s,
                "corner_angle_rad": self.corner_angles_rad,
                "dwell_s": self.dwell_s,
            }
        )


def arc_sweep(
    start_mm: np.ndarray,
    end_mm: np.ndarray,
    center_mm: np.ndarray,
    plane: np.ndarray,
    ccw: np.ndarray,
) -> np.ndarray:
    """Signed swept angle of arcs, positive counter-clockwise.

    Parameters
    ----------
    start_mm, end_mm, center_mm : ndarray, shape (N, 3)
    plane : ndarray of int, shape (N,)
        :class:`Plane` of each arc.
    ccw : ndarray of bool, shape (N,)
        True for G3, False for G2.

    Returns
    -------
    ndarray, shape (N,)
        In (0, 2 pi] for counter-clockwise arcs and [-2 pi, 0) for clockwise ones; a start and
        end that coincide in the plane give a full circle (+-2 pi).
    """
    ax = PLANE_AXES[np.asarray(plane, dtype=np.intp)]
    rows = np.arange(len(ax))
    s = start_mm - center_mm
    e = end_mm - center_mm
    th_s = np.arctan2(s[rows, ax[:, 1]], s[rows, ax[:, 0]])
    th_e = np.arctan2(e[rows, ax[:, 1]], e[rows, ax[:, 0]])
    d = end_mm - start_mm
    full = np.hypot(d[rows, ax[:, 0]], d[rows, ax[:, 1]]) <= 1e-9
    two_pi = 2.0 * np.pi
    ccw_sweep = np.mod(th_e - th_s, two_pi)
    cw_sweep = -np.mod(th_s - th_e, two_pi)
    sweep = np.where(ccw, ccw_sweep, cw_sweep)
    return np.where(full, np.where(ccw, two_pi, -two_pi), sweep)
