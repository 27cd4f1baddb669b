"""Several BP networks trained at once, as one stack of weights.

:func:`fit_stack` trains each member as :func:`nctwin.learn.train.fit` would train it alone,
with one difference: the layers of all members run as one :func:`torch.baddbmm` per layer, and
one SGD step updates them all. A small network's step is mostly fixed cost (autograd, the
optimiser, the Python around them), which the stack pays once: five 325-28-20-1 networks on
batches of 128 rows step about twice as fast as five single networks
(``benchmarks/bp_training.py``).

What each member keeps of :func:`~nctwin.learn.train.fit`
    Its own split into training and validation programs (from its seed), its scalers (fitted on
    its training programs, or its ``init``'s), its initial weights, window offsets and batch
    order (the same draws from the same seeds), dropout masks from its own generator seeded
    with its seed, its early stopping, its history and its checkpoint. A member that has
    stopped leaves the stack; the others go on.
What differs
    A batched product sums in another order than :func:`torch.nn.functional.linear`: a member's
    weights differ from :func:`~nctwin.learn.train.fit`'s in the last bits. Its checkpoint key
    says so (``"stacked": True``), so that :func:`~nctwin.learn.train.fit` never loads it.
    Each member's arithmetic is its own (no product or sum mixes members), so its weights do
    not depend on the other members of its stack; a test checks this bit for bit.

Members may differ in their training seed and their dropout probability only; they share the
data, the network's shape and every other setting, and train by SGD (``optimiser="sgd"``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import torch
from torch import nn
from torch.optim.sgd import sgd

from ..cache import atomic_write_text
from .models import BPConfig, BPNetwork, build_bp
from .train import (
    _BATCHES_PER_GATHER,
    Scaler,
    TrainConfig,
    Trained,
    _loss,
    _Programs,
    _split,
    _windows,
    checkpoint_path,
    data_hash,
    deterministic,
    load_checkpoint,
    save_checkpoint,
    scaled_programs,
)

__all__ = ["fit_stack"]


@dataclass(eq=False)
class _Member:
    """One network of the stack: its data, draws and early-stopping record."""

    model_config: BPConfig
    cfg: TrainConfig
    path: Path
    x_scaler: Scaler
    y_scaler: Scaler
    programs: _Programs
    validation: tuple[torch.Tensor, torch.Tensor, torch.Tensor]  # rows x, y, float mask
    rng: np.random.Generator
    dropout_rng: torch.Generator
    history: dict = field(default_factory=lambda: {"train": [], "val": []})
    best: float = math.inf
    best_state: dict | None = None
    best_epoch: int = 0
    stale: int = 0
    diverged: bool = False


def _check_members(model_configs, train_configs) -> None:
    if not model_configs or len(model_configs) != len(train_configs):
        raise ValueError(
            f"model_configs and train_configs hold {len(model_configs)} and "
            f"{len(train_configs)} configs: allowed the same number, at least 1"
        )
    m0, t0 = model_configs[0], train_configs[0]
    for m, t in zip(model_configs, train_configs, strict=True):
        if not isinstance(m, BPConfig) or replace(m, dropout=m0.dropout) != m0:
            raise ValueError(f"model config {m!r} differs from {m0!r} in more than dropout")
        if replace(t, seed=t0.seed) != t0:
            raise ValueError(f"train config {t!r} differs from {t0!r} in more than seed")
    if t0.optimiser != "sgd":
        raise ValueError(f"optimiser = {t0.optimiser!r}: allowed sgd (a stack trains by SGD)")


def fit_stack(
    model_configs: Sequence[BPConfig],
    train_configs: Sequence[TrainConfig],
    xs: Sequence[np.ndarray],
    ys: Sequence[np.ndarray],
    *,
    names: Sequence[str],
    init: Sequence[Trained] | None = None,
    cache: bool = True,
) -> list[Trained | None]:
    """Train one BP network per config on programs ``xs``/``ys``, as one stack (see the module
    docstring), or load the cached checkpoints.

    Parameters
    ----------
    model_configs : sequence of BPConfig
        One per member; they may differ in ``dropout`` only.
    train_configs : sequence of TrainConfig
        One per member; they may differ in ``seed`` only; ``optimiser="sgd"``.
    xs, ys : sequences of ndarray, shapes (N_i, n_inputs) and (N_i, n_outputs)
        One entry per program, the same for every member.
    names : sequence of str
        Prefix of each member's checkpoint file.
    init : sequence of Trained, optional
        Fine-tune: each member starts from its entry's weights and keeps its scalers.
    cache : bool
        Load the members whose checkpoints exist; save the others.

    Returns
    -------
    list of Trained or None
        One per member, in order; None for a member whose training diverged (no epoch had a
        finite validation loss), which leaves ``<name>-<hash>.diverged`` as
        :func:`~nctwin.learn.train.fit` does. A member's ``train_seconds`` is the stack's wall
        time until that member stopped.

    Raises
    ------
    ValueError
        If the configs differ in more than the above, or ``names`` or ``init`` do not hold
        one entry per member.
    """
    _check_members(model_configs, train_configs)
    n = len(model_configs)
    inits = list(init) if init is not None else [None] * n
    if len(names) != n or len(inits) != n:
        raise ValueError(
            f"names and init hold {len(names)} and {len(inits)} entries: allowed {n}, one per "
            "member"
        )
    data_key = data_hash(xs, ys)
    paths = [
        checkpoint_path(name, m, t, data_key, init=i, stacked=True)
        for name, m, t, i in zip(names, model_configs, train_configs, inits, strict=True)
    ]
    out: list[Trained | None] = [None] * n
    todo = []
    for k, path in enumerate(paths):
        if cache and path.with_suffix(".diverged").exists():
            continue
        if cache and path.exists():
            out[k] = load_checkpoint(path)
        else:
            todo.append(k)
    if todo:
        with deterministic():
            trained = _train_stack(
                [model_configs[k] for k in todo], [train_configs[k] for k in todo], xs, ys,
                [paths[k] for k in todo], [inits[k] for k in todo],
            )  # fmt: skip
        for k, net in zip(todo, trained, strict=True):
            out[k] = net
            if cache and net is None:
                atomic_write_text(
                    paths[k].with_suffix(".diverged"),
                    f"{paths[k].stem}: the validation loss was never finite (the training "
                    f"diverged); learning_rate = {train_configs[k].learning_rate!r} may be "
                    "too large",
                )
            elif cache:
                save_checkpoint(net)
    return out


def _member(model_config, cfg, xs, ys, path, init) -> _Member:
    x_scaler, y_scaler, programs, validation = scaled_programs(
        cfg, xs, ys, _split(len(xs), cfg), init
    )
    w = cfg.window_lines
    x, y, mask = (
        t.flatten(0, 1) for t in validation.batch(_windows(validation.lengths, w, None), w)
    )
    return _Member(
        model_config, cfg, path, x_scaler, y_scaler, programs,
        (x, y, mask.to(torch.float32)), np.random.default_rng([cfg.seed, 2]),
        torch.Generator().manual_seed(cfg.seed),
    )  # fmt: skip


class _Stack:
    """The members' weights as one (S, out, in) tensor and one (S, out) tensor per layer, with
    their SGD momentum buffers."""

    def __init__(self, nets: Sequence[BPNetwork], cfg: TrainConfig) -> None:
        linears = [[m for m in net.layers if isinstance(m, nn.Linear)] for net in nets]
        self.params = []
        for layer in zip(*linears, strict=True):
            self.params.append(torch.stack([m.weight.detach() for m in layer]).requires_grad_())
            self.params.append(torch.stack([m.bias.detach() for m in layer]).requires_grad_())
        self.keys = [
            f"layers.{i}.{kind}"
            for i, m in enumerate(nets[0].layers) if isinstance(m, nn.Linear)
            for kind in ("weight", "bias")
        ]  # fmt: skip
        self.cfg = cfg
        self.buffers: list[torch.Tensor | None] = [None] * len(self.params) if cfg.momentum else []

    def forward(self, x: torch.Tensor, masks=None, *, member: int | None = None):
        """Outputs (S, R, n_outputs) of inputs (S, R, n_inputs).

        ``masks``: one scaled dropout mask (S, R, width) per hidden layer, or None (no
        dropout). ``member``: run that member's network alone on inputs (1, R, n_inputs)."""
        params = self.params if member is None else [p[member : member + 1] for p in self.params]
        h, n_layers = x, len(params) // 2
        for j in range(n_layers):
            w, b = params[2 * j], params[2 * j + 1].unsqueeze(1)
            if w.shape[1] == 1:  # a product with one output column picks another kernel
                h = (h * w).sum(-1, keepdim=True) + b  # in a stack of one: a member's own sum
            else:
                h = torch.baddbmm(b, h, w.transpose(1, 2))
            if j < n_layers - 1:
                h = torch.relu(h)
                if masks is not None:
                    h = h * masks[j]
        return h

    def step(self, x, y, mask, masks) -> torch.Tensor:
        """One SGD step of every member; their batch losses (S,), before the step."""
        se = ((self.forward(x, masks) - y) ** 2 * mask).sum(dim=(1, 2))
        loss = se / mask.sum(dim=(1, 2)).clamp(min=1)
        if self.cfg.loss == "rmse":
            loss = loss.sqrt()
        for p in self.params:
            p.grad = None
        loss.sum().backward()
        with torch.no_grad():
            sgd(self.params, [p.grad for p in self.params], self.buffers, weight_decay=0.0,
                momentum=self.cfg.momentum, lr=self.cfg.learning_rate, dampening=0.0,
                nesterov=False, maximize=False, foreach=True, has_sparse_grad=False)  # fmt: skip
        return loss.detach()

    def state(self, k: int) -> dict:
        """Member ``k``'s weights, as a :class:`BPNetwork` state dict (copies)."""
        return {key: p[k].detach().clone() for key, p in zip(self.keys, self.params, strict=True)}

    def has_nan(self, k: int) -> bool:
        return any(bool(torch.isnan(p[k]).any()) for p in self.params)

    def keep(self, rows: Sequence[int]) -> None:
        """Keep members ``rows`` only (their weights and momentum buffers, as they are)."""
        index = torch.tensor(rows, dtype=torch.long)
        self.params = [p.detach()[index].requires_grad_() for p in self.params]
        self.buffers = [b[index] if b is not None else None for b in self.buffers]


