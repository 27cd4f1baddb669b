"""Machine profiles: the machine apart from its controls, one home for each setting, shipped
files that load, bad values and keys named with the file, the table and the range."""

from __future__ import annotations

import dataclasses
import datetime
import math
import shutil
import tomllib
from pathlib import Path

import pandas as pd
import pytest

from nctwin.controls import CONTROLS, AccDecControl, FanucControl, FirControl, PlannerControl
from nctwin.machine import (
    DEFAULT_MACHINE,
    METHOD_CONTROLS,
    Machine,
    Profile,
    available_machines,
    load_machine,
    load_profile,
    profile_path,
    write_control,
)

RESULTS = Path(__file__).resolve().parents[1] / "results"
TODAY = datetime.date(2026, 1, 2)


def _machine(**changes) -> Machine:
    base = {
        "name": "test",
        "description": "test machine",
        "axis_max_velocity_mm_s": (100.0, 100.0, 50.0),
        "axis_max_acceleration_mm_s2": (1000.0, 1000.0, 500.0),
        "axis_max_jerk_mm_s3": (1e5, 1e5, 5e4),
        "rapid_feed_mm_s": 500.0,
        "max_feed_mm_s": 1000.0,
    }
    return Machine(**{**base, **changes})


def test_shipped_profiles_load():
    names = available_machines()
    assert DEFAULT_MACHINE in names and "linuxcnc_sim" in names
    for name in names:
        p = load_profile(name)
        assert p.name == name == load_machine(name).name
        assert p.controls, f"{name} describes no control"
        # its default method runs on a control it has
        assert p.control_for(p.default_method) is None or p.default_method in METHOD_CONTROLS


def test_linuxcnc_sim_has_the_fixed_limits():
    p = load_profile("linuxcnc_sim")
    m = p.machine
    assert m.axis_max_velocity_mm_s == (200.0, 200.0, 100.0)
    assert m.axis_max_acceleration_mm_s2 == (1000.0, 1000.0, 500.0)
    assert all(math.isinf(j) for j in m.axis_max_jerk_mm_s3)
    assert p.control("planner") == PlannerControl(
        period_s=0.001,
        blend_tol_mm=math.inf,  # LinuxCNC runs the startup mode as a plain G64
        word_stops=True,
        dwell_wait_s=0.003,
        spindle_wait_s=0.004,
        coolant_wait_s=0.12,
        tool_change_wait_s=0.276,
        offset_wait_s=0.0025,
    )
    assert p.default_method == "planner" and p.recordings == "linuxcnc"


def test_linuxcnc_sim_holds_the_chapters_fir_fit():
    """The profile's [control.fir] is what `nctwin calibrate` wrote: the best row of the grid
    search the chapter "Predicting a real controller" ran on the same recordings."""
    best = pd.read_csv(RESULTS / "linuxcnc_real_kernel" / "fir_fit.csv").iloc[0]
    fir = load_profile("linuxcnc_sim").control("fir")
    assert (fir.t1_s, fir.t2_s, fir.acc_scale, fir.blend_ratio, fir.block_periods) == (
        best.fir_t1_s, best.fir_t2_s, best.fir_acc_scale, best.fir_blend_ratio,
        best.fir_block_periods,
    )  # fmt: skip


def test_the_chapters_best_method_is_linuxcnc_sims_default():
    from nctwin.estimate import best_method

    summary = pd.read_csv(RESULTS / "linuxcnc_real_kernel" / "summary.csv")
    assert best_method(summary) == load_profile("linuxcnc_sim").default_method


def test_no_setting_is_both_the_machines_and_a_controls():
    machine = {f.name for f in dataclasses.fields(Machine)}
    for kind, cls in CONTROLS.items():
        shared = machine & {f.name for f in dataclasses.fields(cls)}
        assert not shared, f"[machine] and [control.{kind}] both have {shared}"
    for name in available_machines():
        data = tomllib.loads(profile_path(name).read_text())
        for kind, table in data.get("control", {}).items():
            assert not set(table) & set(data["machine"]), (name, kind)


