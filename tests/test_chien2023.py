"""Chien et al. (2023) experiment: the recording of machine B and the targets read from it."""

import numpy as np
import pytest

from nctwin import gcode
from nctwin.chapters import chien2023 as ch
from nctwin.kernel import fir
from nctwin.machine import load_profile
from nctwin.paths import cache_dir
from nctwin.programs.training import global_program, mixed_program

MACHINE_B = load_profile("paper1_machine_b")


def test_recorded_labels_follow_the_lagging_axes():
    tp = ch.cutting_blocks(gcode.parse("G21 G90 G64 P0.1\nG1 X50 F4200\nY50\n"))
    motion = fir.run(tp, MACHINE_B.machine, MACHINE_B.control("fir"))
    rec = ch.Recording(position_gain_1_s=40.0).apply(motion, np.random.default_rng(0))
    switch = np.flatnonzero(np.diff(motion.block))[0]
    # the exactly discretised loop follows a ramp 1 / Kv = 25 ms = 25 samples late, and the
    # labels are delayed by as much
    assert np.flatnonzero(np.diff(rec.block))[0] - switch == 25
    cruise = np.arange(switch - 300, switch - 200)
    np.testing.assert_allclose(rec.pos_mm[cruise + 25], motion.pos_mm[cruise], atol=1e-6)
    # the motion ends when the axes are within the in-position window
    assert len(rec) > len(motion)
    np.testing.assert_allclose(rec.pos_mm[-1], motion.pos_mm[-1], atol=1e-3)


def test_lag_without_delayed_labels_moves_time_between_short_g_lines():
    text = global_program(5, n_lines=300, feed_mm_s=70.0, tol_mm=0.075)
    lag = ch.Recording(position_gain_1_s=40.0)
    out = ch.recording_effects(text, MACHINE_B, {"lag": lag}).set_index(["recording", "labels"])
    delayed, early = out.loc[("lag", "delayed")], out.loc[("lag", "interpolator")]
    # the cycle time is the same either way (the labels only place the junctions)
    assert delayed.measured_s == early.measured_s
    assert delayed.measured_s == pytest.approx(out.loc[("reference", "kernel")].measured_s, abs=0.5)
    # reading the lagged trace with the interpolator's labels scrambles the short G-lines' times
    assert early.s_rms_short > 1.5 * delayed.s_rms_short
    assert delayed.zero_time_pct <= early.zero_time_pct


def test_noise_alone_leaves_the_times_almost_unchanged():
    text = global_program(6, n_lines=300, feed_mm_s=70.0, tol_mm=0.075)
    out = ch.recording_effects(text, MACHINE_B, {"noise": ch.Recording(noise_mm=0.002)})
    noise = out.set_index("recording").loc["noise"]
    ref = out.set_index("recording").loc["reference"]
    assert noise.measured_s == ref.measured_s
    # a sample either way at a junction: large on the shortest G-lines, nothing on average
    assert noise.s_mean_short == pytest.approx(ref.s_mean_short, rel=0.02)
    assert noise.s_rms_short < 0.2 * ref.s_mean_short


def test_time_by_length_splits_the_cycle_time():
    import torch

    from nctwin.learn.models import ModelConfig, build
    from nctwin.learn.train import Scaler, TrainConfig, Trained

    machine = load_profile("paper1_sim")
    run = ch.simulate_one(mixed_program(7, n_lines=200, feed_mm_s=80.0, tol_mm=0.3), machine)
    model = build(ModelConfig("bilstm", n_outputs=2), generator=torch.Generator().manual_seed(0))
    trained = Trained(model, Scaler.fit([run.features], log_columns=[1]),
                      Scaler(np.zeros(2), np.ones(2)), TrainConfig(), {}, 0, 0.0,
                      cache_dir())  # fmt: skip
    row = ch.time_by_length({("p", 80.0, 0.3): run}, trained).iloc[0]
    assert row.short_lines + row.long_lines == len(run.features)
    assert row.long_lines >= 1
    assert row.short_measured_s + row.long_measured_s == pytest.approx(run.measured_s)
    predicted = ch.predict_run(trained, run)[2]
    assert row.short_predicted_s + row.long_predicted_s == pytest.approx(predicted)


