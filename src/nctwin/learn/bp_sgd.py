r"""One training epoch of the BP network (:class:`~nctwin.learn.models.BPNetwork`) with SGD and
momentum, written out and compiled: the arithmetic of autograd and :class:`torch.optim.SGD`,
batch after batch, in one call (``benchmarks/bp_training.py``: 0.13 ms a step of 128 rows,
against 0.59 ms for autograd).

The BP network of Zhang et al. (2023) is so small (325 x 28 x 20 x 1) that the bookkeeping of
autograd, of the modules and of the optimiser, not the arithmetic, takes most of a step when
torch runs it: a few microseconds for each of some thirty tensor operations, against two matrix
products of about 50 us that every step needs. :class:`BPEpoch` runs a whole epoch in one
compiled function (numba), with the matrix products in BLAS, and per batch:

* forward: :math:`a_k = h_{k-1} W_k^T + b_k`, :math:`h_k = \max(a_k, 0) \odot r_k / (1 - p)`
  for the hidden layers, with dropout masks :math:`r_k \sim \text{Bernoulli}(1 - p)` (eq. 13;
  :math:`p` drops, as :class:`torch.nn.Dropout`), and a linear output;
* loss: the mean square error over the finite targets of the batch (eq. 4), or its root;
* backward, by the chain rule, layer by layer:
  :math:`\partial E / \partial W_k = g_k^T h_{k-1}`, :math:`\partial E / \partial b_k = \sum g_k`,
  :math:`g_{k-1} = (g_k W_k) \odot r_{k-1} / (1 - p) \odot [a_{k-1} > 0]`;
* momentum (eq. 14): :math:`v \leftarrow \beta v - \eta\, \partial E / \partial w`,
  :math:`w \leftarrow w + v`; this is PyTorch's :math:`b \leftarrow \beta b + \partial E /
  \partial w`, :math:`w \leftarrow w - \eta b` with :math:`v = -\eta b`, which is what runs.

Randomness and rounding: the dropout masks come from ``numpy.random.default_rng([seed, 3])``,
one draw of ``random((rows, sum(hidden)), float32)`` per epoch (row ``i`` of the epoch, unit
``j`` of the hidden layers stacked, is kept where the draw is >= :math:`p`). BLAS must run on
one thread (:func:`nctwin.learn.train.fit` sees to it): OpenBLAS splits a long product
differently on two threads, and rounds differently. Its kernels follow the CPU unless
``OPENBLAS_CORETYPE`` pins them (the Makefile pins ``Haswell``), so :func:`blas_kernels` belongs
in a cache key. The loops are compiled without ``fastmath``: no sum is reordered.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg.cython_blas  # noqa: F401  (the BLAS of numba's np.dot: loaded for blas_kernels)
import torch
from numba import njit
from threadpoolctl import threadpool_info
from torch import nn

from .models import BPNetwork

__all__ = ["BPEpoch", "blas_kernels"]


def blas_kernels() -> str:
    """The kernels the loaded OpenBLAS libraries run (e.g. ``"Haswell"``), ``+``-joined."""
    libraries = [i for i in threadpool_info() if i["internal_api"] == "openblas"]
    names = {i.get("architecture") or "?" for i in libraries}
    return "+".join(sorted(names)) or "none"


class BPEpoch:
    """SGD with momentum on a :class:`BPNetwork`, one epoch per call (see the module docstring).

    The weights live in one float32 vector, :attr:`weights`, while training runs; :meth:`load`
    puts a vector back and into ``model``.

    Parameters
    ----------
    model : BPNetwork
        Its weights start the training; :meth:`load` writes into it.
    learning_rate : float
        :math:`\\eta`.
    momentum : float
        :math:`\\beta`, in [0, 1).
    loss : {"mse", "rmse"}
    seed : int
        Seed of the dropout masks.

    Notes
    -----
    Run it under one BLAS thread, as :func:`nctwin.learn.train.fit` does, to get fit's bits.
    """

    def __init__(
        self, model: BPNetwork, learning_rate: float, momentum: float, loss: str, *, seed: int
    ) -> None:
        linears = [m for m in model.layers if isinstance(m, nn.Linear)]
        self.params = [p for m in linears for p in (m.weight, m.bias)]
        self.shapes = np.array([m.weight.shape for m in linears], dtype=np.int64)  # (out, in)
        # W_k transposed (in x out, so that every product runs on C arrays), then b_k
        self.weights = np.concatenate([p.detach().numpy().T.ravel() for p in self.params])
        self.velocity = np.zeros_like(self.weights)
        self.drop = float(model.config.dropout)
        self.n_hidden = int(sum(model.config.hidden))
        self.learning_rate = float(learning_rate)
        self.momentum = float(momentum)
        self.root = loss == "rmse"
        self.rng = np.random.default_rng([seed, 3])
        self.workspaces: dict[str, np.ndarray] = {}

    def _workspace(self, name: str, n_rows: int, n_inputs: int) -> np.ndarray:
        """Scratch memory for batches of ``n_rows``, kept between calls: fresh memory each
        epoch costs page faults (a full-batch epoch took 25 ms against 16 ms)."""
        size = int(_buffer_sizes(n_rows, n_inputs, self.shapes).sum())
        if self.workspaces.get(name, np.empty(0)).size < size:
            self.workspaces[name] = np.empty(size, np.float32)
        return self.workspaces[name]

    def _samples(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """``x`` and ``y`` as C-contiguous float32 (no copy if they are), shapes checked: the
        compiled loops do not check their indices."""
        x = np.ascontiguousarray(x, dtype=np.float32)
        y = np.ascontiguousarray(y, dtype=np.float32)
        n_in, n_out = int(self.shapes[0, 1]), int(self.shapes[-1, 0])
        if x.ndim != 2 or x.shape[1] != n_in:
            raise ValueError(f"x has shape {x.shape}: allowed (N, {n_in})")
        if y.shape != (len(x), n_out):
            raise ValueError(f"y has shape {y.shape}: allowed ({len(x)}, {n_out}), as x")
        return x, y

    def __call__(
        self, x: np.ndarray, y: np.ndarray, rows: np.ndarray, bounds: np.ndarray,
        batch_weights: np.ndarray,
    ) -> float:  # fmt: skip
        """Run one epoch; the mean of its batch losses (each before its update), weighted.

        Parameters
        ----------
        x : ndarray of float32, shape (N, n_inputs)
        y : ndarray of float32, shape (N, n_outputs)
            Targets; NaN ones are left out of the loss.
        rows : ndarray of int64, shape (R,)
            Rows of ``x`` and ``y``, in the order the epoch visits them.
        bounds : ndarray of int64, shape (B + 1,)
            Batch ``b`` is ``rows[bounds[b]:bounds[b + 1]]``.
        batch_weights : ndarray of float64, shape (B,)
            Weight of each batch's loss in the mean (the training loop: its windows).
        """
        x, y = self._samples(x, y)
        rows, bounds = np.asarray(rows, np.int64), np.asarray(bounds, np.int64)
        batch_weights = np.asarray(batch_weights, np.float64)
        if rows.ndim != 1 or (len(rows) and not 0 <= rows.min() <= rows.max() < len(x)):
            raise ValueError(f"rows = {rows!r} is out of range: allowed 1-d, in [0, {len(x)})")
        if bounds.ndim != 1 or len(bounds) < 2 or bounds[0] != 0 or bounds[-1] != len(rows):
            raise ValueError(
                f"bounds = {bounds!r} is out of range: allowed from 0 to len(rows) = {len(rows)}"
            )
        if np.any(np.diff(bounds) < 1):
            raise ValueError(f"bounds = {bounds!r} is out of range: allowed strictly increasing")
        if batch_weights.shape != (len(bounds) - 1,):
            raise ValueError(
                f"batch_weights has shape {batch_weights.shape}: allowed ({len(bounds) - 1},), "
                "one per batch"
            )
        keep = self.rng.random((len(rows), self.n_hidden if self.drop > 0.0 else 0), np.float32)
        n_max = int(np.max(np.diff(bounds)))
        return float(
            _sgd_epoch(
                x, y, rows, bounds, batch_weights, self.weights, self.velocity, self.shapes,
                keep, np.float32(self.drop), np.float32(self.learning_rate),
                np.float32(self.momentum), self.root,
                self._workspace("train", n_max, x.shape[1]), n_max,
            )
        )  # fmt: skip

    def loss(self, x: np.ndarray, y: np.ndarray) -> float:
        """The loss of the current weights on all rows of ``x`` (N, n_inputs) and ``y``
        (N, n_outputs), without dropout (evaluation mode)."""
        x, y = self._samples(x, y)
        workspace = self._workspace("eval", len(x), x.shape[1])
        return float(_eval_loss(x, y, self.weights, self.shapes, self.root, workspace))

    def load(self, weights: np.ndarray) -> None:
        """Set the weights to ``weights`` (a copy of :attr:`weights`), here and in the model."""
        self.weights[:] = weights
        start = 0
        with torch.no_grad():
            for p in self.params:
                block = torch.from_numpy(weights[start : start + p.numel()])
                p.copy_(block.view(p.shape[::-1]).T if p.dim() == 2 else block)
                start += p.numel()


@njit(cache=True)
def _starts(shapes):
    """Offsets of the layers in the weight vector: layer k is W_k^T (in x out), then b_k."""
    starts = np.zeros(shapes.shape[0] + 1, np.int64)
    for k in range(shapes.shape[0]):
        starts[k + 1] = starts[k] + shapes[k, 0] * (shapes[k, 1] + 1)
    return starts


@njit(cache=True)
def _buffer_sizes(n, n_inputs, shapes):
    """Sizes of the views :func:`_buffers` cuts, in order: one layout for both."""
    layers = range(shapes.shape[0])
    sizes = [n * n_inputs, n * shapes[-1, 0]]
    sizes += [n * shapes[k, 0] for k in layers] + [n * shapes[k, 0] for k in layers]
    sizes += [n * shapes[k, 1] for k in layers]
    return np.array(sizes)


@njit(cache=True)
def _buffers(workspace, n, n_inputs, shapes):
    """Views of ``workspace`` for batches of up to ``n`` rows: the batch's inputs (n, n_inputs)
    and targets (n, n_outputs), and per layer k its outputs and factors (n, out_k) and the
    gradient with respect to its inputs (n, in_k); :meth:`BPEpoch._workspace` allocates the sum
    of :func:`_buffer_sizes`."""
    layers = range(shapes.shape[0])
    sizes = _buffer_sizes(n, n_inputs, shapes)
    ends = np.cumsum(sizes)
    views = [workspace[ends[i] - sizes[i] : ends[i]] for i in range(len(sizes))]
    n_layers = shapes.shape[0]
    x_rows = views[0].reshape((n, n_inputs))
    y_rows = views[1].reshape((n, shapes[-1, 0]))
    outs = [views[2 + k].reshape((n, shapes[k, 0])) for k in layers]
    factors = [views[2 + n_layers + k].reshape((n, shapes[k, 0])) for k in layers]
    back = [views[2 + 2 * n_layers + k].reshape((n, shapes[k, 1])) for k in layers]
    return x_rows, y_rows, outs, factors, back


@njit(cache=True)
def _forward(h, weights, shapes, starts, outs, factors, keep, r0, drop):
    """Outputs (n, n_outputs) of the inputs ``h`` (n, n_inputs), in ``outs[-1]``. Every hidden
    layer k leaves its outputs in ``outs[k]`` and d h_k / d a_k (0, 1 or 1/(1-p)) in
    ``factors[k]``; dropout reads ``keep`` from row ``r0`` on when ``drop`` > 0."""
    n = h.shape[0]
    scale = np.float32(1.0) / (np.float32(1.0) - drop)
    column, last = 0, shapes.shape[0] - 1
    for k in range(last + 1):
        out, width = shapes[k, 0], shapes[k, 1]
        wt = weights[starts[k] : starts[k] + out * width].reshape((width, out))
        bias = weights[starts[k] + out * width : starts[k + 1]]
        a = outs[k][:n]
        np.dot(h, wt, a)
        if k == last:
            for i in range(n):
                for j in range(out):
                    a[i, j] += bias[j]
            break
        f = factors[k][:n]
        zero, one = np.float32(0.0), np.float32(1.0)
        for i in range(n):
            fi, ai = f[i], a[i]
            if drop > 0.0:
                kept = keep[r0 + i, column : column + out]
                for j in range(out):
                    v = ai[j] + bias[j]
                    fj = scale if kept[j] >= drop else zero
                    fi[j] = fj if v > zero else zero
                    ai[j] = v * fi[j]
            else:
                for j in range(out):
                    v = ai[j] + bias[j]
                    fi[j] = one if v > zero else zero
                    ai[j] = v * fi[j]
        h = a
        column += out
    return outs[last][:n]


@njit(cache=True)
def _errors(out, y):
    """Turn ``out`` into the errors ``out - y`` (0 where ``y`` is not finite); return the sum
    of their squares and the count of finite targets."""
    valid, sq = 0, np.float32(0.0)
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            if np.isfinite(y[i, j]):
                d = out[i, j] - y[i, j]
                out[i, j] = d
                sq += d * d
                valid += 1
            else:
                out[i, j] = 0.0
    return sq, valid


@njit(cache=True)
def _eval_loss(x, y, weights, shapes, root, workspace):
    _, _, outs, factors, _ = _buffers(workspace, x.shape[0], x.shape[1], shapes)
    no_keep = np.empty((0, 0), np.float32)
    r0, drop = np.int64(0), np.float32(0.0)  # the types _sgd_epoch passes: one compilation
    out = _forward(x, weights, shapes, _starts(shapes), outs, factors, no_keep, r0, drop)
    sq, valid = _errors(out, y)
    loss = sq / np.float32(max(valid, 1))
    return np.sqrt(loss) if root else loss


@njit(cache=True)
def _sgd_epoch(
    x,
    y,
    rows,
    bounds,
    batch_weights,
    weights,
    velocity,
    shapes,
    keep,
    drop,
    lr,
    momentum,
    root,
    workspace,
    n_max,
):
    n_layers, starts = shapes.shape[0], _starts(shapes)
    grad = np.zeros_like(weights)
    x_rows, y_rows, outs, factors, back = _buffers(workspace, n_max, x.shape[1], shapes)
    total, count = 0.0, 0.0
    for b in range(len(bounds) - 1):
        r0, n = bounds[b], bounds[b + 1] - bounds[b]
        h, yb = x_rows[:n], y_rows[:n]
        for i in range(n):
            row = rows[r0 + i]  # a scalar index per element: a row slice costs ~1 us each
            for j in range(x.shape[1]):
                h[i, j] = x[row, j]
            for j in range(y.shape[1]):
                yb[i, j] = y[row, j]
        g = _forward(h, weights, shapes, starts, outs, factors, keep, r0, drop)
        sq, valid = _errors(g, yb)
        denominator = np.float32(max(valid, 1))
        loss = sq / denominator
        g *= np.float32(2.0) / denominator
        if root:
            loss = np.sqrt(loss)
            if loss > 0.0:
                g *= np.float32(1.0) / (np.float32(2.0) * loss)
        total += batch_weights[b] * loss
        count += batch_weights[b]
        for k in range(n_layers - 1, -1, -1):
            out, width = shapes[k, 0], shapes[k, 1]
            w0 = starts[k]
            gradient = grad[w0 : w0 + out * width].reshape((width, out))
            np.dot((h if k == 0 else outs[k - 1][:n]).T, g, gradient)  # dE/dW_k^T = h^T g
            for j in range(out):
                s = np.float32(0.0)
                for i in range(n):
                    s += g[i, j]
                grad[w0 + out * width + j] = s
            if k:
                wt = weights[w0 : w0 + out * width].reshape((width, out))
                propagated = back[k][:n]
                np.dot(g, wt.T, propagated)
                f = factors[k - 1][:n]
                for i in range(n):
                    for m in range(width):
                        propagated[i, m] *= f[i, m]
                g = propagated
        for i in range(weights.size):
            velocity[i] = momentum * velocity[i] + grad[i]
            weights[i] -= lr * velocity[i]
    return total / count