def test_machine_and_controls_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        _machine().max_feed_mm_s = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        FirControl().period_s = 0.002


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("rapid_feed_mm_s", -1.0, "rapid_feed_mm_s = -1.0 is out of range: allowed (0, inf)"),
        ("axis_max_velocity_mm_s", (1.0, 0.0, 1.0), "axis_max_velocity_mm_s[Y] = 0.0"),
        ("axis_max_velocity_mm_s", (1.0, 2.0), "allowed three numbers"),
        ("axis_max_velocity_mm_s", (1.0, float("inf"), 1.0), "axis_max_velocity_mm_s[Y] = inf"),
        ("max_feed_mm_s", "fast", "max_feed_mm_s = 'fast' is out of range"),
        ("name", "", "name = '' is out of range"),
    ],
)
def test_bad_machine_values_name_field_value_and_range(field, value, message):
    with pytest.raises(ValueError) as info:
        _machine(**{field: value})
    assert message in str(info.value)


@pytest.mark.parametrize(
    ("cls", "changes", "message"),
    [
        (FirControl, {"period_s": 0.0}, "period_s = 0.0 is out of range: allowed (0, 0.1]"),
        (FirControl, {"period_s": math.nan}, "period_s = nan is out of range"),
        (
            FirControl,
            {"blend_tol_mm": -0.1},
            "blend_tol_mm = -0.1 is out of range: allowed [0, 10]",
        ),
        (FirControl, {"blend_ratio": 2.0}, "blend_ratio = 2.0 is out of range: allowed (0, 1]"),
        (FirControl, {"block_periods": 1.5}, "block_periods = 1.5 is out of range"),
        (FirControl, {"t1_s": 0.0, "t2_s": 0.0}, "t1_s = 0.0 is out of range: allowed [period_s"),
        (AccDecControl, {"rapid_type": "curved"}, "rapid_type = 'curved' is out of range"),
        (AccDecControl, {"inposition_time_s": (0.0, -1.0, 0.0)}, "inposition_time_s[Y] = -1.0"),
        (FanucControl, {"cut_time_constant_s": 0.0505}, "allowed whole multiples of period_s"),
        (FanucControl, {"servo": "pid"}, "servo = 'pid' is out of range"),
        (PlannerControl, {"blend_tol_mm": 11.0}, "blend_tol_mm = 11.0 is out of range"),
    ],
)
def test_bad_control_values_name_field_value_and_range(cls, changes, message):
    with pytest.raises(ValueError) as info:
        cls(**changes)
    assert message in str(info.value)


def test_jerk_may_be_unlimited():
    assert math.isinf(_machine(axis_max_jerk_mm_s3=(math.inf,) * 3).axis_max_jerk_mm_s3[0])


def _copy(tmp_path: Path, name: str, new: str = "my_mill") -> Path:
    out = tmp_path / f"{new}.toml"
    shutil.copy(profile_path(name), out)
    return out


@pytest.mark.parametrize("name", available_machines())
def test_a_copy_under_another_name_is_the_same_profile(tmp_path, name):
    assert load_profile(_copy(tmp_path, name)) == load_profile(name)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("[machine]", "[machine]\nwarp_factor = 9"),
            r"my_mill.toml: \[machine\] unknown key.*warp_factor",
        ),
        (
            ("[control.fir]", "[control.fir]\nt3_s = 0.1"),
            r"my_mill.toml: \[control.fir\] unknown key.*t3_s",
        ),
        (("[control.fir]", "[control.firr]"), r"my_mill.toml: \[control\] unknown key.*firr"),
        (("default_method", "defualt_method"), r"my_mill.toml: unknown key.*defualt_method"),
        (("t1_s = 0.06", "t1_s = -1"), r"my_mill.toml: \[control.fir\] t1_s = -1 is out of range"),
        (
            ('default_method = "cam"', 'default_method = "fast"'),
            r"default_method = 'fast' is out of",
        ),
        (("[machine]", "[mach]"), r"my_mill.toml: unknown key.*mach"),
    ],
)
def test_bad_keys_are_refused_with_file_table_and_key(tmp_path, edit, message):
    p = _copy(tmp_path, "generic_mill")
    p.write_text(p.read_text().replace(*edit, 1))
    with pytest.raises(ValueError, match=message):
        load_profile(p)


