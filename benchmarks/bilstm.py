"""BiLSTM inference time on the ~4700-G-line pocket (Chien et al. 2023, Table 2): one forward
pass over the whole program, untrained weights of the chapter's architecture (the time does not
depend on the weights)."""

from __future__ import annotations

import numpy as np
import torch
from _common import best_time_s, record

from nctwin import gcode
from nctwin.chapters import chien2023 as ch
from nctwin.learn.models import ModelConfig, build
from nctwin.learn.train import Scaler, TrainConfig, Trained
from nctwin.methods.chien2023 import features as chien2023_features
from nctwin.programs.pocket import pocket_program
from nctwin.toolpath import Toolpath


def main() -> None:
    tp: Toolpath = ch.cutting_blocks(gcode.parse(pocket_program(feed_mm_s=92.0, tol_mm=0.4)))
    x = chien2023_features(tp, 0.4)
    model = build(ModelConfig("bilstm", n_outputs=2), generator=torch.Generator().manual_seed(0))
    model.eval()
    scaler = Scaler.fit([x], log_columns=[1])
    trained = Trained(model, scaler, Scaler(np.zeros(2), np.ones(2)), TrainConfig(), {}, 0, 0.0,
                      ch.paths.cache_dir())  # fmt: skip
    torch.set_num_threads(1)
    t = best_time_s(lambda: trained.predict(x))
    record("bilstm_inference_pocket_s", t, "s", f"< 0.020 s for {len(x)} G-lines")


if __name__ == "__main__":
    main()
