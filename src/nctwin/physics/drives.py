r"""Feed drives and spindle of a 3-axis milling centre with direct linear drives, and how the
controller and a dynamometer record them (the "measurement" of Denkena et al. 2020).

Conventions
-----------
Axes
    X, Y, Z are stacked as on the paper's HSC30 (eq. 2): the Y drive moves
    :math:`m_x + m_y + m_z`, the X drive :math:`m_x + m_z`, the Z drive :math:`m_z` (its weight
    counterbalanced).
Drive equation
    Each axis obeys, at the servo rate,

    .. math:: K_m I = F_{co}(s) + k (s - s_r) + F_{fr} + m \ddot s + F_{ext},

    the paper's eq. 1 with a *richer* friction than the paper's model (DESIGN rule 1):

    * cogging :math:`F_{co}(s) = \sum_h A_h \sin(2\pi h s / p + \psi_h)`, pole pitch
      :math:`p` = 23 mm, harmonics :math:`h` = 1, 2, 3;
    * LuGre dynamic friction (Canudas de Wit et al. 1995) with bristle state :math:`z`,

      .. math:: \dot z = v - \frac{\sigma_0 |v|}{g(v, s)} z, \quad
                F_{fr} = \sigma_0 z + \sigma_1 \dot z + \sigma_2 v, \quad
                g(v, s) = c(s) \left(F_C + (F_S - F_C) e^{-|v/v_s|^{\delta}}\right),

      whose steady state is a Stribeck curve (the paper's eq. 4 with shape factor
      :math:`\delta`), with pre-sliding (a spring of stiffness :math:`\sigma_0` below the
      breakaway force, hence hysteresis at reversals) and a mild position dependence
      :math:`c(s) = 1 + \varepsilon \sin(2\pi s / \lambda + \psi)` (guideway wear). The bristle
      state is advanced with the exact solution for a velocity held over one step, stable at
      any speed;
    * the process force :math:`F_{ext}`, the force on the workpiece (what the dynamometer
      measures). It reaches the slide through the compliance of tool, spindle and head: a mass
      :math:`m_c` (part of the moved mass) on a spring-damper :math:`k_c, c_c` against the
      slide, deflected by :math:`d`,

      .. math:: m_c (\ddot s + \ddot d) = -F_{ext} - k_c d - c_c \dot d,

      so the slide feels :math:`k_c d + c_c \dot d` (:math:`-F_{ext}` in the static limit,
      static deflection :math:`d = -F_{ext} / k_c`) and tooth-frequency forces well above the
      corner :math:`\sqrt{k_c / m_c} / 2\pi` are attenuated by the square of the frequency
      ratio before they shake the slide.
Servo
    Cascade control at ``servo_rate_hz``: a P position loop (gain :math:`k_v`) with velocity
    feedforward, a PI velocity loop of bandwidth ``velocity_bandwidth_hz``, and acceleration
    (force) feedforward with the nominal moved mass; the current loop is ideal
    (:math:`I = F_{cmd} / K_m`).
Recording
    The controller signals (position, current; spindle speed and current) are sampled at
    ``record_rate_hz`` (paper: 250 Hz) without anti-alias filter, as a trace does; the velocity
    is the one the control reports, the mean of the slide velocity over the record period (the
    position difference of the encoder over it divided by the period), then noise and the
    quantum; acceleration is the central difference of the recorded velocity. The
    dynamometer adds white noise to the true force and low-passes it (2nd-order Butterworth,
    paper: 300 Hz) before the same sampling.
Units
    mm, s, mm/s, mm/s², N, A, kg (forces of inertia: :math:`m a \cdot 10^{-3}` N).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from ..checks import check_range

__all__ = [
    "AxisDrive",
    "DriveRecord",
    "FeedDriveMachine",
    "Spindle",
    "cogging_n",
    "dynamometer",
    "lugre_steady_state_n",
    "simulate_drives",
    "spindle_signals",
]


#: The compliance between tool side and slide of every axis, an effective force path (head,
#: spindle, holder, clamping): a 20 Hz mode, below the spindle (43-100 Hz) and tooth (170-400 Hz)
#: frequencies of Table 1, so runout and tooth passing do not shake the slide. Fixed before any
#: LSTM was trained, from the model's errors the paper publishes about its bench (Table 2's ramp
#: row, X and Y; the grooves of Figs. 4-5), by
#: :func:`nctwin.chapters.denkena2020_calibration.calibrate_bench`: of the ``CANDIDATES`` there
#: (60 kg; corners of 16 and 20 Hz, damping ratios of 0.1 and 0.3), this one puts the ramp's X
#: error nearest the paper's, with Y and the grooves inside their bands.
COMPLIANCE_MASS_KG = 60.0
COMPLIANCE_STIFFNESS_N_MM = 947.0
COMPLIANCE_DAMPING_RATIO = 0.3


@dataclass(frozen=True)
class AxisDrive:
    """One direct linear drive with its guideways, cables and servo.

    Parameters
    ----------
    own_mass_kg : float
        The axis' own slide mass (:math:`m_x`, :math:`m_y`, :math:`m_z`); the moved mass adds the
        stacked axes (:meth:`FeedDriveMachine.moved_mass_kg`).
    km_n_a : float
        Motor constant :math:`K_m`.
    cogging_n : tuple of float
        Amplitudes :math:`A_h` of the cogging harmonics 1, 2, 3, ...
    cogging_phase_rad : tuple of float
        Their phases :math:`\\psi_h` (same length).
    pole_pitch_mm : float
        Cogging period :math:`p` (paper: 23 mm).
    restoring_n_mm : float
        Spring constant :math:`k` of cables and covers.
    rest_point_mm : float
        :math:`s_r`.
    coulomb_n, breakaway_n : float
        :math:`F_C` and :math:`F_S \\ge F_C`.
    stribeck_mm_s : float
        :math:`v_s`.
    stribeck_shape : float
        :math:`\\delta` of the true steady state (the paper's model assumes 2).
    viscous_n_s_mm : float
        :math:`\\sigma_2`.
    bristle_stiffness_n_mm, bristle_damping_n_s_mm : float
        LuGre :math:`\\sigma_0` and :math:`\\sigma_1` (pre-sliding).
    friction_position_share : float
        :math:`\\varepsilon`, in [0, 0.5).
    friction_wavelength_mm : float
        :math:`\\lambda`.
    friction_position_phase_rad : float
        :math:`\\psi`.
    kv_1_s : float
        Position-loop gain.
    velocity_bandwidth_hz : float
        Proportional velocity gain :math:`m \\cdot 2\\pi f_{bw}`.
    integral_time_s : float
        Velocity-loop integral time.
    compliance_mass_kg : float
        :math:`m_c`, the tool, spindle and head mass behind the compliance (part of the moved
        mass, below it).
    compliance_stiffness_n_mm : float
        :math:`k_c` between that mass and the slide.
    compliance_damping_ratio : float
        :math:`\\zeta_c`, so :math:`c_c = 2 \\zeta_c \\sqrt{k_c m_c}`.
    """

    own_mass_kg: float
    km_n_a: float
    cogging_n: tuple[float, ...]
    cogging_phase_rad: tuple[float, ...]
    restoring_n_mm: float
    rest_point_mm: float
    coulomb_n: float
    breakaway_n: float
    stribeck_mm_s: float
    viscous_n_s_mm: float
    pole_pitch_mm: float = 23.0
    stribeck_shape: float = 1.5
    bristle_stiffness_n_mm: float = 12000.0
    bristle_damping_n_s_mm: float = 10.0
    friction_position_share: float = 0.12
    friction_wavelength_mm: float = 170.0
    friction_position_phase_rad: float = 0.0
    kv_1_s: float = 60.0
    velocity_bandwidth_hz: float = 80.0
    integral_time_s: float = 0.008
    compliance_mass_kg: float = COMPLIANCE_MASS_KG
    compliance_stiffness_n_mm: float = COMPLIANCE_STIFFNESS_N_MM
    compliance_damping_ratio: float = COMPLIANCE_DAMPING_RATIO

    def __post_init__(self) -> None:
        for name in ("own_mass_kg", "km_n_a", "pole_pitch_mm", "stribeck_mm_s", "stribeck_shape",
                     "bristle_stiffness_n_mm", "friction_wavelength_mm", "kv_1_s",
                     "velocity_bandwidth_hz", "integral_time_s", "compliance_mass_kg",
                     "compliance_stiffness_n_mm"):  # fmt: skip
            check_range(name, getattr(self, name), 0.0, 1e7, low_open=True)
        for name in ("restoring_n_mm", "coulomb_n", "viscous_n_s_mm", "bristle_damping_n_s_mm",
                     "compliance_damping_ratio"):  # fmt: skip
            check_range(name, getattr(self, name), 0.0, 1e7)
        check_range("breakaway_n", self.breakaway_n, self.coulomb_n, 1e7)
        check_range("friction_position_share", self.friction_position_share, 0.0, 0.49)
        if len(self.cogging_n) != len(self.cogging_phase_rad):
            raise ValueError(
                f"cogging_phase_rad has {len(self.cogging_phase_rad)} entries: allowed "
                f"{len(self.cogging_n)} (one per cogging harmonic)"
            )


@dataclass(frozen=True)
class Spindle:
    """Spindle motor: :math:`I_s = (T_{cut} + T_0 + c_v n) / K_t`.

    Parameters
    ----------
    kt_nm_a : float
        Torque constant.
    friction_nm : float
        Bearing friction torque :math:`T_0`.
    viscous_nm_per_rpm : float
        :math:`c_v`.
    droop_rpm_per_nm : float
        Speed droop of the speed loop under load torque.
    current_noise_a, speed_noise_rpm : float
        Standard deviations of the recorded signals.
    """

    kt_nm_a: float = 0.9
    friction_nm: float = 0.35
    viscous_nm_per_rpm: float = 6e-5
    droop_rpm_per_nm: float = 4.0
    current_noise_a: float = 0.05
    speed_noise_rpm: float = 1.0

    def __post_init__(self) -> None:
        check_range("kt_nm_a", self.kt_nm_a, 0.0, 1e3, low_open=True)
        for name in ("friction_nm", "viscous_nm_per_rpm", "droop_rpm_per_nm",
                     "current_noise_a", "speed_noise_rpm"):  # fmt: skip
            check_range(name, getattr(self, name), 0.0, 1e3)


def _default_axes() -> tuple[AxisDrive, AxisDrive, AxisDrive]:
    x = AxisDrive(
        own_mass_kg=160.0, km_n_a=160.0, cogging_n=(30.0, 12.0, 5.0),
        cogging_phase_rad=(0.4, 1.9, 0.7), restoring_n_mm=0.25, rest_point_mm=150.0,
        coulomb_n=120.0, breakaway_n=170.0, stribeck_mm_s=1.5, viscous_n_s_mm=1.2,
        friction_position_phase_rad=0.5,
    )  # fmt: skip
    y = AxisDrive(
        own_mass_kg=260.0, km_n_a=200.0, cogging_n=(36.0, 10.0, 6.0),
        cogging_phase_rad=(2.1, 0.3, 2.5), restoring_n_mm=0.35, rest_point_mm=140.0,
        coulomb_n=180.0, breakaway_n=250.0, stribeck_mm_s=2.0, viscous_n_s_mm=1.8,
        friction_position_phase_rad=2.0, friction_wavelength_mm=210.0,
    )  # fmt: skip
    z = AxisDrive(
        own_mass_kg=90.0, km_n_a=120.0, cogging_n=(20.0, 8.0, 3.0),
        cogging_phase_rad=(1.2, 2.8, 0.1), restoring_n_mm=0.2, rest_point_mm=100.0,
        coulomb_n=90.0, breakaway_n=130.0, stribeck_mm_s=1.2, viscous_n_s_mm=1.0,
        friction_position_phase_rad=4.0, friction_wavelength_mm=150.0,
    )  # fmt: skip
    return x, y, z


@dataclass(frozen=True)
class FeedDriveMachine:
    """The simulated milling centre: three drives, a spindle, rates and noise.

    Parameters
    ----------
    axes : (AxisDrive, AxisDrive, AxisDrive)
        X, Y, Z.
    spindle : Spindle
    servo_rate_hz : float
        Rate of the drive simulation and servo loops (also the tooth-passing resolution).
    record_rate_hz : float
        Controller trace rate (paper: 250 Hz); must divide ``servo_rate_hz``.
    current_noise_a : float
        Noise of the recorded motor currents.
    velocity_noise_mm_s : float
        Noise of the recorded velocities.
    velocity_resolution_mm_s : float
        Quantisation of the recorded velocities, applied after the mean over the record period.
    position_resolution_mm : float
        Quantisation of the recorded positions.
    dynamometer_noise_n : float
        White noise on the dynamometer before its filter.
    dynamometer_cutoff_hz : float
        Its low-pass (paper: 300 Hz).
    """

    axes: tuple[AxisDrive, AxisDrive, AxisDrive] = field(default_factory=_default_axes)
    spindle: Spindle = field(default_factory=Spindle)
    servo_rate_hz: float = 5000.0
    record_rate_hz: float = 250.0
    current_noise_a: float = 0.01
    velocity_noise_mm_s: float = 0.01
    velocity_resolution_mm_s: float = 0.05
    position_resolution_mm: float = 1e-4
    dynamometer_noise_n: float = 2.0
    dynamometer_cutoff_hz: float = 300.0

    def __post_init__(self) -> None:
        check_range("servo_rate_hz", self.servo_rate_hz, 100.0, 1e5)
        check_range("record_rate_hz", self.record_rate_hz, 1.0, self.servo_rate_hz)
        ratio = self.servo_rate_hz / self.record_rate_hz
        if abs(ratio - round(ratio)) > 1e-9:
            raise ValueError(
                f"record_rate_hz = {self.record_rate_hz!r} is out of range: allowed divisors of "
                f"servo_rate_hz = {self.servo_rate_hz!r}"
            )
        check_range("dynamometer_cutoff_hz", self.dynamometer_cutoff_hz, 0.0,
               0.5 * self.servo_rate_hz, low_open=True)  # fmt: skip
        for name in ("current_noise_a", "velocity_noise_mm_s", "position_resolution_mm",
                     "velocity_resolution_mm_s", "dynamometer_noise_n"):  # fmt: skip
            check_range(name, getattr(self, name), 0.0, 1e3)
        for axis, moved in zip(self.axes, self.moved_mass_kg(), strict=True):
            if not axis.compliance_mass_kg < moved:
                raise ValueError(
                    f"compliance_mass_kg = {axis.compliance_mass_kg!r} is out of range: allowed "
                    f"below the axis' moved mass {moved!r}"
                )

    @property
    def decimation(self) -> int:
        """Servo steps per recorded sample."""
        return round(self.servo_rate_hz / self.record_rate_hz)

    def moved_mass_kg(self) -> np.ndarray:
        """Masses the X, Y, Z drives move (eq. 2): :math:`m_x + m_z, m_x + m_y + m_z, m_z`."""
        mx, my, mz = (a.own_mass_kg for a in self.axes)
        return np.array([mx + mz, mx + my + mz, mz])


def cogging_n(s_mm: np.ndarray, axis: AxisDrive) -> np.ndarray:
    """Cogging force :math:`F_{co}(s)`, same shape as ``s_mm``."""
    s = np.asarray(s_mm, dtype=float)
    out = np.zeros_like(s)
    for h, (a, p) in enumerate(zip(axis.cogging_n, axis.cogging_phase_rad, strict=True), 1):
        out += a * np.sin(2.0 * np.pi * h * s / axis.pole_pitch_mm + p)
    return out


def _position_factor(s_mm: np.ndarray, axis: AxisDrive) -> np.ndarray:
    return 1.0 + axis.friction_position_share * np.sin(
        2.0 * np.pi * s_mm / axis.friction_wavelength_mm + axis.friction_position_phase_rad
    )


def _g(v, c, fc, fs, vs, delta):
    return c * (fc + (fs - fc) * np.exp(-(np.abs(v / vs) ** delta)))


def lugre_steady_state_n(v_mm_s: np.ndarray, s_mm: np.ndarray, axis: AxisDrive) -> np.ndarray:
    """Steady-state (constant-velocity) friction of the drive: a Stribeck curve with the true
    shape factor, scaled by the position factor :math:`c(s)`, plus viscous friction."""
    v = np.asarray(v_mm_s, dtype=float)
    c = _position_factor(np.asarray(s_mm, dtype=float), axis)
    g = _g(v, c, axis.coulomb_n, axis.breakaway_n, axis.stribeck_mm_s, axis.stribeck_shape)
    return np.sign(v) * g + axis.viscous_n_s_mm * v


@dataclass(frozen=True, eq=False)
class DriveRecord:
    """Controller trace of a batch of runs.

    Parameters
    ----------
    t_s : ndarray, shape (R,)
    pos_mm, vel_mm_s, acc_mm_s2, current_a : ndarray, shape (B, R, 3)
        Actual position, velocity (mean over the record period), acceleration and motor current
        of X, Y, Z.
    deflection_mm : ndarray, shape (B, R, 3)
        Deflection :math:`d` of the tool-side mass against the slide (not recorded by the
        control; the truth, for checks).
    """

    t_s: np.ndarray
    pos_mm: np.ndarray
    vel_mm_s: np.ndarray
    acc_mm_s2: np.ndarray
    current_a: np.ndarray
    deflection_mm: np.ndarray


def simulate_drives(
    ref_pos_mm: np.ndarray,
    ref_vel_mm_s: np.ndarray,
    ref_acc_mm_s2: np.ndarray,
    force_ext_n: np.ndarray,
    machine: FeedDriveMachine,
    rng: np.random.Generator,
) -> DriveRecord:
    """Run the three servo drives of a batch of runs and record them.

    The loop runs over servo steps (the drive is a dynamic system); every operation inside is
    vectorised over the batch and the axes.

    Parameters
    ----------
    ref_pos_mm, ref_vel_mm_s, ref_acc_mm_s2 : ndarray, shape (B, T, 3)
        Interpolated set points at ``machine.servo_rate_hz``.
    force_ext_n : ndarray, shape (B, T, 3)
        Process force on the workpiece (the drives' external load).
    machine : FeedDriveMachine
    rng : numpy.random.Generator
        Recording noise.

    Returns
    -------
    DriveRecord
        Sampled every ``machine.decimation`` steps, from step 0.
    """
    ref_pos_mm = np.asarray(ref_pos_mm, dtype=float)
    if ref_pos_mm.ndim != 3 or ref_pos_mm.shape[2] != 3:
        raise ValueError(f"ref_pos_mm shape = {ref_pos_mm.shape!r}: allowed (B, T, 3)")
    for name, a in (("ref_vel_mm_s", ref_vel_mm_s), ("ref_acc_mm_s2", ref_acc_mm_s2),
                    ("force_ext_n", force_ext_n)):  # fmt: skip
        if np.shape(a) != ref_pos_mm.shape:
            raise ValueError(f"{name} shape = {np.shape(a)!r}: allowed {ref_pos_mm.shape!r}")
    b, n_t, _ = ref_pos_mm.shape
    dt = 1.0 / machine.servo_rate_hz
    ax = machine.axes
    par = {k: np.array([getattr(a, k) for a in ax]) for k in (
        "km_n_a", "restoring_n_mm", "rest_point_mm", "coulomb_n", "breakaway_n",
        "stribeck_mm_s", "stribeck_shape", "viscous_n_s_mm", "bristle_stiffness_n_mm",
        "bristle_damping_n_s_mm", "kv_1_s", "velocity_bandwidth_hz", "integral_time_s",
        "pole_pitch_mm", "friction_position_share", "friction_wavelength_mm",
        "friction_position_phase_rad", "compliance_mass_kg", "compliance_stiffness_n_mm",
        "compliance_damping_ratio")}  # fmt: skip
    mass = machine.moved_mass_kg()  # (3,)
    m_c, k_c = par["compliance_mass_kg"], par["compliance_stiffness_n_mm"]
    m_slide = mass - m_c
    c_c = 2.0 * par["compliance_damping_ratio"] * np.sqrt(k_c * m_c * 1e-3)  # N s / mm
    kp = mass * 2.0 * np.pi * par["velocity_bandwidth_hz"] * 1e-3  # N s / mm
    sigma0, sigma1 = par["bristle_stiffness_n_mm"], par["bristle_damping_n_s_mm"]
    n_h = max(len(a.cogging_n) for a in ax)
    amp = np.array([list(a.cogging_n) + [0.0] * (n_h - len(a.cogging_n)) for a in ax])
    phase = np.array([list(a.cogging_phase_rad) + [0.0] * (n_h - len(a.cogging_n)) for a in ax])
    wave = 2.0 * np.pi * np.arange(1, n_h + 1)[None, :] / par["pole_pitch_mm"][:, None]  # (3, H)
    eps = par["friction_position_share"]
    k_pos = 2.0 * np.pi / par["friction_wavelength_mm"]
    psi = par["friction_position_phase_rad"]
    s = ref_pos_mm[:, 0].copy()
    v = ref_vel_mm_s[:, 0].copy()
    z = np.zeros((b, 3))
    integ = np.zeros((b, 3))
    d = -force_ext_n[:, 0] / k_c  # the compliance starts in its static deflection
    d_dot = np.zeros((b, 3))
    v_sum, n_sum = np.zeros((b, 3)), 0
    decim = machine.decimation
    n_r = (n_t - 1) // decim + 1
    rec_s = np.empty((b, n_r, 3))
    rec_v = np.empty((b, n_r, 3))
    rec_f = np.empty((b, n_r, 3))
    rec_d = np.empty((b, n_r, 3))
    for k in range(n_t):
        v_sum, n_sum = v_sum + v, n_sum + 1
        e_v = ref_vel_mm_s[:, k] + par["kv_1_s"] * (ref_pos_mm[:, k] - s) - v
        integ += e_v * dt
        f_cmd = mass * ref_acc_mm_s2[:, k] * 1e-3 + kp * (e_v + integ / par["integral_time_s"])
        c = 1.0 + eps * np.sin(k_pos * s + psi)
        g = _g(v, c, par["coulomb_n"], par["breakaway_n"], par["stribeck_mm_s"],
               par["stribeck_shape"])  # fmt: skip
        z_ss = np.sign(v) * g / sigma0
        z_new = z_ss + (z - z_ss) * np.exp(-sigma0 * np.abs(v) * dt / g)
        f_fr = sigma0 * z_new + sigma1 * (z_new - z) / dt + par["viscous_n_s_mm"] * v
        z = z_new
        f_co = (amp * np.sin(wave * s[:, :, None] + phase)).sum(axis=2)
        f_load = f_co + par["restoring_n_mm"] * (s - par["rest_point_mm"]) + f_fr
        f_spring = k_c * d + c_c * d_dot
        acc = (f_cmd - f_load + f_spring) * 1e3 / m_slide
        if k % decim == 0:
            r = k // decim
            rec_s[:, r], rec_v[:, r], rec_f[:, r], rec_d[:, r] = s, v_sum / n_sum, f_cmd, d
            v_sum, n_sum = np.zeros((b, 3)), 0
        d_dot = d_dot + ((-force_ext_n[:, k] - f_spring) * 1e3 / m_c - acc) * dt
        d = d + d_dot * dt
        v = v + acc * dt
        s = s + v * dt
    res = machine.position_resolution_mm
    pos = np.round(rec_s / res) * res if res > 0 else rec_s
    vel = rec_v + machine.velocity_noise_mm_s * rng.standard_normal(rec_v.shape)
    v_res = machine.velocity_resolution_mm_s
    vel = np.round(vel / v_res) * v_res if v_res > 0 else vel
    current = rec_f / par["km_n_a"] + machine.current_noise_a * rng.standard_normal(rec_f.shape)
    t = np.arange(n_r) * decim * dt
    acc_rec = np.gradient(vel, t, axis=1) if n_r > 1 else np.zeros_like(vel)
    return DriveRecord(t, pos, vel, acc_rec, current, rec_d)


def spindle_signals(
    torque_nmm: np.ndarray,
    spindle_rpm: np.ndarray,
    machine: FeedDriveMachine,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Recorded spindle speed and current.

    Parameters
    ----------
    torque_nmm : ndarray, shape (B, T)
        Cutting torque at the servo rate.
    spindle_rpm : ndarray, shape (B, T)
        Commanded speed (0 where the spindle stands).
    machine : FeedDriveMachine
    rng : numpy.random.Generator

    Returns
    -------
    speed_rpm, current_a : ndarray, shape (B, R)
        Sampled at ``machine.record_rate_hz``.
    """
    sp = machine.spindle
    d = machine.decimation
    tq = np.asarray(torque_nmm, dtype=float)[:, ::d] * 1e-3
    n = np.asarray(spindle_rpm, dtype=float)[:, ::d]
    running = n > 0
    speed = (n - sp.droop_rpm_per_nm * tq) * running
    current = (tq + (sp.friction_nm + sp.viscous_nm_per_rpm * n) * running) / sp.kt_nm_a
    speed = speed + sp.speed_noise_rpm * rng.standard_normal(speed.shape) * running
    current = current + sp.current_noise_a * rng.standard_normal(current.shape)
    return speed, current


def dynamometer(
    force_n: np.ndarray, machine: FeedDriveMachine, rng: np.random.Generator
) -> np.ndarray:
    """What the dynamometer records: the true force plus white noise, low-passed (2nd-order
    Butterworth at ``machine.dynamometer_cutoff_hz``, causal like the amplifier's analogue
    filter), sampled at the controller's record instants.

    Parameters
    ----------
    force_n : ndarray, shape (B, T, 3)
        True force on the workpiece at the servo rate.
    machine : FeedDriveMachine
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, shape (B, R, 3)
    """
    f = np.asarray(force_n, dtype=float)
    noisy = f + machine.dynamometer_noise_n * rng.standard_normal(f.shape)
    bb, aa = signal.butter(2, machine.dynamometer_cutoff_hz, fs=machine.servo_rate_hz)
    return signal.lfilter(bb, aa, noisy, axis=1)[:, :: machine.decimation]