@pytest.fixture(scope="module")
def small_ensemble(tmp_path_factory):
    """Two seeds of a small BiLSTM on four short programs, trained through fit_seeds."""
    import os

    from nctwin.learn.models import ModelConfig

    machine = load_profile("paper1_sim")
    texts = [mixed_program(s, n_lines=150, feed_mm_s=80.0, tol_mm=0.3) for s in range(4)]
    runs = [ch.simulate_one(t, machine) for t in texts]
    cfg = ch.train_config(0, scale=8 / ch.MAX_EPOCHS)  # a cap of 8 epochs
    old = os.environ.get("NCTWIN_DATA")
    os.environ["NCTWIN_DATA"] = str(tmp_path_factory.mktemp("data"))
    try:
        nets = ch.fit_seeds(
            {"tiny": (ModelConfig("bilstm", n_outputs=2, hidden=4), cfg,
                      [r.features for r in runs], [r.targets for r in runs])},
            [3, 4], n_jobs=1,
        )  # fmt: skip
    finally:
        if old is None:
            del os.environ["NCTWIN_DATA"]
        else:
            os.environ["NCTWIN_DATA"] = old
    return runs, nets["tiny"]


def test_fit_seeds_one_network_per_seed_and_convergence_rule(small_ensemble):
    _, members = small_ensemble
    assert [m.train_config.seed for m in members] == [3, 4]
    conv = ch.convergence({"tiny": members})
    assert list(conv.seed) == [3, 4]
    for row, m in zip(conv.itertuples(), members, strict=True):
        assert row.epochs_run == len(m.history["val"]) <= row.max_epochs == 8
        # the patience (25) cannot have ended an 8-epoch run: the cap did, so not converged
        assert not row.converged


def test_ensemble_is_the_mean_of_its_members(small_ensemble):
    runs, members = small_ensemble
    run = runs[0]
    one = [ch.predict_run(m, run) for m in members]
    feed, t, total = ch.predict_run(members, run)
    np.testing.assert_allclose(t, 0.5 * (one[0][1] + one[1][1]))
    np.testing.assert_allclose(feed, 0.5 * (one[0][0] + one[1][0]))
    assert total == pytest.approx(0.5 * (one[0][2] + one[1][2]))
    rows = ch.seed_rows({("p", 80.0, 0.3): run}, members, decimals=12).iloc[0]
    # signed errors are linear in the prediction: the ensemble's is the seeds' mean
    assert rows.ensemble_err_pct == pytest.approx(0.5 * (rows.seed_3_err_pct + rows.seed_4_err_pct))
    assert rows.spread_pct == pytest.approx(abs(rows.seed_3_err_pct - rows.seed_4_err_pct))


def test_line_stats_by_hand():
    x = np.array([[70.0, 0.5, 0.0, 0.05, 0.1],
                  [70.0, 20.0, 0.05, 0.05, 0.1],  # long, tangent at both ends
                  [70.0, 5.0, 0.05, 3.0, 0.1],
                  [80.0, 50.0, 3.0, np.pi, 0.1]])  # fmt: skip
    run = ch.ProgramRun(x, np.zeros((4, 2)), np.ones(4), 3600.0, 3000.0)
    row = ch.line_stats({"one": [run]}).iloc[0]
    assert (row.programs, row.glines, row.hours) == (1, 4, 1.0)
    assert (row.under_1mm_pct, row.from_1_to_10mm_pct, row.over_10mm_pct) == (25, 25, 50)
    assert row.turn_over_90deg_pct == 25
    assert (row.long_tangent_both, row.long_tangent_both_pct) == (1, 50)
    assert (row.feed_min_mm_s, row.feed_max_mm_s) == (70, 80)


def test_eq3_is_length_over_predicted_feed_and_an_ensembles_is_its_members_mean(small_ensemble):
    from nctwin.methods.chien2023 import eq3_time_s

    # by hand: 10 mm at 5 mm/s and 20 mm at 10 mm/s
    assert eq3_time_s(np.array([5.0, 10.0]), np.array([10.0, 20.0])) == pytest.approx(4.0)
    runs, members = small_ensemble
    run = runs[0]
    row = ch.eq3_rows({("p", 80.0, 0.3): run}, {"net": members}).iloc[0]
    one = [eq3_time_s(ch.predict_run(m, run)[0], run.features[:, 1]) for m in members]
    assert row.net_eq3_s == pytest.approx(np.mean(one))
    assert row.net_eq3_err_pct == pytest.approx(abs(row.net_eq3_s / run.measured_s - 1) * 100)
    assert row.net_err_pct == pytest.approx(
        abs(ch.predict_run(members, run)[2] / run.measured_s - 1) * 100
    )
