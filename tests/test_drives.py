"""Feed-drive physics: cogging period, steady-state friction, servo tracking, recording."""

import numpy as np
import pytest

from nctwin.physics import drives

MACHINE = drives.FeedDriveMachine()


def test_cogging_has_the_pole_pitch_period():
    axis = MACHINE.axes[0]
    s = np.linspace(0.0, 100.0, 2001)
    np.testing.assert_allclose(drives.cogging_n(s + 23.0, axis), drives.cogging_n(s, axis),
                               atol=1e-9)  # fmt: skip
    spectrum = np.abs(np.fft.rfft(drives.cogging_n(np.arange(2300) * 0.1, axis)))
    assert np.argmax(spectrum) == 10  # 230 mm hold ten 23 mm periods


def _constant_velocity_run(v_mm_s, duration_s=2.0, start_mm=150.0):
    n = int(duration_s * MACHINE.servo_rate_hz)
    t = np.arange(n) / MACHINE.servo_rate_hz
    pos = start_mm + v_mm_s * t
    ref = np.repeat(pos[None, :, None], 3, axis=2)
    vel = np.full_like(ref, v_mm_s)
    rec = drives.simulate_drives(ref, vel, np.zeros_like(ref), np.zeros_like(ref), MACHINE,
                                 np.random.default_rng(0))  # fmt: skip
    return rec


