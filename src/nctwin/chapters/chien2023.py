r"""The experiment of Chien, Sencer & Ward (2023): run programs on the FIR kernel, learn the
average feed per G-line, predict cycle times.

Per program (Sec. 2.2, eq. 1-3): the features of every G-line
(:func:`nctwin.methods.chien2023.features`),
and two targets per G-line read from the kernel's motion at the junction points,

* the average feed :math:`\bar f_k = \tilde l_k / \tilde t_k` (eq. 2), and
* the time ratio :math:`s_k = F \tilde t_k / l_k` (1 where the tool runs the G-line at the
  programmed feed; what CAM assumes everywhere).

Eq. 3, :math:`T = \sum_k \tilde l_k / \bar f_k = \sum_k \tilde t_k`, needs the blended lengths
:math:`\tilde l_k`, which are not known before the program runs and which the paper does not
say how it obtains; using the nominal :math:`l_k` instead overestimates :math:`T` by 4-8 % on the
test contours (the blends cut corners by up to :math:`\varepsilon`). And a network trained with a
squared loss predicts the conditional *mean* of each output, so a cycle time formed from a ratio
of two predictions is biased where the targets are noisy (the junction points of sub-millimetre
G-lines). The networks therefore predict :math:`s_k` as a second output, and the predicted cycle
time is eq. 3 per G-line, linear in the prediction:

.. math:: \hat T = \sum_k \hat s_k\, l_k / F .

The average feed :math:`\hat{\bar f}_k` is what Figs. 7 and 9 show.

Where a G-line's two junction points are the same sample (:math:`\tilde t_k = 0`, a fraction of a
percent of the short G-lines), :math:`\bar f_k` is undefined and left out of the loss.

"Machine B" (Table 3) is recorded the way a real control's trace is:
:class:`~nctwin.physics.measure.Recording` adds the package's position loop
(:class:`~nctwin.physics.servo.PositionLoop`, first order: servo lag, with the wait for the
in-position window at the end) and encoder noise to the kernel's command positions before the
targets are read. The block label of each recorded sample is delayed by the loop's following
time :math:`1/K_v` with the position, so that it names the block the axes are on, as the
kernel's labels do for its own output; without that delay the junction search (which only looks
at samples labelled with the two blocks that meet) misses the junctions of G-lines shorter than
:math:`F/K_v` and moves time between neighbouring short G-lines (:func:`recording_effects`
measures it).

Every network is trained once per seed (:func:`nctwin.learn.seeds.fit_seeds`, in parallel through
:func:`nctwin.runner.run_tasks`) and a table's prediction is the ensemble mean
(:func:`predict_run`). Simulations of a list of programs run through the same runner (one task
per program) and are cached in ``data/cache/chien2023/`` under a hash of the programs' text,
the machine and the recording, written atomically.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from .. import gcode
from ..cache import atomic_savez, cache_path, content_key
from ..estimate import cam
from ..kernel import fir
from ..learn.models import ModelConfig
from ..learn.seeds import fit_seeds
from ..learn.train import TrainConfig, Trained
from ..machine import Profile
from ..methods import chien2023 as chien
from ..metrics import error_pct
from ..motion import Motion
from ..physics.measure import Recording
from ..programs import write_programs
from ..report.papers import side_by_side
from ..runner import run_tasks
from ..targets import block_targets
from ..toolpath import MotionKind, Toolpath

__all__ = [
    "CAM_BLEND_SHARES",
    "LSTM_CONFIG",
    "MAX_EPOCHS",
    "MIN_FEED_MM_S",
    "MLP_CONFIG",
    "PAPER_SHARES",
    "PATIENCE",
    "TABLE_COLUMNS",
    "ProgramRun",
    "Recording",
    "ablation_table",
    "convergence",
    "cutting_blocks",
    "cycle_time_rows",
    "eq3_rows",
    "feed_rmse_mm_s",
    "fit_seeds",
    "line_stats",
    "paper_beside",
    "plot_feed_per_line",
    "predict_run",
    "recording_effects",
    "run_toolpath",
    "seed_rows",
    "simulate",
    "simulate_one",
    "time_by_length",
    "train_config",
    "training_ablation",
    "write_programs",
]

#: Cache format version (part of every cache key).
CACHE_VERSION = 4
#: Floor of a predicted average feed (mm/s), so that a prediction near 0 stays a finite time.
MIN_FEED_MM_S = 1.0
#: The ablation's models without look-ahead (the paper's BiLSTM is
#: :data:`nctwin.methods.chien2023.BILSTM_CONFIG`): a forward-only LSTM of 10 units and a per-line
#: MLP of two tanh layers of 32 units.
LSTM_CONFIG = ModelConfig("lstm", n_inputs=5, n_outputs=2, hidden=10)
MLP_CONFIG = ModelConfig("mlp", n_inputs=5, n_outputs=2, hidden=32, mlp_layers=2)


#: Split of each training set between the paper's two families (Sec. 3.1; the paper does not
#: print it), fixed by its run time (Sec. 4.1: "~2 h" simulated; Sec. 4.2: "~3 h" of air cutting
#: on machine B), before any network is trained: the number of mixed programs whose set's run
#: time lies nearest it. On ``paper1_sim`` a mixed program of 1000 G-lines runs 17-24 min, a
#: global one 30-54 s, so 4 of 80 are mixed (2.12 h; 5: 2.46 h); on machine B a mixed program of
#: 2000 G-lines runs 25-50 min, a global one 20-90 s, so 3 of 30 (``sim_train_hours``,
#: ``b_train_hours`` in the conditions).
PAPER_SHARES = {"sim": {"paper_global": 0.95, "paper_mixed": 0.05},
                "b": {"paper_global": 0.9, "paper_mixed": 0.1}}  # fmt: skip
#: The training sets with CAM-blend programs (:mod:`nctwin.programs.camblend`), not among the
#: paper's families: an ablation row only.
CAM_BLEND_SHARES = {"sim": {"global": 0.3, "mixed": 0.05, "cam": 0.65},
                    "b": {"global": 0.1, "mixed": 1 / 30, "cam": 26 / 30}}  # fmt: skip

#: Epochs without a lower validation loss before training stops (early stopping).
PATIENCE = 25
#: Cap of the epochs, far above where early stopping ends every network of the chapter; a network
#: has converged when its best epoch is below ``max_epochs - PATIENCE`` (:func:`convergence`).
MAX_EPOCHS = 1500


def train_config(seed: int = 0, scale: float = 1.0) -> TrainConfig:
    """The chapter's training settings: at most ``MAX_EPOCHS * scale`` epochs (at least 5),
    early stopping after :data:`PATIENCE` epochs without improvement on the validation programs,
    the length feature (column 1) as its logarithm.

    Parameters
    ----------
    seed : int
        Seed of the initial weights, the validation split and the batch order.
    scale : float
        Multiplies the epoch cap (1.0 for the chapter; smaller for quick checks only).

    Returns
    -------
    TrainConfig
    """
    epochs = max(5, round(MAX_EPOCHS * scale))
    return TrainConfig(seed=seed, max_epochs=epochs, patience=PATIENCE, log_inputs=(1,))


def convergence(models: dict[str, Sequence[Trained]]) -> pd.DataFrame:
    """Best epoch of every network, and whether early stopping (not the cap) ended it.

    Returns
    -------
    pandas.DataFrame
        One row per network and seed: ``network, seed, best_epoch, epochs_run, max_epochs,
        patience`` and ``converged`` (``best_epoch < max_epochs - patience``: the validation
        loss had not improved for ``patience`` epochs when training stopped).
    """
    rows = []
    for name, members in models.items():
        for m in members:
            cfg = m.train_config
            rows.append({"network": name, "seed": cfg.seed, "best_epoch": m.best_epoch,
                         "epochs_run": len(m.history["val"]), "max_epochs": cfg.max_epochs,
                         "patience": cfg.patience,
                         "converged": m.converged})  # fmt: skip
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class ProgramRun:
    """A program run on the kernel: features, targets and times.

    Parameters
    ----------
    features : ndarray, shape (N, 5)
        :func:`nctwin.methods.chien2023.features` of the cutting G-lines.
    targets : ndarray, shape (N, 2)
        Average feed :math:`\\bar f_k` (mm/s, NaN where undefined) and time ratio :math:`s_k`.
    block_time_s : ndarray, shape (N,)
        Measured time between junction points, :math:`\\tilde t_k`.
    measured_s : float
        Measured cycle time, eq. 3 (the sum of ``block_time_s``).
    cam_s : float
        CAM estimate (length over feed).
    """

    features: np.ndarray
    targets: np.ndarray
    block_time_s: np.ndarray
    measured_s: float
    cam_s: float


def cutting_blocks(tp: Toolpath) -> Toolpath:
    """The planar feed moves of a program (drops rapids, plunges and retracts)."""
    planar = np.abs(tp.end_mm[:, 2] - tp.start_mm[:, 2]) == 0
    return tp.take((tp.kind == MotionKind.LINEAR) & planar & (tp.lengths_mm > 0))


def simulate_one(
    text: str, profile: Profile, recording: Recording | None = None, index: int = 0
) -> ProgramRun:
    """Parse ``text``, keep its cutting blocks and :func:`run_toolpath` them."""
    return run_toolpath(cutting_blocks(gcode.parse(text)), profile, recording, index)


def run_toolpath(
    tp: Toolpath, profile: Profile, recording: Recording | None = None, index: int = 0
) -> ProgramRun:
    """Run the G-lines ``tp`` from rest to rest on the FIR kernel (the profile's machine and
    ``[control.fir]``) and read the targets.

    ``index`` seeds the recording's noise together with ``recording.seed``.
    """
    control = profile.control("fir")
    motion = fir.run(tp, profile.machine, control)
    if recording is not None:
        motion = recording.apply(motion, np.random.default_rng([recording.seed, index]))
    bt = block_targets(motion, tp)
    lengths = tp.lengths_mm
    targets = np.column_stack([bt.avg_feed_mm_s, tp.feed_mm_s * bt.time_s / lengths])
    return ProgramRun(
        chien.features(tp, control.blend_tol_mm),
        targets,
        bt.time_s,
        bt.cycle_time_s,
        cam(tp, profile.machine).cycle_time_s,
    )


def recording_effects(
    text: str, profile: Profile, recordings: dict[str, Recording], *, short_mm: float = 1.0
) -> pd.DataFrame:
    """How a recording changes the per-G-line targets of one program (the Table 3 diagnosis).

    The targets are read from the kernel's own motion (the reference) and from each recorded
    motion, once with the recorded labels (delayed with the position) and once with the
    interpolator's labels (not delayed), and compared G-line by G-line.

    Parameters
    ----------
    text : str
        A G-code program.
    profile : Profile
        The machine and its ``[control.fir]``.
    recordings : dict
        ``name -> Recording``; each draws its noise with ``[recording.seed, 0]``.
    short_mm : float
        G-lines shorter than this count as short.

    Returns
    -------
    pandas.DataFrame
        One row per recording and label timing: ``recording``, ``labels`` (``"delayed"`` or
        ``"interpolator"``), ``measured_s``, and over the short and the long G-lines the mean
        time ratio :math:`s_k` (``s_mean_short``, ``s_mean_long``; the reference's in the
        ``reference`` row) and the RMS of its change from the reference (``s_rms_short``,
        ``s_rms_long``), the mean change of the average feed (``feed_bias_mm_s``) and the share
        of G-lines whose two junction points are the same sample (``zero_time_pct``).
    """
    tp = cutting_blocks(gcode.parse(text))
    motion = fir.run(tp, profile.machine, profile.control("fir"))
    lengths = tp.lengths_mm
    short = lengths < short_mm

    def read(m: Motion) -> tuple[np.ndarray, np.ndarray, float, float]:
        bt = block_targets(m, tp)
        ratio = tp.feed_mm_s * bt.time_s / lengths
        return ratio, bt.avg_feed_mm_s, bt.cycle_time_s, 100.0 * float(np.mean(bt.time_s == 0))

    def mean(x: np.ndarray) -> float:
        return float(x.mean()) if len(x) else np.nan

    s0, f0, t0, z0 = read(motion)
    rows = [{"recording": "reference", "labels": "kernel", "measured_s": t0,
             "s_mean_short": mean(s0[short]), "s_mean_long": mean(s0[~short]),
             "s_rms_short": 0.0, "s_rms_long": 0.0, "feed_bias_mm_s": 0.0,
             "zero_time_pct": z0}]  # fmt: skip
    for name, rec in recordings.items():
        recorded = rec.apply(motion, np.random.default_rng([rec.seed, 0]))
        undelayed = np.concatenate(
            [motion.block, np.full(len(recorded) - len(motion), motion.block[-1])]
        )
        variants = {"delayed": recorded}
        if rec.position_gain_1_s > 0:
            variants["interpolator"] = Motion(
                recorded.t_s, recorded.pos_mm, recorded.vel_mm_s, undelayed, recorded.period_s
            )
        for labels, m in variants.items():
            s, f, t, z = read(m)
            d2 = (s - s0) ** 2
            rows.append({"recording": name, "labels": labels, "measured_s": t,
                         "s_mean_short": mean(s[short]), "s_mean_long": mean(s[~short]),
                         "s_rms_short": np.sqrt(mean(d2[short])),
                         "s_rms_long": np.sqrt(mean(d2[~short])),
                         "feed_bias_mm_s": np.nanmean(f - f0), "zero_time_pct": z})  # fmt: skip
    return pd.DataFrame(rows)


def _cache_key(texts: Sequence[str], profile: Profile, recording: Recording | None) -> str:
    meta = {
        "version": CACHE_VERSION,
        "machine": asdict(profile.machine),
        "fir": asdict(profile.control("fir")),
        "recording": None if recording is None else asdict(recording),
    }
    return content_key(*texts, meta)


def _save_runs(path, runs: Sequence[ProgramRun]) -> None:
    atomic_savez(
        path,
        offsets=np.cumsum([0] + [len(r.features) for r in runs]),
        features=np.concatenate([r.features for r in runs]),
        targets=np.concatenate([r.targets for r in runs]),
        block_time_s=np.concatenate([r.block_time_s for r in runs]),
        measured_s=np.array([r.measured_s for r in runs]),
        cam_s=np.array([r.cam_s for r in runs]),
    )


def _load_runs(path) -> list[ProgramRun]:
    with np.load(path) as d:
        o = d["offsets"]
        return [
            ProgramRun(
                d["features"][a:b],
                d["targets"][a:b],
                d["block_time_s"][a:b],
                float(d["measured_s"][i]),
                float(d["cam_s"][i]),
            )
            for i, (a, b) in enumerate(itertools.pairwise(o))
        ]


def simulate(
    texts: Sequence[str],
    profile: Profile,
    *,
    recording: Recording | None = None,
    n_jobs: int = 2,
    desc: str = "programs",
    cache: bool = True,
) -> list[ProgramRun]:
    """Run every program of ``texts`` (see :func:`simulate_one`) through
    :func:`nctwin.runner.run_tasks`, cached.

    Parameters
    ----------
    texts : sequence of str
        G-code programs.
    profile : Profile
        The machine and its ``[control.fir]``.
    recording : Recording, optional
        Servo lag and noise of a real control's trace (program ``i`` draws its noise with
        ``[recording.seed, i]``).
    n_jobs : int
        joblib workers.
    desc : str
        Label of the progress bar.
    cache : bool
        Read and write ``data/cache/chien2023/<hash>.npz``.

    Returns
    -------
    list of ProgramRun
        In the order of ``texts``.
    """
    path = cache_path("chien2023", "runs", _cache_key(texts, profile, recording), ".npz")
    if cache and path.exists():
        return _load_runs(path)
    tasks = ((t, profile, recording, i) for i, t in enumerate(texts))
    runs = run_tasks(simulate_one, tasks, n_jobs=n_jobs, desc=desc)
    if cache:
        _save_runs(path, runs)
    return runs


def _members(models: Trained | Sequence[Trained]) -> list[Trained]:
    return [models] if isinstance(models, Trained) else list(models)


def predict_run(
    models: Trained | Sequence[Trained], run: ProgramRun
) -> tuple[np.ndarray, np.ndarray, float]:
    """Predicted average feeds, block times and cycle time of one program, by one network or
    by an ensemble: the mean of its members' predictions (so its cycle time is the mean of the
    members' cycle times).

    Returns
    -------
    avg_feed_mm_s : ndarray, shape (N,)
        :math:`\\hat{\\bar f}_k`, at least :data:`MIN_FEED_MM_S`.
    block_time_s : ndarray, shape (N,)
        :math:`\\hat s_k l_k / F` (a negative prediction counts as 0).
    cycle_time_s : float
        Their sum (eq. 3).
    """
    preds = [chien.predict(m.predict(run.features), run.features) for m in _members(models)]
    feed = np.mean([p[0] for p in preds], axis=0)
    t = np.mean([p[1] for p in preds], axis=0)
    return feed, t, float(t.sum())


def seed_rows(
    runs: dict[tuple[str, float, float], ProgramRun],
    members: Sequence[Trained],
    *,
    decimals: int = 2,
) -> pd.DataFrame:
    """Each seed's signed cycle-time error beside the ensemble's, per test program.

    Returns
    -------
    pandas.DataFrame
        ``toolpath, feed_mm_s, tol_mm, measured_s``, ``seed_<s>_err_pct`` per member,
        ``ensemble_err_pct`` and ``spread_pct`` (largest minus smallest seed error), all
        :math:`(\\hat T - T)/T \\times 100`; the times and errors rounded to ``decimals``.
    """
    rows = []
    for (name, feed, tol), run in runs.items():
        errs = {f"seed_{m.train_config.seed}_err_pct":
                error_pct(predict_run(m, run)[2], run.measured_s, signed=True)
                for m in members}  # fmt: skip
        ens = error_pct(predict_run(members, run)[2], run.measured_s, signed=True)
        rows.append({"toolpath": name, "feed_mm_s": feed, "tol_mm": tol,
                     "measured_s": run.measured_s, **errs, "ensemble_err_pct": ens,
                     "spread_pct": max(errs.values()) - min(errs.values())})  # fmt: skip
    out = pd.DataFrame(rows)
    values = [c for c in out.columns if c not in ("toolpath", "feed_mm_s", "tol_mm")]
    return out.assign(**{c: out[c].round(decimals) for c in values})


def line_stats(runs: dict[str, Sequence[ProgramRun]], *, tangent_rad: float = 0.1) -> pd.DataFrame:
    """Distributions of a set of programs' G-lines (the inputs the networks see).

    Parameters
    ----------
    runs : dict
        ``label -> programs``.
    tangent_rad : float
        A junction turning by less than this is tangential.

    Returns
    -------
    pandas.DataFrame
        One row per label: ``programs``, ``glines``, ``hours`` (measured), feed and tolerance
        ranges, the shares (%) of G-lines under 1 mm, 1-10 mm and over 10 mm, the share of
        junctions that turn by more than 90 degrees, and the long G-lines (> 10 mm) tangent at
        both ends: their count and share of the long G-lines.
    """
    rows = []
    for label, rs in runs.items():
        x = np.concatenate([r.features for r in rs])
        f, ln, t0, t1, eps = x.T
        long = ln > 10.0
        both = long & (t0 < tangent_rad) & (t1 < tangent_rad)
        rows.append({"set": label, "programs": len(rs), "glines": len(x),
                     "hours": sum(r.measured_s for r in rs) / 3600.0,
                     "feed_min_mm_s": f.min(), "feed_max_mm_s": f.max(),
                     "tol_min_mm": eps.min(), "tol_max_mm": eps.max(),
                     "under_1mm_pct": 100 * np.mean(ln < 1.0),
                     "from_1_to_10mm_pct": 100 * np.mean((ln >= 1.0) & (ln <= 10.0)),
                     "over_10mm_pct": 100 * np.mean(long),
                     "turn_over_90deg_pct": 100 * np.mean(t0 > 0.5 * np.pi),
                     "long_tangent_both": int(both.sum()),
                     "long_tangent_both_pct": 100 * both.sum() / max(long.sum(), 1)})  # fmt: skip
    return pd.DataFrame(rows)


def cycle_time_rows(
    runs: dict[tuple[str, float, float], ProgramRun], models: dict[str, Trained]
) -> pd.DataFrame:
    """Measured, predicted and CAM cycle times per test program, with errors in percent.

    Parameters
    ----------
    runs : dict
        ``(toolpath, feed_mm_s, tol_mm) -> ProgramRun``.
    models : dict
        ``name -> Trained`` or ``name -> [Trained per seed]`` (an ensemble, see
        :func:`predict_run`); each adds ``<name>_s`` and ``<name>_err_pct`` columns.

    Returns
    -------
    pandas.DataFrame
        Columns ``toolpath, feed_mm_s, tol_mm, measured_s, <name>_s, <name>_err_pct, ...,
        cam_s, cam_err_pct``, one row per key in the order of ``runs``.
    """
    rows = []
    for (name, feed, tol), run in runs.items():
        row = {"toolpath": name, "feed_mm_s": feed, "tol_mm": tol, "measured_s": run.measured_s}
        for m, trained in models.items():
            t = predict_run(trained, run)[2]
            row[f"{m}_s"] = t
            row[f"{m}_err_pct"] = error_pct(t, run.measured_s)
        row["cam_s"] = run.cam_s
        row["cam_err_pct"] = error_pct(run.cam_s, run.measured_s)
        rows.append(row)
    return pd.DataFrame(rows)


def eq3_rows(
    runs: dict[tuple[str, float, float], ProgramRun], models: dict[str, Trained | list[Trained]]
) -> pd.DataFrame:
    """Both routes from a network to the cycle time, per test program: the paper's eq. 3 over
    the predicted average feeds with the nominal lengths
    (:func:`nctwin.methods.chien2023.eq3_time_s`), and the chapter's, the predicted time ratio
    (:func:`predict_run`). An ensemble's time is the mean of its members' times on both routes.

    Returns
    -------
    pandas.DataFrame
        ``toolpath, feed_mm_s, tol_mm, measured_s``, then per model ``<name>_eq3_s``,
        ``<name>_eq3_err_pct`` and ``<name>_err_pct`` (the ratio route); errors unsigned, %.
    """
    rows = []
    for (name, feed, tol), run in runs.items():
        row = {"toolpath": name, "feed_mm_s": feed, "tol_mm": tol, "measured_s": run.measured_s}
        for m, trained in models.items():
            lengths = run.features[:, 1]
            t = np.mean([chien.eq3_time_s(predict_run(one, run)[0], lengths)
                         for one in _members(trained)])  # fmt: skip
            row[f"{m}_eq3_s"] = float(t)
            row[f"{m}_eq3_err_pct"] = error_pct(float(t), run.measured_s)
            row[f"{m}_err_pct"] = error_pct(predict_run(trained, run)[2], run.measured_s)
        rows.append(row)
    return pd.DataFrame(rows)


def time_by_length(
    runs: dict[tuple[str, float, float], ProgramRun],
    trained: Trained | Sequence[Trained],
    *,
    short_mm: float = 1.0,
) -> pd.DataFrame:
    """Measured and predicted time spent on the short and on the long G-lines of each program:
    where a cycle-time error comes from.

    Returns
    -------
    pandas.DataFrame
        One row per key of ``runs``: ``toolpath, feed_mm_s, tol_mm``, then for ``short``
        (:math:`l_k` < ``short_mm``) and ``long`` G-lines ``<class>_lines``,
        ``<class>_measured_s``, ``<class>_predicted_s`` and ``<class>_err_pct`` (signed, of the
        class's measured time).
    """
    rows = []
    for (name, feed, tol), run in runs.items():
        t_hat = predict_run(trained, run)[1]
        short = run.features[:, 1] < short_mm
        row = {"toolpath": name, "feed_mm_s": feed, "tol_mm": tol}
        for label, sel in (("short", short), ("long", ~short)):
            measured, predicted = run.block_time_s[sel].sum(), t_hat[sel].sum()
            row |= {f"{label}_lines": int(sel.sum()), f"{label}_measured_s": measured,
                    f"{label}_predicted_s": predicted,
                    f"{label}_err_pct": error_pct(predicted, measured, signed=True)}  # fmt: skip
        rows.append(row)
    return pd.DataFrame(rows)


def feed_rmse_mm_s(trained: Trained | Sequence[Trained], runs: Sequence[ProgramRun]) -> float:
    """Root mean square error of the predicted average feed (one network or an ensemble, see
    :func:`predict_run`) over all G-lines of ``runs``."""
    err = np.concatenate([predict_run(trained, r)[0] - r.targets[:, 0] for r in runs])
    return float(np.sqrt(np.nanmean(err**2)))


def plot_feed_per_line(
    measured_mm_s: np.ndarray,
    predicted_mm_s: np.ndarray,
    *,
    ax=None,
    lines: tuple[int, int] | None = None,
    title: str | None = None,
):
    """Measured and predicted average feed per G-line (Figs. 7 and 9); only draws.

    ``lines`` selects a range of G-line numbers (from 1) to show. Returns the Axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(9, 3.2), constrained_layout=True)
    k = np.arange(1, len(measured_mm_s) + 1)
    sel = slice(None) if lines is None else slice(lines[0] - 1, lines[1])
    ax.plot(k[sel], measured_mm_s[sel], lw=1.0, color="0.3", label="measured (kernel)")
    ax.plot(k[sel], predicted_mm_s[sel], lw=1.0, color="C1", ls="--", label="BiLSTM")
    ax.set_xlabel("G-line")
    ax.set_ylabel("average feed (mm/s)")
    ax.set_ylim(bottom=0)
    ax.legend(loc="lower right", frameon=False)
    if title:
        ax.set_title(title)
    return ax


