"""BiLSTM inference time on the Table 2 pocket of Chien et al. (2023) (about 5000 G-lines): one
forward pass over the whole program, untrained weights of the chapter's architecture (the time
does not depend on the weights); one network, and the chapter's ensemble of five."""

from __future__ import annotations

import numpy as np
import torch
from _common import best_time_s, record

from nctwin import gcode
from nctwin.chapters import chien2023 as ch
from nctwin.learn.models import ModelConfig, build
from nctwin.learn.train import Scaler, TrainConfig, Trained
from nctwin.methods.chien2023 import features as chien2023_features
from nctwin.paths import cache_dir
from nctwin.programs.band_pocket import paper_pocket_program
from nctwin.toolpath import Toolpath


def main() -> None:
    text = paper_pocket_program("table2", feed_mm_s=92.0, tol_mm=0.4)
    tp: Toolpath = ch.cutting_blocks(gcode.parse(text))
    x = chien2023_features(tp, 0.4)
    scaler = Scaler.fit([x], log_columns=[1])
    members = []
    for seed in range(5):
        model = build(ModelConfig("bilstm", n_outputs=2),
                      generator=torch.Generator().manual_seed(seed))  # fmt: skip
        model.eval()
        members.append(Trained(model, scaler, Scaler(np.zeros(2), np.ones(2)), TrainConfig(), {},
                               0, 0.0, cache_dir()))  # fmt: skip
    torch.set_num_threads(1)
    t = best_time_s(lambda: members[0].predict(x))
    record("bilstm_inference_pocket_s", t, "s", f"< 0.020 s for {len(x)} G-lines")
    t5 = best_time_s(lambda: [m.predict(x) for m in members])
    record("bilstm_ensemble5_inference_pocket_s", t5, "s", "five networks: five times one")


if __name__ == "__main__":
    main()
