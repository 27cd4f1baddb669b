r"""What a control does with a machine: one frozen settings type per control model.

A :class:`~nctwin.machine.Machine` says what the machine physically is (axis limits, rapid and
maximum feed). How a control moves it is a control model's business, and each model has its own
settings, in its own table of a profile's file (``[control.<kind>]``, see
:mod:`nctwin.machine`):

============  ======================  ===================================================
kind          type                    used by
============  ======================  ===================================================
``fir``       :class:`FirControl`     :mod:`nctwin.kernel.fir`, ``--method kernel``
``accdec``    :class:`AccDecControl`  :mod:`nctwin.kernel.accdec`, ``--method block_overlap``
``fanuc``     :class:`FanucControl`   :mod:`nctwin.kernel.fanuc`
``planner``   :class:`PlannerControl` ``--method planner`` and the learned methods
``sequence``  :class:`SequenceControl`  :mod:`nctwin.estimate.cycle`, :mod:`nctwin.calibrate`
============  ======================  ===================================================

Each type owns its period, its time constants, its servo and in-position settings and its
default blending tolerance; no setting is the machine's and a control's at once. Every value is
checked on construction: a bad one raises :class:`ValueError` naming the field, the value and
the allowed range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .checks import check_choice, check_int, check_range, whole_periods

__all__ = [
    "CONTROLS",
    "AccDecControl",
    "Control",
    "FanucControl",
    "FirControl",
    "PlannerControl",
    "SequenceControl",
]

_XYZ = tuple[float, float, float]


def _check_period(period_s: float) -> None:
    check_range("period_s", period_s, 0.0, 0.1, low_open=True)


def _check_tolerance(blend_tol_mm: float) -> None:
    check_range("blend_tol_mm", blend_tol_mm, 0.0, 10.0, allow_inf=True)


@dataclass(frozen=True)
class FirControl:
    """nctwin's FIR interpolator (:mod:`nctwin.kernel.fir`, Chien et al. 2023, Sec. 4): two
    moving averages smooth a velocity pulse per block, corners blend within a tolerance.

    Parameters
    ----------
    period_s : float
        Interpolation period, in (0, 0.1] s.
    blend_tol_mm : float
        Corner-blending tolerance where the program sets none (``G64 P`` overrides it), in
        [0, 10] mm, or ``inf`` (no tolerance, a plain ``G64``).
    t1_s, t2_s : float
        Time constants of the two moving averages: acceleration ``F / T1``, jerk
        ``F / (T1 T2)``; in [0, 10] s (the longer must be at least one period).
    acc_scale : float
        The kernel enforces the axis accelerations times this, in (0, 100) (1 for the kernel's
        own machines; fitted where the kernel stands in for another control).
    blend_ratio : float
        The kernel blends a junction within at most this share of the shorter of its two moves
        (a plain ``G64`` within this alone), in (0, 1]; ``inf``: the program's tolerance only.
    block_periods : int
        Shortest time of a move, in periods (a control's block-processing rate): a cutting move
        of length ``l`` runs at most at ``l / (n period_s)``; in [0, 100], 0: no limit.
    rapid_ramp : bool
        Rapids climb to the rapid feed in steps the filters ramp at the axes' acceleration
        (:mod:`nctwin.kernel.fir_rapids`); False: every feed, rapids too, is capped at the
        largest step the filters allow.
    """

    period_s: float = 0.001
    blend_tol_mm: float = 0.05
    t1_s: float = 0.05
    t2_s: float = 0.01
    acc_scale: float = 1.0
    blend_ratio: float = math.inf
    block_periods: int = 0
    rapid_ramp: bool = False

    def __post_init__(self) -> None:
        _check_period(self.period_s)
        _check_tolerance(self.blend_tol_mm)
        for name in ("t1_s", "t2_s"):
            check_range(name, getattr(self, name), 0.0, 10.0)
        check_range("acc_scale", self.acc_scale, 0.0, 100.0, low_open=True, high_open=True)
        if self.blend_ratio != math.inf:
            check_range("blend_ratio", self.blend_ratio, 0.0, 1.0, low_open=True, allow_inf=True)
        if not isinstance(self.rapid_ramp, bool):
            raise ValueError(
                f"rapid_ramp = {self.rapid_ramp!r} is out of range: allowed true, false"
            )
        check_int("block_periods", self.block_periods, 0, 100)
        if max(self.t1_s, self.t2_s) < self.period_s:
            raise ValueError(
                f"t1_s = {self.t1_s!r} is out of range: allowed [period_s, 10] for the longer of "
                f"t1_s and t2_s (period_s = {self.period_s!r})"
            )


@dataclass(frozen=True)
class AccDecControl:
    """The ideal acc/dec-after-interpolation control of Lee et al. 2022 (Sec. 2): the model of
    the block-overlap estimator (:mod:`nctwin.methods.lee2022`) and of the ideal kernel
    (:mod:`nctwin.kernel.accdec`).

    Parameters
    ----------
    period_s : float
        Interpolation period :math:`T_I`, in (0, 0.1] s; every time constant is a whole
        number of it.
    cut_time_constant_s : float
        Acc/dec time constant of cutting feed :math:`A_T` (linear type), in [0, 10] s, whole
        periods (as every time constant here).
    rapid_time_constant_s : float
        Acc/dec time constant of rapids :math:`A_{TR}`, in [0, 10] s.
    rapid_bell_s : float
        Bell-shaped (S-curve) stage added to rapids :math:`A_s`, in [0, 10] s; 0 for none.
    rapid_type : {"linear", "nonlinear"}
        Path of rapids: a straight line at the rapid feed (linear interpolation type), or each
        axis on its own at the rapid feed (non-linear type, Lee et al. 2022, Fig. 3).
    position_gain_per_s : tuple of 3 floats
        Position-loop gain :math:`K_p` of X, Y, Z (first-order loop: following error decays
        as ``exp(-Kp t)``), each > 0.
    inposition_width_mm : tuple of 3 floats
        In-position width of X, Y, Z: after a rapid, the next block waits until every axis's
        following error is within it; each > 0.
    inposition_time_s : tuple of 3 floats
        Measured in-position time of X, Y, Z after a rapid, used by the analytic estimator
        (Lee et al. 2022, Sec. 2.3), each in [0, 10) s; 0 where not measured.
    """

    period_s: float = 0.001
    cut_time_constant_s: float = 0.05
    rapid_time_constant_s: float = 0.1
    rapid_bell_s: float = 0.0
    rapid_type: str = "linear"
    position_gain_per_s: _XYZ = (30.0, 30.0, 30.0)
    inposition_width_mm: _XYZ = (0.02, 0.02, 0.02)
    inposition_time_s: _XYZ = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        _check_period(self.period_s)
        for name in ("cut_time_constant_s", "rapid_time_constant_s", "rapid_bell_s"):
            check_range(name, getattr(self, name), 0.0, 10.0)
        check_choice("rapid_type", self.rapid_type, ("linear", "nonlinear"))
        for name, low_open, hi in (
            ("position_gain_per_s", True, math.inf),
            ("inposition_width_mm", True, math.inf),
            ("inposition_time_s", False, 10.0),
        ):
            xyz = check_range(name, getattr(self, name), 0.0, hi, low_open=low_open, high_open=True,
                              xyz=True)  # fmt: skip
            object.__setattr__(self, name, xyz)
        for name in ("cut_time_constant_s", "rapid_time_constant_s", "rapid_bell_s"):
            self.periods(name)

    def periods(self, name: str) -> int:
        """The time constant ``name`` as a whole number of periods (ValueError if it is not)."""
        return whole_periods(name, getattr(self, name), self.period_s)


@dataclass(frozen=True)
class FanucControl:
    """Parameters of the Fanuc-like control, one field per effect; units in the names.

    Defaults are the paper's testbed where the paper gives a value (Lee et al. 2022, Sec. 3,
    parameter set 1); elsewhere a stated choice, with its reason. Fanuc 0i parameter numbers
    are given for orientation.

    Parameters
    ----------
    period_s : float
        Interpolation period :math:`T_I`; also the servo's sampling period and the period of the
        samples, in (0, 0.1] s. Default 1 ms: a Fanuc 0i interpolates at 1 ms or 2 ms; 1 ms is
        the period of nctwin's testbed profile (``fanuc_0i_testbed``) and divides every time
        constant of the paper.
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
        contours). Not fitted here: the Lee et al. 2022 chapter calibrates the testbed's servo
        to the paper's in-position times (:mod:`nctwin.chapters.lee2022_testbed`).
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

    period_s: float = 0.001
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
        _check_period(self.period_s)
        check_choice("cut_accdec", self.cut_accdec, ("linear", "bell", "exponential"))
        check_choice("rapid_type", self.rapid_type, ("linear", "nonlinear"))
        check_choice("servo", self.servo, ("first_order_ff", "second_order"))
        if not isinstance(self.rapid_overlap, bool):
            raise ValueError(
                f"rapid_overlap = {self.rapid_overlap!r} is out of range: allowed True, False"
            )
        # name: (lo, hi, lo open, hi open)
        ranges = {
            "cut_time_constant_s": (0.0, 10.0, True, False),
            "rapid_time_constant_s": (0.0, 10.0, True, False),
            "rapid_bell_s": (0.0, 10.0, False, False),
            "least_increment_mm": (0.0, 0.1, True, False),
            "rapid_overlap_percent": (0.0, 100.0, False, False),
            "arc_radial_acc_mm_s2": (0.0, math.inf, True, False),
            "block_time_s": (0.0, 1.0, False, True),
            "feedforward": (0.0, 1.0, False, False),
        }
        for name, (lo, hi, low_open, high_open) in ranges.items():
            check_range(name, getattr(self, name), lo, hi, low_open=low_open, high_open=high_open)
        for name, hi, high_open in (
            ("position_gain_per_s", 1000.0, True),
            ("natural_freq_hz", 1000.0, True),
            ("damping", 10.0, False),
            ("inposition_width_mm", 10.0, False),
        ):
            xyz = check_range(
                name, getattr(self, name), 0.0, hi, low_open=True, high_open=high_open, xyz=True
            )
            object.__setattr__(self, name, xyz)
        k_cut = self.periods("cut_time_constant_s")
        for name in ("rapid_time_constant_s", "rapid_bell_s"):
            self.periods(name)
        if self.cut_accdec == "bell" and k_cut % 2:
            raise ValueError(
                f"cut_time_constant_s = {self.cut_time_constant_s!r} is out of range: allowed "
                f"even multiples of period_s = {self.period_s!r} with "
                "cut_accdec = 'bell' (two moving averages of half the time constant)"
            )

    def periods(self, name: str) -> int:
        """The time constant ``name`` as a whole number of periods (ValueError if it is not)."""
        return whole_periods(name, getattr(self, name), self.period_s)


