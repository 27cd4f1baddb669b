"""The chapter "Predicting a real controller" (nctwin.chapters.linuxcnc, nctwin.estimate.learned,
nctwin.identify): moves, features and LinuxCNC's rules, checked on programs small enough to work
out by hand."""

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from nctwin import identify
from nctwin.chapters import linuxcnc as rk
from nctwin.estimate import estimate, learned
from nctwin.estimate.blend_planner import blend_planner
from nctwin.estimate.block_overlap import block_overlap
from nctwin.gcode import parse
from nctwin.machine import load_profile
from nctwin.recordings import RecordedProgram
from nctwin.targets import BlockTargets

PROFILE = load_profile("linuxcnc_sim")
MACHINE = PROFILE.machine  # X/Y 200 mm/s 1000 mm/s^2, Z 100 mm/s 500 mm/s^2
PLANNER = PROFILE.control("planner")  # 1 ms, a plain G64 where a program sets none


def col(name: str) -> int:
    return learned.FEATURES.index(name)


def test_arc_becomes_chords_on_the_arc():
    # a quarter circle of radius 10 mm: 1.571 rad, 15.7 mm -> 16 chords of at most 1 mm
    tp = parse("G21 G90 G17\nG1 X10 F600\nG3 X0 Y10 I-10 J0\nG1 X-5\n", start_mm=(0, 0, 0))
    moves, source = learned.model_blocks(tp)
    pieces = math.ceil(
        max(math.pi / 2 / learned.ARC_CHORD_RAD, 10 * math.pi / 2 / learned.ARC_CHORD_MM)
    )
    assert len(moves) == 2 + pieces
    assert (moves.kind == 1).all()  # all linear
    np.testing.assert_array_equal(source, [0] + [1] * pieces + [2])
    ends = moves.end_mm[1 : 1 + pieces]
    np.testing.assert_allclose(np.hypot(ends[:, 0], ends[:, 1]), 10.0, atol=1e-9)
    np.testing.assert_allclose(moves.end_mm[pieces], [0, 10, 0], atol=1e-9)
    # chords are continuous and the lines keep their programmed points exactly
    np.testing.assert_allclose(moves.start_mm[1:], moves.end_mm[:-1], atol=1e-9)
    np.testing.assert_array_equal(moves.end_mm[0], [10, 0, 0])


def test_dwells_and_zero_moves_are_not_moves():
    tp = parse("G21 G90\nG1 X10 F600\nG4 P0.5\nG1 X10\nG1 X20\n", start_mm=(0, 0, 0))
    data = learned.move_data("p", tp, MACHINE, PLANNER)
    assert len(data.moves) == 2
    assert data.dwell_s == 0.5


def test_feed_is_clipped_to_axes_and_control():
    # X at F 30000 mm/min (500 mm/s) -> 200; Z alone at 150 mm/s -> Z's 100; rapid -> 200
    tp = parse("G21 G90\nG1 X10 F30000\nG1 Z10 F9000\nG0 X0\n", start_mm=(0, 0, 0))
    x = learned.features(learned.model_blocks(tp)[0], MACHINE, PLANNER)
    np.testing.assert_allclose(x[:, col("feed_mm_s")], [200.0, 100.0, 200.0])


def test_path_acceleration_along_the_move():
    tp = parse("G21 G90\nG1 X10 F600\nG1 X20 Y10\nG1 Z10\n", start_mm=(0, 0, 0))
    acc = learned.features(learned.model_blocks(tp)[0], MACHINE, PLANNER)[:, col("acc_mm_s2")]
    np.testing.assert_allclose(acc, [1000.0, 1000.0 * math.sqrt(2), 500.0])


@pytest.mark.parametrize(
    ("g64", "tol", "naive"),
    [
        ("", learned.TOL_CAP_MM, 0.0),  # LinuxCNC runs the start-up mode as a plain G64
        ("G64 P0.1", 0.1, 0.1),  # P without Q: Q = P
        ("G64 P0.1 Q0", 0.1, 0.0),
        ("G64 P0.1 Q0.01", 0.1, 0.01),
        ("G64", learned.TOL_CAP_MM, 0.0),  # no tolerance
        ("G61", 0.0, 0.0),
    ],
)
def test_linuxcnc_tolerance_rules(g64, tol, naive):
    tp = parse(f"G21 G90\n{g64}\nG1 X10 F600\nG1 Y10\n", start_mm=(0, 0, 0))
    x = learned.features(learned.model_blocks(tp)[0], MACHINE, PLANNER)
    np.testing.assert_allclose(x[:, col("tol_mm")], tol)
    np.testing.assert_allclose(x[:, col("naive_tol_mm")], naive)


