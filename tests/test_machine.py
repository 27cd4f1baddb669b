"""Machine profiles: shipped files load, bad values are named with their range."""

from __future__ import annotations

import dataclasses
import math

import pytest

from nctwin.machine import DEFAULT_MACHINE, MachineProfile, available_machines, load_machine


def _profile(**changes) -> MachineProfile:
    base = {
        "name": "test",
        "description": "test machine",
        "axis_max_velocity_mm_s": (100.0, 100.0, 50.0),
        "axis_max_acceleration_mm_s2": (1000.0, 1000.0, 500.0),
        "axis_max_jerk_mm_s3": (1e5, 1e5, 5e4),
        "rapid_feed_mm_s": 500.0,
        "max_feed_mm_s": 1000.0,
    }
    return MachineProfile(**{**base, **changes})


def test_shipped_profiles_load():
    names = available_machines()
    assert DEFAULT_MACHINE in names and "linuxcnc_sim" in names
    for name in names:
        m = load_machine(name)
        assert m.name == name
        assert m.period_s > 0


def test_linuxcnc_sim_has_the_fixed_limits():
    m = load_machine("linuxcnc_sim")
    assert m.axis_max_velocity_mm_s == (200.0, 200.0, 100.0)
    assert m.axis_max_acceleration_mm_s2 == (1000.0, 1000.0, 500.0)
    assert all(math.isinf(j) for j in m.axis_max_jerk_mm_s3)
    assert m.blend_tol_mm == pytest.approx(0.0254)


def test_profile_is_frozen():
    m = _profile()
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.period_s = 0.002


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("rapid_feed_mm_s", -1.0, "rapid_feed_mm_s = -1.0 is out of range: allowed (0, inf)"),
        ("period_s", 0.0, "period_s = 0.0 is out of range: allowed (0, 0.1]"),
        ("period_s", float("nan"), "period_s = nan is out of range"),
        ("blend_tol_mm", -0.1, "blend_tol_mm = -0.1 is out of range: allowed [0, 10]"),
        ("axis_max_velocity_mm_s", (1.0, 0.0, 1.0), "axis_max_velocity_mm_s[Y] = 0.0"),
        ("axis_max_velocity_mm_s", (1.0, 2.0), "must be three numbers"),
        ("axis_max_velocity_mm_s", (1.0, float("inf"), 1.0), "axis_max_velocity_mm_s[Y] = inf"),
        ("max_feed_mm_s", "fast", "max_feed_mm_s = 'fast' is out of range"),
    ],
)
def test_bad_values_name_field_value_and_range(field, value, message):
    with pytest.raises(ValueError) as info:
        _profile(**{field: value})
    assert message in str(info.value)


def test_jerk_may_be_unlimited():
    assert math.isinf(_profile(axis_max_jerk_mm_s3=(math.inf,) * 3).axis_max_jerk_mm_s3[0])


def test_toml_errors(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('description = "x"\nrapid_feed_mm_s = 100\nwarp_factor = 9\n')
    with pytest.raises(ValueError, match=r"unknown field.*warp_factor"):
        load_machine(bad)
    missing = tmp_path / "missing.toml"
    missing.write_text('description = "x"\n')
    with pytest.raises(ValueError, match="missing"):
        load_machine(missing)
    broken = tmp_path / "broken.toml"
    broken.write_text("this is = = not toml")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_machine(broken)
    with pytest.raises(ValueError, match="machine = 'nope' is unknown: allowed"):
        load_machine("nope")


def test_a_profile_missing_keys_names_them(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text('description = "x"\nrapid_feed_mm_s = 100.0\n')
    with pytest.raises(ValueError, match=r"bad.toml: missing field\(s\) axis_max_velocity_mm_s"):
        load_machine(p)


def test_fir_settings_live_apart_from_the_profile():
    from nctwin.kernel.fir import FirSettings

    assert FirSettings.load("paper1_sim") == FirSettings(t1_s=0.08, t2_s=0.02)
    assert FirSettings.load("fanuc_0i_testbed") == FirSettings()  # no [fir] table
    with pytest.raises(ValueError, match=r"blend_ratio = 2.0 is out of range: allowed \(0, 1\]"):
        FirSettings(blend_ratio=2.0)
    with pytest.raises(ValueError, match=r"block_periods = 1.5 is out of range"):
        FirSettings(block_periods=1.5)