def test_toml_errors(tmp_path):
    missing = tmp_path / "missing.toml"
    missing.write_text('[machine]\ndescription = "x"\n')
    with pytest.raises(ValueError, match=r"missing.toml: \[machine\] missing key\(s\) axis_max_"):
        load_profile(missing)
    broken = tmp_path / "broken.toml"
    broken.write_text("this is = = not toml")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_profile(broken)
    with pytest.raises(ValueError, match="machine = 'nope' is unknown: allowed"):
        load_profile("nope")
    with pytest.raises(ValueError, match=r"cannot read machine profile .*absent\.toml"):
        load_profile(tmp_path / "absent.toml")
    no_machine = tmp_path / "no_machine.toml"
    no_machine.write_text('default_method = "cam"\n')
    with pytest.raises(ValueError, match=r"no_machine.toml: no \[machine\] table"):
        load_profile(no_machine)


def test_a_method_needs_its_control():
    p = load_profile("paper1_sim")
    assert p.control_for("cam") is None
    assert p.control_for("kernel") == FirControl(blend_tol_mm=0.4, t1_s=0.16, t2_s=0.02)
    with pytest.raises(
        ValueError,
        match=r"method 'planner' needs a control: .*paper1_sim has no "
        r"\[control.planner\] table \(it has \[control.fir\]\)",
    ):
        p.control_for("planner")
    with pytest.raises(ValueError, match="method = 'magic' is unknown"):
        p.control_for("magic")


def test_write_control_replaces_the_table_and_keeps_the_rest(tmp_path):
    p = _copy(tmp_path, "generic_mill")
    before = p.read_text()
    fitted = FirControl(period_s=0.001, blend_tol_mm=0.05, t1_s=0.045, t2_s=0.003, acc_scale=4.0,
                        blend_ratio=0.25)  # fmt: skip
    write_control(p, "fir", fitted, ["Fitted to nothing, for a test."], today=TODAY)
    after = p.read_text()
    assert "# Fitted to nothing, for a test.\n# Written by nctwin on 2026-01-02.\n" in after
    assert "nctwin's FIR interpolator on this machine" not in after  # the old table's comment
    assert "[control.accdec]" in after and "# LinuxCNC's planning rules" in after
    loaded, original = load_profile(p), load_profile(profile_path("generic_mill"))
    assert loaded.fir == fitted
    assert dataclasses.replace(loaded, fir=original.fir) == original
    write_control(p, "fir", fitted, ["Fitted to nothing, for a test."], today=TODAY)
    assert p.read_text() == after  # written twice, the same file
    assert before.count("[control.fir]") == after.count("[control.fir]") == 1


def test_write_control_appends_a_missing_table_and_refuses_a_wrong_one(tmp_path):
    p = _copy(tmp_path, "paper1_sim")
    write_control(p, "planner", PlannerControl(blend_tol_mm=0.4), ["By hand."], today=TODAY)
    assert load_profile(p).planner == PlannerControl(blend_tol_mm=0.4)
    text = p.read_text()
    with pytest.raises(ValueError, match="allowed a fir control"):
        write_control(p, "fir", PlannerControl(), ["x"], today=TODAY)
    assert p.read_text() == text


def test_a_profile_refuses_a_default_method_without_its_control():
    machine = load_machine("paper1_sim")
    with pytest.raises(
        ValueError, match="default_method = 'planner' is out of range: allowed cam, kernel"
    ):
        Profile(machine, fir=FirControl(), default_method="planner")


def test_best_method_passes_over_rows_a_profile_cannot_name():
    from nctwin.estimate import best_method

    summary = pd.DataFrame(
        {"set": ["public", "public", "public", "test paths"],
         "method": ["planner_fitted", "planner", "cam", "cam"],
         "median_abs_err_pct": [0.03, 0.04, 9.0, 0.0], "worst_abs_err_pct": [1.0, 1.0, 20.0, 0.0]}
    )  # fmt: skip
    assert best_method(summary) == "planner"
    # no public program: the test paths decide
    assert best_method(summary[summary.set == "test paths"]) == "cam"
