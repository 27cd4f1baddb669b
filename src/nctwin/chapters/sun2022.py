"""Sun et al. (2022): one feed-forward network per axis predicts the axis feeds at every cutter
location, and from them the machining time.

The chapter's pipeline, kept out of the notebook:

1. :func:`run_pockets` runs the eight pocket programs of :mod:`nctwin.programs.thinwall` on the
   FIR kernel (the "machine"), records each at about 5 Hz with jitter (the paper's measuring
   device), and pairs every cutter location with the nearest record (the paper's targets). It
   also keeps the true axis feeds at each cutter location (1 kHz), which the paper did not have.
2. :func:`train_axis_models` fits one network per axis (Table 1 features, 2 hidden tanh layers of
   5 and 10, linear output, MSE) on the training pockets of Table 2, validating on the first half
   of pocket 4, with :func:`nctwin.learn.train.fit`.
3. :func:`predict_time` turns the predicted axis feeds into the resultant feed (eq. 9) and the
   machining time (eq. 10).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..estimate import estimate
from ..estimate.kernel import fir_settings
from ..gcode import parse
from ..kernel import fir
from ..learn.train import TrainConfig, Trained, fit
from ..machine import MachineProfile
from ..methods import sun2022 as sun
from ..motion import Motion
from ..physics.measure import ControllerSamples, controller_samples, nearest_sample
from ..programs.thinwall import HOME_MM, POCKETS, pocket_program
from ..report.tables import Claim, error_pct
from ..runner import run_tasks
from ..targets import block_targets
from ..toolpath import MotionKind, Toolpath

__all__ = [
    "PocketRun",
    "claims",
    "oracle_time",
    "predict_feeds",
    "predict_time",
    "run_pocket",
    "run_pockets",
    "time_table",
    "train_axis_models",
]

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
        :func:`nctwin.methods.sun2022.features`.
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
    seed: int = 0,
    *,
    rate_hz: float = 5.0,
    jitter_s: float = 0.03,
) -> PocketRun:
    """Run one pocket program on the FIR kernel and record it; see the module docstring."""
    parsed = parse(text, start_mm=HOME_MM, source=f"pocket {number}")
    tp = parsed.take(parsed.lengths_mm > 0)
    motion = fir.run(tp, machine, fir_settings(machine))
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
        features=sun.features(tp, machine.rapid_feed_mm_s),
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
    tasks = ((pocket_program(spec), spec.number, machine, seed + spec.number) for spec in POCKETS)
    runs = run_tasks(functools.partial(run_pocket, **kwargs), tasks, n_jobs=n_jobs)
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
                sun.MODEL_CONFIG,
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
    feeds = predict_feeds(models, run)
    t = sun.block_times_s(feeds, run.toolpath.lengths_mm, run.commanded_mm_s)
    return float(t.sum()), sun.resultant_feed_mm_s(feeds, run.commanded_mm_s)


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
                "cam_err_pct": error_pct(run.cam_s, run.measured_s, signed=True),
                "nn_s": nn_s,
                "nn_err_pct": error_pct(nn_s, run.measured_s, signed=True),
            }
        )
    return pd.DataFrame(rows)


def oracle_time(run: PocketRun, target: str = "measured") -> float:
    """Eq. 10 fed with the targets themselves: what a perfect network would give."""
    feed = run.measured_feed_mm_s if target == "measured" else run.true_feed_mm_s
    return float(sun.block_times_s(feed, run.toolpath.lengths_mm, run.commanded_mm_s).sum())


def claims(runs: dict[int, PocketRun], sources: pd.DataFrame, table3: pd.DataFrame) -> list[Claim]:
    """The paper's claims, on its own set-up (5 Hz targets) and, as a separate row each, with
    1 kHz block-average targets; the tolerances are the paper's own numbers.

    Model #1's error is under 10 % on every pocket; model #2's is at most 3 % on every pocket and
    lower than model #1's on the pockets model #1 did not see (all but pocket 1); CAD/CAM
    underestimates every pocket.

    Parameters
    ----------
    runs : dict
        ``pocket -> PocketRun`` (only the keys are read: the pockets).
    sources : pandas.DataFrame
        One row per pocket with ``pocket`` and the signed errors ``m1_5hz_err_pct``,
        ``m2_5hz_err_pct``, ``m1_1khz_err_pct``, ``m2_1khz_err_pct`` (the chapter's
        ``error_sources`` table).
    table3 : pandas.DataFrame
        Table 3 (columns ``cam_s``, ``measured_s``).

    Returns
    -------
    list of Claim
    """
    unseen = [k for k in runs if k != 1]
    claims = []
    for target, label in (("measured", "5 Hz records"), ("true", "1 kHz block averages")):
        err = sources.set_index("pocket")
        key = "5hz" if target == "measured" else "1khz"
        m1, m2 = err[f"m1_{key}_err_pct"].abs(), err[f"m2_{key}_err_pct"].abs()
        claims += [
            Claim(f"model1_below_10pct_{key}", f"model #1 error < 10 % on every pocket ({label})",
                  m1.max(), "<", 10.0),
            Claim(f"model2_below_3pct_{key}", f"model #2 error <= 3 % on every pocket ({label})",
                  m2.max(), "<=", 3.0),
            Claim(f"model2_beats_model1_unseen_{key}",
                  f"model #2 error lower than model #1 on every pocket model #1 did not see "
                  f"({label}); value: largest (model #2 - model #1) in percentage points",
                  (m2[unseen] - m1[unseen]).max(), "<", 0.0),
        ]  # fmt: skip
    cam_under = (table3["cam_s"] < table3["measured_s"]).all()
    claims.append(Claim("cam_underestimates", "CAD/CAM underestimates every pocket (1 = all)",
                        float(cam_under), "==", 1.0))
    return claims
