"""Models and the shared training loop: seeded, early stopping, checkpoints, scaling."""

import numpy as np
import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin import paths
from nctwin.learn.models import ModelConfig, build
from nctwin.learn.train import (
    Scaler,
    TrainConfig,
    _Programs,
    _split,
    _windows,
    fit,
    load_checkpoint,
)  # fmt: skip


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("NCTWIN_DATA", str(tmp_path))
    assert paths.cache_dir() == tmp_path / "cache"


def _data(n_programs=6, n=90, seed=0):
    """Target: a running sum over neighbours (needs context) plus a per-line term."""
    rng = np.random.default_rng(seed)
    xs, ys = [], []
    for _ in range(n_programs):
        x = rng.uniform(0.5, 2.0, (n, 2))
        y = np.column_stack([x[:, 0] + np.convolve(x[:, 1], np.ones(5) / 5, mode="same")])
        xs.append(x)
        ys.append(y)
    return xs, ys


CFG = TrainConfig(seed=1, max_epochs=8, patience=3, batch_size=4, window_lines=32)


@pytest.mark.parametrize("kind", ["bilstm", "lstm", "mlp"])
def test_shapes(kind):
    model = build(ModelConfig(kind, n_inputs=2, n_outputs=3, hidden=4))
    assert model(torch.zeros(2, 7, 2)).shape == (2, 7, 3)


def test_build_is_seeded():
    a = build(ModelConfig(), generator=torch.Generator().manual_seed(5)).state_dict()
    b = build(ModelConfig(), generator=torch.Generator().manual_seed(5)).state_dict()
    c = build(ModelConfig(), generator=torch.Generator().manual_seed(6)).state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert not all(torch.equal(a[k], c[k]) for k in a)


def test_same_seed_same_weights_bit_for_bit():
    xs, ys = _data()
    a = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, cache=False, progress=False)
    b = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, cache=False, progress=False)
    sa, sb = a.model.state_dict(), b.model.state_dict()
    assert all(torch.equal(sa[k], sb[k]) for k in sa)
    assert a.history == b.history
    np.testing.assert_array_equal(a.predict(xs[0]), b.predict(xs[0]))


def test_training_lowers_the_loss_and_predicts_long_programs():
    xs, ys = _data()
    cfg = TrainConfig(seed=0, max_epochs=40, patience=40, batch_size=4, window_lines=32)
    t = fit(ModelConfig(n_inputs=2, hidden=8), cfg, xs, ys, cache=False, progress=False)
    assert t.history["val"][t.best_epoch - 1] < 0.5 * t.history["val"][0]
    y = t.predict(np.concatenate(xs))  # longer than a window: overlapping windows
    assert y.shape == (len(xs) * 90, 1) and np.isfinite(y).all()


def test_early_stopping_keeps_best_epoch():
    xs, ys = _data()
    cfg = TrainConfig(seed=0, max_epochs=300, patience=2, batch_size=4, window_lines=32,
                      learning_rate=0.3)  # fmt: skip
    t = fit(ModelConfig(n_inputs=2, hidden=4), cfg, xs, ys, cache=False, progress=False)
    epochs = len(t.history["val"])
    assert epochs < 300
    assert epochs == t.best_epoch + cfg.patience
    assert t.history["val"][t.best_epoch - 1] == min(t.history["val"])


def test_converged_means_early_stopping_ended_the_run():
    xs, ys = _data()
    cfg = TrainConfig(seed=0, max_epochs=300, patience=2, batch_size=4, window_lines=32,
                      learning_rate=0.3)  # fmt: skip
    stopped = fit(ModelConfig(n_inputs=2, hidden=4), cfg, xs, ys, cache=False, progress=False)
    assert stopped.converged  # best epoch + patience = epochs run < 300
    capped = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, cache=False, progress=False)
    # 8 epochs, patience 3: converged only if the best epoch is below 8 - 3 = 5
    assert capped.converged == (capped.best_epoch < 5)


@settings(max_examples=40, deadline=None)
@given(
    lengths=st.lists(st.integers(1, 30), min_size=1, max_size=6),
    w=st.integers(1, 12),
    seed=st.integers(0, 2**16),
)
def test_batch_of_windows_is_the_windows_stacked_by_hand(lengths, w, seed):
    rng = np.random.default_rng(seed)
    xs = [rng.normal(size=(n, 3)) for n in lengths]
    ys = [rng.normal(size=(n, 2)) for n in lengths]
    ys[0][rng.integers(lengths[0]), rng.integers(2)] = np.nan  # a missing target
    windows = np.array(_windows(lengths, w, rng))
    x, y, m = _Programs(xs, ys).batch(windows, w)
    for i, (p, s, v) in enumerate(windows):  # by hand: the window's rows, then zeros
        t = ys[p][s : s + v].astype(np.float32)
        np.testing.assert_array_equal(x[i, :v].numpy(), xs[p][s : s + v].astype(np.float32))
        np.testing.assert_array_equal(m[i, :v].numpy(), np.isfinite(t))
        np.testing.assert_array_equal(y[i, :v].numpy(), np.nan_to_num(t))
        assert not x[i, v:].any() and not y[i, v:].any() and not m[i, v:].any()


