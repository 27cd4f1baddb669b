"""G5/G5.1 splines and G5.2/G5.3 NURBS as LinuxCNC's task runs them, not as its preview draws
them.

LinuxCNC 2.9's interpreter reads a spline (``Interp::convert_spline`` in interp_convert.cc) as
the control points of a non-rational B-spline: G5.1 (quadratic) the current point, the point
I, J from it and the end (order k = 3); G5 (cubic) the current point, the points I, J from it
and P, Q from the end, and the end (order k = 4). With k points and the clamped knot vector of
``knot_vector_creator`` (nurbs_additional_functions.cc) that is the Bezier curve of degree
k - 1 on u in [0, 1], which it passes to the canon's ``NURBS_FEED``. The two canons differ:

* the preview module's (gcodemodule.cc, the one :mod:`nctwin.gcode._interp` runs) draws
  ``15 k`` straight lines through points of the curve, at u accumulated in steps of
  ``1 / (15 k)`` while below 1, then the end point;
* the task's (emccanon.cc, what the machine runs) splits u into ``4 k`` equal parts and joins
  the points of each part by a biarc (``biarc``: two tangent arcs from the tangent at one point
  to the tangent at the next, ``nurbs_tangent``: a central difference of u +- 1e-5, clipped at
  the ends, made a unit vector); each of the two pieces (``arc``) is an ``ARC_FEED`` or, when
  its tangent and chord are parallel (``|den| <= 1e-6`` in program units), a
  ``STRAIGHT_FEED``.

:func:`task_splines` finds a spline's lines among the preview's moves by their points: the 45
(G5.1) or 60 (G5) straight feeds of one line that lie on one Bezier curve at the preview's u
(the interpreter reports a spline line's motion mode as G1); it recovers the control points by
least squares and puts the task's moves in their place.

G5.2/G5.3 (``Interp::convert_nurbs``): the G5.2 lines collect control points X, Y with weights
P (the first is the current point, weight 1, or P of a G5.2 without X and Y), L above 3 sets
the order k (default 3); G5.3 passes them to the same ``NURBS_FEED``. With n + 1 points the
knot vector of ``knot_vector_creator(n, k)`` is k zeros, 1 .. n - k + 1, then k times
``umax = n - k + 2``, and u runs over [0, umax]; ``nurbs_point`` is the rational curve
``sum N_i w_i P_i / sum N_i w_i`` (``Nmix``, ``Rden``). The preview draws ``15 (n + 1)`` lines
at u accumulated in steps of ``umax / (15 (n + 1))``, the task ``4 (n + 1)`` biarcs at
``u = umax i / (4 (n + 1))``, the tangents clipped at umax. :func:`task_splines` takes the
preview's lines of a line whose state before is G5.2 (a G5.3 line), finds the n and k whose
preview has that many lines, recovers the weights and control points as the null vector of a
homogeneous least-squares fit (:func:`nurbs_fit`) and puts the task's biarcs in their place.
Where no NURBS, or more than one, passes through the preview's points within
:data:`FIT_TOL` (the control points lie on one line, say), the block is refused. (Source read:
LinuxCNC at git f1270d6ed7, the commit of Debian's ``2.9.0~pre1`` package.) A live run of the
language program ``nurbs`` in G61 passes within 6e-5 mm of every end of these biarcs (the
trace's 1 ms chords; the preview's lines miss them by up to 0.018 mm).

Straight splines (the control points on the chord) are the one case where this cannot follow
LinuxCNC move for move. Their parts have parallel tangents, and ``biarc`` divides by
``a = 2 (ts . te - 1)``: where ``a`` is exactly 0 (a chord along an axis) it divides zero by
zero, and the task's moves come to one line to the part's end (a live run of
``G5.1 X10 Y0 I5 J0`` from the origin moves 10 mm in the time of a 10 mm line); where ``a`` is
a rounding error (a chord along a diagonal) it either skips the part or takes a root of the
order of 1e15 mm, so what it runs depends on the last bit of the tangents (a live run of
``G5.1 X3 Y4 I0.6 J0.8`` from the origin went 10 m off the part). Here both are read as the
line, the path the program means: a part whose ``|a|`` is at most :data:`PARALLEL_A` is a line.
Where ``biarc`` finds no biarc for a curved part, LinuxCNC skips it and the next arc starts off
its circle: such a spline is refused.
"""

