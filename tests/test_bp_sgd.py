"""The written-out BP epoch against autograd and torch.optim.SGD, on the same dropout masks."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from nctwin.learn.bp_sgd import BPEpoch, blas_kernels
from nctwin.learn.models import BPConfig, build_bp
from nctwin.learn.train import _loss


def _reference_epoch(model, optimiser, drop, x, y, rows, bounds, keep_u, kind):
    """Autograd, batch by batch, on the network written with the masks BPEpoch draws."""
    linears = [m for m in model.layers if isinstance(m, torch.nn.Linear)]
    losses = []
    for b in range(len(bounds) - 1):
        r = rows[bounds[b] : bounds[b + 1]]
        h = torch.from_numpy(x[r])
        column = 0
        for layer in linears[:-1]:
            h = torch.relu(layer(h))
            if drop > 0.0:
                u = keep_u[bounds[b] : bounds[b + 1], column : column + h.shape[1]]
                h = h * torch.from_numpy(u >= drop).float() / (1.0 - drop)
            column += h.shape[1]
        finite = np.isfinite(y[r])
        target = torch.from_numpy(np.where(finite, y[r], 0.0))
        loss = _loss(linears[-1](h), target, torch.from_numpy(finite), kind)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        losses.append(float(loss.detach()))
    return np.array(losses)


@pytest.mark.parametrize(("drop", "kind"), [(0.0, "mse"), (0.5, "mse"), (0.2, "rmse")])
def test_epoch_is_autograd_and_sgd_with_momentum(drop, kind) -> None:
    config = BPConfig(n_inputs=7, hidden=(5, 4), n_outputs=2, dropout=drop, weight_init="uniform")
    fast = build_bp(config, generator=torch.Generator().manual_seed(3))
    slow = build_bp(config, generator=torch.Generator().manual_seed(3))
    epoch = BPEpoch(fast, 0.05, 0.8, kind, seed=4)
    optimiser = torch.optim.SGD(slow.parameters(), lr=0.05, momentum=0.8)
    rng = np.random.default_rng(1)
    x = rng.standard_normal((40, 7)).astype(np.float32)
    y = rng.standard_normal((40, 2)).astype(np.float32)
    y[rng.random((40, 2)) < 0.2] = np.nan  # some targets left out
    masks = np.random.default_rng([4, 3])  # the generator BPEpoch draws its masks from
    bounds = np.array([0, 12, 24, 30])
    batch_weights = np.array([3.0, 3.0, 2.0])
    for _ in range(3):  # momentum carries over between epochs
        rows = rng.permutation(40)[:30]
        loss = epoch(x, y, rows, bounds, batch_weights)
        keep_u = masks.random((30, 9 if drop > 0.0 else 0), np.float32)
        losses = _reference_epoch(slow, optimiser, drop, x, y, rows, bounds, keep_u, kind)
        assert loss == pytest.approx(np.average(losses, weights=batch_weights), rel=1e-5)
        epoch.load(epoch.weights.copy())  # into the torch model
        for (name, a), b in zip(fast.state_dict().items(), slow.state_dict().values(),
                                strict=True):  # fmt: skip
            torch.testing.assert_close(a, b, rtol=1e-5, atol=1e-6, msg=name)
    assert not torch.equal(fast.layers[0].weight, build_bp(config).layers[0].weight)


def test_loss_is_the_evaluation_mode_loss_of_the_model() -> None:
    config = BPConfig(n_inputs=4, hidden=(6,), n_outputs=1, dropout=0.5, weight_init="uniform")
    model = build_bp(config, generator=torch.Generator().manual_seed(0)).eval()
    rng = np.random.default_rng(0)
    x = rng.standard_normal((9, 4)).astype(np.float32)
    y = rng.standard_normal((9, 1)).astype(np.float32)
    y[2] = np.nan
    finite = np.isfinite(y)
    with torch.no_grad():
        pred = model(torch.from_numpy(x))
    for kind in ("mse", "rmse"):
        expected = _loss(pred, torch.from_numpy(np.where(finite, y, 0.0)),
                         torch.from_numpy(finite), kind)  # fmt: skip
        assert BPEpoch(model, 0.1, 0.8, kind, seed=0).loss(x, y) == pytest.approx(
            float(expected), rel=1e-6
        )


def test_all_targets_left_out_leaves_the_weights() -> None:
    config = BPConfig(n_inputs=3, hidden=(4,), dropout=0.0, weight_init="uniform")
    model = build_bp(config, generator=torch.Generator().manual_seed(0))
    epoch = BPEpoch(model, 0.1, 0.8, "rmse", seed=0)
    before = epoch.weights.copy()
    x = np.ones((2, 3), np.float32)
    y = np.full((2, 1), np.nan, np.float32)
    loss = epoch(x, y, np.array([0, 1]), np.array([0, 2]), np.array([1.0]))
    assert loss == 0.0
    np.testing.assert_array_equal(epoch.weights, before)


def test_load_puts_the_weights_into_the_model() -> None:
    config = BPConfig(n_inputs=3, hidden=(2,), dropout=0.0, weight_init="uniform")
    model = build_bp(config, generator=torch.Generator().manual_seed(0))
    epoch = BPEpoch(model, 0.1, 0.8, "mse", seed=0)
    epoch.load(np.arange(epoch.weights.size, dtype=np.float32))
    assert model.layers[0].weight.tolist() == [[0.0, 2.0, 4.0], [1.0, 3.0, 5.0]]  # W^T stored
    assert model.layers[0].bias.tolist() == [6.0, 7.0]
    assert model.layers[-1].weight.tolist() == [[8.0, 9.0]]
    assert model.layers[-1].bias.tolist() == [10.0]


def test_blas_kernels_names_the_openblas_kernels() -> None:
    name = blas_kernels()
    assert name and name != "none"


@pytest.mark.parametrize(
    ("rows", "bounds", "batch_weights", "match"),
    [
        ([0, 9], [0, 2], [1.0], "rows"),
        ([0, -1], [0, 2], [1.0], "rows"),
        ([0, 1], [0, 1], [1.0], "bounds"),
        ([0, 1], [0, 0, 2], [1.0, 1.0], "strictly increasing"),
        ([0, 1], [0, 2], [1.0, 1.0], "batch_weights"),
    ],
)
def test_bad_batches_are_refused_with_the_allowed_range(rows, bounds, batch_weights, match):
    config = BPConfig(n_inputs=3, hidden=(2,), dropout=0.0, weight_init="uniform")
    epoch = BPEpoch(build_bp(config), 0.1, 0.8, "mse", seed=0)
    x, y = np.zeros((4, 3), np.float32), np.zeros((4, 1), np.float32)
    with pytest.raises(ValueError, match=match):
        epoch(x, y, np.array(rows), np.array(bounds), np.array(batch_weights))


def test_samples_of_the_wrong_width_are_refused() -> None:
    config = BPConfig(n_inputs=3, hidden=(2,), dropout=0.0, weight_init="uniform")
    epoch = BPEpoch(build_bp(config), 0.1, 0.8, "mse", seed=0)
    with pytest.raises(ValueError, match=r"x has shape \(4, 2\): allowed \(N, 3\)"):
        epoch.loss(np.zeros((4, 2)), np.zeros((4, 1)))
    with pytest.raises(ValueError, match="y has shape"):
        epoch.loss(np.zeros((4, 3)), np.zeros((3, 1)))
