r"""A 3D ball-end finishing program over a smooth free-form surface, written as CAM writes it.

The ISO 10791-7-style test piece (:mod:`nctwin.programs.iso10791`) is long lines, a few arcs and
a bore of 72 chords. This program is the other kind: a zigzag raster of a ball-end mill over a
free-form surface, thousands of short ``G1`` chords at a CAM tolerance, a tangent lead-in and
lead-out arc in the ZX plane (``G18``) on every pass and short links between the passes. It is
where block overlap, the block-processing time and the arc-radius clamp of a control matter
most.

The surface
    :math:`z = f(x, y)` over ``width_mm`` x ``length_mm`` (X from 0, Y from 0): a sum of
    ``bumps`` Gaussian hills and hollows (heights 2-6 mm of either sign, standard deviations
    3-9 mm, centres anywhere over the patch and a 10 % margin) and one long wave (amplitude
    0.5-1.5 mm, wavelengths 30-60 mm), all drawn from ``numpy.random.default_rng(seed)``. The
    heights are then scaled down, if need be, so that no hollow is tighter than 1.25 tool
    radii (the tool must fit: a ball of radius r cannot finish a hollow of radius < r).
The tool path
    The ball's tip (the programmed point of a ball-end mill) on passes along X (+X and back, in
    turn) at ``y = 0, stepover, 2 stepover, ...``. Each point is an exact drop-cutter position for
    the smooth surface: the ball touches the surface at the point whose normal passes through the
    ball's centre, found by Newton's method. Chords are placed as a CAM system places them: their
    length is :math:`\min(L_{max}, \sqrt{8 \rho \delta})` for the path's local radius of curvature
    :math:`\rho` (the largest curvature within 1 mm) and the tolerance :math:`\delta`, so that no
    chord leaves the path by more than :math:`\delta`; coordinates are written with 3 decimals
    (Fanuc IS-B).
The program
    Fanuc style: F in mm/min (written when it changes), ``G18`` for the lead arcs, one line per
    block, a zigzag raster as both real programs below cut it. The first pass is reached by
    ``G0`` across at the safe height and ``G0`` down to the start of its lead-in; every pass is
    a quarter-ish lead-in arc of ``lead_radius_mm`` that starts straight down and ends tangent
    to the pass, the chords, and a lead-out arc that ends straight up (``G2`` on the passes
    along +X, ``G3`` on those back); the next pass is linked at the finishing feed, a ``G1`` up
    or down to its lead-in's start and a ``G1`` across by the step-over. Chords that descend
    more steeply than ``steep_angle_deg`` run at ``steep_feed_mm_min``, all else at
    ``feed_mm_min``. Defaults: 80 mm x 60 mm, ball radius 3 mm, step-over 0.5 mm, chordal
    tolerance 0.001 mm, chords up to 1 mm, F1300 (F800 on chords steeper than 45 degrees down),
    lead radius 5 mm, 14 bumps.

Why these defaults
------------------
They are taken from the two real CAM 3D ball-end finishing programs shipped in
``data/programs/public/`` (``LHchips4.ngc``, read with its feed words restored by
:func:`real_cam_text`, and ``camotics_bear.nc``), as :func:`program_statistics` measures them:

=====================  ======  =====  =========  ========  ==========  ==============  ======
program                chords  p5     median     < 0.5 mm  lead arcs   cutting feed    G0
=====================  ======  =====  =========  ========  ==========  ==============  ======
``LHchips4.ngc``       6,911   0.167  0.294      62 %      225, R 5    F1300 (77 %)    71
``camotics_bear.nc``   14,831  0.167  0.530      47 %      none        F6000 (100 %)   7
this program, seed 0   22,126  0.168  0.426      63 %      242, R 5    F1300 (99.8 %)  5
=====================  ======  =====  =========  ========  ==========  ==============  ======

(chord lengths in mm; the feed that covers the most cutting length and its share.)

*Chords.* The chord lengths are what a control's block processing sees. A chordal tolerance of
0.01 mm gives chords of at least :math:`\sqrt{8 r \delta}` = 0.49 mm over every convex region
of this surface (the tip path's radius there is at least the ball's radius r), median 1.39 mm,
only 4 % below 0.5 mm: far longer than the real programs. The real programs' short chords come
from a finer chord tolerance (CAM splits the total tolerance between the chords and the surface
fit) and from finer model facets; 0.001 mm with chords of at most 1 mm reproduces their
distribution.

*Leads, feeds and links.* Only ``LHchips4.ngc`` has lead arcs: every one of its 225 arcs has a
radius of 5 mm, and all but the 4 of its final contour are quarter-ish leads in the plane of their
pass, ``G2``/``G3`` as the pass runs, so the lead radius is 5 mm. Its passes run at F1300 and drop
to F800 on chords that descend more steeply than 45 degrees (every F800 chord descends at 41.6
degrees or more, no F1300 chord at more than 45); its few other feeds are a final contour at F1000
and single moves. The feed, lead and link rules are this program's, as a consistent set: the arc
clamp sees :math:`F^2 / R`, so an R 5 lead belongs with the feed it was cut at. ``camotics_bear.nc``
cuts everything at F6000 (the chapter also runs this program at that feed:
:mod:`nctwin.chapters.lee2022_sweeps`). Neither program retracts between adjacent passes:
``LHchips4.ngc`` links most of its 116 passes with two ``G1`` moves (up or down, then across) and
retracts (three ``G0``) only to jump to a pass that is not the next one, ``camotics_bear.nc`` steps
over with ``G1``; this program's passes are all adjacent, so its only rapids are the approach and
the return. :func:`program_statistics` recomputes the table's rows;
``nctwin.chapters.lee2022.program_statistics_table`` writes all three rows to the chapter's results.

Statistics
----------
With the default :class:`FinishingParams` and ``seed=0``:

===============================  ==============================================
lines                            22,626
blocks                           22,497: 22,250 G1, 122 G2, 120 G3, 5 G0
passes                           121 (step-over 0.5 mm, 80 mm long each)
G1 chords (G1 that move in X)    22,126 (with the links across that move in X;
                                 the other 124 G1 do not)
cutting path length (G1, G2, G3) 12,042 mm, of which lead arcs 1,908 mm
rapid path length                159 mm
chord length (mm)                min 0.085, p5 0.168, median 0.426,
                                 mean 0.458, p95 0.869, max 1.001
chords shorter than 0.5 mm       62.6 %
===============================  ==============================================

(``seed=1``: 19,572 blocks, 19,204 chords, median 0.487 mm, min 0.095 mm.) To recompute:
``program_statistics(finishing3d_program(seed=0))``, which parses the text with
:func:`nctwin.gcode.parse` and reads ``Toolpath.lengths_mm``: the chords are the ``G1`` blocks
whose X moves, the percentiles ``numpy.percentile`` of their lengths.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..checks import check_int, check_range
from ..gcode import parse
from ..toolpath import MotionKind, Toolpath

__all__ = [
    "FinishingParams",
    "finishing3d",
    "finishing3d_program",
    "program_statistics",
    "real_cam_text",
    "write_finishing3d",
]


@dataclass(frozen=True)
class FinishingParams:
    """Settings of the finishing program.

    Parameters
    ----------
    width_mm : float
        Length of each pass along X.
    length_mm : float
        Extent of the raster along Y.
    stepover_mm : float
        Distance between passes.
    tool_radius_mm : float
        Radius of the ball-end mill.
    tolerance_mm : float
        CAM chordal tolerance.
    max_segment_mm : float
        Longest chord CAM writes.
    feed_mm_min : float
        Finishing feed of the passes, lead arcs and links.
    steep_feed_mm_min : float
        Feed of the chords that descend more steeply than ``steep_angle_deg``.
    steep_angle_deg : float
        Descent angle (from the horizontal) beyond which a chord takes ``steep_feed_mm_min``.
    lead_radius_mm : float
        Radius of the lead-in and lead-out arcs.
    bumps : int
        Gaussian hills and hollows of the surface.
    """

    width_mm: float = 80.0
    length_mm: float = 60.0
    stepover_mm: float = 0.5
    tool_radius_mm: float = 3.0
    tolerance_mm: float = 0.001
    max_segment_mm: float = 1.0
    feed_mm_min: float = 1300.0
    steep_feed_mm_min: float = 800.0
    steep_angle_deg: float = 45.0
    lead_radius_mm: float = 5.0
    bumps: int = 14

    def __post_init__(self) -> None:
        for name, hi in (
            ("width_mm", 1000.0),
            ("length_mm", 1000.0),
            ("stepover_mm", 100.0),
            ("tool_radius_mm", 50.0),
            ("tolerance_mm", 1.0),
            ("max_segment_mm", 100.0),
            ("feed_mm_min", 100000.0),
            ("steep_feed_mm_min", 100000.0),
            ("steep_angle_deg", 90.0),
            ("lead_radius_mm", 100.0),
        ):
            check_range(name, getattr(self, name), 0.0, hi, low_open=True)
        check_int("bumps", self.bumps, 0)
        if self.max_segment_mm < 10 * self.tolerance_mm:
            raise ValueError(
                f"max_segment_mm = {self.max_segment_mm!r} is out of range: allowed "
                f">= 10 tolerance_mm = {10 * self.tolerance_mm!r}"
            )


class _Surface:
    """:math:`z = f(x, y)`: Gaussian bumps and one wave, with exact first and second
    derivatives."""

    def __init__(self, rng: np.random.Generator, p: FinishingParams) -> None:
        w, h = p.width_mm, p.length_mm
        n = p.bumps
        self.amp = rng.uniform(2.0, 6.0, n) * rng.choice([-1.0, 1.0], n)
        self.sigma = rng.uniform(3.0, 9.0, n)
        self.cx = rng.uniform(-0.1 * w, 1.1 * w, n)
        self.cy = rng.uniform(-0.1 * h, 1.1 * h, n)
        self.wave = rng.uniform(0.5, 1.5)
        self.kx, self.ky = 2.0 * math.pi / rng.uniform(30.0, 60.0, 2)
        self.phase = rng.uniform(0.0, 2.0 * math.pi)
        # the tool must fit every hollow: scale so that the largest concave curvature (the
        # largest eigenvalue of the Hessian, an upper bound) is at most 0.8 / tool radius
        gx, gy = np.meshgrid(np.linspace(0, w, 161), np.linspace(0, h, 121))
        _, _, _, fxx, fxy, fyy = self.eval(gx.ravel(), gy.ravel())
        lam = 0.5 * (fxx + fyy) + np.sqrt(0.25 * (fxx - fyy) ** 2 + fxy**2)
        scale = min(1.0, 0.8 / (p.tool_radius_mm * max(float(lam.max()), 1e-12)))
        self.amp *= scale
        self.wave *= scale

    def eval(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, ...]:
        """``f, fx, fy, fxx, fxy, fyy`` at points ``x, y`` (each shape (n,))."""
        f = np.zeros_like(x)
        fx, fy, fxx, fxy, fyy = (np.zeros_like(x) for _ in range(5))
        for a, s, cx, cy in zip(self.amp, self.sigma, self.cx, self.cy, strict=True):
            dx, dy = x - cx, y - cy
            g = a * np.exp(-(dx * dx + dy * dy) / (2.0 * s * s))
            s2, s4 = s * s, s**4
            f += g
            fx -= dx / s2 * g
            fy -= dy / s2 * g
            fxx += (dx * dx / s4 - 1.0 / s2) * g
            fxy += dx * dy / s4 * g
            fyy += (dy * dy / s4 - 1.0 / s2) * g
        sx, cx_ = np.sin(self.kx * x + self.phase), np.cos(self.kx * x + self.phase)
        sy, cy_ = np.sin(self.ky * y), np.cos(self.ky * y)
        b, kx, ky = self.wave, self.kx, self.ky
        f += b * sx * cy_
        fx += b * kx * cx_ * cy_
        fy -= b * ky * sx * sy
        fxx -= b * kx * kx * sx * cy_
        fxy -= b * kx * ky * cx_ * sy
        fyy -= b * ky * ky * sx * cy_
        return f, fx, fy, fxx, fxy, fyy

    def tip(self, x: np.ndarray, y: np.ndarray, r: float) -> np.ndarray:
        r"""Height of the ball's tip over ``(x, y)`` (shape (n,)) touching the surface.

        The contact point ``(u, v)`` is where the surface normal passes through the ball's
        centre, :math:`(u, v) - r \nabla f / N = (x, y)` with
        :math:`N = \sqrt{1 + |\nabla f|^2}`, solved by Newton's method from ``(x, y)`` (one
        root, as no hollow is tighter than 1.25 r); the tip is then :math:`f + r / N - r`.
        """
        u, v = x.copy(), y.copy()
        for _ in range(30):
            _, fx, fy, fxx, fxy, fyy = self.eval(u, v)
            n2 = 1.0 + fx * fx + fy * fy
            n = np.sqrt(n2)
            ru, rv = u - r * fx / n - x, v - r * fy / n - y
            # Jacobian: I - r (I - g g^T / N^2) H / N, g the gradient, H the Hessian
            p11, p12, p22 = 1.0 - fx * fx / n2, -fx * fy / n2, 1.0 - fy * fy / n2
            j11 = 1.0 - r / n * (p11 * fxx + p12 * fxy)
            j12 = -r / n * (p11 * fxy + p12 * fyy)
            j21 = -r / n * (p12 * fxx + p22 * fxy)
            j22 = 1.0 - r / n * (p12 * fxy + p22 * fyy)
            det = j11 * j22 - j12 * j21
            du, dv = (j22 * ru - j12 * rv) / det, (j11 * rv - j21 * ru) / det
            u, v = u - du, v - dv
            if max(np.abs(du).max(initial=0.0), np.abs(dv).max(initial=0.0)) < 1e-11:
                break
        f, fx, fy, *_ = self.eval(u, v)
        return f + r / np.sqrt(1.0 + fx * fx + fy * fy) - r


def _chord_x(x: np.ndarray, z: np.ndarray, p: FinishingParams) -> np.ndarray:
    """X of the chord ends along one pass whose tip path ``z(x)`` is sampled at ``x`` (m,):
    chords of length ``min(Lmax, sqrt(8 rho tol))``, rho the smallest radius of curvature
    within 1 mm; shape (k + 1,) from ``x[0]`` to ``x[-1]``."""
    h = x[1] - x[0]
    dz = np.gradient(z, h)
    kappa = np.abs(np.gradient(dz, h)) / (1.0 + dz * dz) ** 1.5
    half = max(round(1.0 / h), 1)
    padded = np.pad(kappa, half, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1)
    kappa = windows.max(axis=1)
    density = np.maximum(1.0 / p.max_segment_mm, np.sqrt(kappa / (8.0 * p.tolerance_mm)))
    ds = np.hypot(np.diff(x), np.diff(z))
    count = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * ds)])
    n_seg = max(math.ceil(count[-1] - 1e-9), 1)
    out = np.interp(np.linspace(0.0, count[-1], n_seg + 1), count, x)
    out[0], out[-1] = x[0], x[-1]
    return out


def _num(v: float) -> str:
    """A coordinate with 3 decimals (Fanuc IS-B), no trailing zeros, no negative zero."""
    s = f"{v:.3f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _lead(
    point: np.ndarray, slope: float, r: float, entering: bool, direction: float
) -> tuple[np.ndarray, ...]:
    """Lead arc in the XZ plane of radius ``r`` tangent to the pass at ``point`` (x, z) where the
    pass, travelled along ``direction`` X (+1 or -1), has slope ``dz/dx``: into the pass from
    straight down (``entering``), or out of it to straight up. Returns the arc's start, end and
    centre, each shape (2,) as (x, z)."""
    centre = point + r * np.array([-slope, 1.0]) / math.hypot(1.0, slope)  # above the pass
    outside = centre + np.array([-direction * r, 0.0] if entering else [direction * r, 0.0])
    return (outside, point, centre) if entering else (point, outside, centre)


def _arc(start: np.ndarray, end: np.ndarray, centre: np.ndarray) -> str:
    """The ``G2``/``G3`` block of a lead arc (start, end and centre as (x, z), each (2,)) in the
    ZX plane: clockwise seen from +Y with the plane's axes in the order (Z, X)."""
    a, b = start - centre, end - centre
    cross = a[1] * b[0] - a[0] * b[1]  # (z, x) components: z_a x_b - x_a z_b
    word = "G03" if cross > 0 else "G02"
    i, k = centre - start
    return f"{word} X{_num(end[0])} Z{_num(end[1])} I{_num(i)} K{_num(k)}"


