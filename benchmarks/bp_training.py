"""Speed of one training step of Zhang et al. 2023's BP network (325 -> 28 -> 20 -> 1, batches
of 128 rows, SGD with momentum 0.8), one thread: ``bp_step_autograd_ms``, the step by autograd
and :func:`torch.optim.sgd.sgd` that the training loop runs for it (on a batch's rows as one
matrix), per step, the shortest of 15 runs (after 2 warm-ups); ``bp_stack_speedup``, five
such networks stepped as one stack (:mod:`nctwin.learn.stack`, how the chapter trains them)
against five single steps. The chapter's wall time on an empty cache (its notebook has 6 min on
two cores) is the target that matters; this is its largest part.
"""

from __future__ import annotations

import torch
from _common import best_time_s, record

from nctwin.learn.models import BPConfig, build_bp
from nctwin.learn.stack import _Stack
from nctwin.learn.train import _SGD, TrainConfig, _autograd_step

STEPS = 200


def main() -> None:
    torch.set_num_threads(1)
    config = BPConfig(n_inputs=325, dropout=0.0, weight_init="uniform")
    g = torch.Generator().manual_seed(0)
    bx, by = torch.randn(128, 325, generator=g), torch.randn(128, 1, generator=g)
    mask = torch.ones(128, 1, dtype=torch.bool)
    model = build_bp(config, generator=torch.Generator().manual_seed(0)).train()
    optimiser = _SGD(model.parameters(), lr=1e-4, momentum=0.8)
    t = (
        best_time_s(
            lambda: [_autograd_step(model, optimiser, "mse", bx, by, mask) for _ in range(STEPS)]
        )
        / STEPS
    )
    record("bp_step_autograd_ms", round(1e3 * t, 4), "ms", "baseline")
    nets = [build_bp(config, generator=torch.Generator().manual_seed(s)) for s in range(5)]
    cfg = TrainConfig(learning_rate=1e-4, loss="mse", optimiser="sgd", momentum=0.8)
    stack = _Stack(nets, cfg)
    sx, sy = bx.expand(5, -1, -1), by.expand(5, -1, -1)
    smask = torch.ones(5, 128, 1)
    t5 = best_time_s(lambda: [stack.step(sx, sy, smask, None) for _ in range(STEPS)]) / STEPS
    record("bp_stack_speedup", round(5 * t / t5, 2), "x", ">= 1.5 (five networks, one stack)")


if __name__ == "__main__":
    main()
