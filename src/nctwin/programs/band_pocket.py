r"""The pocket of :mod:`nctwin.programs.pocket` cleared zig-zag across its band: the pocketing test
path of Chien et al. (2023, Fig. 8-9, Tables 2-3) as straights that end in corners and groups of
short segments that blend globally.

The part is :mod:`~nctwin.programs.pocket`'s: the outline :data:`~nctwin.programs.pocket.OUTLINE_MM`
(scaled by ``outline_scale``) and an island at the distance ``band_mm`` from it, so the floor is a
band of constant width between two walls. An end mill of radius :math:`R` (``tool_radius_mm``)
clears it as a CAM system's "zig-zag with finishing pass" does for a narrow floor:

* **Two rings.** The tool centre stays between the *island's ring* (the island offset outward by
  :math:`R`: its sharp corners become arcs of radius :math:`R`) and the *outline's ring* (the
  outline offset inward by :math:`R`). Both are offsets of the same outline, so on a straight
  wall they are parallel, ``band_mm`` :math:`- 2R` apart.
* **Rows.** Each row is one G1 straight from a point of the island's ring along the ring's
  outward normal to where that ray meets the outline's ring. On a straight wall a row is
  ``band_mm`` :math:`- 2R` long; at a convex corner of the island the normals fan out from the
  corner, and where the outline has a sharp corner the band is wider, so the rows there run
  longer (the corner clean-up). The rows' feet are spaced along the island's ring so that
  neither ring has more than ``stepover_mm`` between neighbouring rows (arc length): by the
  measure :math:`\mu = \int \max(\mathrm{d}s, \mathrm{d}t)` of both rings' arc lengths
  :math:`s, t`, in equal steps.
* **Zig-zag.** The rows alternate in direction (island to outline, outline to island), once
  around the island counter-clockwise from the middle of its bottom wall; consecutive rows are
  linked along the ring they end on (one straight on a straight wall, chords within
  ``chord_tol_mm`` on an arc), so every row ends in two corners of about 90 degrees.
* **Finishing pass.** Then one ring along each wall, climb milling with a right-hand spindle
  (the wall on the tool's right): the ring the last row ends on first, then a straight back
  across the cleared band along the last row and the other ring.

The rows themselves alternate climb and conventional cutting, as any zig-zag does; the links
run counter-clockwise (climb on the outline, conventional on the island), the finishing rings
are both climb. Everything is one chain of G1 moves at one depth (stay-down).

:data:`PAPER_POCKETS` holds the settings of the paper's two pockets, each fixed by one statistic
the paper publishes (solved by :func:`nctwin.chapters.chien2023_pocket.solve_pocket`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_range
from .pocket import OUTLINE_MM, _offset, _program_text

__all__ = [
    "BAND_MAX_PER_SCALE_MM",
    "PAPER_POCKETS",
    "TABLE2",
    "TABLE3",
    "PaperPocket",
    "band_pocket_program",
    "band_pocket_rings",
    "paper_pocket_program",
    "paper_pocket_rings",
]

#: Widest band per unit of ``outline_scale`` (mm): beyond it the island's chamfer collapses.
BAND_MAX_PER_SCALE_MM = 44.0
#: Spacing of the feet sampled to place the rows (mm of either ring).
_SAMPLE_MM = 0.1
#: Ring vertices nearer than this to a link's ends are left out (mm).
_NEAR_MM = 1e-3


@dataclass(frozen=True)
class PaperPocket:
    r"""The CAM settings of a band pocket.

    Parameters
    ----------
    outline_scale : float
        Scale of :data:`~nctwin.programs.pocket.OUTLINE_MM` (its vertices and fillets), in
        [0.3, 5].
    band_mm : float
        Distance of the island from the outline, in
        [:math:`2R` + ``stepover_mm``, ``BAND_MAX_PER_SCALE_MM`` ``outline_scale``].
    chord_tol_mm : float
        Largest distance between an arc and its chords, in (0, 0.1 :math:`R`].
    stepover_mm : float
        Largest distance between neighbouring rows along either ring, in (0, :math:`2R`].
    tool_radius_mm : float
        Radius :math:`R` of the end mill, in (0, 10].
    """

    outline_scale: float
    band_mm: float
    chord_tol_mm: float
    stepover_mm: float = 2.0
    tool_radius_mm: float = 4.0

    def __post_init__(self) -> None:
        check_range("outline_scale", self.outline_scale, 0.3, 5.0)
        check_range("tool_radius_mm", self.tool_radius_mm, 0.0, 10.0, low_open=True)
        check_range("stepover_mm", self.stepover_mm, 0.0, 2 * self.tool_radius_mm, low_open=True)
        check_range(
            "band_mm",
            self.band_mm,
            2 * self.tool_radius_mm + self.stepover_mm,
            BAND_MAX_PER_SCALE_MM * self.outline_scale,
        )
        check_range("chord_tol_mm", self.chord_tol_mm, 0.0, 0.1 * self.tool_radius_mm,
                    low_open=True)  # fmt: skip


@dataclass(frozen=True)
class _Ring:
    """A closed counter-clockwise ring of lines and arcs, by arc length from the start of its
    first line. Per piece ``k`` (arrays of shape (m,), points (m, 2)): its start ``start_mm``
    (arc length), ``length_mm``, first point ``a``, unit direction ``u`` (lines) and
    ``centre``, ``radius`` (0: a line), start angle ``phi0`` and signed ``sweep`` (arcs)."""

    start_mm: np.ndarray
    length_mm: np.ndarray
    a: np.ndarray
    u: np.ndarray
    centre: np.ndarray
    radius: np.ndarray
    phi0: np.ndarray
    sweep: np.ndarray

    @property
    def total_mm(self) -> float:
        return float(self.start_mm[-1] + self.length_mm[-1])

    def point(self, t_mm: np.ndarray) -> np.ndarray:
        """Points at the arc lengths ``t_mm`` (any real, wrapped), shape (n,) -> (n, 2)."""
        t = np.mod(np.asarray(t_mm, dtype=float), self.total_mm)
        k = np.clip(np.searchsorted(self.start_mm, t, side="right") - 1, 0, len(self.a) - 1)
        local = t - self.start_mm[k]
        line = self.a[k] + local[:, None] * self.u[k]
        r = np.where(self.radius[k] > 0, self.radius[k], 1.0)
        phi = self.phi0[k] + np.sign(self.sweep[k]) * local / r
        arc = self.centre[k] + self.radius[k][:, None] * np.column_stack([np.cos(phi), np.sin(phi)])
        return np.where((self.radius[k] > 0)[:, None], arc, line)

    def normal(self, t_mm: np.ndarray) -> np.ndarray:
        """Unit normals to the right of the ring's direction at ``t_mm``, shape (n, 2)."""
        t = np.mod(np.asarray(t_mm, dtype=float), self.total_mm)
        k = np.clip(np.searchsorted(self.start_mm, t, side="right") - 1, 0, len(self.a) - 1)
        r = np.where(self.radius[k] > 0, self.radius[k], 1.0)
        phi = self.phi0[k] + np.sign(self.sweep[k]) * (t - self.start_mm[k]) / r
        radial = np.column_stack([np.cos(phi), np.sin(phi)]) * np.sign(self.sweep[k])[:, None]
        line = np.column_stack([self.u[k, 1], -self.u[k, 0]])
        return np.where((self.radius[k] > 0)[:, None], radial, line)

    def vertices(self, chord_tol_mm: float) -> np.ndarray:
        """Arc lengths of the ring's polyline vertices: every piece's start and its arcs' chord
        ends, in equal chords within ``chord_tol_mm``, shape (n,)."""
        out = []
        for start, length, r, sweep in zip(
            self.start_mm, self.length_mm, self.radius, self.sweep, strict=True
        ):
            n = 1
            if r > 0:
                n = max(1, math.ceil(abs(sweep) / (2 * math.acos(max(1 - chord_tol_mm / r, -1)))))
            out.append(start + length * np.arange(n) / n)
        return np.concatenate(out)

    def hit(self, p: np.ndarray, n: np.ndarray) -> np.ndarray:
        """Arc length where each ray ``p + lambda n`` (``lambda > 0``) first meets the ring,
        shapes (m, 2) -> (m,); NaN where it misses."""
        best = np.full(len(p), np.inf)
        where = np.full(len(p), np.nan)
        for k in range(len(self.a)):
            if self.radius[k] == 0:
                d = self.u[k] * self.length_mm[k]
                w = self.a[k] - p
                den = n[:, 0] * d[1] - n[:, 1] * d[0]
                with np.errstate(divide="ignore", invalid="ignore"):
                    lam = (w[:, 0] * d[1] - w[:, 1] * d[0]) / den
                    frac = (w[:, 0] * n[:, 1] - w[:, 1] * n[:, 0]) / den
                cands = [(lam, frac)]
            else:
                q = p - self.centre[k]
                b = (q * n).sum(axis=1)
                disc = b * b - (q * q).sum(axis=1) + self.radius[k] ** 2
                root = np.sqrt(np.where(disc >= 0, disc, np.nan))
                cands = []
                for lam in (-b - root, -b + root):
                    x = q + lam[:, None] * n
                    phi = np.arctan2(x[:, 1], x[:, 0])
                    turned = np.mod((phi - self.phi0[k]) * np.sign(self.sweep[k]), 2 * np.pi)
                    turned = np.where(turned > 2 * np.pi - 1e-12, 0.0, turned)
                    cands.append((lam, turned / abs(self.sweep[k])))
            for lam, frac in cands:
                ok = (lam > 1e-9) & (frac >= -1e-12) & (frac <= 1 + 1e-12) & (lam < best)
                best = np.where(ok, lam, best)
                where = np.where(ok, self.start_mm[k] + np.clip(frac, 0, 1) * self.length_mm[k],
                                 where)  # fmt: skip
        return where


