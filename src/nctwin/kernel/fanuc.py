r"""A Fanuc-like control simulated in the time domain: the "measured" machine of Lee et al. 2022.

The chapter on Lee et al. 2022 (J. Korean Soc. Precis. Eng. 39(7), 537-543; a Fanuc 0i-MD
three-axis testbed) tests an analytic cycle-time estimate against a machine. This kernel is that
machine. It shares no code with the estimate, and no block's time is computed here: every time
comes out of a loop that advances the control one interpolation period :math:`T_I` at a time, as
the control does, and counts the periods. It shares none of the estimate's equations either: no
block is rounded to whole periods (the paper's eq. 2), because the interpolator carries the
remainder of a period from one block into the next; and a rapid is interpolated at
:math:`F_r` and smoothed by acc/dec after interpolation, so a rapid shorter than
:math:`F_r A_{TR}` becomes a slow flat-topped profile that lasts :math:`l/F_r + A_{TR}`,
where the paper's eq. 9-12 price it as a triangle at the acceleration :math:`F_r/A_{TR}`
(shorter). The two agree on a long rapid, whose acceleration is :math:`F_r/T_R` by the
definition of the time constant.

What one period does
--------------------
Interpolator (cutting feed: G1, G2, G3)
    Consecutive cutting blocks, up to a stop, are distributed as one stream: block :math:`k`
    lasts :math:`l_k / v_k` at its feed :math:`v_k` along the path, and the point at the end of
    every period is read off the path, so a period that straddles a junction carries the end of
    one block and the start of the next (Fanuc's pulse distribution works on the remainder of
    the period; nothing is rounded per block). Only a stop ends a period on a block's end point.
    :math:`v_k` is the programmed F, clamped by the
    machine's maximum feed and by what its axis velocities allow along the block
    (:func:`nctwin.limits.path_limits`), by the *feedrate clamp by arc radius* on arcs
    (:math:`v \le \sqrt{a_r R}`, Fanuc No. 1730/1731) and by the *block-processing time*
    :math:`t_b` (a block lasts at least :math:`t_b`: :math:`v \le l / t_b`; a block of no
    length lasts :math:`t_b`).
Acc/dec after interpolation (cutting feed)
    The interpolated displacement of every axis passes through a filter, period by period
    (``cut_accdec``): *linear*, a moving average over :math:`T` (``cut_time_constant_s``);
    *bell*, two moving averages over :math:`T/2` in cascade (an S-curve that still takes
    :math:`T`); *exponential*, the first-order lag of time constant :math:`T`, discretised
    exactly for a velocity held over each period, whose tail ends once less than one least
    increment is left in it. Because the filter runs over the stream of periods, consecutive
    cutting blocks overlap by themselves at every junction and corners are rounded: nothing
    decides an overlap.
Rapids (G0)
    A rapid starts once everything before it has stopped. Its interpolator steps at :math:`F_r`
    (:math:`F_r T_I` per period, the rest in the last one); *linear* type moves along the
    straight line at path speed :math:`F_r`, *non-linear* type steps each axis on its own at
    :math:`F_r` (Lee et al. 2022, Fig. 3). Acc/dec after interpolation (Fanuc's linear or bell
    type for rapid traverse) smooths the steps: a moving average over :math:`T_R` (No. 1620),
    then one over :math:`T_S` (``rapid_bell_s``, No. 1621), so a long rapid accelerates at
    :math:`F_r/T_R` with its jerk spread over :math:`T_S` and lasts
    :math:`l/F_r + T_R + T_S`. With ``rapid_overlap`` (No. 1601#4 RTO) the next rapid starts
    once the current one is interpolated and the filters' output has braked to
    ``rapid_overlap_percent`` of :math:`F_r` (No. 1722), and no in-position check separates them.
Servo
    Each axis follows the command through a position loop with velocity feed-forward
    (``servo="first_order_ff"``: :math:`\dot x = K_p (c - x) + f \dot c`) or a second-order
    loop (``servo="second_order"``:
    :math:`\ddot x = \omega_n^2 (c - x) + 2 \zeta \omega_n (f \dot c - \dot x)`), discretised
    exactly (matrix exponential) for the command velocity held over a period. The servo output
    is the *measured* position the :class:`~nctwin.motion.Motion` reports.
In-position and exact stop
    After a rapid, after a block in exact-stop mode (``G61``/``G61.1``, Fanuc's G61) and at the
    end of the program, the control waits until the command has been delivered and every axis's
    following error is within its in-position width (No. 1826). Before a rapid, a dwell or an
    exact stop, cutting feed decelerates to a stop (the filter empties) without an in-position
    check (the paper's testbed: in-position only after rapids). The waits are what the servo
    simulation gives; :func:`measure_inposition_times` measures them as the paper did.
Dwell (G4)
    The command stands still for the dwell, rounded up to whole periods.

Settings
--------
Every setting of the control is a field of :class:`nctwin.controls.FanucControl` (a profile's
``[control.fanuc]`` table). The :class:`~nctwin.machine.Machine` gives the rapid feed, the
maximum feed and the axis velocities; accelerations are the control's, set by its time
constants, so the machine's acceleration and jerk limits are not read.

Conventions
-----------
Sample ``i`` is at ``t = i * period_s``; sample 0 is the start at rest. The command and
the measured position at sample ``i`` are those at the end of period ``i``; ``block[i]`` is the
block the control executes in period ``i`` (a deceleration, an in-position wait or the tail of
a filter is credited to the block that ends there). Velocities are backward differences of the
measured position. The program's M, S and T words take no time. Fanuc's G09 (exact stop in one
block) is not read by :func:`nctwin.gcode.parse`; write ``G61`` ... ``G64`` around the block.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..controls import FanucControl
from ..geometry import PathGeometry
from ..limits import path_limits
from ..machine import Machine
from ..motion import Motion
from ..physics.servo import PositionLoop
from ..toolpath import MotionKind, PathMode, Toolpath
from . import _fanuc_loops

__all__ = [
    "PAPER_SET_1",
    "PAPER_SET_2",
    "FanucRun",
    "measure_inposition_times",
    "run",
    "simulate",
]

#: Lee et al. 2022, parameter set 1: (ATR, As, AT) = (150, 30, 50) ms (the defaults).
PAPER_SET_1 = FanucControl()
#: Lee et al. 2022, parameter set 2: (ATR, As, AT) = (100, 20, 100) ms.
PAPER_SET_2 = FanucControl(rapid_time_constant_s=0.1, rapid_bell_s=0.02, cut_time_constant_s=0.1)


# ---------------------------------------------------------------------------------------------
# Python side
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class FanucRun:
    """Result of :func:`simulate`.

    Parameters
    ----------
    motion : Motion
        Measured motion (the servo output), ``n`` samples at ``period_s``.
    command_mm : ndarray, shape (n, 3)
        Command position after acc/dec (what the position loops are given).
    block_feed_mm_s : ndarray, shape (N,)
        Feed each cutting block was interpolated at, after the clamps; NaN for other blocks.
    block_times_s : ndarray, shape (N,)
        Time credited to each block (see the module's conventions); sums to the cycle time.
    inposition_wait_s : ndarray, shape (N,)
        In-position wait after each block (rapids, exact stops, the last block); 0 elsewhere.
    command_end_s : ndarray, shape (N,)
        Time the command stopped at the end of a block that stops (a rapid, the last block of
        a chain of cutting blocks, an exact stop); NaN for the others.
    """

    motion: Motion
    command_mm: np.ndarray
    block_feed_mm_s: np.ndarray
    block_times_s: np.ndarray
    inposition_wait_s: np.ndarray
    command_end_s: np.ndarray

    @property
    def following_error_mm(self) -> np.ndarray:
        """Command minus measured position, shape (n, 3)."""
        return self.command_mm - self.motion.pos_mm

    @property
    def cycle_time_s(self) -> float:
        """From cycle start until the last block is done and every axis is in position."""
        return self.motion.cycle_time_s


def _servo_matrices(control: FanucControl) -> tuple[np.ndarray, np.ndarray]:
    """Each axis's :class:`~nctwin.physics.servo.PositionLoop`, discretised over a period:
    ``ad`` (3, 2, 2) and ``bd`` (3, 2)."""
    loops = [
        PositionLoop(
            control.servo,
            control.position_gain_per_s[a],
            control.feedforward,
            control.natural_freq_hz[a],
            control.damping[a],
        )
        for a in range(3)
    ]
    ad, bd = zip(*(loop.matrices(control.period_s) for loop in loops), strict=True)
    return np.stack(ad), np.stack(bd)


def _check_toolpath(tp: Toolpath) -> None:
    """Raise ValueError for a program the kernel cannot run."""
    n = len(tp)
    bad = ~(np.isfinite(tp.start_mm).all(1) & np.isfinite(tp.end_mm).all(1))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"block {k} (line {tp.line[k]}) has a non-finite position")
    if n > 1:
        gap = np.abs(tp.start_mm[1:] - tp.end_mm[:-1]).max(axis=1)
        if gap.max() > 1e-6:
            k = int(np.argmax(gap > 1e-6)) + 1
            raise ValueError(
                f"block {k} (line {tp.line[k]}) starts {gap[k - 1]:.3g} mm away from where "
                f"block {k - 1} ends: the kernel runs continuous programs only"
            )
    cut = ~np.isin(tp.kind, (MotionKind.RAPID, MotionKind.DWELL))
    bad = cut & (tp.lengths_mm > 0) & ~(np.isfinite(tp.feed_mm_s) & (tp.feed_mm_s > 0))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"feed_mm_s = {float(tp.feed_mm_s[k])!r} of block {k} (line {tp.line[k]}) is out "
            "of range: a cutting block needs a feed F > 0"
        )
    bad = tp.is_arc & ~(np.isfinite(tp.radius_mm) & (tp.radius_mm > 0))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"arc block {k} (line {tp.line[k]}) has no finite radius > 0")
    bad = (tp.kind == MotionKind.DWELL) & ~(np.isfinite(tp.dwell_s) & (tp.dwell_s >= 0))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"dwell block {k} (line {tp.line[k]}) has no dwell time >= 0")


def _ceil(x: np.ndarray) -> np.ndarray:
    """Whole periods for ``x`` periods, forgiving 1e-9 of round-off."""
    return np.ceil(np.asarray(x, dtype=float) - 1e-9).astype(np.int64)


def _interpolate(
    tp: Toolpath, duration_s: np.ndarray, cut: np.ndarray, drain_after: np.ndarray, ti: float
) -> tuple[np.ndarray, np.ndarray]:
    """The interpolator's output for the cutting blocks: one displacement per period.

    Consecutive cutting blocks up to a stop (``drain_after``) form a chain, interpolated as one
    stream: block :math:`k` occupies :math:`d_k` of the chain's time (``duration_s``, at its
    feed, constant along it), and the point at the end of every period is read off the path,
    so a period that straddles a junction carries the end of one block and the start of the
    next (the remainder is carried, no block is rounded to whole periods); only the chain's
    last period ends on its end point.

    Returns
    -------
    steps : ndarray, shape (P, 3)
        Displacement of each period, chains one after another.
    periods : ndarray, shape (N,)
        Periods credited to each block (a period to the block its end falls in); 0 for blocks
        that are not cutting blocks.
    """
    n = len(tp)
    periods = np.zeros(n, np.int64)
    steps = []
    geo = PathGeometry(tp)
    ends = np.flatnonzero(drain_after)
    starts = np.concatenate([[0], ends[:-1] + 1]) if len(ends) else np.zeros(0, np.int64)
    for first, last in zip(starts, ends, strict=True):
        first = first + int(np.argmax(cut[first : last + 1]))  # skip rapids and dwells
        t_end = np.cumsum(duration_s[first : last + 1])
        count = int(_ceil(t_end[-1] / ti)) if t_end[-1] > 0 else 0
        t = np.minimum(np.arange(1, count + 1) * ti, t_end[-1])
        k = np.minimum(np.searchsorted(t_end, t - 1e-12 * ti), last - first)
        t0 = t_end[k] - duration_s[first + k]
        frac = np.where(duration_s[first + k] > 0, (t - t0) / duration_s[first + k], 1.0)
        s0, s1 = geo.s_start_mm[first + k], geo.s_start_mm[first + k + 1]
        s_at = np.where(
            t >= t_end[-1], geo.s_start_mm[last + 1], s0 + np.clip(frac, 0, 1) * (s1 - s0)
        )
        pts = geo.points(s_at) if count else np.zeros((0, 3))
        steps.append(np.diff(pts, axis=0, prepend=tp.start_mm[first][None, :]))
        periods[first : last + 1] = np.bincount(k, minlength=last - first + 1)
    out = np.concatenate(steps) if steps else np.zeros((0, 3))
    return np.ascontiguousarray(out), periods


def simulate(toolpath: Toolpath, machine: Machine, control: FanucControl = PAPER_SET_1) -> FanucRun:
    """Run a program on the Fanuc-like control, one interpolation period at a time.

    Parameters
    ----------
    toolpath : Toolpath
        N blocks, continuous (each block starts where the previous one ends).
    machine : Machine
        The machine: ``rapid_feed_mm_s`` (:math:`F_r`, also each axis's rapid feed for the
        non-linear type), ``max_feed_mm_s`` (a larger F is clamped to it) and the axis
        velocities (a cutting block's feed is clamped to what they allow along it,
        :func:`nctwin.limits.path_limits`). The axis accelerations are not read: the control
        accelerates as its time constants say (:math:`F / T` cutting, :math:`F_r / T_R` on
        rapids), which a profile sets within them.
    control : FanucControl
        The control's parameters; default the paper's set 1.

    Returns
    -------
    FanucRun

    Raises
    ------
    ValueError
        For a program the kernel cannot run: a non-finite position, a jump between blocks, a
        cutting block without a feed, an arc without a radius, a negative dwell.
    """
    tp = toolpath
    _check_toolpath(tp)
    s = control
    ti = s.period_s
    n = len(tp)
    kind = np.ascontiguousarray(tp.kind, dtype=np.int64)
    cut = (kind != MotionKind.RAPID) & (kind != MotionKind.DWELL)
    lengths = tp.lengths_mm
    # ---- feed of each cutting block: F, the machine's maximum and axis velocities, the arc
    # clamp, block time
    with np.errstate(invalid="ignore", divide="ignore"):
        feed = np.minimum(tp.feed_mm_s, machine.max_feed_mm_s)
        feed = np.minimum(feed, path_limits(tp, machine).velocity_mm_s)
        arc_limit = np.sqrt(s.arc_radial_acc_mm_s2 * tp.radius_mm)
        feed = np.where(tp.is_arc, np.minimum(feed, arc_limit), feed)
        if s.block_time_s > 0:
            feed = np.minimum(feed, lengths / s.block_time_s)
        feed = np.where(cut & (lengths > 0), feed, np.nan)
        duration = np.where(lengths > 0, lengths / feed, s.block_time_s)
    duration = np.where(cut, duration, 0.0)
    # ---- where the control stops: before rapids and dwells, in exact-stop mode, at the end
    exact = tp.path_mode >= PathMode.EXACT_PATH
    next_cut = np.append(cut[1:], False)
    drain_after = cut & (~next_cut | exact)
    stop_after = cut & exact
    cut_steps, periods = _interpolate(tp, duration, cut, drain_after, ti)
    cut_off = np.concatenate([[0], np.cumsum(periods)]).astype(np.int64)
    pause_n = np.where(kind == MotionKind.DWELL, _ceil(tp.dwell_s / ti), 0)
    # ---- filters and servo
    k_cut = s.periods("cut_time_constant_s")
    exp_cut = s.cut_accdec == "exponential"
    k1, k2 = {"linear": (k_cut, 1), "bell": (k_cut // 2, k_cut // 2)}.get(s.cut_accdec, (1, 1))
    k_bell = max(s.periods("rapid_bell_s"), 1)
    exp_keep = math.exp(-ti / s.cut_time_constant_s)
    exp_gain = s.cut_time_constant_s / ti * (1.0 - exp_keep)
    fr = machine.rapid_feed_mm_s
    k_rapid = s.periods("rapid_time_constant_s")
    ad, bd = _servo_matrices(s)
    width = np.asarray(s.inposition_width_mm)
    # ---- a first guess of the number of samples; doubled until the run fits
    d = np.abs(tp.end_mm - tp.start_mm)
    travel = lengths if s.rapid_type == "linear" else d.max(axis=1, initial=0.0)
    rapid = kind == MotionKind.RAPID
    stops = int(drain_after.sum() + rapid.sum()) + 1
    tail = k1 + k2
    if exp_cut:
        fmax = np.max(np.nan_to_num(feed), initial=1.0)
        tail = int(k_cut * math.log(max(fmax * s.cut_time_constant_s / s.least_increment_mm, 1)))
        tail += 2
    cap = int(
        cut_off[-1]
        + pause_n.sum()
        + (travel[rapid] / (fr * ti)).sum()
        + stops * (tail + 2 * s.rapid_time_constant_s / ti + k_bell + 0.2 / ti)
        + 10
    )
    blocks = _fanuc_loops.Blocks(
        kind, np.ascontiguousarray(tp.start_mm), np.ascontiguousarray(tp.end_mm), cut_steps,
        cut_off, drain_after, stop_after, pause_n.astype(np.int64),
    )  # fmt: skip
    settings = _fanuc_loops.Settings(
        ti, fr, k_rapid, k_bell, s.rapid_type == "linear", s.rapid_overlap,
        s.rapid_overlap_percent / 100.0 * fr, exp_cut, k1, k2, exp_keep, exp_gain,
        s.least_increment_mm, ad, bd, width,
    )  # fmt: skip
    while True:
        cmd = np.empty((cap, 3))
        pos = np.empty((cap, 3))
        blk = np.empty(cap, np.int64)
        wait = np.zeros(n)
        cmd_end = np.full(n, np.nan)
        out = _fanuc_loops.Outputs(cmd, pos, blk, wait, cmd_end)
        count = _fanuc_loops.control_loop(blocks, settings, out)
        if count > 0:
            break
        cap *= 2
    cmd, pos, blk = cmd[:count], pos[:count], blk[:count]
    vel = np.zeros_like(pos)
    np.subtract(pos[1:], pos[:-1], out=vel[1:])
    vel[1:] /= ti
    motion = Motion(t_s=np.arange(count) * ti, pos_mm=pos, vel_mm_s=vel, block=blk, period_s=ti)
    times = np.bincount(blk[1:], minlength=n).astype(float) * ti if n else np.zeros(0)
    return FanucRun(motion, cmd, feed, times, wait, cmd_end)


def run(toolpath: Toolpath, machine: Machine, control: FanucControl = PAPER_SET_1) -> Motion:
    """Measured motion of ``toolpath`` on the Fanuc-like control (see :func:`simulate`)."""
    return simulate(toolpath, machine, control).motion


def measure_inposition_times(
    machine: Machine,
    control: FanucControl = PAPER_SET_1,
    *,
    distances_mm: tuple[float, ...] = (20.0, 50.0, 100.0, 150.0, 200.0),
    axes: tuple[int, ...] = (0, 1, 2),
) -> np.ndarray:
    """Each axis's in-position time, measured as Lee et al. 2022 did (Sec. 2.3 and 3).

    For each axis, one single-axis rapid per distance is run from rest on :func:`simulate`
    (the paper: five repeats per axis); the time from the end of the rapid's command until
    every axis is within its in-position width is recorded, and the mean per axis is the
    in-position time (the paper's testbed's are in ``data/papers/lee2022_inposition.csv``).

    Parameters
    ----------
    machine : Machine
    control : FanucControl
    distances_mm : tuple of float
        Travels of the measured rapids, each > 0.
    axes : tuple of int
        The axes measured (0, 1, 2 for X, Y, Z).

    Returns
    -------
    ndarray, shape (3,)
        Mean in-position time of X, Y, Z (s); NaN for an axis not measured.

    Raises
    ------
    ValueError
        If ``distances_mm`` is empty or holds a travel that is not a finite number > 0.
    """
    dist = np.asarray(distances_mm, dtype=float)
    if dist.ndim != 1 or len(dist) == 0 or not (np.isfinite(dist) & (dist > 0)).all():
        raise ValueError(
            f"distances_mm = {distances_mm!r} is out of range: allowed one or more numbers > 0"
        )
    if not set(axes) <= {0, 1, 2}:
        raise ValueError(f"axes = {axes!r} is out of range: allowed 0, 1, 2 (X, Y, Z)")
    out = np.full(3, np.nan)
    out[list(axes)] = 0.0
    nan3 = np.full((1, 3), np.nan)
    z1 = np.zeros(1)
    for a in axes:
        for x in dist:
            end = np.zeros((1, 3))
            end[0, a] = x
            tp = Toolpath(np.zeros((1, 3)), end, np.array([MotionKind.RAPID]), np.full(1, np.nan),
                          nan3, z1, z1, z1, z1, np.full(1, np.nan), np.full(1, np.nan))  # fmt: skip
            out[a] += simulate(tp, machine, control).inposition_wait_s[0]
    return out / len(dist)
