r"""The ideal block-overlap control: interpolation first, linear acc/dec after it, in-position.

This is the machine the analytic estimator of Lee et al. 2022 (J. Korean Soc. Precis. Eng.
39(7), 537-543; :mod:`nctwin.methods.lee2022`) was derived for: it simulates, sample by sample
at the interpolation period :math:`T_I`, the algorithm behind the paper's eq. 1-16, so the
estimator is exact on it up to rounding and the in-position waits. The chapter uses it only as
its sanity row ("ideal machine"); its measured machine is :mod:`nctwin.kernel.fanuc`, which has
the effects this kernel lacks (block-processing time, arc clamp, other acc/dec shapes).

What is simulated
-----------------
Interpolation (ZOH at :math:`T_I`)
    A *chain* of consecutive cutting blocks (G1, G2, G3) is interpolated back to back along its
    arc length at each block's feed :math:`F_k` (clamped to the machine's ``max_feed_mm_s`` and
    to what its axis velocities allow along the block, :func:`nctwin.limits.path_limits`; the
    estimator has no such clamp). A block may end inside an interpolation period; the rest of
    that period already moves along the next block, so the interpolator rounds the chain, not
    each block, up to a whole number of periods. (The estimator rounds every block up, eq. 2;
    this is one source of its error.)
Acc/dec after interpolation (linear type)
    Each axis's per-period displacement passes through a moving average of length
    :math:`A_T` (``cut_time_constant_s``). The filter is the continuous-time box filter
    sampled exactly on the ZOH input, i.e. the FIR taps
    :math:`\tfrac{1}{K}[\tfrac12, 1, \dots, 1, \tfrac12]` with :math:`K = A_T / T_I`, so an
    isolated block of :math:`m` periods lasts exactly :math:`m T_I + A_T` (eq. 3). Because the
    next block's interpolation starts as soon as the previous one's ends, the filtered
    profiles of consecutive cutting blocks overlap by :math:`A_T`: this is block overlap
    (Fig. 6-7), and a chain lasts :math:`\lceil \sum_k l_k / F_k \rceil_{T_I} + A_T`.
Rapids (G0)
    No overlap: a rapid starts when the previous motion has stopped, and the next block waits
    for it. Linear type: the tool moves on a straight line at the rapid feed :math:`F_r` for
    :math:`m = \lceil l / F_r \rceil_{T_I}` periods, filtered with :math:`A_{TR}`
    (``rapid_time_constant_s``); a short rapid (:math:`m T_I < A_{TR}`) moves for
    :math:`T_a = \lceil \sqrt{l / a} \rceil_{T_I}`, :math:`a = F_r / A_{TR}`, filtered with
    :math:`T_a` (a triangle, eq. 9-11). Non-linear type: each axis does this on its own with its
    own travel (eq. 7, 12). A second moving average of length :math:`A_s` (``rapid_bell_s``)
    gives the bell (S-curve) shape (eq. 13-16).
Position loop and in-position check
    Each axis follows its command through the package's position loop
    (:class:`nctwin.physics.servo.PositionLoop`, first order without feed-forward),
    :math:`\dot e = v_\mathrm{cmd} - K_p e`, discretised exactly for ZOH input. After every
    rapid the next block waits until the following error :math:`|e|` of *every* axis is within
    its in-position width. The wait depends on the rapid's deceleration, the gain and the
    residual error of all axes, not on a table.
Dwell (G4)
    The command stands still for :math:`\lceil t_\mathrm{dwell} \rceil_{T_I}`.

Settings
--------
The control's settings (:math:`T_I`, the time constants, the rapid type, the position loops and
in-position widths) are an :class:`nctwin.controls.AccDecControl` (a profile's
``[control.accdec]`` table); the :class:`~nctwin.machine.Machine` gives the rapid feed
:math:`F_r`, the maximum feed and the axis velocities. Accelerations are the control's, set by
its time constants, so the machine's acceleration and jerk limits are not read.

Conventions
-----------
Samples at ``t = i * period_s``; sample 0 is the start position. The velocity stored at sample
``i`` is the commanded velocity during the period that ends there. Period ``i`` is credited to
the block the interpolator executes at its end; the acc/dec tail of a chain is credited to the
chain's last block, the in-position wait to its rapid. The Motion holds the commanded position
after acc/dec (what Servo Guide calls the command); the actual position is
``pos_mm - following_error_mm``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter

from ..checks import check_int
from ..controls import AccDecControl
from ..limits import path_limits
from ..machine import Machine
from ..motion import Motion
from ..physics.servo import PositionLoop
from ..toolpath import PLANE_AXES, MotionKind, Toolpath

__all__ = ["AccDecRun", "InPositionMeasurement", "measure_inposition_times", "run", "simulate"]

_CUT = (MotionKind.LINEAR, MotionKind.ARC_CW, MotionKind.ARC_CCW)


@dataclass(frozen=True, eq=False)
class AccDecRun:
    """Result of :func:`simulate`.

    Parameters
    ----------
    motion : Motion
        Commanded motion after acc/dec, ``n`` samples.
    following_error_mm : ndarray, shape (n, 3)
        Following error (command minus actual position) of X, Y, Z.
    block_times_s : ndarray, shape (N,)
        Time credited to each block (see the module's conventions); sums to the cycle time.
    inposition_wait_s : ndarray, shape (N,)
        In-position wait after each rapid; 0 for other blocks.
    command_end_s : ndarray, shape (N,)
        For rapids, the time their command ends (the in-position wait starts); NaN otherwise.
    """

    motion: Motion
    following_error_mm: np.ndarray
    block_times_s: np.ndarray
    inposition_wait_s: np.ndarray
    command_end_s: np.ndarray

    @property
    def cycle_time_s(self) -> float:
        """Measured cycle time: from cycle start until the last block is done (and, after a
        rapid, in position)."""
        return self.motion.cycle_time_s


def _ceil_periods(t_s: np.ndarray | float, period_s: float) -> np.ndarray:
    """Whole periods needed for ``t_s`` (ceil, forgiving 1e-9 period of round-off)."""
    return np.ceil(np.asarray(t_s, dtype=float) / period_s - 1e-9).astype(np.int64)


def _box(v: np.ndarray, k: int) -> np.ndarray:
    r"""Moving average of length ``k`` periods, sampled exactly on a ZOH input.

    Parameters
    ----------
    v : ndarray, shape (n, 3)
        Displacement per period.
    k : int
        Filter length in periods; 0 returns ``v``.

    Returns
    -------
    ndarray, shape (n + k, 3)
        Filtered displacement per period (taps :math:`[\tfrac12, 1, \dots, 1, \tfrac12] / k`),
        computed with cumulative sums in O(n).
    """
    if k == 0 or len(v) == 0:
        return v
    n = len(v)
    s = np.zeros((n + k + 1, v.shape[1]))
    np.cumsum(v, axis=0, out=s[1 : n + 1])
    s[n + 1 :] = s[n]
    lag = np.zeros_like(s)
    lag[k:] = s[: n + 1]
    box = (s[1:] - lag[1:]) / k  # causal box of length k, shape (n + k, 3)
    out = 0.5 * box
    out[1:] += 0.5 * box[:-1]
    return out


class _Geometry:
    """Per-block geometry needed to place points on blocks, computed once per program (O(N))."""

    def __init__(self, tp: Toolpath) -> None:
        self.tp = tp
        self.start = tp.start_mm
        self.delta = tp.end_mm - tp.start_mm
        self.is_arc = tp.is_arc
        ax = PLANE_AXES[tp.plane]
        rows = np.arange(len(tp))
        c = np.nan_to_num(tp.center_mm)
        s0, e0 = tp.start_mm - c, tp.end_mm - c
        self.ax = ax
        self.c1, self.c2 = c[rows, ax[:, 0]], c[rows, ax[:, 1]]
        self.rs = np.hypot(s0[rows, ax[:, 0]], s0[rows, ax[:, 1]])
        self.dr = np.hypot(e0[rows, ax[:, 0]], e0[rows, ax[:, 1]]) - self.rs
        self.th = np.arctan2(s0[rows, ax[:, 1]], s0[rows, ax[:, 0]])
        self.sweep = tp.sweep_rad

    def points(self, b: np.ndarray, frac: np.ndarray) -> np.ndarray:
        """Points at fraction ``frac`` (n,) of the arc length of blocks ``b`` (n,); (n, 3)."""
        pos = self.start[b] + frac[:, None] * self.delta[b]
        arc = self.is_arc[b]
        if arc.any():
            i = np.flatnonzero(arc)
            bi, fi = b[i], frac[i]
            th = self.th[bi] + fi * self.sweep[bi]
            r = self.rs[bi] + fi * self.dr[bi]
            ax = self.ax[bi]
            rows = np.arange(len(i))
            p = pos[i]  # the normal axis is already interpolated linearly (helix)
            p[rows, ax[:, 0]] = self.c1[bi] + r * np.cos(th)
            p[rows, ax[:, 1]] = self.c2[bi] + r * np.sin(th)
            pos[i] = p
        return pos


def _chain_path(geo: _Geometry, blocks: np.ndarray, feed: np.ndarray, period_s: float):
    """Interpolate a chain of cutting blocks back to back.

    Returns
    -------
    disp : ndarray, shape (m, 3)
        Displacement per period.
    owner : ndarray of int64, shape (m,)
        Block executed at the end of each period.
    """
    lengths = geo.tp.lengths_mm[blocks]
    durations = lengths / feed[blocks]
    tb = np.concatenate([[0.0], np.cumsum(durations)])
    lb = np.concatenate([[0.0], np.cumsum(lengths)])
    m = int(_ceil_periods(tb[-1], period_s))
    if m == 0:
        return np.zeros((0, 3)), np.zeros(0, np.int64)
    t = np.minimum(np.arange(m + 1) * period_s, tb[-1])
    s = np.interp(t, tb, lb)
    s[-1] = lb[-1]
    nb = len(blocks)
    local = np.clip(np.searchsorted(lb, s, side="left") - 1, 0, nb - 1)
    local[0] = 0
    ln = lengths[local]
    frac = np.divide(s - lb[local], ln, out=np.ones_like(s), where=ln > 0)
    np.clip(frac, 0.0, 1.0, out=frac)
    pos = geo.points(blocks[local], frac)
    return np.diff(pos, axis=0), blocks[local[1:]]


def _rapid_axis_profile(
    d_mm: float, rapid_feed_mm_s: float, control: AccDecControl, k_r: int
) -> np.ndarray:
    """Displacement per period of one straight rapid of signed travel ``d_mm`` at the rapid
    feed (eq. 6-16), before the bell stage; shape (m,)."""
    ti, fr = control.period_s, rapid_feed_mm_s
    length = abs(d_mm)
    if length == 0.0:
        return np.zeros(0)
    m = int(_ceil_periods(length / fr, ti))
    k = k_r
    if m < k_r:  # short rapid: triangle at a = Fr / ATR (eq. 9-12)
        a = fr / control.rapid_time_constant_s
        m = k = max(int(_ceil_periods(math.sqrt(length / a), ti)), 1)
    return _box(np.full((m, 1), d_mm / m), k)[:, 0]


def _rapid(
    tp: Toolpath, j: int, machine: Machine, control: AccDecControl, k_r: int, k_s: int
) -> np.ndarray:
    """Displacement per period of rapid block ``j`` after acc/dec and bell; shape (m, 3)."""
    d = tp.end_mm[j] - tp.start_mm[j]
    fr = machine.rapid_feed_mm_s
    if control.rapid_type == "linear":
        length = float(np.linalg.norm(d))
        if length == 0.0:
            return np.zeros((0, 3))
        prof = _rapid_axis_profile(length, fr, control, k_r)
        disp = prof[:, None] * (d / length)[None, :]
    else:  # non-linear: every axis at the rapid feed on its own (eq. 7, 12)
        profs = [_rapid_axis_profile(float(x), fr, control, k_r) for x in d]
        m = max(len(p) for p in profs)
        disp = np.zeros((m, 3))
        for a, p in enumerate(profs):
            disp[: len(p), a] = p
    return _box(disp, k_s)


def _segments(kind: np.ndarray) -> list[tuple[int, int]]:
    """Split the blocks into chains of cutting blocks and single rapids / dwells:
    ``[(first, stop), ...]``."""
    n = len(kind)
    if n == 0:
        return []
    cut = np.isin(kind, _CUT)
    new = np.ones(n, bool)
    new[1:] = ~(cut[1:] & cut[:-1])
    starts = np.flatnonzero(new)
    stops = np.append(starts[1:], n)
    return list(zip(starts.tolist(), stops.tolist(), strict=True))


def simulate(toolpath: Toolpath, machine: Machine, control: AccDecControl) -> AccDecRun:
    """Run a program on the ideal block-overlap control.

    Parameters
    ----------
    toolpath : Toolpath
        N blocks; cutting blocks need a feed.
    machine : Machine
        Uses ``rapid_feed_mm_s`` (Fr), ``max_feed_mm_s`` and ``axis_max_velocity_mm_s`` (a
        cutting block's feed is clamped to what the axes allow along it,
        :func:`nctwin.limits.path_limits`). Its acceleration and jerk limits are not read: the
        control accelerates as its time constants say, which a profile sets within them.
    control : AccDecControl
        Uses ``period_s`` (TI), ``cut_time_constant_s`` (AT), ``rapid_time_constant_s`` (ATR),
        ``rapid_bell_s`` (As), ``rapid_type``, ``position_gain_per_s`` (Kp) and
        ``inposition_width_mm``. The time constants must be whole multiples of ``period_s``.

    Returns
    -------
    AccDecRun

    Raises
    ------
    ValueError
        If a time constant is not a whole number of periods, or a cutting block has no feed.
    """
    ti = control.period_s
    k_at = control.periods("cut_time_constant_s")
    k_r = control.periods("rapid_time_constant_s")
    k_s = control.periods("rapid_bell_s")
    kind = toolpath.kind
    cut = np.isin(kind, _CUT)
    feed = np.minimum(toolpath.feed_mm_s, machine.max_feed_mm_s)
    feed = np.minimum(feed, path_limits(toolpath, machine).velocity_mm_s)
    bad = cut & ~(feed > 0) & (toolpath.lengths_mm > 0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"feed_mm_s = {float(toolpath.feed_mm_s[j])!r} of block {j} "
            f"(line {toolpath.line[j]}) is out of range: a cutting block needs a feed F > 0"
        )
    width = np.asarray(control.inposition_width_mm)
    # each axis's position loop, exact for a velocity held over a period: e <- r e + g d, with
    # r = exp(-Kp TI) and g = bd / TI per mm of commanded displacement d in the period
    loops = [PositionLoop("first_order_ff", kp) for kp in control.position_gain_per_s]
    ad, bd = zip(*(loop.matrices(ti) for loop in loops), strict=True)
    r = np.array([a[0, 0] for a in ad])
    g = np.array([b[0] for b in bd]) / ti

    n_blocks = len(toolpath)
    geo = _Geometry(toolpath)
    disps, owners, errs = [], [], []
    wait = np.zeros(n_blocks)
    cmd_end = np.full(n_blocks, np.nan)
    e = np.zeros(3)
    n_periods = 0
    for first, stop in _segments(kind):
        k0 = kind[first]
        if cut[first]:
            blocks = np.arange(first, stop)
            d, own = _chain_path(geo, blocks, feed, ti)
            d = _box(d, k_at) if len(d) else d
            own = np.concatenate([own, np.full(len(d) - len(own), stop - 1, np.int64)])
        elif k0 == MotionKind.RAPID:
            d = _rapid(toolpath, first, machine, control, k_r, k_s)
            own = np.full(len(d), first, np.int64)
        else:  # dwell
            d = np.zeros((int(_ceil_periods(toolpath.dwell_s[first], ti)), 3))
            own = np.full(len(d), first, np.int64)
        err = np.empty_like(d)
        for a in range(3):
            err[:, a] = lfilter([g[a]], [1.0, -r[a]], d[:, a], zi=[r[a] * e[a]])[0]
        if len(d):
            e = err[-1].copy()
        n_periods += len(d)
        if k0 == MotionKind.RAPID:
            cmd_end[first] = n_periods * ti
            ratio = np.abs(e) / width
            need = np.where(ratio > 1.0, np.log(np.maximum(ratio, 1.0)) / -np.log(r), 0.0)
            w = int(np.ceil(need.max() - 1e-9)) if need.max() > 0 else 0
            if w:
                decay = r[None, :] ** np.arange(1, w + 1)[:, None]
                err = np.concatenate([err, e[None, :] * decay])
                d = np.concatenate([d, np.zeros((w, 3))])
                own = np.concatenate([own, np.full(w, first, np.int64)])
                e = err[-1].copy()
                n_periods += w
            wait[first] = w * ti
        disps.append(d)
        owners.append(own)
        errs.append(err)

    start = toolpath.start_mm[0] if n_blocks else np.zeros(3)
    disp = np.concatenate([np.zeros((1, 3)), *disps]) if disps else np.zeros((1, 3))
    pos = start + np.cumsum(disp, axis=0)
    owner = np.concatenate(owners) if owners else np.zeros(0, np.int64)
    block = np.concatenate([[0], owner]).astype(np.int64)
    ferr = np.concatenate([np.zeros((1, 3)), *errs]) if errs else np.zeros((1, 3))
    t = np.arange(len(pos)) * ti
    motion = Motion(t_s=t, pos_mm=pos, vel_mm_s=disp / ti, block=block, period_s=ti)
    times = np.bincount(owner, minlength=n_blocks).astype(float) * ti
    return AccDecRun(motion, ferr, times, wait, cmd_end)


def run(toolpath: Toolpath, machine: Machine, control: AccDecControl) -> Motion:
    """Commanded motion of ``toolpath`` on the ideal block-overlap control (see
    :func:`simulate`)."""
    return simulate(toolpath, machine, control).motion


@dataclass(frozen=True, eq=False)
class InPositionMeasurement:
    """Per-axis in-position times measured on the kernel (Lee et al. 2022, Sec. 2.3 and 3).

    Parameters
    ----------
    mean_s : ndarray, shape (3,)
        Mean in-position time of X, Y, Z: the compensation values of the estimator.
    samples_s : ndarray, shape (3, repeats)
        Each measurement: time from the end of the rapid's command until the axis is in
        position.
    distances_mm : ndarray, shape (3, repeats)
        Signed travel of each measured rapid.
    """

    mean_s: np.ndarray
    samples_s: np.ndarray
    distances_mm: np.ndarray


def measure_inposition_times(
    machine: Machine,
    control: AccDecControl,
    *,
    repeats: int = 5,
    seed: int = 0,
    distance_mm: tuple[float, float] = (20.0, 200.0),
) -> InPositionMeasurement:
    """Measure each axis's in-position time as the paper did: repeated single-axis rapids.

    For each axis, ``repeats`` rapids of random length (uniform in ``distance_mm``, random
    sign, drawn from ``numpy.random.default_rng(seed)``) are run on :func:`simulate` from rest;
    the time from the end of the rapid's command until the axis is within its in-position width
    is recorded, and the mean is the compensation value (the paper: 5 repeats; X, Y 25 ms,
    Z 120 ms on its Fanuc 0i-MD testbed).

    Parameters
    ----------
    machine : Machine
    control : AccDecControl
        The machine and control measured (see :func:`simulate`).
    repeats : int
        Rapids per axis, >= 1.
    seed : int
        Seed of the travels and their signs.
    distance_mm : tuple of 2 floats
        Range of the travels, ``0 < lo <= hi``.

    Returns
    -------
    InPositionMeasurement

    Raises
    ------
    ValueError
        If ``repeats`` < 1 or ``distance_mm`` is not ``0 < lo <= hi``.
    """
    check_int("repeats", repeats, 1)
    lo, hi = distance_mm
    if not 0 < lo <= hi < math.inf:
        raise ValueError(f"distance_mm = {distance_mm!r} is out of range: allowed 0 < lo <= hi")
    rng = np.random.default_rng(seed)
    dist = rng.uniform(lo, hi, (3, repeats)) * rng.choice([-1.0, 1.0], (3, repeats))
    samples = np.zeros((3, repeats))
    for a in range(3):
        for i in range(repeats):
            end = np.zeros((1, 3))
            end[0, a] = dist[a, i]
            tp = _single_rapid(end)
            samples[a, i] = simulate(tp, machine, control).inposition_wait_s[0]
    return InPositionMeasurement(samples.mean(axis=1), samples, dist)


def _single_rapid(end_mm: np.ndarray) -> Toolpath:
    """A one-block program: G0 from the origin to ``end_mm`` (1, 3)."""
    z3, z1 = np.zeros((1, 3)), np.zeros(1)
    nan3 = np.full((1, 3), np.nan)
    return Toolpath(
        z3, end_mm, np.array([MotionKind.RAPID]), np.full(1, np.nan), nan3, z1, z1, z1, z1,
        np.full(1, np.nan), np.full(1, np.nan),
    )  # fmt: skip
