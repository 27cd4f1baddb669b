"""Sun et al. (2022): one feed-forward network per axis predicts the axis feeds at every cutter
location, and from them the machining time.

The chapter's pipeline, kept out of the notebook:

1. :func:`run_pockets` runs the eight pocket programs of :mod:`nctwin.programs.thinwall` on the
   FIR kernel (the "machine"), records each at about 5 Hz with jitter (the paper's measuring
   device), and pairs every cutter location with the nearest record (the paper's targets). It
   also keeps the true axis feeds at each cutter location (1 kHz), which the paper did not have.
2. :func:`train_axis_models` fits one network per axis (Table 1 features, 2 hidden tanh layers of
   5 and 10, linear output, MSE) on the training pockets of Table 2, validating on the first half
   of pocket 4, with :func:`nctwin.train.fit`.
3. :func:`predict_time` turns the predicted axis feeds into the resultant feed (eq. 9) and the
   machining time (eq. 10).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from joblib import Parallel, delayed

from .estimate import estimate
from .features import block_targets, sun2022_features
from .gcode import parse
from .kernel import fir
from .machine import MachineProfile
from .measure import ControllerSamples, controller_samples, nearest_sample
from .models import ModelConfig
from .motion import Motion
from .programs.thinwall import HOME_MM, POCKETS, pocket_program
from .toolpath import MotionKind, Toolpath
from .train import TrainConfig, Trained, fit

__all__ = [
    "MODEL_CONFIG",
    "PocketRun",
    "oracle_time",
    "predict_feeds",
    "predict_time",
    "run_pocket",
    "run_pockets",
    "time_table",
    "train_axis_models",
]

#: The paper's network: 9 features, hidden layers of 5 and 10 tanh neurons, one linear output.
MODEL_CONFIG = ModelConfig(kind="mlp", n_inputs=9, n_outputs=1, mlp_widths=(5, 10))

#: Lowest resultant feed eq. 10 divides by, as a share of the commanded feed: a network that
#: predicts a standstill on a cutting move would otherwise give an infinite time.
MIN_FEED_SHARE = 0.01


@dataclass(frozen=True, eq=False)
class PocketRun:
    """One pocket run on the machine and recorded.

    Parameters
    ----------
    number : int
    toolpath : Toolpath
        The program's blocks of non-zero length (cutter location n = end of block n).
    motion : Motion
        The machine's motion (1 ms).
    records : ControllerSamples
        What the 5 Hz logger recorded.
    features : ndarray, shape (N, 3, 9)
        :func:`nctwin.features.sun2022_features`.
    measured_feed_mm_s : ndarray, shape (N, 3)
        Axis feeds of the record nearest to each cutter location (the paper's targets).
    true_feed_mm_s : ndarray, shape (N, 3)
        Average axis feeds over each block, from the 1 kHz motion: the displacement between
        the junction points before and after cutter location n over the time between them
        (Chien et al. 2023, eq. 1-2). This is the feed eq. 10 needs; the instantaneous feed at
        the cutter location is the corner's dip, which eq. 10 would spread over the whole block.
    commanded_mm_s : ndarray, shape (N,)
        Commanded feed of each block (the rapid feed for G0).
    cam_s : float
        CAD/CAM time (:func:`nctwin.estimate.cam`).
    """

    number: int
    toolpath: Toolpath
    motion: Motion
    records: ControllerSamples
    features: np.ndarray
    measured_feed_mm_s: np.ndarray
    true_feed_mm_s: np.ndarray
    commanded_mm_s: np.ndarray
    cam_s: float

    @property
    def measured_s(self) -> float:
        """Machining time on the machine."""
        return self.motion.cycle_time_s


def run_pocket(
    text: str,
    number: int,
    machine: MachineProfile,
    *,
    rate_hz: float = 5.0,
    jitter_s: float = 0.03,
    seed: int = 0,
) -> PocketRun:
    """Run one pocket program on the FIR kernel and record it; see the module docstring."""
    parsed = parse(text, start_mm=HOME_MM, source=f"pocket {number}")
    tp = parsed.take(parsed.lengths_mm > 0)
    motion = fir.run(tp, machine)
    junction = block_targets(motion, tp).junction_sample
    passage = junction[1:]
    dt = np.diff(junction)[:, None] * motion.period_s
    moved = np.diff(motion.pos_mm[junction], axis=0)
    block_avg = np.divide(moved, dt, out=np.zeros_like(moved), where=dt > 0)
    records = controller_samples(motion, rate_hz=rate_hz, jitter_s=jitter_s, seed=seed)
    nearest = nearest_sample(records, tp.end_mm, motion.t_s[passage])
    commanded = np.where(tp.kind == MotionKind.RAPID, machine.rapid_feed_mm_s, tp.feed_mm_s)
    return PocketRun(
        number=number,
        toolpath=tp,
        motion=motion,
        records=records,
        features=sun2022_features(tp, machine.rapid_feed_mm_s),
        measured_feed_mm_s=records.vel_mm_s[nearest],
        true_feed_mm_s=block_avg,
        commanded_mm_s=commanded,
        cam_s=estimate(tp, machine, "cam").cycle_time_s,
    )


def run_pockets(
    machine: MachineProfile, *, seed: int = 0, n_jobs: int = 1, **kwargs
) -> dict[int, PocketRun]:
    """All eight pockets, in parallel through joblib (``n_jobs``); each pocket's record jitter
    is seeded with ``seed + number``. ``kwargs`` go to :func:`run_pocket`."""
    jobs = (
        delayed(run_pocket)(
            pocket_program(spec), spec.number, machine, seed=seed + spec.number, **kwargs
        )
        for spec in POCKETS
    )
    runs = Parallel(n_jobs=n_jobs)(jobs)
    return {r.number: r for r in runs}


def _half(run: PocketRun, second: bool) -> slice:
    mid = len(run.toolpath) // 2
    return slice(mid, None) if second else slice(0, mid)


def train_axis_models(
    runs: dict[int, PocketRun],
    train_pockets: tuple[int, ...],
    *,
    validation_pocket: int = 4,
    target: str = "measured",
    train_config: TrainConfig | None = None,
    name: str = "sun2022",
) -> list[Trained]:
    """One network per axis (X, Y, Z), trained on ``train_pockets`` and validated on the first
    half of ``validation_pocket`` (Sun et al. 2022, Table 2).

    Parameters
    ----------
    runs : dict of PocketRun
    train_pockets : tuple of int
        Pockets to train on (model #1: ``(1,)``; model #2: ``(1, 5, 8)``).
    validation_pocket : int
        Its first half validates (early stopping); its second half is the test set.
    target : {"measured", "true"}
        The 5 Hz nearest record (the paper's) or the 1 kHz block-average axis feed.
    train_config : TrainConfig, optional
        Defaults to MSE loss, seed 0.
    name : str
        Checkpoint name prefix.
    """
    if target not in ("measured", "true"):
        raise ValueError(f"target = {target!r} is unknown: allowed measured, true")
    cfg = train_config or TrainConfig(
        loss="mse", window_lines=256, batch_size=8, max_epochs=400, patience=40, learning_rate=1e-2
    )
    val_run = runs[validation_pocket]
    first = _half(val_run, second=False)
    models = []
    for axis in range(3):

        def ys(run: PocketRun, sl: slice = slice(None), a: int = axis) -> np.ndarray:
            feed = run.measured_feed_mm_s if target == "measured" else run.true_feed_mm_s
            return feed[sl, a : a + 1]

        models.append(
            fit(
                MODEL_CONFIG,
                cfg,
                [runs[p].features[:, axis] for p in train_pockets],
                [ys(runs[p]) for p in train_pockets],
                validation=([val_run.features[first, axis]], [ys(val_run, first)]),
                name=f"{name}-{target}-{'-'.join(map(str, train_pockets))}-{'xyz'[axis]}",
                progress=False,
            )
        )
    return models


def predict_feeds(models: list[Trained], run: PocketRun) -> np.ndarray:
    """Predicted axis feeds at every cutter location, shape (N, 3)."""
    return np.column_stack([m.predict(run.features[:, a])[:, 0] for a, m in enumerate(models)])


def predict_time(models: list[Trained], run: PocketRun) -> tuple[float, np.ndarray]:
    """Machining time from the predicted axis feeds (eq. 9-10).

    Returns the time (s) and the resultant feed at each cutter location, shape (N,). The
    resultant feed is kept above :data:`MIN_FEED_SHARE` of the commanded feed.
    """
    resultant = np.linalg.norm(predict_feeds(models, run), axis=1)  # eq. 9
    resultant = np.maximum(resultant, MIN_FEED_SHARE * run.commanded_mm_s)
    return float((run.toolpath.lengths_mm / resultant).sum()), resultant  # eq. 10


def time_table(runs: dict[int, PocketRun], models: list[Trained]) -> pd.DataFrame:
    """Per pocket: measured, CAD/CAM and network machining times with errors (Tables 3-4).

    Errors are signed, (predicted - measured) / measured * 100: negative is an underestimate.
    """
    rows = []
    for k, run in runs.items():
        nn_s, _ = predict_time(models, run)
        rows.append(
            {
                "pocket": k,
                "measured_s": run.measured_s,
                "cam_s": run.cam_s,
                "cam_err_pct": 100.0 * (run.cam_s - run.measured_s) / run.measured_s,
                "nn_s": nn_s,
                "nn_err_pct": 100.0 * (nn_s - run.measured_s) / run.measured_s,
            }
        )
    return pd.DataFrame(rows)


def oracle_time(run: PocketRun, target: str = "measured") -> float:
    """Eq. 10 fed with the targets themselves: what a perfect network would give."""
    feed = run.measured_feed_mm_s if target == "measured" else run.true_feed_mm_s
    resultant = np.maximum(np.linalg.norm(feed, axis=1), MIN_FEED_SHARE * run.commanded_mm_s)
    return float((run.toolpath.lengths_mm / resultant).sum())