def test_targets_from_block_targets():
    # two lines of 10 mm at 10 mm/s: measured 1.5 s and 1.25 s over 9.9 and 10 mm
    tp = parse("G21 G90\nG1 X10 F600\nG1 Y10\n", start_mm=(0, 0, 0))
    bt = BlockTargets(np.array([0, 1500, 2750]), np.array([9.9, 10.0]), np.array([1.5, 1.25]))
    d = learned.move_data("p", tp, MACHINE, PLANNER, bt)
    np.testing.assert_allclose(d.targets[:, 0], [9.9 / 1.5, 10 / 1.25])
    np.testing.assert_allclose(d.targets[:, 1], np.log([1.5, 1.25]))  # ln(F t / l)
    np.testing.assert_allclose(d.axis_targets, [[9.9 / 1.5, 0, 0], [0, 8.0, 0]])
    assert d.measured_s == 2.75


def test_block_overlap_constants_from_acceleration():
    # main cutting feed 100 mm/s (the longer cut) -> A_T = 100 / 1000 = 0.1 s; A_TR = 0.2 s
    tp = parse("G21 G90\nG1 X100 F6000\nG1 Y10 F1200\n", start_mm=(0, 0, 0))
    m = identify.identified_block_overlap(tp, MACHINE, 0.001)
    assert m.cut_time_constant_s == pytest.approx(0.1)
    assert m.rapid_time_constant_s == pytest.approx(0.2)
    assert m.inposition_time_s == (0.0, 0.0, 0.0)
    # a single line: L/F + A_T, LinuxCNC's L/F + F/A
    line = parse("G21 G90\nG1 X100 F6000\n", start_mm=(0, 0, 0))
    lee = identify.identified_block_overlap(line, MACHINE, 0.001)
    assert block_overlap(line, MACHINE, lee).cycle_time_s == pytest.approx(1.0 + 0.1)


def test_learned_methods_need_recordings():
    tp = parse("G21 G90\nG1 X10 F600\n", start_mm=(0, 0, 0))
    with pytest.raises(ValueError, match=r"paper1_sim has no \[control.planner\] table"):
        estimate(tp, load_profile("paper1_sim"), "bilstm")
    no_recordings = dataclasses.replace(PROFILE, recordings=None)
    with pytest.raises(ValueError, match="recordings = None of machine profile linuxcnc_sim"):
        learned.training_data(no_recordings)


def _recording(name: str, program: str, time_s: float, source: str = "nctwin") -> RecordedProgram:
    targets = BlockTargets(
        np.array([0, round(time_s / 0.001)]), np.array([60.0]), np.array([time_s])
    )
    return RecordedProgram(name, program, PROFILE.name, targets, np.zeros(1), 0, "", "", source)


def test_planner_ablation_on_recordings_by_hand():
    # G61: 60/50 + 50/1000 = 1.25 s; plain G64, last move at a/2: 60/50 + 50/500 = 1.3 s
    recs = {
        "train_a": _recording("train_a", "G21 G90 G61\nG1 X60 F3000\n", 1.25),
        "broad_b": _recording("broad_b", "G21 G90 G64\nG1 X60 F3000\n", 1.3 * 1.04),
    }
    programs = {n: (n.split("_")[0], parse(r.program), r.cycle_time_s) for n, r in recs.items()}
    rows = rk.planner_ablation(programs, PROFILE)
    rows = rows[rows.rules == "all"]
    assert list(rows.set) == ["train", "broad"]
    assert list(rows["mode"]) == ["G61", "G64"]
    np.testing.assert_allclose(rows.predicted_s, [1.25, 1.3])
    np.testing.assert_allclose(rows.err_pct, [0.0, 100 * (1 / 1.04 - 1)])
    summary = rk.method_summary(rows, by=["mode"])
    assert list(summary.underestimates) == [0, 1]
    gaps = rk.planner_block_gaps(recs["broad_b"], PROFILE, n=1)
    assert gaps.block.tolist() == [0] and gaps.kind.tolist() == ["linear"]
    assert gaps.planner_s.iloc[0] == pytest.approx(1.3)
    with pytest.raises(ValueError, match="n = 0"):
        rk.planner_block_gaps(recs["broad_b"], PROFILE, n=0)


