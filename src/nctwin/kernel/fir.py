r"""FIR-filter interpolation with corner blending within a tolerance, and look-ahead.

The "NC kernel simulator" of Chien, Sencer & Ward (2023, Sec. 4), after the FIR interpolation
of Tajima & Sencer (2018) and Hayasaka et al. (2019): every block is commanded as a velocity pulse
along the path; a cascade of two moving-average (FIR) filters of lengths :math:`T_1` and
:math:`T_2` smooths the pulses. A straight line of length :math:`L` at feed :math:`F` takes exactly

.. math:: t = L / F + T_1 + T_2,

with acceleration :math:`A = F / T_1` and jerk :math:`J = F / (T_1 T_2)`.

Where consecutive pulses overlap in the filter window, the filtered path cuts the corner. For an
isolated corner of angle :math:`\theta` passed at speed :math:`V` the deviation from the corner is

.. math:: \varepsilon = V \sin(\theta / 2) \, \frac{3 T_1^2 + T_2^2}{12\, T_1}
   \qquad (T_1 \ge T_2),

derived in :func:`corner_deviation_mm`. The kernel plans, for every junction, the highest speed
whose filtered path stays within the blending tolerance of the corner:

* **Local blending.** An isolated sharp corner: the speed is lowered so that the deviation is the
  tolerance.
* **Global blending.** Where the filter window spans several short blocks, they are averaged
  together; the deviation is evaluated on the filtered polyline itself (the discrete filter
  applied to the path at constant speed), so a series of short segments on a smooth curve keeps
  a high feed and the feed drops only as far as the deviation requires.
* **Look-ahead.** A reduced junction speed is commanded over the filter window centred on the
  junction (half a window before, half after), so the tool slows before the corner; where windows
  of several junctions overlap the lowest speed wins. Block feeds are capped by the axis velocity
  limits, by ``A_axis * T1`` per axis (so that no velocity step exceeds the axis acceleration
  once filtered), by the centripetal acceleration and filter shrinkage on arcs.
* G61/G61.1, a zero tolerance and dwells stop the tool: the command waits one filter length so
  the filters drain, then dwells.

Conventions: the filters act on the command positions sampled at the interpolation period
``Ts``; a box of ``T/Ts + 1`` taps ramps a velocity step over exactly ``T``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .._rows import row_min, row_norm
from ..checks import check_range
from ..controls import FirControl
from ..geometry import PathGeometry
from ..limits import path_limits
from ..machine import Machine
from ..motion import Motion
from ..toolpath import MotionKind, Toolpath
from . import _fir_loops, fir_rapids
from ._fir_command import Plan, _Command, _command

__all__ = [
    "FirFilter",
    "corner_deviation_mm",
    "enforced_machine",
    "plan",
    "run",
    "stand_in",
]


@dataclass(frozen=True)
class FirFilter:
    """The two-stage moving-average filter of the interpolator.

    Parameters
    ----------
    t1_s, t2_s : float
        Lengths of the two moving averages (``t1_s >= period_s``).
    period_s : float
        Interpolation period.
    """

    t1_s: float
    t2_s: float
    period_s: float

    def __post_init__(self) -> None:
        check_range("period_s", self.period_s, 0.0, 0.1, low_open=True)
        check_range("t1_s", self.t1_s, self.period_s, 10.0)
        check_range("t2_s", self.t2_s, 0.0, 10.0)

    @classmethod
    def of(cls, control: FirControl) -> FirFilter:
        """The filter of the control's settings (the longer time constant first)."""
        t1, t2 = max(control.t1_s, control.t2_s), min(control.t1_s, control.t2_s)
        return cls(t1, t2, control.period_s)

    @property
    def taps(self) -> tuple[int, int]:
        """Number of taps of each box: ``T / Ts + 1``."""
        return (
            round(self.t1_s / self.period_s) + 1,
            round(self.t2_s / self.period_s) + 1,
        )

    @property
    def weights(self) -> np.ndarray:
        """Impulse response of the cascade, shape (n1 + n2 - 1,); sums to 1."""
        n1, n2 = self.taps
        return np.convolve(np.full(n1, 1.0 / n1), np.full(n2, 1.0 / n2))

    @property
    def length_s(self) -> float:
        """Duration over which the cascade spreads a step: ``T1 + T2`` (as sampled)."""
        return (len(self.weights) - 1) * self.period_s

    @property
    def variance_s2(self) -> float:
        """Variance of the impulse response in time (s^2): sets the shrinkage of arcs."""
        w = self.weights
        k = np.arange(len(w)) * self.period_s
        mean = (w * k).sum()
        return float((w * (k - mean) ** 2).sum())

    def apply(self, x: np.ndarray) -> np.ndarray:
        """Filter sampled positions ``x``, shape (3, n), axis-major, that start and end at rest.

        Returns shape (3, n + n1 + n2 - 2), the transpose of a C-contiguous (n + n1 + n2 - 2, 3)
        array: the input is held at its first and last value outside its span. Each box is a
        difference of running sums, O(n); the sums run over positions relative to the start,
        which keeps their rounding below 1e-7 mm.
        """
        return self._apply_rows(x.T).T

    def _apply_rows(self, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """:meth:`apply` on sample-major positions, (n, 3), to (n', 3) C-contiguous: into
        ``out`` if given, of which ``x`` may be the first n rows (filtered in place)."""
        taps = np.array([n for n in self.taps if n > 1], dtype=np.int64)
        if out is None:
            out = np.empty((len(x) + int(taps.sum()) - len(taps), 3))
        _fir_loops.box_cascade(x, taps, out)
        return out


def corner_deviation_mm(speed_mm_s, angle_rad, t1_s: float, t2_s: float):
    r"""Deviation from an isolated corner filtered at constant speed (continuous time).

    The filtered velocity is :math:`V(u_1 + (u_2 - u_1) S(t))`, with :math:`S` the step response
    of the cascade. At the middle of the transition the tool is at
    :math:`C + V (u_2 - u_1) \int_0^{T/2} S`, and :math:`|u_2 - u_1| = 2 \sin(\theta/2)`. With
    :math:`T_1 \ge T_2`, :math:`\int_0^{(T_1+T_2)/2} S = (3 T_1^2 + T_2^2) / (24 T_1)`.

    Parameters
    ----------
    speed_mm_s : float or ndarray
    angle_rad : float or ndarray
        Change of direction at the corner (0 = straight on).
    t1_s, t2_s : float
        Filter lengths.
    """
    t1, t2 = max(t1_s, t2_s), min(t1_s, t2_s)
    return speed_mm_s * np.sin(np.asarray(angle_rad) / 2) * (3 * t1**2 + t2**2) / (12 * t1)


def _block_feeds(
    tp: Toolpath,
    machine: Machine,
    fir: FirFilter,
    feed_mm_s: np.ndarray,
    tol_mm: np.ndarray,
    ramp_rapids: bool = False,
) -> np.ndarray:
    """Cruise feed of each block (mm/s), shape (N,): the programmed feed ``feed_mm_s`` (N,)
    within every limit (:func:`nctwin.limits.path_limits` of the axes' velocities and of the
    velocity steps the filters make of their accelerations and jerks; on arcs, the centripetal
    acceleration and the filter's radial shrinkage within the tolerance ``tol_mm`` (N,): the
    program's, or on an exact-stop arc the control's, since exact stop acts at a block's ends))."""
    kind = tp.kind
    f = np.where(
        kind == MotionKind.RAPID,
        machine.rapid_feed_mm_s,
        np.minimum(np.nan_to_num(feed_mm_s, nan=np.inf), machine.max_feed_mm_s),
    )
    limits = path_limits(tp, machine)
    with np.errstate(divide="ignore"):
        step = fir_rapids.step_mm_s(machine, limits, fir.t1_s, fir.t2_s)
        # a ramped rapid climbs to its feed in steps (fir_rapids); every other block is capped
        step[(kind == MotionKind.RAPID) & ramp_rapids] = np.inf
        f = np.minimum(f, np.minimum(limits.cap(machine.axis_max_velocity_mm_s), step))
        arc = tp.is_arc
        if arc.any():
            r = tp.radius_mm[arc]
            v_arc = np.sqrt(limits.acceleration_mm_s2[arc] * r)  # centripetal acceleration
            v_shrink = np.sqrt(2.0 * r * tol_mm[arc] / fir.variance_s2)  # filter's radial shrink
            f[arc] = np.minimum(f[arc], np.minimum(v_arc, v_shrink))
    f[kind == MotionKind.DWELL] = np.inf
    return f


def _filtered_deviation(geo, s_mm, point_mm, speed_mm_s, fir: FirFilter) -> np.ndarray:
    """Distance from each junction to the filtered path, the path run at constant speed.

    The filter output at the junction's passing time is the weighted mean of the path points
    ``speed * Ts * (c - m)`` ahead (``c`` the centre tap), which is what the kernel computes when
    the speed is constant over the window. Consecutive taps are pooled into at most
    :data:`DEVIATION_NODES` nodes (weights summed, offsets averaged), exact wherever the path is
    straight within a node. Shape (K,).
    """
    w, offsets = _deviation_nodes(fir)
    filt = np.empty((len(s_mm), 3))
    _fir_loops.filtered_points(s_mm, speed_mm_s, offsets, w, geo.loop_arrays, filt)
    return row_norm(filt - point_mm)


#: Share of the tolerance kept in reserve: the plan evaluates the filter at the junction's
#: passing time, the samples fall up to half a period beside it (measured: < 0.05 %).
PHASE_MARGIN = 0.002

#: Relative precision of planned junction speeds (or of the deviation reaching the tolerance).
V_RTOL = 0.002

#: Quadrature nodes of the deviation check (pooled filter taps).
DEVIATION_NODES = 24


@lru_cache(maxsize=16)
def _deviation_nodes(fir: FirFilter) -> tuple[np.ndarray, np.ndarray]:
    """Pooled weights and time offsets (s) of the filter taps, centred on the middle tap
    (cached per filter: the plan evaluates them in every step; not to be modified)."""
    w = fir.weights
    offsets = (0.5 * (len(w) - 1) - np.arange(len(w))) * fir.period_s
    nodes = min(DEVIATION_NODES, len(w))
    groups = np.arange(len(w)) * nodes // len(w)
    wg = np.bincount(groups, weights=w)
    og = np.bincount(groups, weights=w * offsets) / wg
    return wg, og


def plan(
    tp: Toolpath, machine: Machine, control: FirControl, *, geo: PathGeometry | None = None
) -> Plan:
    """Look-ahead: cruise feeds, junction speeds and pauses (see the module docstring).

    Parameters
    ----------
    tp : Toolpath
        N blocks.
    machine : Machine
        The limits (the accelerations times ``control.acc_scale``, :func:`enforced_machine`).
    control : FirControl
        The filters, and the feeds and tolerances the kernel runs (:func:`stand_in`).
    geo : PathGeometry, optional
        The path's geometry (computed if not given).
    """
    n = len(tp)
    geo = geo if geo is not None else PathGeometry(tp)
    machine = enforced_machine(machine, control)
    fir = FirFilter.of(control)
    feed_mm_s, tol = stand_in(tp, control)
    contour_tol = np.where(tol > 0, tol, control.blend_tol_mm)
    feed = _block_feeds(tp, machine, fir, feed_mm_s, contour_tol, control.rapid_ramp)
    v = np.zeros(n + 1)
    pause = np.zeros(n + 1)
    if n == 0:
        return Plan(feed, v, pause)
    amax = np.asarray(machine.axis_max_acceleration_mm_s2)
    jmax = np.asarray(machine.axis_max_jerk_mm_s3)
    dwell = tp.kind == MotionKind.DWELL

    j = np.arange(1, n)  # junction j: end of block j-1, start of block j
    cap = np.minimum(feed[j - 1], feed[j])
    # a velocity step across the corner, per axis, is smoothed over T1 (acceleration), T1 T2 (jerk)
    du = np.abs(tp.start_tangents[j] - tp.end_tangents[j - 1])
    with np.errstate(divide="ignore"):
        step = amax * fir.t1_s
        if fir.t2_s > 0:
            step = np.minimum(step, jmax * fir.t1_s * fir.t2_s)
        cap = np.minimum(cap, row_min(step / du))
    stop = dwell[j] | dwell[j - 1] | (tol[j] == 0)
    cap[stop] = 0.0
    v[j] = cap
    # contour deviation within the tolerance of the block that starts at the junction
    check = np.flatnonzero((cap > 0) & np.isfinite(tol[j]))
    if len(check):
        jj = j[check]
        s_j, p_j, tol_j = geo.s_start_mm[jj], tp.start_mm[jj], tol[jj] * (1 - PHASE_MARGIN)
        hi = cap[check].copy()
        e_hi = _filtered_deviation(geo, s_j, p_j, hi, fir)
        # largest V with e(V) <= tol: secant steps on log e over log V (e ~ V for a local
        # corner, ~ V^2 for a smooth curve) alternating with bisection of the bracket [lo, hi]
        lo, e_lo = np.zeros_like(hi), np.zeros_like(hi)
        # an isolated corner between two lines longer than half a window: the deviation is
        # exactly proportional to the speed, so one step solves it
        reach = hi * (0.5 * fir.length_s + fir.period_s)
        line = (tp.kind[jj - 1] <= MotionKind.LINEAR) & (tp.kind[jj] <= MotionKind.LINEAR)
        alone = line & (tp.lengths_mm[jj - 1] > reach) & (tp.lengths_mm[jj] > reach)
        alone &= e_hi > tol_j
        lo[alone] = hi[alone] * tol_j[alone] / e_hi[alone]
        e_lo[alone] = tol_j[alone]
        active = np.flatnonzero((e_hi > tol_j) & ~alone)
        for it in range(60):
            if not len(active):
                break
            a = active
            lo_a, hi_a, e_lo_a, e_hi_a, tol_a = lo[a], hi[a], e_lo[a], e_hi[a], tol_j[a]
            guess = 0.5 * (lo_a + hi_a)  # odd steps bisect
            if it % 2 == 0:
                with np.errstate(divide="ignore", invalid="ignore"):
                    slope = np.where(lo_a > 0, np.log(e_hi_a / e_lo_a) / np.log(hi_a / lo_a), 1.0)
                    slope = np.clip(np.where(np.isnan(slope), 1.0, slope), 0.5, 4.0)
                    secant = hi_a * (tol_a / e_hi_a) ** (1.0 / slope)
                inside = (secant > lo_a) & (secant < hi_a)
                guess[inside] = secant[inside]
            e = _filtered_deviation(geo, s_j[a], p_j[a], guess, fir)
            ok = e <= tol_a
            lo_a[ok], e_lo_a[ok] = guess[ok], e[ok]
            hi_a[~ok], e_hi_a[~ok] = guess[~ok], e[~ok]
            lo[a], hi[a], e_lo[a], e_hi[a] = lo_a, hi_a, e_lo_a, e_hi_a
            done = (hi_a - lo_a <= V_RTOL * hi_a) | (e_lo_a >= (1 - V_RTOL) * tol_a)
            active = a[~done]
        v[jj] = np.where(e_hi <= tol_j, hi, lo)
    # waiting: the filters drain before a stop (not after a dwell, already at rest), and dwells
    drain = (v[:n] == 0) & np.concatenate([[False], ~dwell[:-1]])
    drain[0] = False
    pause[:n] = np.where(drain, fir.length_s, 0.0) + np.where(dwell, tp.dwell_s, 0.0)
    ramp = None
    if control.rapid_ramp:
        step = fir_rapids.step_mm_s(machine, path_limits(tp, machine), fir.t1_s, fir.t2_s)
        ramp = np.where(tp.kind == MotionKind.RAPID, step, np.nan)
    return Plan(feed, v, pause, ramp)


#: Largest distance between an arc and the chords the command is interpolated on (mm).
ARC_CHORD_TOL_MM = 1e-6


def _arc_refinement(tp: Toolpath, geo: PathGeometry, cmd: _Command):
    """Knots to add inside arcs so that interpolating positions linearly in time between knots
    stays within :data:`ARC_CHORD_TOL_MM` of the arc (speed is constant between knots).

    Returns, for the refined knots, the interval of the command's :attr:`~_Command.knot_s` each
    starts and its fraction of the way along it (both shape (R,)), for :func:`_refined`; None
    where no knot is added (at once without arcs). The refinement depends on arc lengths only:
    it holds for the time knots of every pass."""
    if not tp.is_arc.any():
        return None
    s_knots = cmd.knot_s
    ds = np.diff(s_knots)
    if not len(ds):
        return None
    mid = 0.5 * (s_knots[:-1] + s_knots[1:])
    b = geo.block_at_ordered(mid)
    r = np.where(tp.is_arc[b], tp.radius_mm[b], np.inf)
    r = np.where(r > 0, r, np.inf)
    # chord of angle dphi deviates r (1 - cos(dphi / 2)) ~ r dphi^2 / 8 from the arc
    dphi = np.sqrt(8.0 * ARC_CHORD_TOL_MM / r)
    with np.errstate(invalid="ignore"):
        planar = np.abs(tp.sweep_rad[b]) * np.divide(
            ds, geo.lengths_mm[b], out=np.zeros_like(ds), where=geo.lengths_mm[b] > 0
        )
    need = np.divide(planar, dphi, out=np.zeros_like(planar), where=dphi > 0)
    parts = np.maximum(1, np.ceil(need).astype(np.int64))
    if parts.max() == 1:
        return None
    seg = np.repeat(np.arange(len(ds)), parts)
    frac = (np.arange(len(seg)) - np.repeat(np.cumsum(parts) - parts, parts)) / parts[seg]
    return seg, frac


def _refined(knots: np.ndarray, refinement) -> np.ndarray:
    """Time or arc-length knots (K,) with the knots of :func:`_arc_refinement` added."""
    if refinement is None:
        return knots
    seg, frac = refinement
    return np.append(knots[seg] + frac * np.diff(knots)[seg], knots[-1])


#: Relative excess over an axis limit that counts as a violation (rounding of differences).
LIMIT_RTOL = 1e-6
#: Passes of slowing down where a filtered profile still exceeds an axis limit.
MAX_SLOWDOWNS = 12
#: Extra slow-down per pass, so that the passes converge.
SLOWDOWN_MARGIN = 0.02


def _first_change(x: np.ndarray, ref: np.ndarray) -> int:
    """Index of the first row of ``x`` (n, 3) that differs from ``ref`` (3,), ``n`` if none.

    Searches growing chunks from the start: the answer is near it, and the rest is not read."""
    start, size = 0, 256
    while start < len(x):
        hit = np.flatnonzero((x[start : start + size] != ref).any(axis=1))
        if len(hit):
            return start + int(hit[0])
        start, size = start + size, 4 * size
    return len(x)


def _interpolate(tp, fir: FirFilter, t_knots, x_knots):
    """Sample the command, positions ``x_knots`` (K, 3) at times ``t_knots`` (K,), at the period
    and filter it; exact rest at both ends.

    Returns the filtered positions and room for their velocities, shape (2, n, 3): one
    allocation, which numpy lets the kernel back with huge pages from 4 MB on (a fault each
    2 MB instead of each 4 kB); and the filter lag in samples."""
    ts = fir.period_s
    n_cmd = int(np.ceil(t_knots[-1] / ts - 1e-9)) + 1
    n1, n2 = fir.taps
    lag = n1 + n2 - 2
    samples = np.empty((2, n_cmd + lag, 3))
    pos = samples[0]
    x = pos[:n_cmd]  # the command, filtered in place
    _fir_loops.sample_command(n_cmd, ts, t_knots, np.ascontiguousarray(x_knots), 0, x)
    x[0], x[-1] = tp.start_mm[0], tp.end_mm[-1]
    first, last = x[0].copy(), x[-1].copy()
    head = _first_change(x, first)  # samples at rest at the start
    still = _first_change(x[::-1], last)  # and at the end
    fir._apply_rows(x, pos)
    # the filter's sums of equal values carry rounding: rest is exact at both ends
    pos[:head] = first
    pos[n_cmd - still + lag if still < n_cmd else 0 :] = last
    return samples, lag


def _limit_ratio(pos: np.ndarray, ts: float, limits: np.ndarray) -> np.ndarray | None:
    """The largest ratio of axis velocity, acceleration and jerk to their limits (3, 3) per
    sample of ``pos`` (n, 3), shape (n,); None when no sample exceeds a limit (the common case,
    checked first on the peaks of one compiled pass). Derivatives are backward differences."""
    peak = _fir_loops.derivative_peaks(pos, ts)
    over = peak > limits * (1.0 + LIMIT_RTOL)  # (order, axis) above the limit
    if not over.any():
        return None
    ratio = np.empty(len(pos))
    _fir_loops.limit_ratios(pos, ts, limits, over, ratio)
    return ratio


def _velocities(pos: np.ndarray, ts: float, vel: np.ndarray) -> None:
    """Axis velocities of ``pos`` (n, 3) into ``vel`` (n, 3): backward differences, 0 at the
    first sample."""
    vel[0] = 0.0
    np.subtract(pos[1:], pos[:-1], out=vel[1:])
    vel[1:] /= ts


def _moves(tp: Toolpath) -> np.ndarray:
    """Blocks of nonzero length, shape (N,): ``tp.lengths_mm > 0``, with the arc geometry
    (which the kernel computes again on the kept blocks) evaluated on the arcs only."""
    moves = row_norm(tp.end_mm - tp.start_mm) > 0  # the chord of lines
    arc = np.flatnonzero(tp.is_arc)
    if len(arc):
        moves[arc] = tp.take(arc).lengths_mm > 0
    return moves


def enforced_machine(machine: Machine, control: FirControl) -> Machine:
    """The limits the kernel keeps to: ``machine`` with its axis accelerations times
    ``control.acc_scale`` (itself where that is 1)."""
    if control.acc_scale == 1.0:
        return machine
    acc = tuple(control.acc_scale * a for a in machine.axis_max_acceleration_mm_s2)
    return dataclasses.replace(machine, axis_max_acceleration_mm_s2=acc)


def stand_in(toolpath: Toolpath, control: FirControl) -> tuple[np.ndarray, np.ndarray]:
    """The feed and the blending tolerance of each block as the kernel runs them, shapes
    (N,).

    The tolerance is the program's (``G64 P``) or else the control's, lowered by
    ``blend_ratio`` to that share of the shorter of the junction's two moves; ``block_periods``
    caps the feed of each cutting move at its length over that many periods. These two make
    the kernel stand in for another control; with their defaults (inf, 0) the programmed feeds
    and the tolerances come back unchanged.
    """
    tol = toolpath.effective_tolerance_mm(control.blend_tol_mm)
    feed = toolpath.feed_mm_s
    if control.blend_ratio == np.inf and control.block_periods == 0:
        return feed, tol
    length = toolpath.lengths_mm
    moving = length > 0
    prev = np.full(len(toolpath), np.inf)
    idx = np.flatnonzero(moving)
    prev[idx[1:]] = length[idx[:-1]]
    limit = np.where(moving, control.blend_ratio * np.minimum(length, prev), np.inf)
    tol = np.where(tol > 0, np.minimum(tol, limit), tol)
    if control.block_periods:
        cap = length / (control.block_periods * control.period_s)
        feed = np.where((toolpath.kind != MotionKind.RAPID) & moving, np.minimum(feed, cap), feed)
    return feed, tol


@dataclass(frozen=True, eq=False)
class Prepared:
    """What every pass of the kernel over a tool path shares (:func:`prepare`).

    Parameters
    ----------
    fir : FirFilter
    kept : ndarray of int, shape (M,)
        The blocks of the tool path the kernel runs (moves of non-zero length and dwells).
    tp : Toolpath
        Those blocks (M).
    cmd : _Command
        The speed command.
    limits : ndarray, shape (3, 3)
        Axis velocity, acceleration and jerk limits (row = order, column = axis).
    refinement : tuple or None
        :func:`_arc_refinement`.
    x_knots : ndarray, shape (K, 3)
        The path points of the (refined) knots, the same in every pass.
    """

    fir: FirFilter
    kept: np.ndarray
    tp: Toolpath
    cmd: _Command
    limits: np.ndarray
    refinement: tuple | None
    x_knots: np.ndarray


def prepare(toolpath: Toolpath, machine: Machine, control: FirControl) -> Prepared | None:
    """Plan ``toolpath`` and build its speed command; None where no block moves or dwells."""
    fir = FirFilter.of(control)
    # zero-length moves are no-ops: plan without them, report the kept blocks' indices
    kept = np.flatnonzero(_moves(toolpath) | (toolpath.kind == MotionKind.DWELL))
    tp = toolpath if len(kept) == len(toolpath) else toolpath.take(kept)
    if len(tp) == 0:
        return None
    geo = PathGeometry(tp)
    cmd = _command(
        tp, geo, plan(tp, machine, control, geo=geo), fir.length_s, fir.t1_s, fir.period_s
    )
    machine = enforced_machine(machine, control)
    limits = np.array(
        [
            machine.axis_max_velocity_mm_s,
            machine.axis_max_acceleration_mm_s2,
            machine.axis_max_jerk_mm_s3,
        ]
    )
    # the path points of the knots are the same in every pass: computed once
    refinement = _arc_refinement(tp, geo, cmd)
    if refinement is None:
        x_knots = np.repeat(geo.points(cmd.cuts), 2, axis=0)
    else:
        x_knots = geo.points(_refined(cmd.knot_s, refinement))
    return Prepared(fir, kept, tp, cmd, limits, refinement, x_knots)


def slow_down(
    scale: np.ndarray, t_knots: np.ndarray, bad: np.ndarray, ratio: np.ndarray, lag: int, ts: float
) -> None:
    """Lower ``scale`` (C - 1,), the command's speed factors, in place over the windows that made
    the samples ``bad`` (B,) exceed a limit by ``ratio`` (B,) (``t_knots`` (2C,) of the pass,
    ``lag`` the filter's lag in samples, ``ts`` the period)."""
    t_lo = (bad - lag - 3) * ts
    t_hi = bad * ts
    move_t0 = t_knots[1::2][:-1]  # start times of the moving intervals
    i_lo = np.searchsorted(move_t0, t_lo, side="right") - 1
    i_hi = np.searchsorted(move_t0, t_hi, side="right")
    factor = _fir_loops.range_min(len(scale), np.maximum(i_lo, 0), i_hi, 1.0 / ratio)
    slow = factor < 1.0
    scale[slow] *= factor[slow] * (1.0 - SLOWDOWN_MARGIN)


def run(toolpath: Toolpath, machine: Machine, control: FirControl) -> Motion:
    """Interpolate a tool path on the FIR kernel.

    Parameters
    ----------
    toolpath : Toolpath
    machine : Machine
        The axis limits, the rapid feed and the maximum feed.
    control : FirControl
        The period, the default tolerance, the filters and the stand-in settings
        (:func:`enforced_machine`, :func:`stand_in`).

    Returns
    -------
    Motion
        Samples every ``period_s`` from rest at the start to rest at the end, labelled with
        the blocks of ``toolpath``.
    """
    prep = prepare(toolpath, machine, control)
    if prep is None:
        z = np.zeros((1, 3))
        return Motion(np.zeros(1), z, z, np.zeros(1, dtype=np.int64), control.period_s)
    fir, cmd, refinement = prep.fir, prep.cmd, prep.refinement
    ts = fir.period_s
    scale = np.ones(len(cmd.speed))
    for _ in range(MAX_SLOWDOWNS + 1):
        t_knots = cmd.knot_times(scale)
        samples, lag = _interpolate(prep.tp, fir, _refined(t_knots, refinement), prep.x_knots)
        pos = samples[0]
        ratio = _limit_ratio(pos, ts, prep.limits)
        if ratio is None:
            break
        # slow the command over the windows that made the violating samples
        bad = np.flatnonzero(ratio > 1.0 + LIMIT_RTOL)
        slow_down(scale, t_knots, bad, ratio[bad], lag, ts)
    vel = samples[1]
    _velocities(pos, ts, vel)
    t = np.arange(len(pos), dtype=np.float64)
    t *= ts
    # block of each sample: the command's block at the centre of the filter window
    block = cmd.sample_blocks(t_knots, ts, lag // 2, prep.kept, 0, len(pos))
    return Motion(t, pos, vel, block, ts)
