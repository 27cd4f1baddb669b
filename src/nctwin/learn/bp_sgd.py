r"""One training step of the BP network (:class:`~nctwin.learn.models.BPNetwork`) with SGD and
momentum, written out: the arithmetic of autograd and :class:`torch.optim.SGD`, in less than
half the time (``benchmarks/bp_training.py``: 0.22 against 0.47 ms for 128 rows).

The BP network of Zhang et al. (2023) is so small (325 x 28 x 20 x 1) that the bookkeeping of
autograd, of the modules and of the optimiser, not the arithmetic, takes most of a step.
:class:`BPStep` runs the same step in a few tensor operations:

* forward: :math:`a_k = h_{k-1} W_k^T + b_k`, :math:`h_k = \max(a_k, 0) \odot r_k / (1 - p)`
  for the hidden layers, with dropout masks :math:`r_k \sim \text{Bernoulli}(1 - p)` (eq. 13;
  :math:`p` drops, as :class:`torch.nn.Dropout`), and a linear output;
* loss: the mean square error over the valid targets (eq. 4), or its root;
* backward, by the chain rule, layer by layer:
  :math:`\partial E / \partial W_k = g_k^T h_{k-1}`, :math:`\partial E / \partial b_k = \sum g_k`,
  :math:`g_{k-1} = (g_k W_k) \odot r_{k-1} / (1 - p) \odot [a_{k-1} > 0]`;
* momentum (eq. 14): :math:`v \leftarrow \beta v - \eta\, \partial E / \partial w`,
  :math:`w \leftarrow w + v`; this is PyTorch's :math:`b \leftarrow \beta b + \partial E /
  \partial w`, :math:`w \leftarrow w - \eta b` with :math:`v = -\eta b`, which is what runs.

The dropout masks come from torch's global generator, as :class:`torch.nn.Dropout`'s do (drawn
differently, so the two give different bits for the same seed).
"""

from __future__ import annotations

import torch
from torch import nn

from .models import BPNetwork

__all__ = ["BPStep"]


class BPStep:
    """SGD with momentum on a :class:`BPNetwork`, one batch per call (see the module docstring).

    Parameters
    ----------
    model : BPNetwork
        Updated in place.
    learning_rate : float
        :math:`\\eta`.
    momentum : float
        :math:`\\beta`, in [0, 1).
    loss : {"mse", "rmse"}
    """

    def __init__(self, model: BPNetwork, learning_rate: float, momentum: float, loss: str):
        self.linears = [m for m in model.layers if isinstance(m, nn.Linear)]
        self.params = [p for layer in self.linears for p in (layer.weight, layer.bias)]
        self.buffers = [torch.zeros_like(p) for p in self.params]
        self.drop = model.config.dropout
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.root = loss == "rmse"

    def __call__(self, x: torch.Tensor, y: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """Update the weights on one batch and return its loss (before the update).

        Parameters
        ----------
        x : Tensor, shape (..., n_inputs)
        y : Tensor, shape (..., n_outputs)
        mask : Tensor of bool, shape (..., n_outputs)
            Targets in the loss.
        """
        with torch.no_grad():
            h = x.reshape(-1, x.shape[-1])
            inputs, actives, keeps = [], [], []
            for layer in self.linears[:-1]:
                inputs.append(h)
                a = torch.addmm(layer.bias, h, layer.weight.T)
                actives.append(a > 0)
                h = a.clamp_min(0.0)
                keep = None
                if self.drop > 0.0:
                    keep = torch.empty_like(h).bernoulli_(1.0 - self.drop).div_(1.0 - self.drop)
                    h = h * keep
                keeps.append(keep)
            inputs.append(h)
            last = self.linears[-1]
            valid = mask.reshape(-1, mask.shape[-1]).to(h.dtype)
            d = (torch.addmm(last.bias, h, last.weight.T) - y.reshape(valid.shape)) * valid
            n = valid.sum().clamp(min=1.0)
            loss = (d * d).sum() / n
            g = d * (2.0 / n)
            if self.root:
                loss = loss.sqrt()
                g = g / (2.0 * loss)
            grads = []
            for k in range(len(self.linears) - 1, -1, -1):
                grads[:0] = [g.T @ inputs[k], g.sum(0)]
                if k:
                    g = g @ self.linears[k].weight
                    if keeps[k - 1] is not None:
                        g = g * keeps[k - 1]
                    g = g * actives[k - 1]
            torch._foreach_mul_(self.buffers, self.momentum)
            torch._foreach_add_(self.buffers, grads)
            torch._foreach_add_(self.params, self.buffers, alpha=-self.learning_rate)
        return loss