@settings(max_examples=40, deadline=None)
@given(
    lengths=st.lists(st.integers(1, 30), min_size=1, max_size=6),
    w=st.integers(1, 12),
    batch_size=st.integers(1, 5),
    seed=st.integers(0, 2**16),
)
def test_one_gather_for_many_batches_gives_each_batch_as_its_own_gather(
    lengths, w, batch_size, seed
):
    """The epoch gathers many batches' windows at once; each slice is the batch gathered alone
    (so a network trains bit for bit as with one gather per batch)."""
    rng = np.random.default_rng(seed)
    xs = [rng.normal(size=(n, 3)) for n in lengths]
    ys = [np.where(rng.random((len(x), 1)) < 0.2, np.nan, x[:, :1]) for x in xs]
    programs = _Programs(xs, ys)
    windows = _windows(lengths, w, rng)
    windows = windows[rng.permutation(len(windows))]
    together = programs.batch(windows, w)
    for b in range(0, len(windows), batch_size):
        alone = programs.batch(windows[b : b + batch_size], w)
        for t, u in zip(together, alone, strict=True):
            np.testing.assert_array_equal(t[b : b + batch_size].numpy(), u.numpy())


def test_checkpoint_round_trip_and_cache_hit():
    xs, ys = _data()
    a = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, name="t", progress=False)
    assert a.path.exists() and a.path.parent == paths.cache_dir() / "models"
    assert not list(a.path.parent.glob("*.tmp"))
    b = load_checkpoint(a.path)  # torch.load(..., weights_only=True)
    assert b.model.config == a.model.config and b.train_config == CFG
    np.testing.assert_array_equal(a.predict(xs[1]), b.predict(xs[1]))
    c = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, name="t", progress=False)
    assert c.path == a.path and c.train_seconds == a.train_seconds  # loaded, not retrained
    # other data: another checkpoint
    d = fit(ModelConfig(n_inputs=2, hidden=4), CFG, *_data(seed=9), name="t", progress=False)
    assert d.path != a.path


def test_cache_is_keyed_by_the_cpu_kernels(monkeypatch):
    """A network trained on other CPU kernels (AVX-512 outside make's AVX2 pins) rounds
    differently: it gets a checkpoint of its own, never the other's."""
    import torch

    xs, ys = _data()
    a = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, name="t", progress=False)
    other = "AVX512" if torch.backends.cpu.get_cpu_capability() != "AVX512" else "AVX2"
    monkeypatch.setattr(torch.backends.cpu, "get_cpu_capability", lambda: other)
    b = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, name="t", progress=False)
    assert b.path != a.path and a.path.exists() and b.path.exists()


def test_scaling_uses_training_programs_only():
    xs, ys = _data()
    train_idx, val_idx = _split(len(xs), CFG)
    xs[val_idx[0]] = xs[val_idx[0]] + 100.0  # an outlier among the validation programs
    t = fit(ModelConfig(n_inputs=2, hidden=4), CFG, xs, ys, cache=False, progress=False)
    expected = Scaler.fit([xs[i] for i in train_idx])
    np.testing.assert_allclose(t.x_scaler.mean, expected.mean)
    np.testing.assert_allclose(t.x_scaler.std, expected.std)
    assert (t.x_scaler.mean < 2.0).all()  # the outlier (inputs > 100) left no trace


def test_scaler_log_columns_and_inverse():
    x = np.array([[1.0, 10.0], [3.0, 1000.0]])
    s = Scaler.fit([x], log_columns=[1])
    z = s.transform(x)
    np.testing.assert_allclose(z.mean(axis=0), 0, atol=1e-6)
    np.testing.assert_allclose(s.inverse(z), x, rtol=1e-6)


def test_split_holds_out_whole_programs():
    tr, va = _split(10, CFG)
    assert len(va) >= 1 and set(tr).isdisjoint(va) and len(tr) + len(va) == 10
    with pytest.raises(ValueError, match="at least 2"):
        _split(1, CFG)


def test_stacked_lstm_with_dropout_and_unchanged_default_keys():
    """lstm_layers/dropout build a stacked LSTM; at their defaults the config dict (hence every
    existing checkpoint key) is what it was before they existed."""
    base = ModelConfig(kind="lstm", n_inputs=4, hidden=5)
    assert "lstm_layers" not in base.to_dict() and "dropout" not in base.to_dict()
    stacked = ModelConfig(kind="lstm", n_inputs=4, hidden=5, lstm_layers=3, dropout=0.2)
    assert stacked.to_dict()["lstm_layers"] == 3
    model = build(stacked, generator=torch.Generator().manual_seed(0))
    assert model.body.num_layers == 3 and model.body.dropout == 0.2
    assert model(torch.zeros(2, 7, 4)).shape == (2, 7, 1)
    with pytest.raises(ValueError, match="dropout"):
        ModelConfig(dropout=1.0)
    with pytest.raises(ValueError, match="lstm_layers"):
        ModelConfig(lstm_layers=0)


def test_fit_seeds_takes_each_jobs_seeds():
    from nctwin.learn.seeds import fit_seeds

    xs, ys = _data()
    cfg_m = ModelConfig(kind="mlp", n_inputs=2, hidden=4)
    jobs = {"a": (cfg_m, CFG, xs, ys), "b": (cfg_m, CFG, xs[:4], ys[:4])}
    each = fit_seeds(jobs, {"a": [2], "b": [5, 3]}, n_jobs=1)
    assert list(each) == ["a", "b"]
    assert [[n.train_config.seed for n in nets] for nets in each.values()] == [[2], [5, 3]]
    # the same networks as one seed list per call (the cache is keyed by job and seed)
    b = fit_seeds({"b": jobs["b"]}, [5, 3], n_jobs=1)["b"]
    for x, y in zip(each["b"], b, strict=True):
        assert x.path == y.path
        sx, sy = x.model.state_dict(), y.model.state_dict()
        assert all(torch.equal(sx[k], sy[k]) for k in sx)
