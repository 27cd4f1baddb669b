"""The written-out BP step against autograd and torch.optim.SGD, on the same dropout masks."""

from __future__ import annotations

import pytest
import torch

from nctwin.learn.bp_sgd import BPStep
from nctwin.learn.models import BPConfig, build_bp
from nctwin.learn.train import _loss


def _reference_step(model, optimiser, drop, x, y, mask, kind):
    """Autograd on the network written with explicit masks, drawn as BPStep draws them."""
    linears = [m for m in model.layers if isinstance(m, torch.nn.Linear)]
    h = x
    for layer in linears[:-1]:
        h = torch.relu(layer(h))
        if drop > 0.0:
            keep = torch.empty_like(h).bernoulli_(1.0 - drop).div_(1.0 - drop)
            h = h * keep
    loss = _loss(linears[-1](h), y, mask, kind)
    optimiser.zero_grad()
    loss.backward()
    optimiser.step()
    return loss.detach()


@pytest.mark.parametrize(("drop", "kind"), [(0.0, "mse"), (0.5, "mse"), (0.2, "rmse")])
def test_step_is_autograd_and_sgd_with_momentum(drop, kind) -> None:
    config = BPConfig(n_inputs=7, hidden=(5, 4), n_outputs=2, dropout=drop, weight_init="uniform")
    fast = build_bp(config, generator=torch.Generator().manual_seed(3))
    slow = build_bp(config, generator=torch.Generator().manual_seed(3))
    step = BPStep(fast, 0.05, 0.8, kind)
    optimiser = torch.optim.SGD(slow.parameters(), lr=0.05, momentum=0.8)
    g = torch.Generator().manual_seed(1)
    for k in range(6):  # momentum carries over between steps
        x = torch.randn(3, 4, 7, generator=g)
        y = torch.randn(3, 4, 2, generator=g)
        mask = torch.rand(3, 4, 2, generator=g) > 0.2  # some targets left out
        torch.manual_seed(k)
        loss_fast = step(x, y, mask)
        torch.manual_seed(k)
        loss_slow = _reference_step(slow, optimiser, drop, x.reshape(12, 7), y.reshape(12, 2),
                                    mask.reshape(12, 2), kind)  # fmt: skip
        torch.testing.assert_close(loss_fast, loss_slow, rtol=1e-5, atol=1e-6)
        for (name, a), b in zip(fast.state_dict().items(), slow.state_dict().values(),
                                strict=True):  # fmt: skip
            torch.testing.assert_close(a, b, rtol=1e-5, atol=1e-6, msg=name)
    assert not torch.equal(fast.layers[0].weight, build_bp(config).layers[0].weight)


def test_all_targets_masked_leaves_the_weights() -> None:
    config = BPConfig(n_inputs=3, hidden=(4,), dropout=0.0, weight_init="uniform")
    model = build_bp(config, generator=torch.Generator().manual_seed(0))
    before = {k: v.clone() for k, v in model.state_dict().items()}
    loss = BPStep(model, 0.1, 0.8, "mse")(torch.ones(2, 3), torch.ones(2, 1), torch.zeros(2, 1) > 0)
    assert float(loss) == 0.0
    assert all(torch.equal(before[k], v) for k, v in model.state_dict().items())