@pytest.mark.parametrize(
    ("program", "mode"),
    [
        ("G1 X1 F600\n", "G64"),  # the startup mode: LinuxCNC runs a plain G64
        ("G64 P0.1\nG1 X1 F600\n", "G64 P Q>0"),  # Q = P
        ("G64 P0.1 Q0\nG1 X1 F600\nG64\nG1 X2\nG61\nG1 X3\nG61.1\nG1 X4\n",
         "G64 P Q0, G64, G61, G61.1"),
    ],
)  # fmt: skip
def test_path_control_follows_linuxcnc(program, mode):
    assert rk.path_control(parse("G21 G90\n" + program), PROFILE) == mode


def test_planner_block_gaps_need_the_program_text():
    rec = _recording("public_x", "", 1.0, source="public/x.ngc")
    with pytest.raises(ValueError, match=r"source = 'public/x\.ngc'"):
        rk.planner_block_gaps(rec, PROFILE)


def test_planner_ablation_by_hand():
    # G61, two lines with a 0.001 rad kink at 60 mm/s: tangent with the kink rule, a stop at
    # full acceleration without it (the sizes of blend arcs do not matter: there are none)
    tp = parse("G21 G90 G61\nG1 X10 F3600\nX20 Y0.01\n", start_mm=(0, 0, 0))
    rows = rk.planner_ablation({"kink": ("test", tp, 1.0)}, PROFILE)
    assert list(rows.rules) == list(rk.PLANNER_RULES)
    t = dict(zip(rows.rules, rows.predicted_s, strict=True))
    stop = 2 * (10 / 60 + 60 / 1000)  # two trapezoids from rest to rest (L/F + F/a)
    assert t["as first written"] == pytest.approx(stop, rel=1e-5)
    assert t["no kinks"] == pytest.approx(2 * 0.227)  # each on a whole period
    assert t["all"] == t["largest arcs"] < stop - 0.05
    assert t["stops off periods"] < t["all"]
    np.testing.assert_allclose(rows.err_pct, 100 * (rows.predicted_s - 1.0))


def test_fit_planner_recovers_the_limits_that_made_the_times():
    # "recordings" made by the planner itself on a machine with other limits: moves that need
    # every axis's acceleration (short moves) and velocity (rapids along one axis, fast Z)
    truth = dataclasses.replace(
        MACHINE,
        axis_max_acceleration_mm_s2=(800.0, 1200.0, 300.0),
        axis_max_velocity_mm_s=(150.0, 180.0, 60.0),
    )
    texts = [
        "G21 G90 G61\nG1 X5 F6000\nG1 X10\nG1 X0 Y0\n",
        "G21 G90 G61\nG1 Y5 F6000\nG1 Y10\nG1 X3 Y0\n",
        "G21 G90 G61\nG1 Z2 F6000\nG1 Z4\nG1 Z0\n",
        "G21 G90\nG0 X200\nG0 X0\n",
        "G21 G90\nG0 Y200\nG0 Y0\n",
        "G21 G90\nG1 Z100 F12000\nG1 Z0\n",
        "G21 G90 G64 P0.1\nG1 X20 Y20 Z5 F3000\nG1 X40 Y0 Z0\nG1 X0 Y-20 Z5\n",
    ]
    programs = []
    for text in texts:
        tp = parse(text, start_mm=(0, 0, 0))
        programs.append((tp, blend_planner(tp, truth, PLANNER).cycle_time_s))
    fit = identify.fit_planner(programs, MACHINE, PLANNER)
    # the "recordings" stop on whole 1 ms periods, the fit plans half a period per stop: the
    # limits come back within a few tenths of a percent
    np.testing.assert_allclose(fit.machine.axis_max_acceleration_mm_s2, (800, 1200, 300), rtol=5e-3)
    np.testing.assert_allclose(fit.machine.axis_max_velocity_mm_s, (150, 180, 60), rtol=5e-3)
    assert fit.max_err_pct < 0.5
    assert list(fit.limits.profile) == [1000, 1000, 500, 200, 200, 100]