from __future__ import annotations

import math

import numpy as np

from ._errors import GCodeError
from ._modal import MM_PER_INCH

#: Preview points per control point (gcodemodule.cc ``NURBS_FEED``).
PREVIEW_DIV_PER_POINT = 15
#: Biarcs per control point (emccanon.cc ``NURBS_FEED``).
TASK_DIV_PER_POINT = 4
#: Step of ``nurbs_tangent``'s central difference, in u.
TANGENT_DU = 1e-5
#: ``arc``'s test of a piece being straight: ``|den|`` at most this (program units).
STRAIGHT_DEN = 1e-6
#: ``biarc``'s ``a`` (twice the tangents' dot product less 1) at most this: parallel tangents.
PARALLEL_A = 1e-12
#: Orders of the splines: G5.1 quadratic (3), G5 cubic (4).
ORDERS = (3, 4)
#: Lowest order of a G5.2 NURBS (``convert_nurbs`` starts at 3 and reads only L > 3).
NURBS_MIN_ORDER = 3
#: A NURBS fit is unique where its second-smallest singular value is above this share of the
#: largest (the smallest is the curve's, 0 up to rounding).
UNIQUE_SV = 1e-8
#: The interpreter's motion mode (``gcodes[1]``) while G5.2 control points are read.
G5_2_MODE = 52
#: Farthest a preview point may lie from the fitted curve (inches): the preview's rounding.
FIT_TOL = 1e-9
_N_MOVE = 7


def bezier(u: np.ndarray, ctrl: np.ndarray) -> np.ndarray:
    """Points of the Bezier curve of control points ``ctrl`` (k, 2) at ``u`` (m,): (m, 2)."""
    d = len(ctrl) - 1
    u = np.asarray(u, dtype=float)[:, None]
    basis = np.hstack([math.comb(d, i) * u**i * (1.0 - u) ** (d - i) for i in range(d + 1)])
    return basis @ ctrl


def preview_u(k: int, n: int | None = None) -> np.ndarray:
    """The u of the preview module's points of a spline of order ``k`` and ``n + 1`` control
    points (default n = k - 1, G5/G5.1): steps of ``umax / (15 (n + 1))`` accumulated while
    below ``umax = n - k + 2``, then ``umax`` (the last control point)."""
    n = k - 1 if n is None else n
    umax = float(n - k + 2)
    step, u, out = umax / (PREVIEW_DIV_PER_POINT * (n + 1)), 0.0, []
    while u + step < umax:  # as gcodemodule.cc accumulates it
        out.append(u + step)
        u += step
    return np.array([*out, umax])


def control_points(points: np.ndarray, k: int) -> np.ndarray:
    """The control points (k, 2) of the spline whose preview points are ``points`` (m, 2)."""
    u = preview_u(k)
    basis = bezier(u, np.eye(k))
    return np.linalg.lstsq(basis, points, rcond=None)[0]