#: Columns of ``results/chien2023_bilstm/table{1,2,3}.csv`` (the chapter's contract).
TABLE_COLUMNS = (
    "toolpath", "feed_mm_s", "tol_mm", "measured_s", "bilstm_s", "bilstm_err_pct", "cam_s",
    "cam_err_pct", "paper_measured_s", "paper_bilstm_err_pct", "paper_cam_err_pct",
)  # fmt: skip


def paper_beside(rows: pd.DataFrame, paper: pd.DataFrame, *, decimals: int = 2) -> pd.DataFrame:
    """Our cycle-time rows beside the paper's, with exactly :data:`TABLE_COLUMNS`, rounded."""
    out = side_by_side(
        rows[["toolpath", "feed_mm_s", "tol_mm", "measured_s", "bilstm_s", "bilstm_err_pct",
              "cam_s", "cam_err_pct"]],
        paper,
        on=["toolpath", "feed_mm_s", "tol_mm"],
        columns=["measured_s", "bilstm_err_pct", "cam_err_pct"],
    )  # fmt: skip
    out = out[list(TABLE_COLUMNS)]
    values = [c for c in TABLE_COLUMNS if c not in ("toolpath", "feed_mm_s", "tol_mm")]
    return out.assign(**{c: out[c].round(decimals) for c in values})