def test_fit_planner_with_fixed_velocities_recovers_the_accelerations():
    # the velocities known (a real machine's rapid plateaus), only the accelerations are fitted;
    # two programs run at a 50 % rapid override: their axis velocities and rapid feed halve
    truth = dataclasses.replace(MACHINE, axis_max_acceleration_mm_s2=(800.0, 1200.0, 300.0))
    texts = [
        "G21 G90 G61\nG1 X5 F6000\nG1 X10\nG1 X0 Y0\n",
        "G21 G90 G61\nG1 Y5 F6000\nG1 Y10\nG1 X3 Y0\n",
        "G21 G90 G61\nG1 Z2 F6000\nG1 Z4\nG1 Z0\n",
        "G21 G90\nG0 X200\nG0 Y0\n",
        "G21 G90\nG0 Z50\nG0 Z0\n",
    ]
    overrides = [1.0, 1.0, 1.0, 0.5, 0.5]
    programs = []
    for text, k in zip(texts, overrides, strict=True):
        tp = parse(text, start_mm=(0, 0, 0))
        run_on = dataclasses.replace(
            truth,
            axis_max_velocity_mm_s=tuple(v * k for v in truth.axis_max_velocity_mm_s),
            rapid_feed_mm_s=truth.rapid_feed_mm_s * k,
        )
        programs.append((tp, blend_planner(tp, run_on, PLANNER).cycle_time_s))
    fit = identify.fit_planner(
        programs, MACHINE, PLANNER, fit_velocities=False, rapid_overrides=overrides
    )
    np.testing.assert_allclose(fit.machine.axis_max_acceleration_mm_s2, (800, 1200, 300), rtol=5e-3)
    assert fit.machine.axis_max_velocity_mm_s == MACHINE.axis_max_velocity_mm_s
    velocity = fit.limits[fit.limits.limit == "velocity_mm_s"]
    assert list(velocity.start) == list(velocity.fitted) == list(MACHINE.axis_max_velocity_mm_s)
    assert fit.max_err_pct < 0.5
    with pytest.raises(ValueError, match="allowed one per program, in"):
        identify.fit_planner(programs, MACHINE, PLANNER, rapid_overrides=[1.0, 57.0])


def test_fit_planner_rejects_bad_input():
    tp = parse("G21 G90\nG1 X10 F600\n", start_mm=(0, 0, 0))
    with pytest.raises(ValueError, match="programs is empty"):
        identify.fit_planner([], MACHINE, PLANNER)
    with pytest.raises(ValueError, match="allowed > 0"):
        identify.fit_planner([(tp, 0.0)], MACHINE, PLANNER)
    with pytest.raises(ValueError, match=r"start = \(500.0, 400.0\) is out of range"):
        identify.fit_planner([(tp, 1.0)], MACHINE, PLANNER, start=(500.0, 400.0))


def test_planner_numbers_by_hand():
    rows = pd.DataFrame(
        [(p, s, m, r, e) for p, s, m, errs in (
            ("train_1", "train", "G64 P Q0", (0.1, 0.1, 0.1, 0.1, 0.1)),
            ("broad_1", "broad", "G64", (-2.0, 0.0, 0.0, 0.0, 0.0)),
            ("cam_1", "cam", "G61", (0.2, 60.0, 0.2, 0.4, 0.3)),
            ("cam_2", "cam", "G64", (-0.4, 0.1, -20.0, 0.8, 0.5)),
            ("contour", "public", "G64", (9.0, 9.0, 9.0, 9.0, 9.0)),
        ) for r, e in zip(("all", "no kinks", "largest arcs", "stops off periods",
                           "blend arcs at the smaller feed"), errs, strict=True)],
        columns=["program", "set", "mode", "rules", "err_pct"],
    )  # fmt: skip
    limits = pd.DataFrame(
        {"axis": ["X", "Y", "X", "Y"],
         "limit": ["acceleration_mm_s2"] * 2 + ["velocity_mm_s"] * 2,
         "start": [500.0, 500.0, 100.0, 100.0], "fitted": [990.0, 1020.0, 190.0, 180.0],
         "profile": [1000.0, 1000.0, 200.0, 200.0]}
    )  # fmt: skip
    n = rk.planner_numbers(rows, limits)
    # the public program is not one of nctwin's own; the worst of the rest is broad_1's -2 %
    assert n["own_n"] == 4 and n["own_worst"] == 2.0 and n["own_worst_signed"] == -2.0
    assert n["own_worst_program"] == "broad_1"
    assert n["own_cam_median"] == pytest.approx(0.3) and n["own_cam_worst"] == 0.4
    assert n["no_kinks_g61_worst"] == 60.0 and n["largest_arcs_g64_worst"] == 20.0
    assert n["all_cam_median"] == pytest.approx(0.3)
    assert n["stops_off_cam_median"] == pytest.approx(0.6)
    assert n["smaller_feed_cam_median"] == pytest.approx(0.4)
    assert n["fit_Y_acc_fitted"] == 1020.0 and n["fit_X_vel_start"] == 100.0
    assert n["fit_acc_worst_pct"] == pytest.approx(2.0)  # Y: 1020 for 1000