def nurbs_fit(points: np.ndarray, n: int, k: int):
    """The control points (n + 1, 2) and weights (n + 1,) of the NURBS of order ``k`` whose
    preview points are ``points`` (m, 2), or None where no NURBS of that size and order passes
    through them or more than one does.

    Each point q at its u is a homogeneous linear equation in the weights w_i and the weighted
    points w_i P_i: ``sum_i N_i(u) w_i (P_i - q) = 0``. Its least-squares null vector (SVD, the
    points centred and scaled) gives them up to a common factor, which does not change the
    curve; the weights are scaled to w_0 = 1.
    """
    u = preview_u(k, n)
    if len(u) != len(points):
        return None
    basis = nurbs_basis(u, n, k)
    centre = points.mean(axis=0)
    size = max(float(np.abs(points - centre).max()), 1e-300)
    q = (points - centre) / size
    zero = np.zeros_like(basis)
    a = np.block([[-basis * q[:, :1], basis, zero], [-basis * q[:, 1:], zero, basis]])
    sv, vt = np.linalg.svd(a)[1:]
    if sv[-2] <= UNIQUE_SV * sv[0]:
        return None
    v = vt[-1] if vt[-1, : n + 1].sum() > 0 else -vt[-1]
    w = v[: n + 1]
    if (w <= 0).any():
        return None
    ctrl = np.column_stack([v[n + 1 : 2 * n + 2] / w, v[2 * n + 2 :] / w]) * size + centre
    return ctrl, w / w[0]


