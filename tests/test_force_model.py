"""The paper's four fitting steps recover the parameters they were generated with when the truth
has the model's own form."""

import numpy as np
import pytest

from nctwin.methods import denkena2020 as fm


def test_friction_fit_recovers_its_own_parameters():
    truth = fm.StribeckParams(coulomb_n=120.0, breakaway_n=170.0, stribeck_mm_s=1.5,
                              viscous_n_s_mm=1.2)  # fmt: skip
    v = np.geomspace(0.05, 150.0, 40)
    v = np.concatenate([v, -v])
    fit = fm.fit_stribeck(v, fm.stribeck_n(v, truth))
    assert fit.coulomb_n == pytest.approx(120.0, rel=1e-4)
    assert fit.breakaway_n == pytest.approx(170.0, rel=1e-4)
    assert fit.stribeck_mm_s == pytest.approx(1.5, rel=1e-3)
    assert fit.viscous_n_s_mm == pytest.approx(1.2, rel=1e-4)


def test_stribeck_curve_values():
    p = fm.StribeckParams(coulomb_n=100.0, breakaway_n=150.0, stribeck_mm_s=2.0,
                          viscous_n_s_mm=1.0)  # fmt: skip
    assert fm.stribeck_n(np.array([2.0]), p)[0] == pytest.approx(100 + 50 * np.exp(-1) + 2)
    assert fm.stribeck_n(np.array([-1e-9]), p)[0] == pytest.approx(-150.0, abs=1e-6)


def test_restoring_line_and_cogging_table():
    # ten whole cogging periods of a cosine from a pole edge: cogging and the line are
    # uncorrelated, so the regression line is the restoring line itself
    s = np.linspace(23.0, 253.0, 23001)
    cog = 30.0 * np.cos(2 * np.pi * s / 23.0)
    line = 0.25 * (s - 150.0)
    k, s_r, grid, table = fm.fit_restoring(s, line + cog + 140.0, s[::-1],
                                           (line + cog - 140.0)[::-1], bin_mm=0.25)  # fmt: skip
    assert k == pytest.approx(0.25, rel=1e-3)
    assert s_r == pytest.approx(150.0, abs=0.5)
    np.testing.assert_allclose(table, 30.0 * np.cos(2 * np.pi * grid / 23.0), atol=1.0)


def test_line_plus_table_is_the_position_force_whatever_the_phase():
    s = np.linspace(20.0, 280.0, 20001)
    position_force = 0.25 * (s - 150.0) + 30.0 * np.sin(2 * np.pi * s / 23.0 + 0.7)
    k, s_r, grid, table = fm.fit_restoring(s, position_force + 140.0, s[::-1],
                                           (position_force - 140.0)[::-1], bin_mm=0.25)  # fmt: skip
    expected = 0.25 * (grid - 150.0) + 30.0 * np.sin(2 * np.pi * grid / 23.0 + 0.7)
    np.testing.assert_allclose(k * (grid - s_r) + table, expected, atol=1.0)


def test_masses_from_the_stacked_sums():
    rng = np.random.default_rng(0)
    a = [rng.normal(0, 1000, 500) for _ in range(3)]
    m_x, m_y, m_z = 160.0, 260.0, 90.0
    moved = [m_x + m_z, m_x + m_y + m_z, m_z]
    forces = [m * ai * 1e-3 for m, ai in zip(moved, a, strict=True)]
    np.testing.assert_allclose(fm.fit_masses(forces, a), [m_x, m_y, m_z])


def test_bad_parameters_name_themselves():
    with pytest.raises(ValueError, match="stribeck_mm_s"):
        fm.StribeckParams(1.0, 2.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="bin_mm"):
        fm.fit_restoring(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), bin_mm=0.0)
