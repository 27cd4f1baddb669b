"""Speed of the per-axis networks of Sun et al. 2022 on the whole thin-wall part:

* ``axis_nn_inference_8_pockets_s``: the chapter's reported network, the ensemble of
  :data:`nctwin.chapters.sun2022.SEEDS` (five seeds x three axes, 2 hidden layers of 5 and 10
  tanh neurons), predicting the axis feeds at every cutter location of the eight pockets (about
  25,000), averaging the seeds and summing eq. 9-10 per pocket
  (:func:`nctwin.chapters.sun2022.predict_times`: each network runs once over all pockets), one
  torch thread (target < 0.05 s);
* ``axis_nn_inference_8_pockets_one_seed_s``: the same with one seed (three networks), the
  paper's own set-up (target < 0.05 s). The
  features (eq. 5-8) are built beforehand, as the chapter builds them with the runs; the weights
  are the untrained initial ones: inference time does not depend on their values.
* ``axis_nn_features_8_pockets_s``: building those features from the eight parsed programs
  (:func:`nctwin.methods.sun2022.features`; no target: for scale).

Both are the shortest of 15 runs after 2 warm-ups (``_common.best_time_s``).
"""

from __future__ import annotations

from pathlib import Path

import torch
from _common import best_time_s, record

from nctwin.chapters.sun2022 import SEEDS, TRAIN_CONFIG, predict_times, run_pockets
from nctwin.learn.models import build
from nctwin.learn.train import Scaler, Trained
from nctwin.machine import load_profile
from nctwin.methods.sun2022 import MODEL_CONFIG, features


def main() -> None:
    torch.set_num_threads(1)
    profile = load_profile("sun2022_siemens")
    runs = run_pockets(profile)
    x = [r.features[:, a] for r in runs.values() for a in range(3)]
    y = [r.measured_feed_mm_s[:, :1] for r in runs.values()]
    members = [
        [
            Trained(
                build(MODEL_CONFIG, generator=torch.Generator().manual_seed(3 * s + a)).eval(),
                *(Scaler.fit(x), Scaler.fit(y), TRAIN_CONFIG, {}, 0, 0.0, Path("untrained.pt")),
            )
            for a in range(3)
        ]
        for s in SEEDS
    ]
    t = best_time_s(lambda: predict_times(members, list(runs.values())))
    record("axis_nn_inference_8_pockets_s", round(t, 5), "s", "< 0.05")
    t = best_time_s(lambda: predict_times(members[:1], list(runs.values())))
    record("axis_nn_inference_8_pockets_one_seed_s", round(t, 5), "s", "< 0.05")
    rapid_mm_s = profile.machine.rapid_feed_mm_s
    t = best_time_s(lambda: [features(r.toolpath, rapid_mm_s) for r in runs.values()])
    record("axis_nn_features_8_pockets_s", round(t, 5), "s", "for scale")


if __name__ == "__main__":
    main()
