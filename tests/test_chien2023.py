"""Chien et al. (2023) experiment: the recording of machine B and the targets read from it."""

import numpy as np
import pytest

from nctwin import gcode
from nctwin.chapters import chien2023 as ch
from nctwin.kernel import fir
from nctwin.machine import load_machine
from nctwin.paths import cache_dir
from nctwin.programs.training import global_program, mixed_program

MACHINE_B = load_machine("paper1_machine_b")


def test_recorded_labels_follow_the_lagging_axes():
    tp = ch.cutting_blocks(gcode.parse("G21 G90 G64 P0.1\nG1 X50 F4200\nY50\n"))
    motion = fir.run(tp, MACHINE_B, fir.FirSettings.load("paper1_machine_b"))
    rec = ch.Recording(position_gain_1_s=40.0).apply(motion, np.random.default_rng(0))
    switch = np.flatnonzero(np.diff(motion.block))[0]
    # the discrete loop follows a ramp 1 / (1 - exp(-Kv Ts)) = 25.5 samples late (1 / Kv = 25 ms)
    assert np.flatnonzero(np.diff(rec.block))[0] - switch in (25, 26)
    cruise = np.arange(switch - 300, switch - 200)
    late = 0.5 * (rec.pos_mm[cruise + 25] + rec.pos_mm[cruise + 26])
    np.testing.assert_allclose(late, motion.pos_mm[cruise], atol=1e-3)
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

    machine = load_machine("paper1_sim")
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
