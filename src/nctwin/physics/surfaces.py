r"""Smooth free-form surfaces and iso-parametric ball-end tool paths on them.

Zhang et al. (2023) compute the step error of three-axis ball-end finishing paths on three
free-form surfaces whose bounding boxes they give (``data/papers/zhang2023_surfaces.csv``) but
whose shapes they do not. This module builds stand-ins with those boxes
and the tool paths of the paper: iso-parametric lines of cutter-contact (CC) points, as many as
the paper's (the same table).

Conventions
-----------
Parameters
    Every surface maps :math:`(u, v) \in [0, 1]^2` to a point :math:`S(u, v)` in mm. A tool path
    line is an iso-:math:`v` curve; :math:`u` runs along the feed direction.
Normals
    :math:`n(u, v)` is the unit normal on the side the tool is on (for a height field
    :math:`z = h(x, y)`, the upper side: :math:`n = (-h_x, -h_y, 1) / \lVert\cdot\rVert`).
Cutter location
    The ball centre of a ball-end tool of radius :math:`R` touching at :math:`S` is
    :math:`CL = S + R\, n`.
Shapes
    :class:`BumpSurface` is a height field :math:`h = c_0 + c_1 \sum_k w_k
    \exp(-\tfrac12 ((x - x_k)/\sigma_{x,k})^2 - \tfrac12 ((y - y_k)/\sigma_{y,k})^2)` on the
    rectangle :math:`[0, L_x] \times [0, L_y]`: positive bumps give convex regions, negative ones
    concave regions, and :math:`c_0, c_1` are fitted so that :math:`\min h = 0` and
    :math:`\max h = L_z` exactly (to the optimiser's tolerance). :class:`Sphere` and
    :class:`Cylinder` are the closed-form references (outside: convex; inside: concave).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy import optimize

from ..checks import check_int, check_range
from ..report.papers import load_paper_table

__all__ = [
    "PAPER_BUMPS",
    "BumpSurface",
    "Cylinder",
    "GridSurface",
    "Sphere",
    "ToolPath",
    "iso_parametric_path",
    "paper_surface",
]

#: ``curve_jet(v)`` of a surface, for ``v`` of shape (n,): ``jet(u, rows=slice(None))`` gives
#: the points :math:`c(u)`, :math:`c_u` and :math:`c_{uu}` of the iso-``v[rows]`` curves at ``u``
#: (one per row), each shape (len(u), 3).
CurveJet = Callable[..., tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class BumpSurface:
    r"""Height field of Gaussian bumps on a rectangle, scaled to a given bounding box.

    Parameters
    ----------
    size_x_mm, size_y_mm, size_z_mm : float
        Bounding box :math:`L_x \times L_y \times L_z`; the surface spans
        :math:`[0, L_x] \times [0, L_y]` and :math:`0 \le z \le L_z`.
    bumps : tuple of tuple of float
        One ``(x, y, sigma_x, sigma_y, weight)`` per bump; centres and widths as fractions of
        :math:`L_x, L_y`, weights signed (negative weights make dents).

    Raises
    ------
    ValueError
        If a size or a width is not > 0, a bump does not have five numbers, or every weight is 0.
    """

    size_x_mm: float
    size_y_mm: float
    size_z_mm: float
    bumps: tuple[tuple[float, float, float, float, float], ...]

    def __post_init__(self) -> None:
        for name in ("size_x_mm", "size_y_mm", "size_z_mm"):
            check_range(name, getattr(self, name), 0.0, np.inf, low_open=True, high_open=True)
        if not self.bumps or any(len(b) != 5 for b in self.bumps):
            raise ValueError(
                f"bumps = {self.bumps!r} is out of range: allowed a non-empty tuple of "
                "(x, y, sigma_x, sigma_y, weight)"
            )
        for b in self.bumps:
            check_range("bump sigma_x", b[2], 0.0, np.inf, low_open=True, high_open=True)
            check_range("bump sigma_y", b[3], 0.0, np.inf, low_open=True, high_open=True)
        if all(b[4] == 0 for b in self.bumps):
            raise ValueError(f"bumps = {self.bumps!r} is out of range: allowed a non-zero weight")

    @cached_property
    def _arrays(self) -> tuple[np.ndarray, ...]:
        b = np.asarray(self.bumps, dtype=float)
        return (
            b[:, 0] * self.size_x_mm,
            b[:, 1] * self.size_y_mm,
            b[:, 2] * self.size_x_mm,
            b[:, 3] * self.size_y_mm,
            b[:, 4],
        )

    def _raw_value(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Unscaled field at points of any (same) shape (the hot path of the step error)."""
        xk, yk, sx, sy, w = self._arrays
        dx = (x[..., None] - xk) / sx
        dy = (y[..., None] - yk) / sy
        return np.exp(-0.5 * (dx * dx + dy * dy)) @ w

    def _raw(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unscaled field and its x, y derivatives at points of any (same) shape."""
        xk, yk, sx, sy, w = self._arrays
        dx = (x[..., None] - xk) / sx
        dy = (y[..., None] - yk) / sy
        g = w * np.exp(-0.5 * (dx * dx + dy * dy))
        return g.sum(-1), (-g * dx / sx).sum(-1), (-g * dy / sy).sum(-1)

    @cached_property
    def _scale(self) -> tuple[float, float]:
        """``(c0, c1)`` with ``h = c0 + c1 * raw``: min 0 and max ``size_z_mm`` on the domain."""
        grid_x, grid_y = np.meshgrid(
            np.linspace(0, self.size_x_mm, 241), np.linspace(0, self.size_y_mm, 241)
        )
        raw = self._raw(grid_x, grid_y)[0]
        bounds = [(0.0, self.size_x_mm), (0.0, self.size_y_mm)]
        extremes = []
        for sign in (1.0, -1.0):  # minimum, then maximum

            def f(p, sign=sign):
                value, gx, gy = self._raw(np.asarray(p[0]), np.asarray(p[1]))
                return sign * float(value), sign * np.array([gx, gy], dtype=float)

            i = np.unravel_index(np.argmin(sign * raw), raw.shape)
            start = np.array([grid_x[i], grid_y[i]])
            res = optimize.minimize(
                f, start, jac=True, method="L-BFGS-B", bounds=bounds,
                options={"ftol": 1e-15, "gtol": 1e-12},
            )  # fmt: skip
            extremes.append(sign * min(res.fun, sign * raw[i]))
        lo, hi = extremes
        c1 = self.size_z_mm / (hi - lo)
        return -lo * c1, c1

    def height_mm(self, x_mm: np.ndarray, y_mm: np.ndarray) -> np.ndarray:
        """Height :math:`h(x, y)` in mm at points of any shape."""
        c0, c1 = self._scale
        return c0 + c1 * self._raw_value(np.asarray(x_mm, float), np.asarray(y_mm, float))

    def point(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Surface points :math:`S(u, v)`, shape ``(*u.shape, 3)`` in mm (no range check)."""
        x = np.asarray(u, float) * self.size_x_mm
        y = np.asarray(v, float) * self.size_y_mm
        c0, c1 = self._scale
        return np.stack([x, y, c0 + c1 * self._raw_value(x, y)], axis=-1)

    def curve_jet(self, v: np.ndarray) -> CurveJet:
        r"""Points of the iso-``v`` curves and their first two derivatives in :math:`u`.

        ``curve_jet(v)(u, rows)`` is ``(c, c_u, c_uu)`` (:data:`CurveJet`) with
        :math:`c = (L_x u,\ L_y v,\ h)`, :math:`c_u = (L_x, 0, L_x h_x)` and
        :math:`c_{uu} = (0, 0, L_x^2 h_{xx})`. The y factors of the bumps are computed once.
        """
        v = np.asarray(v, float)
        xk, yk, sx, sy, w = (a[:, None] for a in self._arrays)  # (bumps, 1): rows add fast
        y = v * self.size_y_mm
        dy = (y - yk) / sy
        wy = w * np.exp(-0.5 * dy * dy)  # (bumps, n)
        c0, c1 = self._scale
        lx = self.size_x_mm

        def jet(u: np.ndarray, rows=slice(None)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            x = np.asarray(u, float) * lx
            slope = (x - xk) / (sx * sx)  # (bumps, n)
            g = np.exp(-0.5 * (x - xk) * slope) * wy[:, rows]
            gs = g * slope
            c, c_u, c_uu = np.zeros((3, len(x), 3))
            c[:, 0], c[:, 1], c[:, 2] = x, y[rows], c0 + c1 * g.sum(axis=0)
            c_u[:, 0], c_u[:, 2] = lx, -lx * c1 * gs.sum(axis=0)
            c_uu[:, 2] = lx * lx * c1 * (gs * slope - g / (sx * sx)).sum(axis=0)
            return c, c_u, c_uu

        return jet

    def point_normal(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and upward unit normals, each shape ``(*u.shape, 3)``."""
        x = np.asarray(u, float) * self.size_x_mm
        y = np.asarray(v, float) * self.size_y_mm
        c0, c1 = self._scale
        h, hx, hy = self._raw(x, y)
        normal = np.stack([-c1 * hx, -c1 * hy, np.ones_like(x)], axis=-1)
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        return np.stack([x, y, c0 + c1 * h], axis=-1), normal


@dataclass(frozen=True)
class Sphere:
    r"""A sphere of radius :math:`\rho` about the origin, parametrised by meridians.

    :math:`S(u, v) = \rho\,(\sin\theta\cos\phi, \sin\theta\sin\phi, \cos\theta)` with polar angle
    :math:`\theta = \theta_0 + u\,\Delta\theta` and azimuth :math:`\phi = 2\pi v`: every
    iso-:math:`v` line is an arc of a great circle, so the step error has the closed form of
    :func:`nctwin.physics.steperror.chord_step_error_um`.

    Parameters
    ----------
    radius_mm : float
        :math:`\rho`, > 0.
    inside : bool
        Tool inside the sphere (concave; normals point to the centre, and ``radius_mm`` must
        exceed the tool radius) instead of outside (convex).
    theta0_rad, sweep_rad : float
        :math:`\theta_0` and :math:`\Delta\theta`.
    """

    radius_mm: float
    inside: bool = False
    theta0_rad: float = 0.2
    sweep_rad: float = 1.2

    def __post_init__(self) -> None:
        check_range("radius_mm", self.radius_mm, 0.0, np.inf, low_open=True, high_open=True)
        check_range("sweep_rad", self.sweep_rad, 0.0, np.inf, low_open=True, high_open=True)

    def point_normal(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and unit normals on the tool's side, each shape ``(*u.shape, 3)``."""
        theta = self.theta0_rad + np.asarray(u, float) * self.sweep_rad
        phi = 2 * np.pi * np.asarray(v, float)
        radial = np.stack(
            [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1
        )
        return self.radius_mm * radial, (-radial if self.inside else radial)

    def point(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Surface points, shape ``(*u.shape, 3)``."""
        return self.point_normal(u, v)[0]

    def curve_jet(self, v: np.ndarray) -> CurveJet:
        r"""Iso-``v`` great-circle arcs: ``curve_jet(v)(u, rows)`` is :math:`(c, c_u, c_{uu})`
        (:data:`CurveJet`), with :math:`c_u = \rho\,\Delta\theta\,\partial_\theta(\dots)` and
        :math:`c_{uu} = -\Delta\theta^2 c`."""
        phi = 2 * np.pi * np.asarray(v, float)
        cos_phi, sin_phi = np.cos(phi), np.sin(phi)
        rho, sweep = self.radius_mm, self.sweep_rad

        def jet(u: np.ndarray, rows=slice(None)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            theta = self.theta0_rad + np.asarray(u, float) * sweep
            st, ct = np.sin(theta), np.cos(theta)
            cp, sp = cos_phi[rows], sin_phi[rows]
            c = rho * np.stack([st * cp, st * sp, ct], axis=-1)
            c_u = rho * sweep * np.stack([ct * cp, ct * sp, -st], axis=-1)
            return c, c_u, -(sweep * sweep) * c

        return jet


@dataclass(frozen=True)
class Cylinder:
    r"""A circular cylinder of radius :math:`\rho` about the y axis.

    :math:`S(u, v) = (\rho \sin\varphi, L v, \rho\cos\varphi)` with
    :math:`\varphi = \varphi_0 + u\,\Delta\varphi`: iso-:math:`v` lines are circular arcs.

    Parameters
    ----------
    radius_mm : float
        :math:`\rho`, > 0.
    length_mm : float
        :math:`L`, > 0.
    inside : bool
        Tool inside (concave) instead of outside (convex).
    phi0_rad, sweep_rad : float
        :math:`\varphi_0` and :math:`\Delta\varphi`.
    """

    radius_mm: float
    length_mm: float = 100.0
    inside: bool = False
    phi0_rad: float = -1.0
    sweep_rad: float = 2.0

    def __post_init__(self) -> None:
        check_range("radius_mm", self.radius_mm, 0.0, np.inf, low_open=True, high_open=True)
        check_range("length_mm", self.length_mm, 0.0, np.inf, low_open=True, high_open=True)
        check_range("sweep_rad", self.sweep_rad, 0.0, np.inf, low_open=True, high_open=True)

    def point_normal(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and unit normals on the tool's side, each shape ``(*u.shape, 3)``."""
        phi = self.phi0_rad + np.asarray(u, float) * self.sweep_rad
        y = self.length_mm * np.asarray(v, float)
        radial = np.stack([np.sin(phi), np.zeros_like(phi), np.cos(phi)], axis=-1)
        point = self.radius_mm * radial + np.stack([np.zeros_like(y), y, np.zeros_like(y)], axis=-1)
        return point, (-radial if self.inside else radial)

    def point(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Surface points, shape ``(*u.shape, 3)``."""
        return self.point_normal(u, v)[0]

    def curve_jet(self, v: np.ndarray) -> CurveJet:
        r"""Iso-``v`` circular arcs: ``curve_jet(v)(u, rows)`` is :math:`(c, c_u, c_{uu})`
        (:data:`CurveJet`), with
        :math:`c_u = \rho\,\Delta\varphi\,(\cos\varphi, 0, -\sin\varphi)`."""
        y = self.length_mm * np.asarray(v, float)
        rho, sweep = self.radius_mm, self.sweep_rad

        def jet(u: np.ndarray, rows=slice(None)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            phi = self.phi0_rad + np.asarray(u, float) * sweep
            sp, cp = np.sin(phi), np.cos(phi)
            zero = np.zeros_like(phi)
            c = np.stack([rho * sp, y[rows] + zero, rho * cp], axis=-1)
            c_u = rho * sweep * np.stack([cp, zero, -sp], axis=-1)
            c_uu = -(rho * sweep * sweep) * np.stack([sp, zero, cp], axis=-1)
            return c, c_u, c_uu

        return jet


@dataclass(frozen=True, eq=False)
class GridSurface:
    r"""A height field :math:`z = h(x, y)` given on a grid, interpolated by a bicubic spline
    through every grid point (:class:`scipy.interpolate.RectBivariateSpline`, no smoothing).

    :math:`S(u, v) = (x_0 + u L_x,\ y_0 + v L_y,\ h)` over the grid's rectangle.

    Parameters
    ----------
    x_mm : ndarray, shape (nx,)
        Strictly increasing, at least 4 values.
    y_mm : ndarray, shape (ny,)
        Strictly increasing, at least 4 values.
    z_mm : ndarray, shape (ny, nx)
        Heights, row ``j`` at ``y_mm[j]``; finite.

    Raises
    ------
    ValueError
        If a grid axis has fewer than 4 values or does not increase, or the shapes or the
        heights are not as above.
    """

    x_mm: np.ndarray
    y_mm: np.ndarray
    z_mm: np.ndarray

    def __post_init__(self) -> None:
        for name in ("x_mm", "y_mm"):
            a = np.asarray(getattr(self, name), dtype=float)
            if a.ndim != 1 or len(a) < 4 or not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0):
                raise ValueError(
                    f"{name} is out of range: allowed at least 4 finite, strictly increasing "
                    f"values (got {len(a.ravel())})"
                )
            object.__setattr__(self, name, a)
        z = np.asarray(self.z_mm, dtype=float)
        if z.shape != (len(self.y_mm), len(self.x_mm)) or not np.all(np.isfinite(z)):
            raise ValueError(
                f"z_mm has shape {z.shape}: allowed ({len(self.y_mm)}, {len(self.x_mm)}) finite "
                "heights"
            )
        object.__setattr__(self, "z_mm", z)

    @cached_property
    def _spline(self):
        from scipy.interpolate import RectBivariateSpline

        return RectBivariateSpline(self.x_mm, self.y_mm, self.z_mm.T, kx=3, ky=3, s=0)

    @property
    def size_mm(self) -> tuple[float, float]:
        """:math:`(L_x, L_y)`."""
        return float(self.x_mm[-1] - self.x_mm[0]), float(self.y_mm[-1] - self.y_mm[0])

    def _xy(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lx, ly = self.size_mm
        return self.x_mm[0] + np.asarray(u, float) * lx, self.y_mm[0] + np.asarray(v, float) * ly

    def height_mm(self, x_mm: np.ndarray, y_mm: np.ndarray) -> np.ndarray:
        """Height :math:`h(x, y)` in mm at points of any (same) shape."""
        x, y = np.broadcast_arrays(np.asarray(x_mm, float), np.asarray(y_mm, float))
        return self._spline.ev(x.ravel(), y.ravel()).reshape(x.shape)

    def point(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Surface points :math:`S(u, v)`, shape ``(*u.shape, 3)`` in mm."""
        x, y = self._xy(u, v)
        return np.stack([x, y, self.height_mm(x, y)], axis=-1)

    def curve_jet(self, v: np.ndarray) -> CurveJet:
        r"""``(c, c_u, c_uu)`` of the iso-``v`` curves (:data:`CurveJet`):
        :math:`c_u = (L_x, 0, L_x h_x)`, :math:`c_{uu} = (0, 0, L_x^2 h_{xx})`."""
        lx, _ = self.size_mm
        y = self._xy(0.0, np.asarray(v, float))[1]
        ev = self._spline.ev

        def jet(u: np.ndarray, rows=slice(None)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            x = self._xy(np.asarray(u, float), 0.0)[0]
            yr = np.broadcast_to(y[rows], x.shape)
            c, c_u, c_uu = np.zeros((3, len(x), 3))
            c[:, 0], c[:, 1], c[:, 2] = x, yr, ev(x, yr)
            c_u[:, 0], c_u[:, 2] = lx, lx * ev(x, yr, dx=1)
            c_uu[:, 2] = lx * lx * ev(x, yr, dx=2)
            return c, c_u, c_uu

        return jet

    def point_normal(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and upward unit normals, each shape ``(*u.shape, 3)``."""
        x, y = np.broadcast_arrays(*self._xy(u, v))
        ev = self._spline.ev
        hx = ev(x.ravel(), y.ravel(), dx=1).reshape(x.shape)
        hy = ev(x.ravel(), y.ravel(), dy=1).reshape(x.shape)
        normal = np.stack([-hx, -hy, np.ones_like(x)], axis=-1)
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        return np.stack([x, y, self.height_mm(x, y)], axis=-1), normal

    def concave_curvature_per_mm(self, x_mm: np.ndarray, y_mm: np.ndarray) -> np.ndarray:
        r"""The larger principal curvature towards the upward normal, :math:`H + \sqrt{H^2 - K}`
        (mean curvature :math:`H`, Gaussian :math:`K` of the height field), at points of any
        (same) shape, in 1/mm: positive where the surface is concave seen from the tool in some
        direction. A ball of radius :math:`R` fits the surface there only if
        :math:`R\,\kappa < 1`."""
        x, y = np.broadcast_arrays(np.asarray(x_mm, float), np.asarray(y_mm, float))
        p, q, r, s, t = (self._spline.ev(x.ravel(), y.ravel(), dx=i, dy=j).reshape(x.shape)
                         for i, j in ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2)))  # fmt: skip
        w = 1 + p * p + q * q
        gauss = (r * t - s * s) / (w * w)
        mean = ((1 + q * q) * r - 2 * p * q * s + (1 + p * p) * t) / (2 * w**1.5)
        return mean + np.sqrt(np.maximum(mean * mean - gauss, 0.0))


Surface = BumpSurface | Sphere | Cylinder | GridSurface


@dataclass(frozen=True, eq=False)
class ToolPath:
    r"""An iso-parametric ball-end tool path: CC points, normals and CL points.

    Parameters
    ----------
    surface : BumpSurface, Sphere or Cylinder
    tool_radius_mm : float
        Ball radius :math:`R`.
    u : ndarray, shape (n_points,)
        Curve parameter of the CC points along every line (increasing).
    v : ndarray, shape (n_lines,)
        Parameter of each line.
    cc_mm, normal, cl_mm : ndarray, shape (n_lines, n_points, 3)
        CC points :math:`S(u_i, v)`, unit normals :math:`n_i` and CL points
        :math:`CL_i = CC_i + R\, n_i`.
    """

    surface: Surface
    tool_radius_mm: float
    u: np.ndarray
    v: np.ndarray
    cc_mm: np.ndarray
    normal: np.ndarray
    cl_mm: np.ndarray

    @property
    def n_segments(self) -> int:
        """CL segments: ``n_lines * (n_points - 1)``."""
        return len(self.v) * (len(self.u) - 1)

    def segments(self) -> dict[str, np.ndarray]:
        """All CL segments, line by line, flattened.

        Returns
        -------
        dict of ndarray
            ``u0``, ``u1``, ``v``: shape (n_segments,), the parameters of both ends and of the
            line; ``cc0``, ``cc1``, ``cl0``, ``cl1``: shape (n_segments, 3), in mm.
        """
        n_lines, n_points = len(self.v), len(self.u)
        m = n_points - 1
        return {
            "u0": np.tile(self.u[:-1], n_lines),
            "u1": np.tile(self.u[1:], n_lines),
            "v": np.repeat(self.v, m),
            "cc0": self.cc_mm[:, :-1].reshape(-1, 3),
            "cc1": self.cc_mm[:, 1:].reshape(-1, 3),
            "cl0": self.cl_mm[:, :-1].reshape(-1, 3),
            "cl1": self.cl_mm[:, 1:].reshape(-1, 3),
        }


def iso_parametric_path(
    surface: Surface,
    *,
    n_lines: int = 200,
    n_points: int = 100,
    tool_radius_mm: float = 5.0,
) -> ToolPath:
    r"""The iso-parametric path of Zhang et al. (2023, Sec. "Sample construction").

    ``n_lines`` lines at :math:`v = 0, 1/(n_\text{lines}-1), \dots, 1`, each with ``n_points`` CC
    points at :math:`u = 0, 1/(n_\text{points}-1), \dots, 1`; CL = CC + R n.

    Parameters
    ----------
    surface : BumpSurface, Sphere or Cylinder
    n_lines : int
        Lines, >= 1 (paper: 200).
    n_points : int
        CC points per line, >= 2 (paper: 100).
    tool_radius_mm : float
        Ball radius R, > 0 (paper: 5 mm).

    Returns
    -------
    ToolPath
        With ``n_lines * (n_points - 1)`` segments (paper: 19,800).

    Raises
    ------
    ValueError
        If a count or the radius is out of range.
    """
    check_int("n_lines", n_lines, 1)
    check_int("n_points", n_points, 2)
    check_range("tool_radius_mm", tool_radius_mm, 0.0, np.inf, low_open=True, high_open=True)
    u = np.linspace(0.0, 1.0, n_points)
    v = np.linspace(0.0, 1.0, n_lines)
    cc, normal = surface.point_normal(*np.meshgrid(u, v))
    return ToolPath(surface, tool_radius_mm, u, v, cc, normal, cc + tool_radius_mm * normal)


#: The bumps of the three stand-in surfaces (each ``(x, y, sigma_x, sigma_y, weight)``, as
#: :class:`BumpSurface` takes them), on the bounding boxes of Zhang et al. (2023, Fig. 4;
#: ``data/papers/zhang2023_surfaces.csv``). The bumps are ours, placed by hand and their widths
#: then scaled once (bisection on the largest step error of the paper's path) so that each
#: surface has convex and concave regions and step errors up to just under the paper's largest.
PAPER_BUMPS: dict[int, tuple[tuple[float, float, float, float, float], ...]] = {
    1: ((0.30, 0.35, 0.2120, 0.2332, 1.0), (0.72, 0.65, 0.1908, 0.2120, 0.8),
        (0.55, 0.20, 0.1696, 0.1484, -0.45), (0.25, 0.80, 0.1908, 0.1696, -0.35)),
    2: ((0.40, 0.40, 0.2721, 0.2474, 1.0), (0.75, 0.75, 0.1979, 0.2227, 0.6),
        (0.20, 0.80, 0.1856, 0.1979, -0.40), (0.80, 0.25, 0.1979, 0.1856, -0.45)),
    3: ((0.50, 0.50, 0.3302, 0.3302, 1.0), (0.20, 0.25, 0.2202, 0.2202, -0.30),
        (0.80, 0.75, 0.2339, 0.2339, -0.35), (0.78, 0.22, 0.2477, 0.2202, 0.35)),
}  # fmt: skip


def paper_surface(index: int) -> BumpSurface:
    """Stand-in for surface ``index`` (1, 2 or 3) of Zhang et al. (2023): the paper's bounding
    box (read from ``data/papers/zhang2023_surfaces.csv``) with :data:`PAPER_BUMPS`."""
    if index not in PAPER_BUMPS:
        raise ValueError(f"index = {index!r} is out of range: allowed 1, 2, 3")
    box = load_paper_table("zhang2023_surfaces").set_index("surface").loc[index]
    return BumpSurface(float(box["bbox_x_mm"]), float(box["bbox_y_mm"]), float(box["bbox_z_mm"]),
                       PAPER_BUMPS[index])  # fmt: skip
