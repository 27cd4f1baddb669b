"""The Denkena chapter's experiment design and scoring: semi-stability drawn independently of
the load, windows from the set points, RMSE per window by hand, the claims' reading."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import torch

from nctwin.chapters import denkena2020 as dk
from nctwin.chapters import denkena2020_calibration as cal
from nctwin.chapters import denkena2020_claims as dc
from nctwin.chapters.denkena2020_bench import _segment, chatter_regeneration_mm
from nctwin.physics import drives
from nctwin.report.claims import Claim
from nctwin.report.papers import load_paper_table

GRID = {k: sorted(g["value"].astype(float))
        for k, g in load_paper_table("denkena2020_table1").groupby("parameter")}  # fmt: skip


def test_segment_travels_its_length_at_its_speed() -> None:
    dt = 2e-4
    s = _segment(50.0, 10.0, dt)
    assert s[-1] == pytest.approx(50.0, abs=1e-9)
    v = np.diff(s) / dt
    assert v.max() == pytest.approx(10.0, rel=1e-9) and v.min() >= -1e-12
    # 5 s at speed, plus the filter's 60 + 15 ms (each box T/dt + 1 taps)
    assert len(s) - 1 == pytest.approx(5.0 / dt + 0.075 / dt + 2, abs=2)


def test_semi_stability_is_independent_of_the_load() -> None:
    procs = dk.design_processes(GRID, seed=0, duration_s=13.0, semi_stable_share=0.5)
    straight = pd.DataFrame([vars(p) for p in procs if p.kind in ("side", "groove")])
    load = straight.ap_mm * straight.ae_mm
    train = straight[~straight.test]
    semi = train.semi_stable
    assert semi.any() and (load[~straight.test][semi] < 12.0).any()  # light cuts too
    assert not any(p.semi_stable for p in procs if p.kind in ("pocket", "ramp"))
    test = straight[straight.test]
    # the paper's Fig. 8 case: semi-stable side cuts in -x, several of them, off the grid
    cases = test[test.semi_stable]
    assert len(cases) == 4 and (~test.semi_stable).sum() == 10
    assert set(cases.kind) == {"side"} and set(cases.feed_direction) == {"-x"}
    assert (cases.ae_mm < 10.0).all() and not cases.vf_mm_min.isin(GRID["vf_mm_min"]).any()
    lo, hi = dk.CHATTER_RATIO
    assert cases.chatter_hz.between(lo * dk.MODE_HZ, hi * dk.MODE_HZ).all()
    assert dk.MODE_HZ == pytest.approx(np.sqrt(947e3 / 60.0) / (2 * np.pi))
    assert sum(p.test for p in procs) == 21
    with pytest.raises(ValueError, match="semi_stable_share"):
        dk.design_processes(GRID, seed=0, duration_s=13.0, semi_stable_share=1.5)
    with pytest.raises(ValueError, match="semi_stable_test"):
        dk.design_processes(GRID, seed=0, duration_s=13.0, semi_stable_test=15)


def test_chatter_regenerates_the_chip_normal_to_the_feed() -> None:
    p = dk.Process(0, "side", "-x", 2.0, 1.0, 300.0, 3000.0, (0, 0, 0), True, 25.0, 0.04, True)
    t = np.array([0.0, 0.01, 0.2])
    regen = chatter_regeneration_mm(p, t)
    period = 60.0 / (4 * 3000.0)

    def y(s: float) -> float:
        return 0.04 * 0.5 * (1 + np.sin(2 * np.pi * 0.7 * s)) * np.sin(2 * np.pi * 25.0 * s)

    np.testing.assert_allclose(regen[:, 1], [y(s) - y(s - period) for s in t], atol=1e-15)
    assert (regen[:, 0] == 0).all()
    stable = dk.Process(0, "side", "-x", 2.0, 1.0, 300.0, 3000.0, (0, 0, 0), False, 0, 0, True)
    assert (chatter_regeneration_mm(stable, t) == 0).all()


def test_training_lies_on_the_grid_and_testing_off_it_with_the_paper_ramp() -> None:
    ramp = cal.paper_ramp(load_paper_table("denkena2020_table2"))
    procs = dk.design_processes(GRID, seed=0, duration_s=13.0, paper_test=[ramp])
    keys = ("ae_mm", "ap_mm", "vf_mm_min", "n_rpm")
    on_grid = [all(getattr(p, k) in GRID[k] for k in keys) for p in procs]
    assert all(g for g, p in zip(on_grid, procs, strict=True) if not p.test)
    assert not any(g for g, p in zip(on_grid, procs, strict=True) if p.test)
    assert sum(p.test for p in procs) == 21 and sum(not p.test for p in procs) == 160
    first_ramp = next(p for p in procs if p.test and p.kind == "ramp")
    assert {k: getattr(first_ramp, k) for k in keys} == {k: ramp[k] for k in keys}
    machine = drives.FeedDriveMachine()
    w = dk.process_windows(procs[::10], machine, duration_s=13.0)
    assert w.cutting.shape == (len(procs[::10]), 13 * 250)
    # every path stays inside the 20-280 mm travel the model's air moves cover
    for p in procs:
        u = np.array(dk.DIRECTIONS.get(p.feed_direction, (0.0, -1.0 if p.kind == "ramp" else 0.0)))
        end = np.array(p.start_mm[:2]) + u * p.vf_mm_min / 60.0 * 12.4
        assert 20.0 < min(*p.start_mm[:2], *end) and max(*p.start_mm[:2], *end) < 280.0, p


def test_windows_of_a_straight_cut_and_a_pocket() -> None:
    procs = dk.design_processes(GRID, seed=0, duration_s=6.0)
    machine = drives.FeedDriveMachine()
    cut_x = next(p for p in procs if p.feed_direction == "+x")
    pocket = next(p for p in procs if p.kind == "pocket")
    w = dk.process_windows([cut_x, pocket], machine, duration_s=6.0)
    assert w.cutting.shape == (2, 1500) and w.moving.shape == (2, 1500, 3)
    # a +x cut: X moves, Y and Z stand still all the time; it never reverses
    assert w.moving[0, :, 0].any() and not w.moving[0, :, 1:].any()
    assert not w.reversal[0].any()
    # the tool is in the material only while X moves, and the record ends at rest
    assert not (w.cutting[0] & ~w.moving[0, :, 0]).any() and not w.moving[0, -1].any()
    # a ccw circle reverses X and Y while cutting
    assert w.reversal[1, :, 0].any() and w.reversal[1, :, 1].any()
    assert not (w.reversal[1] & ~w.cutting[1, :, None]).any()
    with pytest.raises(ValueError, match="reversal_s"):
        dk.process_windows([cut_x], machine, duration_s=6.0, reversal_s=0.0)


def test_rmse_per_window_by_hand() -> None:
    procs = dk.design_processes(GRID, seed=0, duration_s=6.0)
    p = next(q for q in procs if q.test)
    n = 4

    rec = SimpleNamespace(processes=[p])  # the one field table2 reads

    targets = np.zeros((p.index + 1, n, 3))
    targets[p.index, :, 0] = [0.0, 10.0, -20.0, 0.0]
    lstm = {p.index: np.zeros((n, 3))}
    lstm[p.index][:, 0] = 1.0
    model = {p.index: np.zeros((n, 3))}
    cutting = np.zeros((p.index + 1, n), dtype=bool)
    cutting[p.index, 1:3] = True
    moving = np.zeros((p.index + 1, n, 3), dtype=bool)
    moving[p.index, :3, 0] = True
    w = dk.Windows(cutting, moving, np.zeros_like(moving))
    row = dk.table2(rec, targets, lstm, model, w, axes="X").iloc[0]
    # model error over the cut: (-10, 20) -> sqrt(250); LSTM: (-9, 21) -> sqrt(261)
    assert row.model_cutting_rmse_n == pytest.approx(np.sqrt(250.0))
    assert row.lstm_cutting_rmse_n == pytest.approx(np.sqrt(261.0))
    assert row.model_rmse_n == pytest.approx(np.sqrt(500.0 / 4))
    assert row.model_standstill_rmse_n == 0.0  # the last sample only
    assert row.max_abs_force_n == 20.0
    assert row.model_cutting_nrmse == pytest.approx(np.sqrt(250.0) / 20.0)


def test_two_sided_band_claims() -> None:
    table = pd.DataFrame({"process": ["circular pocket", "side milling", "ramp milling"],
                          "lstm_cutting_rmse_n": [10.0, 20.0, 12.0],
                          "model_cutting_rmse_n": [30.0, 10.0, 40.0],
                          "lstm_cutting_nrmse": [0.1, 0.3, 0.2],
                          "semi_stable": [False, True, False]})  # fmt: skip
    summary = pd.DataFrame({"lstm_lower_pct": [40.0]})
    reversal = pd.DataFrame({"window": ["reversal windows", "rest of the cut"],
                             "lstm_rmse_n": [5.0, 5.0], "model_rmse_n": [20.0, 10.0]})  # fmt: skip
    paper = load_paper_table("denkena2020_summary")
    claims = {c.id: c for c in dc.claims(table, summary, reversal, paper, (10.0, 35.0))}
    assert claims["lstm_lower_at_least"].holds and not claims["lstm_lower_at_most"].holds
    assert claims["reversal_model_fails"].value == 2.0
    assert claims["reversal_model_worse"].value == 15.0
    assert claims["pocket_model_worse"].value == 20.0
    # LSTM below the model on 2 of 3 rows; ramp 12 against the mean 14
    assert claims["lstm_better_most"].value == pytest.approx(200.0 / 3)
    assert claims["ramp_below_average"].value == pytest.approx(12.0 / 14.0)
    # semi-stable 20 N against the others' mean of 11 N
    assert claims["semi_stable_lstm_above"].value == pytest.approx(9.0)
    assert claims["semi_stable_lstm_above"].holds
    assert claims["semi_stable_lstm_above"].whose == "paper"
    assert "semi_stable_y_velocity" in claims["semi_stable_lstm_above"].requires
    assert "ramp_model_rmse_x" in claims["lstm_lower_at_least"].requires
    assert claims["reversal_model_fails"].requires == dc.MODEL_REQUIRES


def test_standing_axis_motion_counts_nonzero_velocity_while_cutting() -> None:
    inputs = np.zeros((1, 4, 14))
    inputs[0, :, 3] = [0.0, 0.05, -0.1, 0.3]  # X stands (set point), its velocity reads
    inputs[0, :, 4] = 5.0  # Y moves
    rec = SimpleNamespace(processes=[SimpleNamespace(kind="side", feed_direction="+y")],
                          inputs=inputs)  # fmt: skip
    moving = np.zeros((1, 4, 3), dtype=bool)
    moving[0, :, 1] = True
    cutting = np.array([[False, True, True, True]])
    w = dk.Windows(cutting, moving, np.zeros_like(moving))
    table = dc.standing_axis_motion(rec, w, [0], 0.05)
    row = table.iloc[0]
    assert (row.axis, row.samples, row.moving_share_pct) == ("X", 3, 100.0)
    assert row.max_abs_v_mm_s == pytest.approx(0.3)
    assert len(table) == 2 and table.iloc[-1].process == "all"
    forces = np.zeros((1, 4, 3))
    recon = {0: np.array([[0.0] * 3, [100.0] * 3, [-100.0] * 3, [0.0] * 3])}
    with_model = dc.standing_axis_motion(rec, w, [0], 0.05, model=(forces, recon, [100.0] * 3))
    # two of the three cutting samples off by 100 N; all three read a quantum
    assert with_model.iloc[0].model_rmse_n == pytest.approx(100.0 * np.sqrt(2 / 3))
    assert with_model.iloc[0].switch_rmse_n == pytest.approx(100.0)


def test_conditions_read_the_paper_and_measure_ours() -> None:
    procs = [dk.Process(0, "ramp", "-y/+z", 10.0, 2.0, 600.0, 5000.0, (0, 0, 0), False, 0, 0,
                        test=True),
             dk.Process(1, "groove", "+x", 10.0, 1.0, 300.0, 2600.0, (0, 0, 0), False, 0, 0,
                        test=True)]  # fmt: skip
    targets = np.zeros((2, 4, 3))
    recon = {0: np.full((4, 3), 50.6), 1: np.full((4, 3), 20.0)}
    w = dk.Windows(np.ones((2, 4), dtype=bool), np.ones((2, 4, 3), dtype=bool),
                   np.zeros((2, 4, 3), dtype=bool))  # fmt: skip
    vel = np.zeros((2, 4, 3))
    cond = {c.id: c for c in dc.paper_conditions(procs, targets, recon, w, GRID, 250.0, 6.0,
                                                 vel)}  # fmt: skip
    assert cond["ramp_model_rmse_x"].ours == pytest.approx(50.6) and cond["ramp_model_rmse_x"].met
    assert cond["ramp_model_rmse_y"].ours == pytest.approx(50.6)
    assert not cond["ramp_model_rmse_y"].met  # paper 18.2 N
    assert cond["groove_model_rmse"].ours == 20.0 and cond["groove_model_rmse"].met
    # the ramp (f 600, n 5000) is off the grid, the groove on it; the paper's row is off it
    assert (cond["test_off_grid"].paper, cond["test_off_grid"].ours) == (100.0, 50.0)
    assert cond["sample_rate"].met and not cond["run_duration"].met
    assert not cond["variations"].met and cond["test_processes"].ours == 2
    # no semi-stable side cut in -x: too few cases, and no vibration to measure
    assert cond["semi_stable_cases"].ours == 0 and not cond["semi_stable_cases"].met
    assert not cond["semi_stable_y_velocity"].met


def test_semi_stable_condition_measures_the_y_velocity() -> None:
    procs = [dk.Process(i, "side", "-x" if i < 3 else "+x", 2.0, 1.0, 300.0, 2600.0, (0, 0, 0),
                        i < 3, 25.0 * (i < 3), 0.04 * (i < 3), test=i != 3)
             for i in range(4)]  # fmt: skip
    vel = np.zeros((4, 4, 3))
    vel[:3, :, 1] = [1.0, -1.0, 1.0, -1.0]  # std 1 mm/s
    vel[3, :, 1] = [0.25, -0.25, 0.25, -0.25]  # std 0.25 mm/s
    w = dk.Windows(np.ones((4, 4), dtype=bool), np.ones((4, 4, 3), dtype=bool),
                   np.zeros((4, 4, 3), dtype=bool))  # fmt: skip
    recon = {i: np.zeros((4, 3)) for i in range(3)}
    cond = {c.id: c for c in dc.paper_conditions(procs, np.zeros((4, 4, 3)), recon, w, GRID,
                                                 250.0, 13.0, vel)}  # fmt: skip
    assert cond["semi_stable_cases"].ours == 3 and cond["semi_stable_cases"].met
    assert cond["semi_stable_y_velocity"].ours == pytest.approx(4.0)
    assert cond["semi_stable_y_velocity"].met


def test_claims_by_seed_reads_every_seed_beside_the_ensemble() -> None:
    def claims(lower: float, pocket: float) -> list:
        return [Claim("lower", "reduction", lower, ">=", 10.0),
                Claim("pocket", "pocket", pocket, ">", 0.0)]  # fmt: skip

    table = dk.claims_by_seed(claims(20.0, 1.0), {3: claims(5.0, 2.0), 4: claims(30.0, -1.0),
                                                  5: claims(25.0, 3.0)})  # fmt: skip
    row = table.set_index("id").loc["lower"]
    assert (row.ensemble, row.holds, row.seed_3, row.seed_4, row.seed_5) == (20.0, True, 5, 30, 25)
    assert (row.seed_min, row.seed_max, row.seeds_holding) == (5.0, 30.0, 2)
    assert row.seed_std == pytest.approx(np.std([5.0, 30.0, 25.0], ddof=1))
    assert table.set_index("id").loc["pocket", "seeds_holding"] == 2


@pytest.mark.slow
def test_seeds_train_in_parallel_with_the_sequential_bits(tmp_path, monkeypatch) -> None:
    from joblib.externals.loky import get_reusable_executor

    rng = np.random.default_rng(0)
    procs = [SimpleNamespace(test=i == 5) for i in range(6)]
    rec = SimpleNamespace(processes=procs, inputs=rng.normal(0.0, 1.0, (6, 300, 14)))
    targets = rng.normal(0.0, 50.0, (6, 300, 3))
    monkeypatch.setenv("NCTWIN_DATA", str(tmp_path / "sequential"))
    one, _ = dk.train_lstms(rec, targets, [0, 1], max_epochs=2, n_jobs=1)
    # fresh workers that see a fresh cache: the networks are trained there, not loaded
    get_reusable_executor().shutdown(wait=True)
    monkeypatch.setenv("NCTWIN_DATA", str(tmp_path / "parallel"))
    try:
        two, _ = dk.train_lstms(rec, targets, [0, 1], max_epochs=2, n_jobs=2)
    finally:
        get_reusable_executor().shutdown(wait=True)
    assert len(list((tmp_path / "parallel").rglob("*.pt"))) == 4
    for s in (0, 1):
        assert list(one[s]) == list(two[s]) == ["X", "Y"]
        for axis in "XY":
            a, b = one[s][axis], two[s][axis]
            assert a.train_config.seed == s and a.history == b.history
            for k, v in a.model.state_dict().items():
                assert torch.equal(v, b.model.state_dict()[k]), (s, axis, k)
    # the seeds differ, the axes differ
    assert not torch.equal(one[0]["X"].model.head.weight, one[1]["X"].model.head.weight)


def test_judged_claims_count_single_seeds_and_keep_the_model_claim_without_seeds() -> None:
    procs = [dk.Process(0, "pocket", "ccw", 10.0, 1.0, 300.0, 2600.0, (0, 0, 0), False, 0, 0,
                        test=True),
             dk.Process(1, "ramp", "-y/+z", 10.0, 2.0, 300.0, 2600.0, (0, 0, 0), False, 0, 0,
                        test=True),
             dk.Process(2, "side", "+x", 2.0, 1.0, 300.0, 2600.0, (0, 0, 0), True, 50, 0.5,
                        test=True)]  # fmt: skip
    rec = SimpleNamespace(processes=procs)
    targets = np.full((3, 4, 3), 100.0)
    reversal = np.zeros((3, 4, 3), dtype=bool)
    reversal[0, :2, 0] = True
    w = dk.Windows(np.ones((3, 4), dtype=bool), np.ones((3, 4, 3), dtype=bool), reversal)
    recon = {i: np.full((4, 3), 110.0) for i in range(3)}
    # seed 0 errs by 2 N everywhere, seed 1 by 6 N: the ensemble by 4 N, the model by 10 N
    per_seed = {0: {i: np.full((4, 3), 102.0) for i in range(3)},
                1: {i: np.full((4, 3), 106.0) for i in range(3)}}  # fmt: skip
    paper = load_paper_table("denkena2020_summary")
    judged, by_seed = dc.judged_claims(rec, targets, per_seed, recon, w, paper)
    c = {x.id: x for x in judged}
    assert c["lstm_lower_at_least"].value == pytest.approx(60.0)  # 1 - 4/10
    assert (c["lstm_lower_at_most"].seeds_passing, c["lstm_lower_at_most"].seeds) == (0, 2)
    low, high = c["lstm_lower_at_least"].interval
    assert 40.0 - 1e-9 <= low <= high <= 80.0 + 1e-9  # between seed 1's and seed 0's alone
    assert c["reversal_model_fails"].seeds is None
    row = by_seed.set_index("id").loc["lstm_lower_at_least"]
    assert (row.seed_0, row.seed_1) == pytest.approx((80.0, 40.0))


def test_chatter_band_splits_the_error_by_parseval() -> None:
    p = dk.Process(0, "side", "-x", 2.0, 1.0, 300.0, 2600.0, (0, 0, 0), True, 25.0, 0.04, True)
    t = np.arange(500) / 250.0
    rec = SimpleNamespace(processes=[p], t_s=t)
    targets = np.zeros((1, 500, 3))
    lstm = {0: np.zeros((500, 3))}
    lstm[0][:, 1] = 10.0 * np.sin(2 * np.pi * 25.0 * t)  # error at the vibration: 10/sqrt 2
    model = {0: np.full((500, 3), 3.0)}  # a constant error: none of it in the band
    w = dk.Windows(np.ones((1, 500), dtype=bool), np.ones((1, 500, 3), dtype=bool),
                   np.zeros((1, 500, 3), dtype=bool))  # fmt: skip
    out = dk.chatter_band_scores(rec, targets, lstm, model, w).set_index("axis")
    assert out.loc["Y", "lstm_band_rmse_n"] == pytest.approx(10.0 / np.sqrt(2))
    assert out.loc["Y", "lstm_rest_rmse_n"] == pytest.approx(0.0, abs=1e-9)
    assert out.loc["X", "model_rmse_n"] == pytest.approx(3.0)
    assert out.loc["X", "model_band_rmse_n"] == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="band_hz"):
        dk.chatter_band_scores(rec, targets, lstm, model, w, band_hz=0.0)