def _train_stack(model_configs, cfgs, xs, ys, paths, inits) -> list[Trained | None]:
    t0 = time.perf_counter()
    members, nets = [], []
    for model_config, c, path, init in zip(model_configs, cfgs, paths, inits, strict=True):
        members.append(_member(model_config, c, xs, ys, path, init))
        net = build_bp(model_config, generator=torch.Generator().manual_seed(c.seed))
        if init is not None:
            net.load_state_dict(init.model.state_dict())
        nets.append(net)
    cfg = cfgs[0]
    stack = _Stack(nets, cfg)
    active = list(range(len(members)))  # members in the stack, in its order
    done: dict[int, Trained | None] = {}
    w, chunk = cfg.window_lines, cfg.batch_size * _BATCHES_PER_GATHER
    widths = model_configs[0].hidden
    for epoch in range(1, cfg.max_epochs + 1):
        group = [members[k] for k in active]
        orders = []
        for m in group:
            windows = _windows(m.programs.lengths, w, m.rng)
            orders.append(windows[m.rng.permutation(len(windows))])
        n_windows = len(orders[0])
        totals = np.zeros(len(group))
        for c in range(0, n_windows, chunk):
            xs_, ys_, ms_ = _gather(group, [o[c : c + chunk] for o in orders], w)
            for b in range(0, xs_.shape[1], cfg.batch_size):
                bx, by, bm = (t[:, b : b + cfg.batch_size].flatten(1, 2) for t in (xs_, ys_, ms_))
                masks = _dropout_masks(group, bx.shape[1], widths)
                losses = stack.step(bx, by, bm, masks).tolist()
                count = min(cfg.batch_size, xs_.shape[1] - b)
                for j, (m, loss) in enumerate(zip(group, losses, strict=True)):
                    if m.best_state is None and not math.isfinite(loss) and stack.has_nan(j):
                        m.diverged = True
                    totals[j] += loss * count
        stopped = []
        for j, m in enumerate(group):
            if m.diverged:
                stopped.append(j)
                continue
            val = _validate(stack, j, m)
            m.history["train"].append(float(totals[j] / n_windows))
            m.history["val"].append(val)
            if val < m.best:
                m.best, m.best_state, m.best_epoch, m.stale = val, stack.state(j), epoch, 0
            else:
                m.stale += 1
                if m.stale >= cfg.patience:
                    stopped.append(j)
        if epoch == cfg.max_epochs:
            stopped = list(range(len(group)))
        for j in stopped:
            done[active[j]] = _trained(group[j], nets[active[j]], time.perf_counter() - t0)
        if stopped:
            keep = [j for j in range(len(group)) if j not in stopped]
            if not keep:
                break
            stack.keep(keep)
            active = [active[j] for j in keep]
    return [done[k] for k in range(len(members))]


