"""Speed of one training step of Zhang et al. 2023's BP network (325 -> 28 -> 20 -> 1, batches
of 128 rows, SGD with momentum 0.8, the chapter's converging variant), one thread:

* ``bp_step_written_out_ms``: :class:`nctwin.learn.bp_sgd.BPEpoch`, what the training loop runs
  for this network, over an epoch of 97 batches drawn from 13,860 rows, per batch (target
  < 0.25 ms: the chapter trains about 1.5 million such steps, and its notebook has 3 min on two
  cores);
* ``bp_step_autograd_ms``: the same step by autograd and :class:`torch.optim.SGD` (the
  baseline, the loop's step for every other network), without the batch gather.

Both are the shortest of 15 runs (after 2 warm-ups).
"""

from __future__ import annotations

import numpy as np
import torch
from _common import best_time_s, record
from threadpoolctl import threadpool_limits

from nctwin.learn.bp_sgd import BPEpoch
from nctwin.learn.models import BPConfig, build_bp
from nctwin.learn.train import _autograd_step

STEPS = 200


def main() -> None:
    torch.set_num_threads(1)
    config = BPConfig(n_inputs=325, dropout=0.0, weight_init="uniform")

    rng = np.random.default_rng(0)
    x = rng.standard_normal((13_860, 325)).astype(np.float32)
    y = rng.standard_normal((13_860, 1)).astype(np.float32)
    rows = rng.permutation(12_416)
    bounds = np.arange(0, 12_417, 128)
    epoch = BPEpoch(build_bp(config, generator=torch.Generator().manual_seed(0)), 1e-4, 0.8,
                    "mse", seed=0)  # fmt: skip
    with threadpool_limits(1, user_api="blas"):
        t = best_time_s(lambda: epoch(x, y, rows, bounds, np.ones(len(bounds) - 1)))
    record("bp_step_written_out_ms", round(1e3 * t / (len(bounds) - 1), 4), "ms", "< 0.25")

    g = torch.Generator().manual_seed(0)
    bx, by = torch.randn(16, 8, 325, generator=g), torch.randn(16, 8, 1, generator=g)
    mask = torch.ones(16, 8, 1, dtype=torch.bool)
    model = build_bp(config, generator=torch.Generator().manual_seed(0)).train()
    optimiser = torch.optim.SGD(model.parameters(), lr=1e-4, momentum=0.8)
    t = (
        best_time_s(
            lambda: [_autograd_step(model, optimiser, "mse", bx, by, mask) for _ in range(STEPS)]
        )
        / STEPS
    )
    record("bp_step_autograd_ms", round(1e3 * t, 4), "ms", "baseline")


if __name__ == "__main__":
    main()
