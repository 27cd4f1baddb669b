r"""A Fanuc-like control simulated in the time domain: the "measured" machine of Lee et al. 2022.

The chapter on Lee et al. 2022 (J. Korean Soc. Precis. Eng. 39(7), 537-543; a Fanuc 0i-MD
three-axis testbed) tests an analytic cycle-time estimate against a machine. This kernel is that
machine. It shares no code and no equation with the estimate: nothing here computes a block's
time; every time comes out of a loop that advances the control one interpolation period
:math:`T_I` at a time, as the control does, and counts the periods.

What one period does
--------------------
Interpolator (cutting feed: G1, G2, G3)
    Each block is distributed at its feed :math:`v_k` along the path, one period at a time
    (:math:`v_k T_I` of arc length per period, the rest in the block's last period); the next
    cutting block starts in the next period. :math:`v_k` is the programmed F, clamped by the
    machine's maximum feed, by the *feedrate clamp by arc radius* on arcs
    (:math:`v \le \sqrt{a_r R}`, Fanuc No. 1730/1731) and by the *block-processing time*
    :math:`t_b` (a block lasts at least :math:`t_b`: :math:`v \le l / t_b`).
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
    A rapid starts once everything before it has stopped. Its interpolator accelerates at the
    constant :math:`a = F_r / T_R` (the acceleration No. 1420 and No. 1620 set), cruises at
    :math:`F_r` and brakes so as to stop on the end point, decided period by period from the
    distance left; *linear* type moves along the straight line at path speed :math:`F_r`,
    *non-linear* type runs one such interpolator per axis (Lee et al. 2022, Fig. 3). A moving
    average over :math:`T_S` (``rapid_bell_s``, No. 1621) makes the profile bell-shaped. With
    ``rapid_overlap`` (No. 1601#4 RTO) the next rapid starts once the current one has braked to
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

Conventions
-----------
Sample ``i`` is at ``t = i * interp_period_s``; sample 0 is the start at rest. The command and
the measured position at sample ``i`` are those at the end of period ``i``; ``block[i]`` is the
block the control executes in period ``i`` (a deceleration, an in-position wait or the tail of
a filter is credited to the block that ends there). Velocities are backward differences of the
measured position. The program's M, S and T words take no time. Fanuc's G09 (exact stop in one
block) is not read by :func:`nctwin.gcode.parse`; write ``G61`` ... ``G64`` around the block.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from ..geometry import PathGeometry
from ..machine import MachineProfile, load_table
from ..machine import _check as _check_number
from ..motion import Motion
from ..physics.servo import PositionLoop
from ..toolpath import MotionKind, PathMode, Toolpath
from . import _fanuc_loops

__all__ = [
    "PAPER_SET_1",
    "PAPER_SET_2",
    "FanucRun",
    "FanucSettings",
    "measure_inposition_times",
    "run",
    "simulate",
]

_XYZ = tuple[float, float, float]


def _check_choice(name: str, value, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise ValueError(
            f"{name} = {value!r} is out of range: allowed {', '.join(map(repr, allowed))}"
        )


def _check_xyz(name: str, value, hi: float, hi_closed: bool) -> _XYZ:
    """Three numbers (X, Y, Z), each in (0, hi), as a tuple of floats."""
    try:
        v = tuple(value)
    except TypeError:
        raise ValueError(f"{name} = {value!r} is out of range: allowed three numbers") from None
    if len(v) != 3:
        raise ValueError(f"{name} = {value!r} is out of range: allowed three numbers")
    for axis, x in zip("XYZ", v, strict=True):
        _check_number(f"{name}[{axis}]", x, 0.0, hi, hi_closed=hi_closed)
    return tuple(float(x) for x in v)


@dataclass(frozen=True)
class FanucSettings:
    """Parameters of the Fanuc-like control, one field per effect; units in the names.

    Defaults are the paper's testbed where the paper gives a value (Lee et al. 2022, Sec. 3,
    parameter set 1); elsewhere a stated choice, with its reason. Fanuc 0i parameter numbers
    are given for orientation.

    Parameters
    ----------
    interp_period_s : float
        Interpolation period :math:`T_I`; also the servo's sampling period and the period of the
        samples. Default 1 ms: a Fanuc 0i interpolates at 1 ms or 2 ms; 1 ms is the period of
        nctwin's testbed profile (``fanuc_0i_testbed``) and divides every time constant of the
        paper.
    cut_accdec : {"linear", "bell", "exponential"}
        Acc/dec type after interpolation for cutting feed (No. 1610). Default ``"linear"``: the
        paper's testbed (its Fig. 1 and 2 are trapezoids). ``"bell"`` is two moving averages
        of :math:`T/2` in cascade: Fanuc's bell type after interpolation reaches the feed in
        the same time constant :math:`T` as the linear type, with the acceleration ramping up
        and down (Fanuc gives the bell type after interpolation one time constant, No. 1622, the
        whole acc/dec time); the cascade of two equal boxes is the FIR that does that (its
        acceleration is a triangle of peak :math:`2F/T`), where a linear stage followed by a
        shorter one would need a second constant Fanuc does not have for cutting feed.
        ``"exponential"`` is Fanuc's oldest type.
    cut_time_constant_s : float
        Time constant :math:`T` of cutting acc/dec (No. 1622), in (0, 10] s, a whole number of
        periods (an even number for ``"bell"``). Default 50 ms: the paper's set 1 (set 2:
        100 ms).
    least_increment_mm : float
        Least command increment (IS-B: 1 um). The exponential filter's tail ends once less than
        this is left in it on every axis; the rest is output at once. Default 0.001 mm (IS-B,
        the usual increment of a 0i-MD).
    rapid_type : {"linear", "nonlinear"}
        Rapid traverse path (No. 1401#1 LRP): a straight line at path speed :math:`F_r`, or each
        axis on its own at :math:`F_r` (Lee et al. 2022, Fig. 3). Default ``"linear"``: the
        paper's testbed.
    rapid_time_constant_s : float
        Rapid acc/dec time constant :math:`T_R` (No. 1620), in (0, 10] s, whole periods; it sets
        the acceleration :math:`F_r / T_R`. Default 150 ms: the paper's set 1 (set 2: 100 ms).
    rapid_bell_s : float
        Bell-shaped (S-curve) part of rapid acc/dec :math:`T_S` (No. 1621), in [0, 10] s, whole
        periods; 0 for linear rapid acc/dec. Default 30 ms: the paper's set 1 (set 2: 20 ms).
    rapid_overlap : bool
        Rapid traverse block overlap (No. 1601#4 RTO). Default False: the paper's testbed
        overlaps no rapid (Sec. 2.2).
    rapid_overlap_percent : float
        With ``rapid_overlap``, the next rapid starts once the current one has braked to this
        share of :math:`F_r` (No. 1722), in [0, 100]. Default 50 %: No. 1722 has no factory
        value; half the rapid feed is a middle setting.
    arc_radial_acc_mm_s2 : float
        Allowed radial acceleration of the feedrate clamp by arc radius, in (0, inf]: an arc of
        radius :math:`R` runs at most at :math:`\\sqrt{a_r R}` (Fanuc sets it as a feed V for a
        radius R, No. 1730 and 1731, :math:`a_r = V^2/R`); ``inf`` turns the clamp off.
        Default 200 mm/s^2 (No. 1730 = 1200 mm/min for No. 1731 = 2 mm): the clamp exists to
        bound the radial error acc/dec after interpolation causes on arcs; for the linear
        filter that error is :math:`a_r T^2 / 24`, 21 um at the default 50 ms, the order of a
        finishing tolerance. It leaves the paper's test piece alone (its smallest arcs, R5 at
        1000 mm/min, need 56 mm/s^2).
    block_time_s : float
        Block-processing time :math:`t_b`: the shortest time a cutting block can take, so a
        block of length :math:`l` runs at most at :math:`l / t_b`; in [0, 1) s, 0 for no limit.
        Default 4 ms (250 blocks/s), an assumption: Fanuc publishes block rates only for its
        high-speed options (AI contour control with high-speed processing, about 1 ms); a 0i-MD
        running plain acc/dec after interpolation, as the paper's testbed does, buffers and
        prepares blocks more slowly. At the default a 0.5 mm block runs at most at 7.5 m/min.
    servo : {"first_order_ff", "second_order"}
        Servo model. Default ``"first_order_ff"``: a Fanuc position loop (proportional gain over
        a much faster velocity loop) behaves as a first-order lag of :math:`1/K_p`.
    position_gain_per_s : tuple of 3 floats
        Position loop gain :math:`K_p` of X, Y, Z (No. 1825, in 0.01/s), each in (0, 1000).
        Default 50 1/s on all axes (No. 1825 = 5000): Fanuc's initial value is 3000 (30 1/s);
        tuned ball-screw axes commonly run at 50-80 1/s; the same on every axis because Fanuc
        asks for equal gains on axes that interpolate together (unequal gains distort
        contours). Not fitted to the paper's in-position times.
    feedforward : float
        Velocity feed-forward coefficient :math:`f` in [0, 1] (No. 2092 / 10000), for both
        servo models. Default 0: Fanuc's feed-forward is enabled with its preview control (AI
        contour control), which the paper's testbed does not use.
    natural_freq_hz : tuple of 3 floats
        Natural frequency of the second-order loop of X, Y, Z, each in (0, 1000) Hz. Default
        11 Hz: with the default damping its following error at constant feed,
        :math:`2 \\zeta / \\omega_n` times the feed, is that of the first-order default
        (:math:`1/K_p` = 20 ms), so the two servo models lag alike and differ in transients.
    damping : tuple of 3 floats
        Damping ratio :math:`\\zeta` of the second-order loop of X, Y, Z, each in (0, 10].
        Default 0.7: a well-damped servo tuning (about 5 % overshoot on a step).
    inposition_width_mm : tuple of 3 floats
        In-position width of X, Y, Z (No. 1826), each in (0, 10] mm. Default 0.02 mm (No. 1826
        = 20 at a 1 um detection unit), a common machining-centre setting; the paper does not
        give its own.

    Raises
    ------
    ValueError
        For a value out of its range, naming the field, the value and the allowed range.
    """

    interp_period_s: float = 0.001
    cut_accdec: str = "linear"
    cut_time_constant_s: float = 0.05
    least_increment_mm: float = 0.001
    rapid_type: str = "linear"
    rapid_time_constant_s: float = 0.15
    rapid_bell_s: float = 0.03
    rapid_overlap: bool = False
    rapid_overlap_percent: float = 50.0
    arc_radial_acc_mm_s2: float = 200.0
    block_time_s: float = 0.004
    servo: str = "first_order_ff"
    position_gain_per_s: _XYZ = (50.0, 50.0, 50.0)
    feedforward: float = 0.0
    natural_freq_hz: _XYZ = (11.0, 11.0, 11.0)
    damping: _XYZ = (0.7, 0.7, 0.7)
    inposition_width_mm: _XYZ = (0.02, 0.02, 0.02)

    def __post_init__(self) -> None:
        _check_number("interp_period_s", self.interp_period_s, 0.0, 0.1, hi_closed=True)
        _check_choice("cut_accdec", self.cut_accdec, ("linear", "bell", "exponential"))
        _check_choice("rapid_type", self.rapid_type, ("linear", "nonlinear"))
        _check_choice("servo", self.servo, ("first_order_ff", "second_order"))
        if not isinstance(self.rapid_overlap, bool):
            raise ValueError(
                f"rapid_overlap = {self.rapid_overlap!r} is out of range: allowed True, False"
            )
        # name: (lo, hi, lo closed, hi closed)
        ranges = {
            "cut_time_constant_s": (0.0, 10.0, False, True),
            "rapid_time_constant_s": (0.0, 10.0, False, True),
            "rapid_bell_s": (0.0, 10.0, True, True),
            "least_increment_mm": (0.0, 0.1, False, True),
            "rapid_overlap_percent": (0.0, 100.0, True, True),
            "arc_radial_acc_mm_s2": (0.0, math.inf, False, True),
            "block_time_s": (0.0, 1.0, True, False),
            "feedforward": (0.0, 1.0, True, True),
        }
        for name, (lo, hi, lo_closed, hi_closed) in ranges.items():
            _check_number(name, getattr(self, name), lo, hi, lo_closed=lo_closed,
                          hi_closed=hi_closed)  # fmt: skip
        for name, hi, hi_closed in (
            ("position_gain_per_s", 1000.0, False),
            ("natural_freq_hz", 1000.0, False),
            ("damping", 10.0, True),
            ("inposition_width_mm", 10.0, True),
        ):
            object.__setattr__(self, name, _check_xyz(name, getattr(self, name), hi, hi_closed))
        k_cut = self._periods("cut_time_constant_s", self.cut_time_constant_s)
        for name in ("rapid_time_constant_s", "rapid_bell_s"):
            self._periods(name, getattr(self, name))
        if self.cut_accdec == "bell" and k_cut % 2:
            raise ValueError(
                f"cut_time_constant_s = {self.cut_time_constant_s!r} is out of range: allowed "
                f"even multiples of interp_period_s = {self.interp_period_s!r} with "
                "cut_accdec = 'bell' (two moving averages of half the time constant)"
            )

    @classmethod
    def load(cls, machine: str | Path | None = None) -> FanucSettings:
        """The ``[fanuc]`` table of a machine profile's file (:func:`nctwin.machine.load_table`);
        the defaults for the fields it does not set.

        Raises
        ------
        ValueError
            For a field the table names that :class:`FanucSettings` does not have, or a value
            out of its range.
        """
        try:
            return cls(**load_table(machine, "fanuc"))
        except TypeError as err:  # a field FanucSettings does not have
            allowed = ", ".join(f.name for f in fields(cls))
            raise ValueError(f"[fanuc] of {machine}: {err}; allowed: {allowed}") from None

    def _periods(self, name: str, value_s: float) -> int:
        """A time constant as a whole number of interpolation periods (ValueError if it is not)."""
        k = round(value_s / self.interp_period_s)
        if not math.isclose(k * self.interp_period_s, value_s, rel_tol=1e-9, abs_tol=1e-12):
            raise ValueError(
                f"{name} = {value_s!r} is out of range: allowed whole multiples of "
                f"interp_period_s = {self.interp_period_s!r}"
            )
        return k


#: Lee et al. 2022, parameter set 1: (ATR, As, AT) = (150, 30, 50) ms (the defaults).
PAPER_SET_1 = FanucSettings()
#: Lee et al. 2022, parameter set 2: (ATR, As, AT) = (100, 20, 100) ms.
PAPER_SET_2 = FanucSettings(rapid_time_constant_s=0.1, rapid_bell_s=0.02, cut_time_constant_s=0.1)


# ---------------------------------------------------------------------------------------------
# Python side
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class FanucRun:
    """Result of :func:`simulate`.

    Parameters
    ----------
    motion : Motion
        Measured motion (the servo output), ``n`` samples at ``interp_period_s``.
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


