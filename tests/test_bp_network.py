"""The BP network of Zhang et al. (2023) and the training-loop options it needs (SGD with
momentum, N(0, 1) weights, dropout, fine-tuning from a trained network)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from nctwin import paths
from nctwin.learn.models import BPConfig, BPNetwork, build_bp
from nctwin.learn.train import TrainConfig, fit, load_checkpoint


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("NCTWIN_DATA", str(tmp_path))
    assert paths.cache_dir() == tmp_path / "cache"


def _rows(n=400, seed=0, shift=0.0):
    """Rows in chunks of 8 (the loop's programs); target a smooth function of the inputs."""
    rng = np.random.default_rng(seed)
    x = rng.normal(shift, 1.0, (n, 6))
    y = (x[:, :1] ** 2 + np.sin(x[:, 1:2])) / 2
    return np.split(x, n // 8), np.split(y, n // 8)


CFG = TrainConfig(
    seed=3, max_epochs=30, patience=30, batch_size=10, window_lines=8, learning_rate=1e-2,
    loss="mse", optimiser="sgd", momentum=0.8, val_share=0.1,
)  # fmt: skip


def test_paper_initialisation_is_standard_normal_and_seeded() -> None:
    config = BPConfig(n_inputs=325)
    a = build_bp(config, generator=torch.Generator().manual_seed(0))
    b = build_bp(config, generator=torch.Generator().manual_seed(0))
    w = a.layers[0].weight.detach().numpy()
    assert w.shape == (28, 325)
    assert abs(w.mean()) < 0.02 and abs(w.std() - 1.0) < 0.02
    for pa, pb in zip(a.parameters(), b.parameters(), strict=True):
        assert torch.equal(pa, pb)
    uniform = build_bp(BPConfig(n_inputs=325, weight_init="uniform"))
    assert uniform.layers[0].weight.abs().max() <= 325**-0.5
    dropouts = [m.p for m in a.layers if isinstance(m, torch.nn.Dropout)]
    assert dropouts == [0.5, 0.5]  # after each hidden layer


def test_sgd_with_momentum_learns_and_the_checkpoint_round_trips() -> None:
    xs, ys = _rows()
    config = BPConfig(n_inputs=6, hidden=(16, 8), dropout=0.0, weight_init="uniform")
    trained = fit(config, CFG, xs, ys, name="bp", progress=False)
    assert trained.history["train"][-1] < 0.5 * trained.history["train"][0]
    again = fit(config, CFG, xs, ys, name="bp", progress=False)  # from the cache
    loaded = load_checkpoint(trained.path)
    assert isinstance(loaded.model, BPNetwork) and loaded.model.config == config
    x = np.concatenate(xs)
    np.testing.assert_array_equal(loaded.predict(x), trained.predict(x))
    np.testing.assert_array_equal(again.predict(x), trained.predict(x))
    assert trained.predict(x).shape == (len(x), 1)


def test_fine_tuning_starts_from_the_weights_and_keeps_the_scalers() -> None:
    config = BPConfig(n_inputs=6, hidden=(16, 8), dropout=0.0, weight_init="uniform")
    base = fit(config, CFG, *_rows(), name="bp", progress=False)
    xs, ys = _rows(160, seed=1, shift=0.5)
    tuned = fit(config, CFG, xs, ys, name="bp", progress=False, init=base)
    np.testing.assert_array_equal(tuned.x_scaler.mean, base.x_scaler.mean)
    assert tuned.path != base.path
    # the first epoch of fine-tuning starts where the base network is, not from scratch
    scratch = fit(config, CFG, xs, ys, name="bp", progress=False)
    assert tuned.history["train"][0] < scratch.history["train"][0]
    with pytest.raises(ValueError, match="model_config"):
        fit(BPConfig(n_inputs=6), CFG, xs, ys, progress=False, init=base)


def test_bad_parameters_raise() -> None:
    with pytest.raises(ValueError, match="dropout"):
        BPConfig(dropout=1.0)
    with pytest.raises(ValueError, match="weight_init"):
        BPConfig(weight_init="xavier")
    with pytest.raises(ValueError, match="hidden"):
        BPConfig(hidden=(28, 0))
    with pytest.raises(ValueError, match="optimiser"):
        TrainConfig(optimiser="rmsprop")
    with pytest.raises(ValueError, match="momentum"):
        TrainConfig(momentum=1.0)
    assert "optimiser" not in TrainConfig().to_dict()  # default keys of old checkpoints unchanged


def test_dropout_training_repeats_bit_for_bit_and_leaves_the_global_rng_alone() -> None:
    xs, ys = _rows()
    config = BPConfig(n_inputs=6, hidden=(16, 8), dropout=0.5, weight_init="uniform")
    torch.manual_seed(123)
    before = torch.random.get_rng_state()
    a = fit(config, CFG, xs, ys, cache=False, progress=False)
    assert torch.equal(torch.random.get_rng_state(), before)
    torch.rand(5)  # a different global state must not matter
    b = fit(config, CFG, xs, ys, cache=False, progress=False)
    assert a.history == b.history
    for pa, pb in zip(a.model.parameters(), b.model.parameters(), strict=True):
        assert torch.equal(pa, pb)


def test_a_diverging_training_raises_a_clear_error() -> None:
    from nctwin.learn.train import TrainingDivergedError

    xs, ys = _rows()
    config = BPConfig(n_inputs=6, hidden=(16, 8), dropout=0.0, weight_init="normal",
                      weight_std=50.0)  # fmt: skip
    cfg = TrainConfig(seed=0, max_epochs=5, patience=5, batch_size=10, window_lines=8,
                      learning_rate=10.0, loss="mse", optimiser="sgd", momentum=0.8)  # fmt: skip
    with pytest.raises(TrainingDivergedError, match="diverged"):
        fit(config, cfg, xs, ys, cache=False, progress=False)


def test_a_diverged_training_stops_at_its_first_nan_weight_and_is_cached(monkeypatch) -> None:
    from nctwin.learn import train as tr

    xs, ys = _rows()
    config = BPConfig(n_inputs=6, hidden=(16, 8), dropout=0.0, weight_init="normal",
                      weight_std=50.0)  # fmt: skip
    cfg = TrainConfig(seed=0, max_epochs=5, patience=5, batch_size=1, window_lines=8,
                      learning_rate=10.0, loss="mse", optimiser="sgd", momentum=0.8)  # fmt: skip
    steps = []
    step = tr._autograd_step
    monkeypatch.setattr(tr, "_autograd_step", lambda *a: steps.append(1) or step(*a))
    with pytest.raises(tr.TrainingDivergedError, match="diverged") as first:
        fit(config, cfg, xs, ys, progress=False)
    assert 0 < len(steps) < 42  # 42 of the 50 chunks train, one a step: stopped in epoch 1
    monkeypatch.setattr(tr, "_train", lambda *a: pytest.fail("trained again"))
    with pytest.raises(tr.TrainingDivergedError) as again:  # the divergence is cached
        fit(config, cfg, xs, ys, progress=False)
    assert str(again.value) == str(first.value)


@pytest.mark.parametrize("momentum", [0.0, 0.8])
def test_the_loops_sgd_on_rows_is_torch_optim_sgd_on_windows_bit_for_bit(momentum) -> None:
    """The loop's step (:class:`_SGD`, a batch's windows as one matrix of rows, a float mask) and
    ``torch.optim.SGD`` on the (windows, rows, n) batch, with the same dropout masks: the same
    losses and weights, bit for bit."""
    from nctwin.learn.train import _SGD, _autograd_step

    config = BPConfig(n_inputs=6, hidden=(16, 8), dropout=0.5, weight_init="uniform")
    g = torch.Generator().manual_seed(0)
    x, y = torch.randn(6, 4, 3, 6, generator=g), torch.randn(6, 4, 3, 1, generator=g)
    mask = torch.rand(6, 4, 3, 1, generator=g) > 0.2  # padded rows are masked out
    runs = []
    for rows in (True, False):
        net = build_bp(config, generator=torch.Generator().manual_seed(1)).train()
        if rows:
            opt = _SGD(net.parameters(), 0.05, momentum)
        else:
            opt = torch.optim.SGD(net.parameters(), lr=0.05, momentum=momentum, foreach=True)
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(2)
            batches = [(x[i], y[i], mask[i]) for i in range(len(x))]
            if rows:  # as the loop runs them: rows, a float mask
                batches = [(bx.flatten(0, 1), by.flatten(0, 1), bm.flatten(0, 1).float())
                           for bx, by, bm in batches]  # fmt: skip
            losses = [float(_autograd_step(net, opt, "mse", *b)) for b in batches]
        runs.append((losses, [p.detach().clone() for p in net.parameters()]))
    (ours, ours_w), (ref, ref_w) = runs
    assert ours == ref
    start = build_bp(config, generator=torch.Generator().manual_seed(1)).parameters()
    for a, b, w0 in zip(ours_w, ref_w, start, strict=True):
        assert torch.equal(a, b)
        assert not torch.equal(a, w0)  # the steps moved every weight
