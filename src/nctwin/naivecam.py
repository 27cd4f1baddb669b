r"""LinuxCNC's naive-CAM detector (``G64 Q``): short feed moves merged into longer lines.

Before LinuxCNC's trajectory planner sees a straight feed move, its canon layer
(``src/emc/task/emccanon.cc``, LinuxCNC 2.9) may hold it back and join it to the moves before
it. :func:`merge_naive_cam` does the same to a :class:`~nctwin.toolpath.Toolpath`; the rules
below are those of that source (function names in brackets) and were checked on LinuxCNC.

* ``STRAIGHT_FEED`` passes each G1 end point to ``see_segment``, which appends it to the chain
  of held points (``chained_points``) if it is ``linkable``, and otherwise first flushes the
  chain (``flush_segments``) and then starts a new chain with it.
* A point :math:`p` is ``linkable`` when the motion mode is continuous (``G64``), the naive-CAM
  tolerance :math:`Q` (``naivecamTolerance``) is not 0, the chain holds at most 100 points (so a
  merged line joins at most 101 moves), :math:`p` differs from the chain's start :math:`B` (the
  end point of the last flushed move, ``canon.endPoint``), and every held point :math:`P` lies
  within :math:`Q` of the segment from :math:`B` to :math:`p`: with :math:`M = p - B`,
  :math:`t = \mathrm{clip}(M \cdot (P - B) / M \cdot M, 0, 1)`, :math:`|P - (B + t M)| \le Q`.
* ``flush_segments`` sends one straight feed move from :math:`B` to the last held point, at the
  feed in force, under the source line of the last held point (``interp_list.set_line_number``).
* ``ARC_FEED`` in the XY plane under ``G64`` hands an arc whose sagitta (``chord_deviation``,
  measured from the start radius) is below :math:`Q` to ``see_segment`` as two points, the arc's
  middle (the Z of a helix half-way) and its end, both under the arc's line; every other arc
  flushes the chain first.
* The chain is flushed by a rapid (``STRAIGHT_TRAVERSE``), a dwell (``DWELL``), a new feed
  (``SET_FEED_RATE``, only if the value changes), any ``G61``/``G61.1``/``G64``
  (``SET_MOTION_CONTROL_MODE``), an S word (``SET_SPINDLE_SPEED``), M words (spindle, coolant,
  tool change, stops, program end, I/O), an offset (the origin offsets, ``SET_ORIGIN_OFFSETS``,
  and the tool length offset, before which the task stops the motion in any case: the tool
  path's ``G`` events), and the program's end (``FINISH``). A T word
  (``SELECT_POCKET``) and a plane change (``SELECT_PLANE``) do not flush it.
* ``G64 P`` without Q sets :math:`Q = P`; a plain ``G64``, ``G64 P0`` and ``G61``/``G61.1``
  turn it off (``convert_control_mode`` in ``interp_convert.cc``); see
  :meth:`~nctwin.toolpath.Toolpath.effective_naive_tol_mm`.

nctwin's tool path records no repeated ``G64`` word, nor an F or M word between blocks that
changes nothing; a feed, path mode or tolerance that differs from the block before breaks the
chain. Only the XYZ axes are modelled.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .toolpath import MotionKind, PathMode, Plane, Toolpath

__all__ = ["MAX_CHAIN", "merge_naive_cam", "small_arc_points"]

#: Most moves one merged line joins: ``linkable`` refuses a point once 101 are held.
MAX_CHAIN = 101

#: Event words that make LinuxCNC's canon flush the chain (a T word does not; G: the offsets).
_FLUSHING_WORDS = ("M", "S", "G")


def small_arc_points(tp: Toolpath, q_mm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Arcs LinuxCNC feeds to the naive-CAM chain as two points (``chord_deviation``).

    Parameters
    ----------
    tp : Toolpath
        N blocks.
    q_mm : ndarray, shape (N,)
        Naive-CAM tolerance of each block (:meth:`Toolpath.effective_naive_tol_mm`).

    Returns
    -------
    small : ndarray of bool, shape (N,)
        XY-plane arcs under ``G64`` whose sagitta :math:`r (1 - \cos(\phi / 2))` is below Q,
        :math:`r` the start radius and :math:`\phi` the sweep as LinuxCNC unwraps it.
    mid_mm : ndarray, shape (N, 3)
        The arc's middle point (Z half-way between start and end); NaN for the other blocks.
    """
    n = len(tp)
    small = np.zeros(n, bool)
    mid = np.full((n, 3), np.nan)
    idx = np.flatnonzero(
        tp.is_arc & (tp.plane == Plane.XY) & (tp.path_mode == PathMode.BLEND) & (q_mm > 0)
    )
    if not len(idx):
        return small, mid
    s, e, c = tp.start_mm[idx], tp.end_mm[idx], tp.center_mm[idx]
    th1 = np.arctan2(s[:, 1] - c[:, 1], s[:, 0] - c[:, 0])
    th2 = np.arctan2(e[:, 1] - c[:, 1], e[:, 0] - c[:, 0])
    r = np.hypot(s[:, 1] - c[:, 1], s[:, 0] - c[:, 0])
    cw = tp.kind[idx] == MotionKind.ARC_CW
    for _ in range(2):  # twice, for atan2's -pi and pi (as chord_deviation does)
        dth = th2 - th1
        th2 = np.where(cw & (dth >= -1e-5), th2 - 2 * np.pi, th2)
        th2 = np.where(~cw & (dth <= 1e-5), th2 + 2 * np.pi, th2)
    dev = r * (1 - np.cos(np.abs(th2 - th1) / 2))
    ok = dev < q_mm[idx]
    mid_angle = (th1 + th2) / 2
    small[idx] = ok
    mid[idx[ok], 0] = c[ok, 0] + r[ok] * np.cos(mid_angle[ok])
    mid[idx[ok], 1] = c[ok, 1] + r[ok] * np.sin(mid_angle[ok])
    mid[idx[ok], 2] = (s[ok, 2] + e[ok, 2]) / 2
    return small, mid