def _make_ring(vertices: np.ndarray, radii: np.ndarray, reference: np.ndarray) -> _Ring:
    """The ring of a counter-clockwise polygon with corner fillets (vertices (m, 2), radii (m,)),
    an offset of a polygon whose edges run along ``reference`` (m, 2): line ``i`` along edge
    ``i -> i + 1`` between the fillets, then the fillet of vertex ``i + 1``.

    Raises ValueError where an edge has turned round or a fillet no longer fits on its edges (the
    offset has collapsed).
    """
    u = np.roll(vertices, -1, axis=0) - vertices
    edge = np.linalg.norm(u, axis=1)
    u = u / edge[:, None]
    u_in = np.roll(u, 1, axis=0)
    turn = np.arctan2(u_in[:, 0] * u[:, 1] - u_in[:, 1] * u[:, 0], (u_in * u).sum(axis=1))
    tangent = radii * np.tan(0.5 * np.abs(turn))
    line_mm = edge - tangent - np.roll(tangent, -1)
    if (line_mm < 0).any() or ((u * reference).sum(axis=1) <= 0).any():
        raise ValueError("the offset has collapsed: a fillet no longer fits on its edges")
    pieces = []  # (a, u, centre, radius, phi0, sweep, length)
    m = len(vertices)
    for i in range(m):
        j = (i + 1) % m
        pieces.append(
            (vertices[i] + u[i] * tangent[i], u[i], np.zeros(2), 0.0, 0.0, 0.0, line_mm[i])
        )
        if radii[j] > 0:
            a = vertices[j] - u[i] * tangent[j]
            normal = np.sign(turn[j]) * np.array([-u[i, 1], u[i, 0]])
            centre = a + radii[j] * normal
            phi0 = math.atan2(a[1] - centre[1], a[0] - centre[0])
            pieces.append((a, u[i], centre, radii[j], phi0, turn[j], radii[j] * abs(turn[j])))
    a, uu, centre, radius, phi0, sweep, length = (
        np.array(c, dtype=float) for c in zip(*pieces, strict=True)
    )
    start = np.concatenate([[0.0], np.cumsum(length)[:-1]])
    return _Ring(start, length, a, uu, centre, radius, phi0, sweep)