def ablation_table(
    rows: pd.DataFrame, models: dict[str, Sequence[Trained]], runs: Sequence[ProgramRun]
) -> pd.DataFrame:
    """Cycle-time errors and feed RMSE of each model's ensemble on the same test programs.

    Parameters
    ----------
    rows : pandas.DataFrame
        From :func:`cycle_time_rows` with every model of ``models``.
    models : dict
        ``name -> [Trained per seed]``.
    runs : sequence of ProgramRun
        The test programs (for the per-G-line feed RMSE).

    Returns
    -------
    pandas.DataFrame
        ``model, parameters, mean_err_pct, max_err_pct, feed_rmse_mm_s`` of the ensemble, the
        largest error of the worst single seed (``seed_max_err_pct``) and the best epochs'
        range (``best_epoch_min``, ``best_epoch_max``).
    """
    out = []
    for name, members in models.items():
        err = rows[f"{name}_err_pct"]
        seed_max = max(error_pct(predict_run(m, r)[2], r.measured_s) for m in members
                       for r in runs)  # fmt: skip
        epochs = [m.best_epoch for m in members]
        out.append({"model": name,
                    "parameters": sum(p.numel() for p in members[0].model.parameters()),
                    "mean_err_pct": err.mean(), "max_err_pct": err.max(),
                    "feed_rmse_mm_s": feed_rmse_mm_s(members, runs),
                    "seed_max_err_pct": seed_max,
                    "best_epoch_min": min(epochs), "best_epoch_max": max(epochs)})  # fmt: skip
    return pd.DataFrame(out).round(2)


def training_ablation(rows: pd.DataFrame, bars_pct: dict[str, float]) -> pd.DataFrame:
    """Each training set's BiLSTM ensemble per table: its mean and largest cycle-time error and
    whether the largest is under the table's bar.

    Parameters
    ----------
    rows : pandas.DataFrame
        :func:`cycle_time_rows` of every test program with a column ``table`` and one
        ``<set>_err_pct`` column per training set.
    bars_pct : dict
        ``table -> bar`` (%).

    Returns
    -------
    pandas.DataFrame
        ``table, training, mean_err_pct, max_err_pct, bar_pct, under_bar``.
    """
    sets = [c.removesuffix("_err_pct") for c in rows.columns
            if c.endswith("_err_pct") and c != "cam_err_pct"]  # fmt: skip
    out = [{"table": table, "training": name, "mean_err_pct": g[f"{name}_err_pct"].mean(),
            "max_err_pct": g[f"{name}_err_pct"].max(), "bar_pct": bars_pct[table],
            "under_bar": bool(g[f"{name}_err_pct"].max() < bars_pct[table])}
           for table, g in rows.groupby("table", sort=False) for name in sets]  # fmt: skip
    return pd.DataFrame(out).round(2)