def _gather(group: Sequence[_Member], windows: Sequence[np.ndarray], w: int):
    """The members' batches of ``windows`` (one (B, 3) array each, as
    :meth:`~nctwin.learn.train._Programs.batch` takes) as (S, B, w, n) inputs and targets and
    an (S, B, w, 1) float32 mask, gathered into one array each."""
    b = len(windows[0])
    x = np.empty((len(group), b, w, group[0].programs.x.shape[1]), dtype=np.float32)
    y = np.empty((len(group), b, w, group[0].programs.y.shape[1]), dtype=np.float32)
    masks = [m.programs.batch(win, w, out=(x[j], y[j]))[2]
             for j, (m, win) in enumerate(zip(group, windows, strict=True))]  # fmt: skip
    return torch.from_numpy(x), torch.from_numpy(y), torch.stack(masks).to(torch.float32)


def _dropout_masks(group: Sequence[_Member], rows: int, widths) -> list[torch.Tensor] | None:
    """One scaled mask (S, rows, width) per hidden layer, each member's from its own generator
    (ones where its dropout is 0); None if no member drops."""
    if all(m.model_config.dropout == 0.0 for m in group):
        return None
    masks = []
    for width in widths:
        layer = torch.ones(len(group), rows, width)
        for j, m in enumerate(group):
            p = m.model_config.dropout
            if p > 0.0:
                layer[j].bernoulli_(1.0 - p, generator=m.dropout_rng).div_(1.0 - p)
        masks.append(layer)
    return masks


def _validate(stack: _Stack, j: int, m: _Member) -> float:
    """Member ``j``'s validation loss, alone (no padding shared with the other members)."""
    x, y, mask = m.validation
    with torch.no_grad():
        return float(_loss(stack.forward(x[None], member=j)[0], y, mask, m.cfg.loss))


def _trained(m: _Member, net: BPNetwork, seconds: float) -> Trained | None:
    """The member's network with its best weights, or None if it diverged."""
    if m.best_state is None:
        return None
    net.load_state_dict(m.best_state)
    net.eval()
    return Trained(net, m.x_scaler, m.y_scaler, m.cfg, m.history, m.best_epoch, seconds, m.path)