def _between(ring: _Ring, grid_mm: np.ndarray, t0: float, length_mm: float) -> np.ndarray:
    """The ring's polyline (vertices ``grid_mm``) forward from ``t0`` over ``length_mm`` (at
    most once round), both ends included, shape (n, 2)."""
    total = ring.total_mm
    t0 = t0 % total
    t1 = t0 + length_mm
    grid = np.concatenate([grid_mm, grid_mm + total, grid_mm + 2 * total])
    inner = grid[(grid > t0 + _NEAR_MM) & (grid < t1 - _NEAR_MM)]
    return ring.point(np.concatenate([[t0], inner, [t1]]))


def _rows(spec: PaperPocket, island: _Ring, outline: _Ring) -> tuple[np.ndarray, np.ndarray]:
    """Arc lengths of the rows' feet on the island's ring and of their ends on the outline's
    ring, from the middle of the island's bottom wall counter-clockwise, shapes (n,), (n,)."""
    total = island.total_mm
    band = spec.band_mm
    # on an arc of radius r the ray's end moves up to ~(r + band) / r times as fast: finer there
    s = np.concatenate(
        [
            np.linspace(
                st,
                st + ln,
                math.ceil(ln * (r + band) / (r + 1e-9) / _SAMPLE_MM)
                if r > 0
                else max(2, math.ceil(ln / _SAMPLE_MM)),
                endpoint=False,
            )
            for st, ln, r in zip(island.start_mm, island.length_mm, island.radius, strict=True)
        ]
    )
    s0 = island.start_mm[0] + 0.5 * island.length_mm[0]
    s = np.append(s, total)
    t = outline.hit(island.point(s), island.normal(s))
    if np.isnan(t).any():
        raise ValueError("a row misses the outline's ring")
    dt = np.diff(t)
    dt = np.where(dt < -0.5 * outline.total_mm, dt + outline.total_mm, dt)
    mu = np.concatenate([[0.0], np.cumsum(np.maximum(np.diff(s), dt))])
    n_rows = math.ceil(mu[-1] / (0.99 * spec.stepover_mm))
    mu_rows = (np.interp(s0, s, mu) + mu[-1] * np.arange(n_rows) / n_rows) % mu[-1]
    s_rows = np.interp(mu_rows, mu, s)
    return s_rows, outline.hit(island.point(s_rows), island.normal(s_rows))