def test_constant_velocity_current_is_the_sum_of_the_position_and_friction_forces():
    v = 20.0
    rec = _constant_velocity_run(v)
    late = slice(len(rec.t_s) // 2, None)
    for i, axis in enumerate(MACHINE.axes):
        s = rec.pos_mm[0, late, i]
        expected = (drives.cogging_n(s, axis) + axis.restoring_n_mm * (s - axis.rest_point_mm)
                    + drives.lugre_steady_state_n(np.full_like(s, v), s, axis))  # fmt: skip
        motor = axis.km_n_a * rec.current_a[0, late, i]
        # inertia of the cogging ripple and noise only
        assert np.abs(motor.mean() - expected.mean()) < 3.0
        assert np.abs(rec.vel_mm_s[0, late, i] - v).max() < 0.5


def test_reversal_shows_pre_sliding_not_a_friction_jump():
    """At a sinusoidal reversal the LuGre force changes sign gradually; a Stribeck model would
    jump by 2 F_br within one sample."""
    f_hz, amp = 1.0, 5.0
    n = int(2.0 * MACHINE.servo_rate_hz)
    t = np.arange(n) / MACHINE.servo_rate_hz
    w = 2 * np.pi * f_hz
    ref = np.repeat((150.0 + amp * np.sin(w * t))[None, :, None], 3, axis=2)
    vel = np.repeat((amp * w * np.cos(w * t))[None, :, None], 3, axis=2)
    acc = np.repeat((-amp * w**2 * np.sin(w * t))[None, :, None], 3, axis=2)
    rec = drives.simulate_drives(ref, vel, acc, np.zeros_like(ref), MACHINE,
                                 np.random.default_rng(1))  # fmt: skip
    axis = MACHINE.axes[0]
    force = axis.km_n_a * rec.current_a[0, :, 0]
    jump = np.abs(np.diff(force)).max()
    assert jump < axis.breakaway_n  # a Stribeck model's jump is 2 F_br


def test_bad_parameters_name_themselves():
    with pytest.raises(ValueError, match="record_rate_hz"):
        drives.FeedDriveMachine(record_rate_hz=300.0)
    with pytest.raises(ValueError, match="breakaway_n"):
        drives.AxisDrive(own_mass_kg=1, km_n_a=1, cogging_n=(), cogging_phase_rad=(),
                         restoring_n_mm=0, rest_point_mm=0, coulomb_n=10, breakaway_n=5,
                         stribeck_mm_s=1, viscous_n_s_mm=0)  # fmt: skip


def test_dynamometer_passes_slow_forces_and_cuts_fast_ones():
    n = 10000
    t = np.arange(n) / MACHINE.servo_rate_hz
    slow = np.sin(2 * np.pi * 20 * t)
    fast = np.sin(2 * np.pi * 1500 * t)
    f = np.stack([slow, fast, 0 * t], axis=1)[None] * 100.0
    quiet = drives.FeedDriveMachine(dynamometer_noise_n=0.0)
    out = drives.dynamometer(f, quiet, np.random.default_rng(0))
    assert out.shape == (1, n // 20, 3)
    assert np.abs(out[0, 100:, 0]).max() > 95.0
    assert np.abs(out[0, 100:, 1]).max() < 10.0


def _standing_run(force_n, machine, duration_s=1.0):
    """A batch of one run whose set points stand at 150 mm while ``force_n(t)`` (N) loads all
    three axes."""
    n = int(duration_s * machine.servo_rate_hz)
    t = np.arange(n) / machine.servo_rate_hz
    ref = np.full((1, n, 3), 150.0)
    f = np.repeat(force_n(t)[None, :, None], 3, axis=2)
    zero = np.zeros_like(ref)
    return drives.simulate_drives(ref, zero, zero, f, machine, np.random.default_rng(2))


def test_standing_axis_under_a_tooth_frequency_force_reads_far_below_the_quantum():
    """200 Hz, 100 N on X and Y (moved masses 250 and 510 kg): a rigid slide would swing at
    100 / (m 2 pi 200) = 0.32 and 0.16 mm/s, two to six quanta. The 20 Hz compliance (damping
    ratio 0.3, frequency ratio 10) passes sqrt(1 + 6^2) / sqrt(99^2 + 6^2) = 0.06 of the force to
    the slide (190 and 450 kg): 0.026 and 0.011 mm/s; the 4 ms mean keeps
    sin(0.8 pi) / (0.8 pi) = 0.23 of that, about 0.006 and 0.003 mm/s, so both read 0."""
    exact = drives.FeedDriveMachine(velocity_noise_mm_s=0.0, velocity_resolution_mm_s=0.0)
    rec = _standing_run(lambda t: 100.0 * np.sin(2 * np.pi * 200.0 * t), exact)
    swing = np.abs(rec.vel_mm_s[0, 50:, :2]).max(axis=0)
    assert (swing < 0.25 * MACHINE.velocity_resolution_mm_s).all()


def test_constant_force_deflects_the_compliance_by_f_over_k():
    force = 400.0
    rec = _standing_run(lambda t: np.where(t > 0.1, force, 0.0), MACHINE)
    k = np.array([a.compliance_stiffness_n_mm for a in MACHINE.axes])
    np.testing.assert_allclose(rec.deflection_mm[0, -1], -force / k, rtol=1e-6)
    np.testing.assert_allclose(rec.pos_mm[0, -1], 150.0, atol=2e-4)  # the servo holds the slide


def test_recorded_velocity_is_the_mean_over_the_record_period():
    """Without noise and quanta the recorded velocity is the encoder's position difference over
    the record period; at constant velocity it is that velocity."""
    exact = drives.FeedDriveMachine(velocity_noise_mm_s=0.0, velocity_resolution_mm_s=0.0,
                                    position_resolution_mm=0.0)  # fmt: skip
    n = int(1.0 * exact.servo_rate_hz)
    t = np.arange(n) / exact.servo_rate_hz
    pos = np.repeat((150.0 + 5.0 * np.sin(2 * np.pi * 3.0 * t))[None, :, None], 3, axis=2)
    vel = np.gradient(pos, t, axis=1)
    rec = drives.simulate_drives(pos, vel, np.gradient(vel, t, axis=1), np.zeros_like(pos),
                                 exact, np.random.default_rng(3))  # fmt: skip
    period = 1.0 / exact.record_rate_hz
    np.testing.assert_allclose(rec.vel_mm_s[0, 1:], np.diff(rec.pos_mm[0], axis=0) / period,
                               rtol=0, atol=1e-9)  # fmt: skip
    v = 4.0
    start = drives.FeedDriveMachine(velocity_noise_mm_s=0.0, velocity_resolution_mm_s=0.0)
    rec = drives.simulate_drives(150.0 + v * t[None, :, None] + 0 * pos, np.full_like(pos, v),
                                 np.zeros_like(pos), np.zeros_like(pos), start,
                                 np.random.default_rng(4))  # fmt: skip
    assert np.abs(rec.vel_mm_s[0, -50:] - v).max() < 0.05  # cogging ripple only