def _chain_breaks(tp: Toolpath, q_mm: np.ndarray) -> np.ndarray:
    """Whether LinuxCNC flushes the chain before each block's move, shape (N,)."""
    n = len(tp)
    brk = np.ones(n, bool)

    def same(a: np.ndarray) -> np.ndarray:
        return (a[1:] == a[:-1]) | (np.isnan(a[1:]) & np.isnan(a[:-1]))

    brk[1:] = ~(
        same(tp.feed_mm_s)
        & same(tp.blend_tol_mm)
        & same(tp.naive_tol_mm)
        & (tp.path_mode[1:] == tp.path_mode[:-1])
        & (q_mm[1:] == q_mm[:-1])
    )
    ev = tp.events
    flushing = ev["block"][np.isin(ev["word"], _FLUSHING_WORDS)]
    brk[flushing[flushing < n]] = True
    return brk


def merge_naive_cam(tp: Toolpath) -> tuple[Toolpath, np.ndarray]:
    """The tool path LinuxCNC's planner receives after its naive-CAM detector (``G64 Q``).

    Parameters
    ----------
    tp : Toolpath
        N blocks as programmed.

    Returns
    -------
    merged : Toolpath
        M blocks: every chain of straight feed moves (and small XY arcs, as two points each)
        that LinuxCNC joins is one line from the chain's start to its last point, with the
        fields (feed, line, path mode, tolerances) of the block of that last point; all other
        blocks are unchanged. An arc fed to the detector whose two points end up in different
        lines becomes two lines. ``tp`` itself is returned where Q is 0 everywhere.
    source : ndarray of int64, shape (M,)
        For each merged block, the original block whose source line LinuxCNC reports while it
        runs (for a joined line, the block of its last point); non-decreasing. The original
        blocks a merged block ``k`` covers are those after ``source[k - 1]`` up to
        ``source[k]``.
    """
    n = len(tp)
    q_all = tp.effective_naive_tol_mm()
    if not (q_all > 0).any():
        return tp, np.arange(n, dtype=np.int64)
    small, mid = small_arc_points(tp, q_all)
    lines = (tp.kind == MotionKind.LINEAR) & (q_all > 0)
    fed = lines | small
    brk = _chain_breaks(tp, q_all).tolist()
    fed_l, small_l, q_l = fed.tolist(), small.tolist(), q_all.tolist()
    start_l, end_l, mid_l = tp.start_mm.tolist(), tp.end_mm.tolist(), mid.tolist()

    src: list[int] = []  # per merged block: the original block it is reported under
    rows: list[tuple[int, list[float], list[float]]] = []  # (merged index, start, end) of lines
    chain: list[list[float]] = []
    chain_whole = False  # the chain is one original line, kept as it is
    chain_src = 0
    base: list[float] | None = None  # B: end point of the last flushed move

    def flush() -> None:
        nonlocal base
        if chain_whole:
            src.append(chain_src)
        else:
            rows.append((len(src), base, chain[-1]))
            src.append(chain_src)
        base = chain[-1]
        chain.clear()

    for i in range(n):
        if chain and brk[i]:
            flush()
        if not fed_l[i]:
            if chain:
                flush()
            src.append(i)
            base = None
            continue
        if base is None:
            base = start_l[i]
        q = q_l[i]
        for p in (mid_l[i], end_l[i]) if small_l[i] else (end_l[i],):
            if chain and not _linkable(chain, base, p, q):
                flush()
            chain_whole = not chain and not small_l[i]
            chain.append(p)
            chain_src = i
    if chain:
        flush()

    source = np.asarray(src, dtype=np.int64)
    if not rows:
        return tp, source
    out = tp.take(source)
    at = np.array([r[0] for r in rows], dtype=np.intp)
    start, end = out.start_mm.copy(), out.end_mm.copy()
    start[at] = [r[1] for r in rows]
    end[at] = [r[2] for r in rows]
    kind, center = out.kind.copy(), out.center_mm.copy()
    kind[at] = MotionKind.LINEAR
    center[at] = np.nan
    merged = dataclasses.replace(out, start_mm=start, end_mm=end, kind=kind, center_mm=center)
    return merged, source


def _linkable(chain: list[list[float]], base: list[float], p: list[float], q: float) -> bool:
    """``linkable`` of emccanon.cc: whether point ``p`` may join the held points ``chain``."""
    if len(chain) >= MAX_CHAIN:
        return False
    bx, by, bz = base
    mx, my, mz = p[0] - bx, p[1] - by, p[2] - bz
    if mx == 0.0 and my == 0.0 and mz == 0.0:
        return False
    mm = mx * mx + my * my + mz * mz
    for px, py, pz in chain:
        t = (mx * (px - bx) + my * (py - by) + mz * (pz - bz)) / mm
        t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
        dx, dy, dz = px - (bx + t * mx), py - (by + t * my), pz - (bz + t * mz)
        if math.sqrt(dx * dx + dy * dy + dz * dz) > q:
            return False
    return True