def band_pocket_rings(spec: PaperPocket) -> list[np.ndarray]:
    """The tool-centre path of the band pocket ``spec`` as polylines in cutting order, each
    starting where the previous one ends: the zig-zag, the first finishing ring, the straight
    back across the band and the second finishing ring, each shape (n_i, 2).

    Raises ValueError where the settings leave no band to clear.
    """
    verts = spec.outline_scale * np.array([p for p, _ in OUTLINE_MM])
    radii = spec.outline_scale * np.array([r for _, r in OUTLINE_MM])
    island_poly = _offset(verts, radii, spec.band_mm)
    edges = np.roll(verts, -1, axis=0) - verts
    island = _make_ring(*_offset(*island_poly, -spec.tool_radius_mm), edges)
    outline = _make_ring(*_offset(verts, radii, spec.tool_radius_mm), edges)
    grid_in, grid_out = island.vertices(spec.chord_tol_mm), outline.vertices(spec.chord_tol_mm)
    s_rows, t_rows = _rows(spec, island, outline)
    feet, ends = island.point(s_rows), outline.point(t_rows)
    zigzag = [feet[0]]
    for k in range(len(s_rows)):  # even rows island -> outline, odd rows back
        ring, grid, at, points = (outline, grid_out, t_rows, ends) if k % 2 == 0 else (
            island, grid_in, s_rows, feet)  # fmt: skip
        zigzag.append(points[k])
        if k + 1 < len(s_rows):  # the link along the ring the row ends on
            link = _between(ring, grid, at[k], (at[k + 1] - at[k]) % ring.total_mm)
            zigzag += list(link[1:])
    on_outline = len(s_rows) % 2 == 1  # the last row ends on the outline's ring
    s_end, t_end = s_rows[-1], t_rows[-1]
    around_outline = _between(outline, grid_out, t_end, outline.total_mm)
    around_island = _between(island, grid_in, s_end, island.total_mm)[::-1]  # climb
    if on_outline:
        return [np.array(zigzag), around_outline, np.array([ends[-1], feet[-1]]), around_island]
    return [np.array(zigzag), around_island, np.array([feet[-1], ends[-1]]), around_outline]


