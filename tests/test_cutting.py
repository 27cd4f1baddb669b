"""Mechanistic milling forces against closed forms (Altintas 2012, eq. 2.27)."""

import numpy as np
import pytest

from nctwin.physics import cutting

TOOL = cutting.EndMill(runout_mm=0.0)
C = cutting.C45


def _average(ae_mm, mode, helix_deg=0.0, ap=3.0, fz=0.04, n=3000.0):
    tool = cutting.EndMill(helix_deg=helix_deg, runout_mm=0.0, disc_mm=0.05)
    phi_st, phi_ex = cutting.immersion(ae_mm, tool.radius_mm, mode)
    rev_s = 60.0 / n
    t = np.arange(20000) * (rev_s / 20000)  # one revolution, finely
    f, torque = cutting.tool_forces(
        t, spindle_rpm=n, feed_per_tooth_mm=fz, ap_mm=ap, phi_start_rad=phi_st,
        phi_exit_rad=phi_ex, tool=tool,
    )  # fmt: skip
    return f.mean(axis=0), torque.mean()


def test_slot_average_force_matches_closed_form():
    n_t, a, c = 4, 3.0, 0.04
    mean, torque = _average(10.0, "down")
    fx = -n_t * a * c * C.krc_n_mm2 / 4 - n_t * a * C.kre_n_mm / np.pi
    fy = n_t * a * c * C.ktc_n_mm2 / 4 + n_t * a * C.kte_n_mm / np.pi
    fz = n_t * a * C.kac_n_mm2 * c / np.pi + n_t * a * C.kae_n_mm / 2
    np.testing.assert_allclose(mean, [fx, fy, fz], rtol=2e-3)
    # mean torque: R * N/(2 pi) * integral of (Ktc c sin phi + Kte) a over [0, pi]
    expected = 5.0 * n_t / (2 * np.pi) * a * (2 * C.ktc_n_mm2 * c + np.pi * C.kte_n_mm)
    np.testing.assert_allclose(torque, expected, rtol=2e-3)


def test_helix_does_not_change_the_slot_average():
    straight, _ = _average(10.0, "down")
    helical, _ = _average(10.0, "down", helix_deg=36.5)
    np.testing.assert_allclose(helical, straight, rtol=5e-3)


def test_immersion_angles():
    assert cutting.immersion(5.0, 5.0, "up") == pytest.approx((0.0, np.pi / 2))
    assert cutting.immersion(5.0, 5.0, "down") == pytest.approx((np.pi / 2, np.pi))
    assert cutting.immersion(10.0, 5.0, "up") == pytest.approx((0.0, np.pi))
    st, ex = cutting.immersion(2.5, 5.0, "down")
    assert ex - st == pytest.approx(np.pi / 3)  # arccos(1 - 0.5)
    with pytest.raises(ValueError, match="ae_mm"):
        cutting.immersion(11.0, 5.0, "up")


def test_workpiece_force_is_the_rotated_reaction():
    f = np.array([[10.0, 20.0, 5.0]])
    np.testing.assert_allclose(cutting.workpiece_forces(f, np.array([0.0])), -f)
    rot = cutting.workpiece_forces(f, np.array([np.pi / 2]))
    np.testing.assert_allclose(rot, [[20.0, -10.0, -5.0]], atol=1e-12)


def test_runout_keeps_the_average_but_adds_a_spindle_period():
    t = np.arange(4000) / 40000.0  # 0.1 s at 3000 rpm: 5 revolutions
    kw = dict(spindle_rpm=3000.0, feed_per_tooth_mm=0.04, ap_mm=2.0, phi_start_rad=0.0,
              phi_exit_rad=np.pi)  # fmt: skip
    f0, _ = cutting.tool_forces(t, tool=TOOL, **kw)
    f1, _ = cutting.tool_forces(t, tool=cutting.EndMill(runout_mm=0.005, helix_deg=0.0), **kw)
    assert np.abs(f1[:, 1].mean() - f0[:, 1].mean()) < 0.02 * abs(f0[:, 1].mean())
    spectrum = np.abs(np.fft.rfft(f1[:, 1] - f1[:, 1].mean()))
    freqs = np.fft.rfftfreq(len(t), 1 / 40000.0)
    assert (
        spectrum[np.argmin(np.abs(freqs - 50.0))]
        > 10 * np.abs(np.fft.rfft(f0[:, 1] - f0[:, 1].mean()))[np.argmin(np.abs(freqs - 50.0))]
    )


def test_bad_parameters_name_themselves():
    with pytest.raises(ValueError, match="teeth"):
        cutting.EndMill(teeth=0)
    with pytest.raises(ValueError, match="spindle_rpm"):
        cutting.tool_forces(np.zeros(3), spindle_rpm=0.0, feed_per_tooth_mm=0.1, ap_mm=1.0,
                            phi_start_rad=0.0, phi_exit_rad=1.0, tool=TOOL)  # fmt: skip


def test_regenerative_chip_adds_to_the_chip_thickness():
    # h = (f_z + dx') sin(phi) + dy' cos(phi): a constant dx' is a larger feed per tooth
    t = np.arange(2000) / 40000.0
    kw = dict(spindle_rpm=3000.0, ap_mm=2.0, phi_start_rad=0.0, phi_exit_rad=np.pi, tool=TOOL)
    regen = np.zeros((len(t), 2))
    regen[:, 0] = 0.01
    f_regen, tq_regen = cutting.tool_forces(t, feed_per_tooth_mm=0.04, regeneration_mm=regen, **kw)
    f_feed, tq_feed = cutting.tool_forces(t, feed_per_tooth_mm=0.05, **kw)
    np.testing.assert_allclose(f_regen, f_feed, atol=1e-9)
    np.testing.assert_allclose(tq_regen, tq_feed, atol=1e-9)
    # a vibration normal to the feed at 22 Hz puts a 22 Hz line into the force normal to it
    t = np.arange(40000) / 40000.0
    y = 0.03 * np.sin(2 * np.pi * 22.0 * t)
    period = 60.0 / (4 * 3000.0)
    regen = np.stack([0 * t, y - 0.03 * np.sin(2 * np.pi * 22.0 * (t - period))], axis=1)
    lines = []
    for r in (None, regen):
        f, _ = cutting.tool_forces(t, feed_per_tooth_mm=0.04, regeneration_mm=r, **kw)
        lines.append(np.abs(np.fft.rfft(f[:, 1] - f[:, 1].mean()))[22] / len(t))
    assert lines[0] < 0.1 and lines[1] > 10.0
    with pytest.raises(ValueError, match="regeneration_mm"):
        cutting.tool_forces(t, feed_per_tooth_mm=0.04, regeneration_mm=regen[:10], **kw)