def finishing3d_program(seed: int = 0, params: FinishingParams | None = None) -> str:
    """The finishing program as G-code text (see the module docstring).

    Parameters
    ----------
    seed : int
        Seed of ``numpy.random.default_rng`` that draws the surface.
    params : FinishingParams, optional
        Default ``FinishingParams()``.

    Returns
    -------
    str
        The program, ending with ``M30``.
    """
    p = FinishingParams() if params is None else params
    rng = np.random.default_rng(seed)
    surf = _Surface(rng, p)
    r = p.tool_radius_mm
    n_pass = math.floor(p.length_mm / p.stepover_mm + 1e-9) + 1
    ys = np.arange(n_pass) * p.stepover_mm
    h = 0.05
    xs = np.linspace(0.0, p.width_mm, round(p.width_mm / h) + 1)
    dense = surf.tip(np.tile(xs, n_pass), np.repeat(ys, len(xs)), r).reshape(n_pass, len(xs))
    safe_z = math.ceil(dense.max() + p.lead_radius_mm + 5.0)
    head = [
        "%",
        "(3D BALL-END FINISHING, ZIGZAG RASTER ALONG X, WRITTEN BY NCTWIN.PROGRAMS.FINISHING3D)",
        f"(SEED={seed}, " + ", ".join(f"{k}={v}" for k, v in asdict(p).items()) + ")",
        "G21 G90 G18 G40 G49 G80 G94",
        "M03 S12000",
        f"G00 Z{_num(safe_z)}",
    ]
    chord_x = [_chord_x(xs, dense[k], p) for k in range(n_pass)]
    sizes = [len(c) for c in chord_x]
    chord_z = np.split(surf.tip(np.concatenate(chord_x), np.repeat(ys, sizes), r),
                       np.cumsum(sizes)[:-1])  # fmt: skip
    # the pass's slope at both ends, for the tangent lead arcs
    dx = 1e-3
    ex = np.tile([0.0, dx, p.width_mm - dx, p.width_mm], n_pass)
    edge = surf.tip(ex, np.repeat(ys, 4), r).reshape(n_pass, 4)
    steep = math.tan(math.radians(p.steep_angle_deg))
    body: list[str] = []
    modal: list[str] = [""]  # the F word in force

    def feed(value: float) -> str:
        word = f" F{_num(value)}"
        if word == modal[0]:
            return ""
        modal[0] = word
        return word

    for k, y in enumerate(ys):
        d = 1.0 if k % 2 == 0 else -1.0  # zigzag: even passes along +X, odd ones back
        cx, cz = (chord_x[k], chord_z[k]) if d > 0 else (chord_x[k][::-1], chord_z[k][::-1])
        s0, s1 = (edge[k, 1] - edge[k, 0]) / dx, (edge[k, 3] - edge[k, 2]) / dx
        slope_in, slope_out = (s0, s1) if d > 0 else (s1, s0)
        a0, a1, ac = _lead(np.array([cx[0], cz[0]]), slope_in, p.lead_radius_mm, True, d)
        b0, b1, bc = _lead(np.array([cx[-1], cz[-1]]), slope_out, p.lead_radius_mm, False, d)
        body.append(f"(PASS {k + 1} OF {n_pass}, Y{_num(y)})")
        if k == 0:  # rapid to the lead-in's start, as the CAM programs do
            body.append(f"G00 X{_num(a0[0])} Y{_num(y)}")
            body.append(f"G00 Z{_num(a0[1])}")
        else:  # link from the last lead-out at the finishing feed: down or up, then across
            body.append(f"G01 Z{_num(a0[1])}" + feed(p.feed_mm_min))
            body.append(f"G01 X{_num(a0[0])} Y{_num(y)}" + feed(p.feed_mm_min))
        body.append(_arc(a0, a1, ac) + feed(p.feed_mm_min))
        down = -np.diff(cz) > steep * np.abs(np.diff(cx))
        for x, z, dn in zip(cx[1:], cz[1:], down, strict=True):
            body.append(f"G01 X{_num(x)} Z{_num(z)}" + feed(p.steep_feed_mm_min if dn
                                                               else p.feed_mm_min))  # fmt: skip
        body.append(_arc(b0, b1, bc) + feed(p.feed_mm_min))
    body.append(f"G00 Z{_num(safe_z)}")
    tail = ["G00 X0 Y0", "M05", "M30", "%"]
    return "\n".join(head + body + tail) + "\n"


