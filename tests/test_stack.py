"""A stack of BP networks (nctwin.learn.stack): each member trains as it would alone."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from nctwin.learn.models import BPConfig
from nctwin.learn.stack import fit_stack
from nctwin.learn.train import TrainConfig, fit

MODEL = BPConfig(n_inputs=6, hidden=(8, 5), dropout=0.0, weight_init="uniform")
TRAIN = TrainConfig(seed=0, max_epochs=40, patience=4, batch_size=16, window_lines=8,
                    learning_rate=1e-2, val_share=0.1, loss="mse", optimiser="sgd",
                    momentum=0.8)  # fmt: skip


def _programs(n_rows: int = 1600, seed: int = 0):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(n_rows, MODEL.n_inputs))
    y = (np.sin(x[:, :3]).sum(axis=1) + 0.1 * rng.normal(size=n_rows))[:, None]
    return np.array_split(x, n_rows // 8), np.array_split(y, n_rows // 8)


def _same(a, b) -> bool:
    sa, sb = a.model.state_dict(), b.model.state_dict()
    return (a.history == b.history and a.best_epoch == b.best_epoch
            and all(torch.equal(sa[k], sb[k]) for k in sa))  # fmt: skip


def test_a_member_trains_as_it_would_alone(tmp_path, monkeypatch) -> None:
    """Bit for bit, with members that drop out, stop at other epochs and leave the stack."""
    monkeypatch.setenv("NCTWIN_CACHE", str(tmp_path))
    xs, ys = _programs()
    models = [MODEL, replace(MODEL, dropout=0.3), MODEL]
    trains = [replace(TRAIN, seed=s) for s in (0, 1, 2)]
    stack = fit_stack(models, trains, xs, ys, names=["m0", "m1", "m2"], cache=False)
    epochs = {len(net.history["val"]) for net in stack}
    assert len(epochs) > 1  # members stopped at different epochs
    for k in range(3):
        (alone,) = fit_stack(models[k : k + 1], trains[k : k + 1], xs, ys, names=["one"],
                             cache=False)  # fmt: skip
        assert _same(stack[k], alone), k


def test_a_member_learns_what_fit_learns(tmp_path, monkeypatch) -> None:
    """Not the same bits (a batched product sums in another order), the same network: the
    first epochs' losses agree to float32 rounding, and early stopping ends at the same
    epoch."""
    monkeypatch.setenv("NCTWIN_CACHE", str(tmp_path))
    xs, ys = _programs()
    (stacked,) = fit_stack([MODEL], [TRAIN], xs, ys, names=["s"], cache=False)
    alone = fit(MODEL, TRAIN, xs, ys, name="f", cache=False, progress=False)
    np.testing.assert_allclose(stacked.history["val"][:5], alone.history["val"][:5], rtol=1e-5)
    assert stacked.best_epoch == alone.best_epoch


def test_checkpoints_are_reused_and_never_fits(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("NCTWIN_CACHE", str(tmp_path))
    xs, ys = _programs()
    trains = [replace(TRAIN, seed=s, max_epochs=3) for s in (0, 1)]
    first = fit_stack([MODEL, MODEL], trains, xs, ys, names=["a", "b"])
    again = fit_stack([MODEL, MODEL], trains, xs, ys, names=["a", "b"])
    assert [n.path for n in again] == [n.path for n in first]
    assert [n.train_seconds for n in again] == [n.train_seconds for n in first]  # loaded
    alone = fit(MODEL, trains[0], xs, ys, name="a", progress=False)
    assert alone.path != first[0].path  # fit keys its own checkpoints
    assert len(list(tmp_path.rglob("*.pt"))) == 3


def test_a_diverging_member_is_none_and_leaves_its_message(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("NCTWIN_CACHE", str(tmp_path))
    xs, ys = _programs(800)
    hot = replace(TRAIN, learning_rate=1e6, max_epochs=5)  # NaN weights in the first epoch
    with pytest.raises(ValueError, match="more than seed"):
        fit_stack([MODEL, MODEL], [TRAIN, hot], xs, ys, names=["ok", "hot"])
    nets = fit_stack([MODEL], [hot], xs, ys, names=["hot"])
    assert nets == [None]
    (message,) = tmp_path.rglob("*.diverged")
    assert "diverged" in message.read_text(encoding="utf-8")
    assert fit_stack([MODEL], [hot], xs, ys, names=["hot"]) == [None]  # read, not retrained


@pytest.mark.parametrize(
    ("models", "trains", "match"),
    [
        ([MODEL, replace(MODEL, hidden=(4,))], [TRAIN, TRAIN], "more than dropout"),
        ([MODEL], [replace(TRAIN, optimiser="adam")], "allowed sgd"),
        ([MODEL], [TRAIN, TRAIN], "the same number"),
    ],
)
def test_members_that_cannot_share_a_stack_are_refused(models, trains, match) -> None:
    xs, ys = _programs(400)
    with pytest.raises(ValueError, match=match):
        fit_stack(models, trains, xs, ys, names=["x"] * len(models), cache=False)


def test_a_kernel_pin_outside_make_keys_another_checkpoint(monkeypatch) -> None:
    """A network trained without make's kernel pins (MKL_CBWR, ...) rounds differently, even
    where torch reports the same CPU capability: it must not be reused under make."""
    from nctwin.learn.train import KERNEL_PINS, checkpoint_path

    monkeypatch.setenv("MKL_CBWR", "AVX2")
    pinned = checkpoint_path("n", MODEL, TRAIN, "data")
    monkeypatch.delenv("MKL_CBWR")
    assert "MKL_CBWR" in KERNEL_PINS and checkpoint_path("n", MODEL, TRAIN, "data") != pinned