@dataclass(frozen=True)
class PlannerControl:
    """LinuxCNC's trajectory planner (:mod:`nctwin.estimate.blend_planner`): blend arcs within
    a tolerance, look-ahead over the queue, a move never shorter than a few cycles.

    Parameters
    ----------
    period_s : float
        Trajectory (servo) period, in (0, 0.1] s: LinuxCNC's ``[TRAJ] CYCLE_TIME``.
    blend_tol_mm : float
        Blending tolerance where the program sets no ``G61``/``G64`` (LinuxCNC's startup
        code), in [0, 10] mm, or ``inf`` (no tolerance: a plain ``G64``, what LinuxCNC 2.9
        runs there whatever its startup code asks; see ``data/machines/linuxcnc_sim.toml``).
    word_stops : bool
        True: the tool stops before the M-codes LinuxCNC's task waits for the motion to end
        for (:mod:`nctwin.estimate.task_waits`), as on LinuxCNC; False (default, a control
        that runs them on the fly): they neither stop it nor take time.
    dwell_wait_s, spindle_wait_s, coolant_wait_s, tool_change_wait_s, offset_wait_s : float
        How long the tool rests, beyond a dwell's own time, where the task stops it for a
        dwell, a spindle word (``M3``-``M5``), a coolant word (``M7``-``M9``), a tool change
        (``M6``) or an offset (``G43``, ``G49``, ``G92``, a new G54-G59.3; the
        :data:`~nctwin.toolpath.OFFSET_EVENTS`) between two moves (the words' and offsets' with
        ``word_stops`` only), each in [0, 600] s.
    """

    period_s: float = 0.001
    blend_tol_mm: float = 0.0254
    word_stops: bool = False
    dwell_wait_s: float = 0.0
    spindle_wait_s: float = 0.0
    coolant_wait_s: float = 0.0
    tool_change_wait_s: float = 0.0
    offset_wait_s: float = 0.0

    def __post_init__(self) -> None:
        _check_period(self.period_s)
        _check_tolerance(self.blend_tol_mm)
        if not isinstance(self.word_stops, bool):
            raise ValueError(
                f"word_stops = {self.word_stops!r} is not allowed: allowed True, False"
            )
        for name in ("dwell_wait_s", "spindle_wait_s", "coolant_wait_s", "tool_change_wait_s",
                     "offset_wait_s"):  # fmt: skip
            check_range(name, getattr(self, name), 0.0, 600.0)