def finishing3d(seed: int = 0, params: FinishingParams | None = None) -> Toolpath:
    """The finishing program as a :class:`~nctwin.toolpath.Toolpath` (parsed from its text)."""
    return parse(finishing3d_program(seed, params), source=f"finishing3d_seed{seed}.nc")


def write_finishing3d(
    path: str | Path, seed: int = 0, params: FinishingParams | None = None
) -> Path:
    """Write the program to ``path`` (atomically: a temporary file, then a rename)."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.tmp")
    tmp.write_text(finishing3d_program(seed, params), encoding="utf-8", newline="\n")
    tmp.replace(target)
    return target


def real_cam_text(path: str | Path) -> str:
    """The text of a real CAM program with its feed words restored.

    ``LHchips4.ngc``'s post-processor wrote every letter F as ``F999``: its comments read
    ``F999ile``, ``F999inished`` and ``ONLY F999INISH``, its feed words ``F9991300.0`` and
    ``F999800.0``. Where a text holds ``F999ile``, every ``F999`` is put back to ``F``; any
    other text is returned as read.

    Parameters
    ----------
    path : str or path-like
        The program's file.

    Returns
    -------
    str
    """
    text = Path(path).read_text()
    return text.replace("F999", "F") if "F999ile" in text else text


def program_statistics(text: str) -> dict[str, float]:
    """Size of a program: lines, blocks, path lengths, feeds, arc radii and the chord lengths.

    Parameters
    ----------
    text : str
        A program :func:`nctwin.gcode.parse` reads.

    Returns
    -------
    dict of str to float
        ``lines``; ``blocks`` and ``g0``, ``g1``, ``g2``, ``g3`` blocks; ``cut_length_mm`` (G1,
        G2, G3), ``arc_length_mm``, ``rapid_length_mm``; the cutting feeds (mm/min) over the
        G1, G2, G3 blocks: ``feed_main_mm_min``, the feed that covers the most cutting length,
        and ``feed_main_share``, the share it covers, ``feed_min_mm_min`` and
        ``feed_max_mm_min``; the arcs' radii ``arc_radius_min_mm``, ``arc_radius_median_mm``,
        ``arc_radius_max_mm`` (NaN without arcs); over the G1 blocks that move in X (the
        chords, not the plunges): ``chords`` and their length ``chord_min_mm``,
        ``chord_p5_mm``, ``chord_median_mm``, ``chord_mean_mm``, ``chord_p95_mm``,
        ``chord_max_mm`` and ``chord_share_below_0_5mm``.
    """
    tp = parse(text)
    counts = np.bincount(tp.kind, minlength=len(MotionKind))
    lengths = tp.lengths_mm
    lin = tp.kind == MotionKind.LINEAR
    chords = lin & (np.abs(tp.end_mm[:, 0] - tp.start_mm[:, 0]) > 0)
    c = lengths[chords]
    q = np.percentile(c, [5, 50, 95]) if len(c) else np.full(3, np.nan)
    cut = (tp.kind >= 1) & (tp.kind <= 3)
    feeds, where = np.unique(np.round(60.0 * tp.feed_mm_s[cut], 3), return_inverse=True)
    per_feed = np.bincount(where, weights=lengths[cut], minlength=len(feeds))
    main = int(np.argmax(per_feed)) if len(feeds) else -1
    radii = tp.radius_mm[tp.is_arc]
    return {
        "lines": float(text.count("\n")),
        "blocks": float(len(tp)),
        "g0": float(counts[MotionKind.RAPID]),
        "g1": float(counts[MotionKind.LINEAR]),
        "g2": float(counts[MotionKind.ARC_CW]),
        "g3": float(counts[MotionKind.ARC_CCW]),
        "cut_length_mm": float(lengths[cut].sum()),
        "arc_length_mm": float(lengths[tp.is_arc].sum()),
        "rapid_length_mm": float(lengths[tp.kind == MotionKind.RAPID].sum()),
        "feed_main_mm_min": float(feeds[main]) if len(feeds) else math.nan,
        "feed_main_share": float(per_feed[main] / per_feed.sum()) if len(feeds) else math.nan,
        "feed_min_mm_min": float(feeds[0]) if len(feeds) else math.nan,
        "feed_max_mm_min": float(feeds[-1]) if len(feeds) else math.nan,
        "arc_radius_min_mm": float(radii.min()) if len(radii) else math.nan,
        "arc_radius_median_mm": float(np.median(radii)) if len(radii) else math.nan,
        "arc_radius_max_mm": float(radii.max()) if len(radii) else math.nan,
        "chords": float(len(c)),
        "chord_min_mm": float(c.min()) if len(c) else math.nan,
        "chord_p5_mm": float(q[0]),
        "chord_median_mm": float(q[1]),
        "chord_mean_mm": float(c.mean()) if len(c) else math.nan,
        "chord_p95_mm": float(q[2]),
        "chord_max_mm": float(c.max()) if len(c) else math.nan,
        "chord_share_below_0_5mm": float((c < 0.5).mean()) if len(c) else math.nan,
    }
