r"""Exact step error of ball-end CL segments, and the samples of Zhang et al. (2023).

Conventions
-----------
Step error (Zhang et al. 2023, eq. 1)
    The tool moving from :math:`CL_i` to :math:`CL_{i+1}` sweeps a cylinder of radius :math:`R`
    about the CL line. With :math:`c(u)`, :math:`u \in [u_i, u_{i+1}]`, the CC curve between
    :math:`CC_i` and :math:`CC_{i+1}` and

    .. math:: d(u) = \frac{\lVert \overrightarrow{CL_i CL_{i+1}} \times
              \overrightarrow{CL_i\, c(u)} \rVert}{\lVert \overrightarrow{CL_i CL_{i+1}} \rVert},

    the step error is :math:`e_i = |R - L_i|` with :math:`L_i = \min_u d(u)` where the curve is
    convex (bulges towards the tool) and :math:`L_i = \max_u d(u)` where it is concave.
Convex or concave
    A segment is convex if the curve's mid-parameter point lies on the tool's side of the
    :math:`CC_i CC_{i+1}` chord: :math:`(c(\bar u) - \tfrac12(CC_i + CC_{i+1})) \cdot \bar n > 0`,
    with :math:`\bar n` the mean of the two end normals.
Exact method
    :func:`step_error_um` refines :math:`u` on the continuous curve, all segments at once (one
    surface evaluation per step for every segment): golden-section steps shrink the bracket to
    ``xtol`` of the segment (10 steps for the default 1e-2), then one parabolic step through the
    best point and its neighbours lands next to the extreme (Brent's combination, without the
    per-segment branching). On a bracket of width :math:`w` in arc length (here
    :math:`10^{-2} \Delta s \lesssim 0.016` mm) the vertex misses the extreme by about
    :math:`|d'''/d''|\, w^2`, and the value by :math:`\tfrac12 |d''|` times its square: far
    below 1e-6 um. An extreme at an end of the segment is exact. The tests compare with the
    closed form on spheres and cylinders and with the iterative method to 1e-6 um.
Iterative method
    :func:`step_error_iterative_um` is the straightforward alternative: a Python loop over the
    segments, each refined by scipy's bounded Brent search with scalar surface evaluations, as
    the iterative geometric methods the paper compares against do.
Units
    Points in mm, step errors in um.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from .surfaces import Surface, ToolPath

__all__ = [
    "StepError",
    "chord_step_error_um",
    "inner_points_for_hidden_width",
    "sample_columns",
    "step_error_iterative_um",
    "step_error_samples",
    "step_error_um",
]

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0  # 0.618...


@dataclass(frozen=True)
class StepError:
    """Exact step errors of the segments of a tool path.

    Parameters
    ----------
    error_um : ndarray, shape (n_segments,)
        :math:`e_i = |R - L_i|` in um.
    u_critical : ndarray, shape (n_segments,)
        Curve parameter of the critical point :math:`p_i^e`.
    convex : ndarray of bool, shape (n_segments,)
        Segment classified convex (minimum distance) rather than concave (maximum).
    """

    error_um: np.ndarray
    u_critical: np.ndarray
    convex: np.ndarray


def _line_distance2(points: np.ndarray, cl0: np.ndarray, axis: np.ndarray) -> np.ndarray:
    r"""Squared distance of ``points`` (n, 3) from the lines through ``cl0`` (n, 3) along unit
    ``axis`` (n, 3): :math:`\lVert w \rVert^2 - (w \cdot a)^2`, :math:`w` = point - ``cl0``."""
    w = points - cl0
    along = np.einsum("ij,ij->i", w, axis)
    return np.einsum("ij,ij->i", w, w) - along * along


def _convex(surface: Surface, seg: dict[str, np.ndarray], radius_mm: float) -> np.ndarray:
    mid = surface.point(0.5 * (seg["u0"] + seg["u1"]), seg["v"])
    n_mean = (seg["cl0"] - seg["cc0"] + seg["cl1"] - seg["cc1"]) / (2.0 * radius_mm)
    return np.einsum("ij,ij->i", mid - 0.5 * (seg["cc0"] + seg["cc1"]), n_mean) > 0.0


def step_error_um(path: ToolPath, *, xtol: float = 1e-2) -> StepError:
    r"""Exact step error of every CL segment of ``path`` (eq. 1), vectorised.

    Brent-style refinement of the extreme of :math:`d(u)` on :math:`[u_i, u_{i+1}]` (minimum on
    convex segments, maximum on concave ones), run on all segments at once: golden-section
    steps until the bracket is ``xtol`` of the segment, then one parabolic step through the best
    point and its two neighbours. The two ends of the segment are candidates too (near an
    inflection :math:`d` can be monotone on a segment).

    Parameters
    ----------
    path : ToolPath
        ``n_lines`` lines of ``n_points`` CC/CL points.
    xtol : float
        Bracket width before the parabolic step, as a fraction of the segment's parameter
        interval, in (0, 0.1]. The default, 1e-2 (10 golden-section steps), gives errors below
        1e-6 um on the paper's surfaces (see the module docstring).

    Returns
    -------
    StepError
        Arrays of shape (n_segments,) = (n_lines * (n_points - 1),), line by line.

    Raises
    ------
    ValueError
        If ``xtol`` is out of range.
    """
    if not 0.0 < xtol <= 0.1:
        raise ValueError(f"xtol = {xtol!r} is out of range: allowed (0, 0.1]")
    seg = path.segments()
    surface, radius = path.surface, path.tool_radius_mm
    axis = seg["cl1"] - seg["cl0"]
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    convex = _convex(surface, seg, radius)
    sign = np.where(convex, 1.0, -1.0)

    curve = surface.curve(seg["v"])

    def f(u: np.ndarray) -> np.ndarray:
        return sign * _line_distance2(curve(u), seg["cl0"], axis)

    a, b = seg["u0"], seg["u1"]
    fa, fb = f(a), f(b)
    ends_u, ends_f = (a, b), (fa, fb)
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(math.ceil(math.log(xtol) / math.log(_GOLDEN))):
        left = fc < fd  # the extreme is in [a, d]
        a, fa = np.where(left, a, c), np.where(left, fa, fc)
        b, fb = np.where(left, d, b), np.where(left, fd, fb)
        new = np.where(left, b - _GOLDEN * (b - a), a + _GOLDEN * (b - a))
        fnew = f(new)
        c, d = np.where(left, new, d), np.where(left, c, new)
        fc, fd = np.where(left, fnew, fd), np.where(left, fc, fnew)
    # one parabolic step through the best inner point and its neighbours, kept between them
    left = fc < fd
    x1, x2, x3 = np.where(left, a, c), np.where(left, c, d), np.where(left, d, b)
    f1, f2, f3 = np.where(left, fa, fc), np.where(left, fc, fd), np.where(left, fd, fb)
    p = (x2 - x1) ** 2 * (f2 - f3) - (x2 - x3) ** 2 * (f2 - f1)
    q = 2.0 * ((x2 - x1) * (f2 - f3) - (x2 - x3) * (f2 - f1))
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = x2 - p / q
    vertex = np.where(np.isfinite(vertex) & (vertex > x1) & (vertex < x3), vertex, x2)
    candidates_u = np.stack([*ends_u, c, d, vertex])
    candidates_f = np.stack([*ends_f, fc, fd, f(vertex)])
    best = np.argmin(candidates_f, axis=0)
    u_star = np.take_along_axis(candidates_u, best[None], axis=0)[0]
    length = np.sqrt(sign * np.take_along_axis(candidates_f, best[None], axis=0)[0])
    return StepError(np.abs(radius - length) * 1000.0, u_star, convex)


def step_error_iterative_um(
    path: ToolPath, *, segments: np.ndarray | None = None, xatol: float = 1e-10
) -> np.ndarray:
    """Step error segment by segment: a Python loop of scalar Brent searches (method (b)).

    Parameters
    ----------
    path : ToolPath
    segments : ndarray of int, optional
        Indices of the segments to compute (default all), in :meth:`ToolPath.segments` order.
    xatol : float
        Absolute tolerance on the curve parameter :math:`u`, > 0.

    Returns
    -------
    ndarray, shape (len(segments),)
        Step errors in um; equal to :func:`step_error_um` to well below 1e-6 um.

    Raises
    ------
    ValueError
        If ``xatol`` is not > 0.
    """
    if not xatol > 0:
        raise ValueError(f"xatol = {xatol!r} is out of range: allowed > 0")
    seg = path.segments()
    surface, radius = path.surface, path.tool_radius_mm
    index = np.arange(path.n_segments) if segments is None else np.asarray(segments)
    out = np.empty(len(index))
    for k, i in enumerate(index):
        u0, u1, v = float(seg["u0"][i]), float(seg["u1"][i]), float(seg["v"][i])
        cc0, cc1, cl0, cl1 = (seg[key][i] for key in ("cc0", "cc1", "cl0", "cl1"))
        axis = (cl1 - cl0) / np.linalg.norm(cl1 - cl0)
        mid = surface.point(np.float64(0.5 * (u0 + u1)), np.float64(v))
        n_mean = (cl0 - cc0 + cl1 - cc1) / (2.0 * radius)
        sign = 1.0 if float(np.dot(mid - 0.5 * (cc0 + cc1), n_mean)) > 0.0 else -1.0

        def f(u: float, v=v, cl0=cl0, axis=axis, sign=sign) -> float:
            p = surface.point(np.float64(u), np.float64(v))
            return sign * float(np.linalg.norm(np.cross(p - cl0, axis)))

        res = optimize.minimize_scalar(
            f, bounds=(u0, u1), method="bounded", options={"xatol": xatol}
        )
        extreme = sign * min(res.fun, f(u0), f(u1))
        out[k] = abs(radius - extreme) * 1000.0
    return out


def chord_step_error_um(
    radius_mm: float, tool_radius_mm: float, angle_rad: np.ndarray, *, inside: bool
) -> np.ndarray:
    r"""Closed-form step error on a circular arc of radius :math:`\rho` (sphere or cylinder).

    The CL points lie on the concentric circle of radius :math:`\rho \pm R`; a CL chord over the
    angle :math:`\Delta\theta` lies :math:`(\rho \pm R)\cos(\Delta\theta/2)` from the centre, so

    .. math:: e = (\rho \pm R)\,\bigl(1 - \cos\tfrac{\Delta\theta}{2}\bigr)
              = 2 (\rho \pm R) \sin^2\tfrac{\Delta\theta}{4},

    with :math:`+` outside (convex) and :math:`-` inside (concave): the sagitta of the CL chord.

    Parameters
    ----------
    radius_mm, tool_radius_mm : float
        :math:`\rho` and :math:`R`; inside, :math:`\rho > R`.
    angle_rad : array_like
        :math:`\Delta\theta` of each segment.
    inside : bool

    Returns
    -------
    ndarray
        Step errors in um, the shape of ``angle_rad``.

    Raises
    ------
    ValueError
        If ``inside`` and ``radius_mm <= tool_radius_mm``.
    """
    if inside and radius_mm <= tool_radius_mm:
        raise ValueError(
            f"radius_mm = {radius_mm!r} is out of range: allowed > tool_radius_mm "
            f"({tool_radius_mm!r}) for a tool inside"
        )
    cl_radius = radius_mm - tool_radius_mm if inside else radius_mm + tool_radius_mm
    return 2.0 * cl_radius * np.sin(np.asarray(angle_rad, float) / 4.0) ** 2 * 1000.0


def inner_points_for_hidden_width(
    hidden: int = 28, *, n_outputs: int = 1, a_min: float = 1.0, a_max: float = 10.0
) -> int:
    r"""Fewest inner CC points :math:`k` whose input width fits the hidden width by eq. 8.

    Zhang et al. (2023) size the first hidden layer by :math:`n_1 = \sqrt{n + m} + a` (eq. 8),
    :math:`a \in [1, 10]`. A sample (Table 1) holds :math:`k` inner points, :math:`CC_i,
    CC_{i+1}, CL_i, CL_{i+1}` (3 coordinates each) and :math:`R`: :math:`n = 3k + 13`. This returns
    the smallest :math:`k \ge 1` with :math:`a = n_1 - \sqrt{n + m} \in [a_\min, a_\max]`.

    Parameters
    ----------
    hidden : int
        :math:`n_1` (paper: 28).
    n_outputs : int
        :math:`m` (paper: 1).
    a_min, a_max : float
        Range of :math:`a`.

    Raises
    ------
    ValueError
        If no :math:`k \ge 1` fits.
    """
    k_lo = math.ceil(((hidden - a_max) ** 2 - n_outputs - 13) / 3)
    k = max(k_lo, 1)
    if hidden - math.sqrt(3 * k + 13 + n_outputs) < a_min:
        raise ValueError(
            f"hidden = {hidden!r} is out of range: no inner point count fits eq. 8 with "
            f"a in [{a_min}, {a_max}]"
        )
    return k


def sample_columns(n_inner: int) -> list[str]:
    """Names of the :func:`step_error_samples` columns (``p1_x`` ... ``cc0_x`` ... ``R``)."""
    names = [f"p{j}_{c}" for j in range(1, n_inner + 1) for c in "xyz"]
    names += [f"{p}_{c}" for p in ("cc0", "cc1", "cl0", "cl1") for c in "xyz"]
    return [*names, "R"]


def step_error_samples(path: ToolPath, n_inner: int) -> np.ndarray:
    r"""Network inputs of every segment, as in Zhang et al. (2023, Table 1).

    Row :math:`i` holds :math:`k` points :math:`p_j = c(u_i + j\,\Delta u / (k+1))`,
    :math:`j = 1 \dots k`, evenly spaced in the parameter strictly between :math:`CC_i` and
    :math:`CC_{i+1}`, then :math:`CC_i, CC_{i+1}, CL_i, CL_{i+1}` and :math:`R`: width
    :math:`3k + 13`. Unnormalised (mm); the Z-score of eq. 7 is applied with training statistics.

    Parameters
    ----------
    path : ToolPath
    n_inner : int
        :math:`k`, >= 1 (see :func:`inner_points_for_hidden_width`).

    Returns
    -------
    ndarray, shape (n_segments, 3 * n_inner + 13)
        Columns :func:`sample_columns`.

    Raises
    ------
    ValueError
        If ``n_inner`` < 1.
    """
    if n_inner < 1:
        raise ValueError(f"n_inner = {n_inner!r} is out of range: allowed >= 1")
    seg = path.segments()
    frac = np.arange(1, n_inner + 1) / (n_inner + 1)
    u = seg["u0"][:, None] + frac * (seg["u1"] - seg["u0"])[:, None]
    inner = path.surface.point(u, np.broadcast_to(seg["v"][:, None], u.shape))
    n = path.n_segments
    return np.concatenate(
        [
            inner.reshape(n, -1),
            seg["cc0"], seg["cc1"], seg["cl0"], seg["cl1"],
            np.full((n, 1), path.tool_radius_mm),
        ],
        axis=1,
    )  # fmt: skip