@dataclass(frozen=True)
class SequenceControl:
    """What a control spends on lines that are no motion, as a real machine's logs time them
    (:mod:`nctwin.calibrate`): net of the motion of the lines involved, which a motion model
    times.

    Parameters
    ----------
    tool_change_s : float
        A tool change: from the ``G91 G28 Z0.`` before a ``Tn M6`` to the ``M6`` (an ``M01``
        between them included), in [0, 600] s.
    spindle_start_s, spindle_start_s_per_krpm : float
        A spindle start (``S.. M3`` and the line after it) takes
        ``spindle_start_s + spindle_start_s_per_krpm * S / 1000``; each in [-600, 600] (s, and
        s per 1000 rev/min), the law's value at 0 rev/min may be negative.
    optional_stop_s : float
        An ``M01`` line outside a tool change, optional stop off, in [0, 600] s.
    program_start_s, program_end_s : float
        Cycle start to the first block; the M30 line to the end of the run; each in [0, 600] s.
    first_tool_change_s : float or None
        A tool change before the program's first spindle start (the spindle at rest, no
        return before it: the ``Tn M6`` a program opens with), in [0, 600] s; None (the key
        left out): as ``tool_change_s``.
    """

    tool_change_s: float = 0.0
    spindle_start_s: float = 0.0
    spindle_start_s_per_krpm: float = 0.0
    optional_stop_s: float = 0.0
    program_start_s: float = 0.0
    program_end_s: float = 0.0
    first_tool_change_s: float | None = None

    def __post_init__(self) -> None:
        for name in ("tool_change_s", "optional_stop_s", "program_start_s", "program_end_s"):
            check_range(name, getattr(self, name), 0.0, 600.0)
        if self.first_tool_change_s is not None:
            check_range("first_tool_change_s", self.first_tool_change_s, 0.0, 600.0)
        for name in ("spindle_start_s", "spindle_start_s_per_krpm"):
            check_range(name, getattr(self, name), -600.0, 600.0)

    def tool_change_at_s(self, first: bool) -> float:
        """The time (s) of a tool change, ``first``: before the program's first spindle
        start."""
        if first and self.first_tool_change_s is not None:
            return self.first_tool_change_s
        return self.tool_change_s

    def spindle_s(self, rpm: float) -> float:
        """The time (s) of a spindle start to ``rpm`` rev/min."""
        return self.spindle_start_s + self.spindle_start_s_per_krpm * rpm / 1000.0


#: A control's settings, of any model.
Control = FirControl | AccDecControl | FanucControl | PlannerControl | SequenceControl

#: The control models by the name of their table in a profile's file (``[control.<kind>]``).
CONTROLS: dict[str, type] = {
    "fir": FirControl,
    "accdec": AccDecControl,
    "fanuc": FanucControl,
    "planner": PlannerControl,
    "sequence": SequenceControl,
}
