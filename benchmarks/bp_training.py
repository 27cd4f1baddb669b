"""Speed of one training step of Zhang et al. 2023's BP network (325 -> 28 -> 20 -> 1, batches
of 128 rows, SGD with momentum 0.8, the chapter's converging variant), one torch thread:

* ``bp_step_written_out_ms``: :class:`nctwin.learn.bp_sgd.BPStep`, the step the training loop
  runs for this network (target < 0.4 ms: the chapter trains about 2.5 million such steps);
* ``bp_step_autograd_ms``: the same step by autograd and :class:`torch.optim.SGD` (the
  baseline, the loop's step for every other network).

Both are the shortest of 15 runs of 200 steps (after 2 warm-ups), per step.
"""

from __future__ import annotations

import torch
from _common import best_time_s, record

from nctwin.learn.bp_sgd import BPStep
from nctwin.learn.models import BPConfig, build_bp
from nctwin.learn.train import _autograd_step

STEPS = 200


def main() -> None:
    torch.set_num_threads(1)
    g = torch.Generator().manual_seed(0)
    x, y = torch.randn(16, 8, 325, generator=g), torch.randn(16, 8, 1, generator=g)
    mask = torch.ones(16, 8, 1, dtype=torch.bool)
    config = BPConfig(n_inputs=325, dropout=0.0, weight_init="uniform")

    model = build_bp(config, generator=torch.Generator().manual_seed(0))
    step = BPStep(model, 1e-4, 0.8, "mse")
    t = best_time_s(lambda: [step(x, y, mask) for _ in range(STEPS)]) / STEPS
    record("bp_step_written_out_ms", round(1e3 * t, 4), "ms", "< 0.4")

    model = build_bp(config, generator=torch.Generator().manual_seed(0)).train()
    optimiser = torch.optim.SGD(model.parameters(), lr=1e-4, momentum=0.8)
    t = (
        best_time_s(
            lambda: [_autograd_step(model, optimiser, "mse", x, y, mask) for _ in range(STEPS)]
        )
        / STEPS
    )
    record("bp_step_autograd_ms", round(1e3 * t, 4), "ms", "baseline")


if __name__ == "__main__":
    main()
