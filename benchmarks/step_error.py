"""Speed of the step error of one Zhang et al. 2023 surface (surface 2: 200 lines x 100 CC
points, 19,800 CL segments, R = 5 mm), three ways:

* ``step_error_exact_vectorised_s``: the exact (Newton) method on all segments at once
  (target < 0.1 s; the paper's geometric method: 9.27 s);
* ``step_error_iterative_s``: the per-segment Brent loop, timed on every 20th segment and scaled
  to 19,800 (no target: the baseline);
* ``step_error_nn_inference_s``: the BP network (325 -> 28 -> 20 -> 1) predicting 19,800 Table 1
  samples with :func:`nctwin.chapters.zhang2023.predict_um`, the chapter's prediction: from the
  inputs,
  already built (float64, (19,800, 325)), and the model, already loaded, to the step errors in
  um (Z-score folded into the first layer, forward pass, back-scaling), one torch thread
  (target < 0.05 s; the paper: 2.86 s with model import, on a GPU). Building the inputs from
  the surface is not part of it (the chapter times it apart, about 0.5 s). The weights are the
  untrained initial ones: inference time does not depend on their values.

The exact method and the network are timed as the shortest of 15 runs after 2 warm-ups
(``_common.best_time_s``); the iterative method runs once.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import torch
from _common import best_time_s, record

from nctwin.chapters.zhang2023 import predict_um
from nctwin.learn.models import BPConfig, build_bp
from nctwin.learn.train import Scaler, TrainConfig, Trained
from nctwin.physics.steperror import (
    inner_points_for_hidden_width,
    step_error_iterative_um,
    step_error_samples,
    step_error_um,
)
from nctwin.physics.surfaces import iso_parametric_path, paper_surface


def main() -> None:
    torch.set_num_threads(1)
    path = iso_parametric_path(paper_surface(2))
    t = best_time_s(lambda: step_error_um(path))
    record("step_error_exact_vectorised_s", round(t, 5), "s", "< 0.1")

    every = np.arange(0, path.n_segments, 20)
    t0 = time.perf_counter()
    step_error_iterative_um(path, segments=every)
    t = (time.perf_counter() - t0) * path.n_segments / len(every)
    record("step_error_iterative_s", round(t, 3), "s", "baseline")

    x = step_error_samples(path, inner_points_for_hidden_width(28))
    y = step_error_um(path).error_um[:, None]
    config = BPConfig(n_inputs=x.shape[1])
    model = build_bp(config, generator=torch.Generator().manual_seed(0)).eval()
    trained = Trained(
        model, Scaler.fit([x]), Scaler.fit([y]), TrainConfig(), {}, 0, 0.0, Path("untrained.pt")
    )
    t = best_time_s(lambda: predict_um(trained, x))
    record("step_error_nn_inference_s", round(t, 5), "s", "< 0.05")


if __name__ == "__main__":
    main()