def nurbs_sizes(m: int) -> list[tuple[int, int]]:
    """The sizes (n, k) of the NURBS of which the preview draws ``m`` lines: n + 1 control
    points, order k from 3 (``convert_nurbs`` reads L only above 3) to n + 1."""
    return [
        (n, k)
        for n in range(max(2, m // PREVIEW_DIV_PER_POINT - 2), m // PREVIEW_DIV_PER_POINT + 1)
        for k in range(NURBS_MIN_ORDER, n + 2)
        if len(preview_u(k, n)) == m
    ]


def knot_vector(n: int, k: int) -> list[int]:
    """``knot_vector_creator(n, k)`` (nurbs_additional_functions.cc): k zeros, the integers
    1 .. n - k + 1, then k times ``umax = n - k + 2``; n + 1 control points of order k."""
    return [0 if i < k else (i - k + 1 if i <= n else n - k + 2) for i in range(n + k + 1)]


def _nmix(i: int, k: int, u: float, knots: list[int]) -> float:
    """``Nmix`` (nurbs_additional_functions.cc), the B-spline basis, case for case."""
    if k == 1:
        return 1.0 if knots[i] <= u <= knots[i + 1] else 0.0
    left, right = knots[i + k - 1] - knots[i], knots[i + k] - knots[i + 1]
    if left == 0 and right != 0:
        return ((knots[i + k] - u) * _nmix(i + 1, k - 1, u, knots)) / right
    if right == 0 and left != 0:
        return ((u - knots[i]) * _nmix(i, k - 1, u, knots)) / left
    if left == 0 and right == 0:
        return 0.0
    return ((u - knots[i]) * _nmix(i, k - 1, u, knots)) / left + (
        (knots[i + k] - u) * _nmix(i + 1, k - 1, u, knots)
    ) / right


def nurbs_basis(u: np.ndarray, n: int, k: int) -> np.ndarray:
    """``Nmix(i, k, u)`` for i = 0 .. n at each of ``u`` (m,): (m, n + 1)."""
    knots = knot_vector(n, k)
    return np.array([[_nmix(i, k, float(v), knots) for i in range(n + 1)] for v in u])


def nurbs_points(u: np.ndarray, ctrl: np.ndarray, weights=None, k: int | None = None):
    """``nurbs_point`` at each of ``u`` (m,) for control points ``ctrl`` (n + 1, 2) of weights
    ``weights`` (n + 1,) (default 1) and order ``k`` (default n + 1, a Bezier curve), in
    LinuxCNC's order of operations (its rounding): (m, 2)."""
    n = len(ctrl) - 1
    k = n + 1 if k is None else k
    w = np.ones(n + 1) if weights is None else np.asarray(weights, dtype=float)
    basis = nurbs_basis(u, n, k)
    den = np.zeros(len(u))
    for i in range(n + 1):  # Rden
        den = den + basis[:, i] * w[i]
    out = np.zeros((len(u), 2))
    for i in range(n + 1):
        out = out + ctrl[i] * basis[:, i, None] * w[i] / den[:, None]
    return out


def task_moves(ctrl: np.ndarray, z: float, weights=None, k: int | None = None) -> list[tuple]:
    """The task canon's moves (emccanon.cc ``NURBS_FEED``) of a NURBS of control points ``ctrl``
    (n + 1, 2), program units, weights ``weights`` (n + 1,) (default 1) and order ``k`` (default
    n + 1: G5/G5.1's Bezier curve) at height ``z``: rows (kind 1 line or 2 arc, x, y, z, centre
    x, centre y, rotation +1 ccw or -1 cw), as the preview module reports moves.

    Raises
    ------
    ValueError
        If ``biarc`` finds no biarc for a part (LinuxCNC skips it).
    """
    n = len(ctrl) - 1
    k = n + 1 if k is None else k
    umax = float(n - k + 2)
    div = TASK_DIV_PER_POINT * (n + 1)
    u = umax * np.arange(div + 1) / div
    p = nurbs_points(u, ctrl, weights, k)
    lo, hi = np.maximum(0.0, u - TANGENT_DU), np.minimum(umax, u + TANGENT_DU)
    t = (nurbs_points(hi, ctrl, weights, k) - nurbs_points(lo, ctrl, weights, k)) / (hi - lo)[
        :, None
    ]
    t = _unit(t)
    rows: list[tuple] = []
    for i in range(div):
        rows += _biarc(p[i], t[i], p[i + 1], t[i + 1], z)
    return rows


def _unit(t: np.ndarray) -> np.ndarray:
    """``unit``: each row (m, 2) divided by its length, where that is not 0."""
    h = np.hypot(t[:, 0], t[:, 1])
    return np.where((h != 0)[:, None], t / np.where(h != 0, h, 1.0)[:, None], t)


def _biarc(p0, ts, p4, te, z) -> list[tuple]:
    """emccanon.cc ``biarc`` with r = 1 (it makes the tangents unit vectors again)."""
    ts, te = _unit(np.array([ts, te]))
    vx, vy = p0[0] - p4[0], p0[1] - p4[1]
    c = vx * vx + vy * vy
    b = 2.0 * (vx * (ts[0] + te[0]) + vy * (ts[1] + te[1]))
    a = 2.0 * (ts[0] * te[0] + ts[1] * te[1] - 1.0)
    discr = b * b - 4.0 * a * c
    if discr < 0:
        raise ValueError("no biarc")
    if abs(a) <= PARALLEL_A:  # parallel tangents: a line (see the module docstring)
        return [(1.0, p4[0], p4[1], z, 0.0, 0.0, 0.0)]
    disq = math.sqrt(discr)
    beta1, beta2 = (-b - disq) / 2.0 / a, (-b + disq) / 2.0 / a
    if beta1 > 0 and beta2 > 0:
        raise ValueError("no biarc")
    beta = beta2 if beta1 < beta2 else beta1
    p1 = p0 + beta * ts
    p3 = p4 - beta * te
    p2 = (p1 * beta + p3 * beta) / (2.0 * beta)
    tm = p3 - p2
    hm = math.hypot(tm[0], tm[1])
    tm = tm / hm if hm != 0 else tm
    return [_arc(p0, p2, ts, z), _arc(p2, p4, tm, z)]


def _arc(p0, p1, d, z) -> tuple:
    """emccanon.cc ``arc``: from ``p0`` leaving along ``d`` to ``p1``."""
    x, y = p1[0] - p0[0], p1[1] - p0[1]
    den = 2.0 * (y * d[0] - x * d[1])
    if abs(den) > STRAIGHT_DEN:
        r = -(x * x + y * y) / den
        cx, cy = p0[0] + d[1] * r, p0[1] - d[0] * r
        return (2.0, p1[0], p1[1], z, cx, cy, 1.0 if r < 0 else -1.0)
    return (1.0, p1[0], p1[1], z, 0.0, 0.0, 0.0)


def task_splines(moves: np.ndarray, events: np.ndarray, modal: np.ndarray, source):
    """The child's tables with every G5/G5.1 and G5.3 line's preview lines replaced by the
    task's moves.

    Parameters
    ----------
    moves : ndarray, shape (M, 7)
        The preview's moves (inches).
    events : ndarray, shape (E, 14)
        Events, one a line; column 0 counts the values (7 a move) before each, column 5 holds
        the units (200 G20, 210 G21) of the state after each line.
    modal : ndarray, shape (K, 13)
        Modal records; column 0 as in ``events``.
    source : str or None
        The program's name, for errors.

    Returns
    -------
    moves, events, modal : ndarray
        The same tables, moves of the splines replaced (shapes (M', 7), (E, 9), (K, 13)).
    """
    if not len(events):
        return moves, events, modal
    after = np.vstack([events[1:], events[-1:]])
    before = (events[:, 0] / _N_MOVE).astype(np.int64)
    ends = np.r_[before[1:], len(moves)]
    order = {len(preview_u(k)): k for k in ORDERS}
    nurbs = events[:, 7] == G5_2_MODE  # a G5.3 line: its state before is G5.2's
    pieces, counts = [], np.ones(len(moves), dtype=np.int64)
    for e in np.flatnonzero((np.isin(ends - before, list(order)) | nurbs) & (ends > before)):
        lo, hi = before[e], ends[e]
        if (moves[lo:hi, 0] != 1).any():
            continue
        scale = MM_PER_INCH if after[e, 5] == 210 else 1.0  # program units, as the task's
        points = moves[lo:hi, 1:3] * scale
        if nurbs[e]:
            ctrl, weights, k = _nurbs_of(points, scale, int(events[e, 1]), source)
        else:
            ctrl, weights, k = control_points(points, order[hi - lo]), None, order[hi - lo]
            if np.abs(bezier(preview_u(k), ctrl) - points).max() > FIT_TOL * scale:
                continue  # straight feeds of another kind (a subroutine's, say)
        try:
            rows = np.array(task_moves(ctrl, moves[lo, 3] * scale, weights, k))
        except ValueError:
            raise GCodeError(
                int(events[e, 1]), "", "LinuxCNC finds no biarc for a part of this spline and"
                " skips it: not read", source,
            ) from None  # fmt: skip
        rows[:, 1:6] /= scale
        rows[:, 3] = moves[lo, 3]
        pieces.append((lo, hi, rows))
        counts[lo:hi] = 0
        counts[lo] = len(rows)
    if not pieces:
        return moves, events, modal
    out, at = [], 0
    for lo, hi, rows in pieces:
        out += [moves[at:lo], rows]
        at = hi
    out.append(moves[at:])
    new_before = np.r_[0, np.cumsum(counts)]
    events, modal = events.copy(), modal.copy()
    events[:, 0] = new_before[before] * _N_MOVE
    modal[:, 0] = new_before[(modal[:, 0] / _N_MOVE).astype(np.int64)] * _N_MOVE
    return np.vstack(out), events, modal


def _nurbs_of(points: np.ndarray, scale: float, line: int, source):
    """Control points (n + 1, 2), weights (n + 1,) and order of the one G5.2/G5.3 NURBS whose
    preview points are ``points`` (m, 2), program units (``scale`` of an inch)."""
    found = []
    for n, k in nurbs_sizes(len(points)):
        fit = nurbs_fit(points, n, k)
        if fit is not None:
            err = np.abs(nurbs_points(preview_u(k, n), fit[0], fit[1], k) - points).max()
            if err <= FIT_TOL * scale:
                found.append((*fit, k))
    if len(found) != 1:
        raise GCodeError(
            line, "", "this NURBS's control points and weights cannot be told from LinuxCNC's"
            " preview (no one NURBS fits its lines: control points on one line, say): not read",
            source,
        )  # fmt: skip
    return found[0]