def band_pocket_program(spec: PaperPocket, *, feed_mm_s: float, tol_mm: float | None = None) -> str:
    """G-code of the band pocket ``spec`` in mm, absolute: a plunge at the first row's foot, then
    :func:`band_pocket_rings` as one chain of G1 moves at one depth, at ``feed_mm_s`` (in
    (0, 1000]) and with a ``G64 P`` blending tolerance ``tol_mm`` (none: the machine's)."""
    path = np.vstack(band_pocket_rings(spec))
    return _program_text(path, feed_mm_s, tol_mm, "zig-zag across the band around an island, "
                         "then a finishing ring along each wall")  # fmt: skip


#: Table 2's pocket, solved on ``paper1_sim`` (the FIR kernel, unrecorded): the scale for 12.42 m
#: of path (the mean of the 11.5-13.1 m that Table 2's CAM times imply), the chordal tolerance
#: for 5000 G-lines (the paper: 5000) and the band for CAM's error (ours 37.2, 33.6, 42.9 and
#: 39.3 % at 75 and 92 mm/s by 0.3 and 0.4 mm, the paper's 36, 35, 41, 41 %; mean difference 0).
TABLE2 = PaperPocket(outline_scale=0.9269, band_mm=39.379, chord_tol_mm=2.02e-05)
#: Table 3's pocket, solved on ``paper1_machine_b`` recorded through its position loop: the
#: scale for 4.41 m of path (the paper's CAM times imply 4.34-4.48 m, mean 4.41 m) and Table 2's
#: chordal tolerance (the same post-processor; 4508 G-lines). At Table 2's 2 mm stepover even the
#: widest band a part of this path allows (the island's chamfer collapsed, ``band_mm`` =
#: ``BAND_MAX_PER_SCALE_MM`` ``outline_scale``: 24.9 mm, rows of 17 mm, two 90-degree corners
#: every 19 mm of zig-zag) leaves CAM 25-30 % short on the four rows (mean 27.7 %; the paper's
#: 12-14 %, mean 13 %), so the band stays the widest and the stepover (which the paper does not
#: print) is solved for CAM's error instead. A wider stepover clears the path's area with fewer
#: rows, so the same 4.41 m belongs to a larger part with a wider band: CAM's mean error falls to
#: 24.8 % at 4 mm, 18.5 % at 6 mm and 16.5 % at the tool's diameter, 8 mm, the widest a zig-zag
#: leaves no ridges at (band 40.7 mm, rows of 33 mm, two corners every 41 mm). The solver stops
#: there, the closest this tool comes: CAM's error 16.1, 14.6, 18.6 and 17.2 % (measured/CAM
#: 1.19, 1.17, 1.23, 1.21; the paper's 14, 13, 13, 12 %, 1.16, 1.15, 1.17, 1.13), the rows at
#: 70 mm/s within about 2 points (2.07 at 0.075 mm), those at 80 mm/s not: ours rises by 2.5
#: points from 70 to 80 mm/s where the paper's falls by one, a property of machine B's corners,
#: not of the path.
TABLE3 = PaperPocket(
    outline_scale=0.9253, band_mm=40.712, chord_tol_mm=TABLE2.chord_tol_mm, stepover_mm=8.0
)
#: The pockets of Tables 2 and 3 (:func:`nctwin.chapters.chien2023_pocket.solve_pocket`).
PAPER_POCKETS = {"table2": TABLE2, "table3": TABLE3}


def _spec(name: str) -> PaperPocket:
    if name not in PAPER_POCKETS:
        raise ValueError(f"name = {name!r} is unknown: allowed {', '.join(PAPER_POCKETS)}")
    return PAPER_POCKETS[name]


def paper_pocket_rings(name: str) -> list[np.ndarray]:
    """The tool-centre polylines of :data:`PAPER_POCKETS` ``[name]`` (:func:`band_pocket_rings`)."""
    return band_pocket_rings(_spec(name))


def paper_pocket_program(name: str, *, feed_mm_s: float, tol_mm: float | None = None) -> str:
    """G-code of the pocket of Chien et al. (2023) Table 2 (``"table2"``) or Table 3
    (``"table3"``): :func:`band_pocket_program` with the settings of :data:`PAPER_POCKETS`."""
    return band_pocket_program(_spec(name), feed_mm_s=feed_mm_s, tol_mm=tol_mm)