def _servo_matrices(settings: FanucSettings) -> tuple[np.ndarray, np.ndarray]:
    """Each axis's :class:`~nctwin.physics.servo.PositionLoop`, discretised over a period:
    ``ad`` (3, 2, 2) and ``bd`` (3, 2)."""
    loops = [
        PositionLoop(
            settings.servo,
            settings.position_gain_per_s[a],
            settings.feedforward,
            settings.natural_freq_hz[a],
            settings.damping[a],
        )
        for a in range(3)
    ]
    ad, bd = zip(*(loop.matrices(settings.interp_period_s) for loop in loops), strict=True)
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


def simulate(
    toolpath: Toolpath, machine: MachineProfile, settings: FanucSettings = PAPER_SET_1
) -> FanucRun:
    """Run a program on the Fanuc-like control, one interpolation period at a time.

    Parameters
    ----------
    toolpath : Toolpath
        N blocks, continuous (each block starts where the previous one ends).
    machine : MachineProfile
        The machine: ``rapid_feed_mm_s`` (:math:`F_r`, also each axis's rapid feed for the
        non-linear type) and ``max_feed_mm_s`` (a larger F is clamped to it). Every control
        parameter comes from ``settings``.
    settings : FanucSettings
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
    s = settings
    ti = s.interp_period_s
    n = len(tp)
    kind = np.ascontiguousarray(tp.kind, dtype=np.int64)
    cut = (kind != MotionKind.RAPID) & (kind != MotionKind.DWELL)
    lengths = tp.lengths_mm
    # ---- feed of each cutting block: F, the machine's maximum, the arc clamp, block time
    with np.errstate(invalid="ignore", divide="ignore"):
        feed = np.minimum(tp.feed_mm_s, machine.max_feed_mm_s)
        arc_limit = np.sqrt(s.arc_radial_acc_mm_s2 * tp.radius_mm)
        feed = np.where(tp.is_arc, np.minimum(feed, arc_limit), feed)
        if s.block_time_s > 0:
            feed = np.minimum(feed, lengths / s.block_time_s)
        feed = np.where(cut & (lengths > 0), feed, np.nan)
        periods = np.where(lengths > 0, lengths / (feed * ti), 0.0)
    periods = np.maximum(_ceil(np.nan_to_num(periods)), _ceil(s.block_time_s / ti))
    periods = np.where(cut, periods, 0)
    cut_off = np.concatenate([[0], np.cumsum(periods)]).astype(np.int64)
    # ---- interpolated points of every period of every cutting block
    geo = PathGeometry(tp)
    owner = np.repeat(np.arange(n), periods)
    j = np.arange(len(owner)) - cut_off[owner]
    step_mm = np.where(lengths > 0, np.nan_to_num(feed) * ti, 0.0)  # arc length per period
    arc_len = np.minimum((j + 1) * step_mm[owner], lengths[owner])
    last = j == periods[owner] - 1
    s_at = np.where(last, geo.s_start_mm[owner + 1], geo.s_start_mm[owner] + arc_len)
    cut_pts = geo.points(s_at) if len(s_at) else np.zeros((0, 3))
    # ---- where the control stops: before rapids and dwells, in exact-stop mode, at the end
    exact = tp.path_mode >= PathMode.EXACT_PATH
    next_cut = np.append(cut[1:], False)
    drain_after = cut & (~next_cut | exact)
    stop_after = cut & exact
    pause_n = np.where(kind == MotionKind.DWELL, _ceil(tp.dwell_s / ti), 0)
    # ---- filters and servo
    k_cut = s._periods("cut_time_constant_s", s.cut_time_constant_s)
    exp_cut = s.cut_accdec == "exponential"
    k1, k2 = {"linear": (k_cut, 1), "bell": (k_cut // 2, k_cut // 2)}.get(s.cut_accdec, (1, 1))
    k_bell = max(s._periods("rapid_bell_s", s.rapid_bell_s), 1)
    exp_keep = math.exp(-ti / s.cut_time_constant_s)
    exp_gain = s.cut_time_constant_s / ti * (1.0 - exp_keep)
    fr = machine.rapid_feed_mm_s
    rapid_acc = fr / s.rapid_time_constant_s
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
    start = np.ascontiguousarray(tp.start_mm)
    end = np.ascontiguousarray(tp.end_mm)
    while True:
        cmd = np.empty((cap, 3))
        pos = np.empty((cap, 3))
        blk = np.empty(cap, np.int64)
        wait = np.zeros(n)
        cmd_end = np.full(n, np.nan)
        count = _fanuc_loops.control_loop(
            kind, start, end, np.ascontiguousarray(cut_pts), cut_off, drain_after, stop_after,
            pause_n.astype(np.int64), ti, fr, rapid_acc, k_bell, s.rapid_type == "linear",
            s.rapid_overlap, s.rapid_overlap_percent / 100.0 * fr, exp_cut, k1, k2, exp_keep,
            exp_gain, s.least_increment_mm, ad, bd, width, cmd, pos, blk, wait, cmd_end,
        )  # fmt: skip
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


def run(
    toolpath: Toolpath, machine: MachineProfile, settings: FanucSettings = PAPER_SET_1
) -> Motion:
    """Measured motion of ``toolpath`` on the Fanuc-like control (see :func:`simulate`)."""
    return simulate(toolpath, machine, settings).motion


def measure_inposition_times(
    machine: MachineProfile,
    settings: FanucSettings = PAPER_SET_1,
    *,
    distances_mm: tuple[float, ...] = (20.0, 50.0, 100.0, 150.0, 200.0),
) -> np.ndarray:
    """Each axis's in-position time, measured as Lee et al. 2022 did (Sec. 2.3 and 3).

    For each axis, one single-axis rapid per distance is run from rest on :func:`simulate`
    (the paper: five repeats per axis); the time from the end of the rapid's command until
    every axis is within its in-position width is recorded, and the mean per axis is the
    in-position time (the paper's testbed: X, Y 25 ms, Z 120 ms).

    Parameters
    ----------
    machine : MachineProfile
    settings : FanucSettings
    distances_mm : tuple of float
        Travels of the measured rapids, each > 0.

    Returns
    -------
    ndarray, shape (3,)
        Mean in-position time of X, Y, Z (s).

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
    out = np.zeros(3)
    nan3 = np.full((1, 3), np.nan)
    z1 = np.zeros(1)
    for a in range(3):
        for x in dist:
            end = np.zeros((1, 3))
            end[0, a] = x
            tp = Toolpath(np.zeros((1, 3)), end, np.array([MotionKind.RAPID]), np.full(1, np.nan),
                          nan3, z1, z1, z1, z1, np.full(1, np.nan), np.full(1, np.nan))  # fmt: skip
            out[a] += simulate(tp, machine, settings).inposition_wait_s[0]
    return out / len(dist)
