"""Sun, Dominguez-Caballero, Ward, Ayvar-Soberanis & Curtis (2022): one feed-forward network per
axis predicts the axis feeds at every cutter location, and from them the machining time.

The chapter's pipeline, kept out of the notebook:

1. :func:`run_pockets` runs the eight pocket programs of :mod:`nctwin.programs.thinwall` on the
   FIR kernel (the "machine"), records each at the paper's logger rate with jitter (its measuring
   device, records per second as ``data/papers/sun2022_summary.csv`` gives them for pocket
   1), and pairs every cutter location with the nearest record (the paper's targets). It
   also keeps the block-average axis feeds at each cutter location (1 kHz), which the paper did
   not have. :func:`part_stats` and :func:`machine_check` put the part and the machine beside
   the paper's published statistics.
2. :func:`train_ensembles` fits one network per axis (Table 1 features, 2 hidden tanh layers of
   5 and 10, linear output, MSE) on the training pockets of Table 2 (:data:`MODELS`), validating
   on the first half of pocket 4, once per seed of :data:`SEEDS`, the seeds in parallel through
   :func:`nctwin.runner.run_tasks`.
3. :func:`predict_time` turns each seed's predicted axis feeds into the resultant feed (eq. 9)
   and block times (eq. 10); the ensemble's time is the mean of the seeds' times.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..estimate.cam import cam
from ..gcode import parse
from ..kernel import fir
from ..learn.train import TrainConfig, Trained, fit
from ..machine import Profile
from ..methods import sun2022 as sun
from ..metrics import error_pct
from ..motion import Motion
from ..physics.measure import ControllerSamples, controller_samples, nearest_sample
from ..programs.thinwall import POCKETS, pocket_program, start_mm
from ..runner import run_tasks
from ..targets import block_targets
from ..toolpath import MotionKind, Toolpath
from .your_program import ProgramResult, block_feeds, domain_notes, program_times, run_program

__all__ = [
    "IMPROVED_POCKETS",
    "LONG_BLOCK_MM",
    "MODELS",
    "SEEDS",
    "TRAIN_CONFIG",
    "PocketRun",
    "error_sources",
    "logger_variant",
    "machine_check",
    "member_feeds",
    "part_stats",
    "predict_all_feeds",
    "predict_feeds",
    "predict_time",
    "predict_times",
    "program_times",
    "run_pocket",
    "run_pockets",
    "seed_table",
    "target_time",
    "time_by_block_length",
    "train_ensembles",
    "training_table",
    "your_program",
]

#: Training pockets of the paper's two models (Table 2); both validate on the first half of
#: pocket 4 and leave its second half as the test set.
MODELS = {"model #1": (1,), "model #2": (1, 5, 8)}

#: Seeds of the ensembles: each seed initialises and shuffles one network per axis.
SEEDS = (0, 1, 2, 3, 4)

#: Training: MSE (the paper's loss), Adam, early stopping on the validation half of pocket 4
#: after 50 epochs without improvement. The epoch cap is far above where training stops, so
#: that it never decides (:func:`training_table` reports it).
TRAIN_CONFIG = TrainConfig(
    loss="mse", window_lines=256, batch_size=8, max_epochs=3000, patience=50, learning_rate=1e-2
)

#: Targets: the record nearest to each cutter location (the paper's logger), or the 1 kHz
#: block-average axis feed (an ablation the paper could not run).
TARGETS = ("measured", "true")


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
        What the logger recorded.
    features : ndarray, shape (N, 3, 9)
        :func:`nctwin.methods.sun2022.features`.
    measured_feed_mm_s : ndarray, shape (N, 3)
        Axis feeds of the record nearest to each cutter location (the paper's targets); for a
        rapid, the nearest of the records taken while the tool was on it (see :func:`run_pocket`).
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

    def target(self, target: str) -> np.ndarray:
        """The axis-feed targets, shape (N, 3): ``"measured"`` (the logger's) or ``"true"``
        (1 kHz)."""
        if target not in TARGETS:
            raise ValueError(f"target = {target!r} is unknown: allowed {', '.join(TARGETS)}")
        return self.measured_feed_mm_s if target == "measured" else self.true_feed_mm_s


def run_pocket(
    text: str,
    number: int,
    profile: Profile,
    seed: int = 0,
    *,
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
    rate_hz: float = 5.0,
    jitter_s: float = 0.03,
) -> PocketRun:
    """Run one pocket program from ``start`` (mm) on the FIR kernel (the profile's machine and
    ``[control.fir]``) and record it.

    Every cutter location is paired with the record nearest to it in space among those within
    2 s of the tool's passage (the paper's target). A rapid's cutter location is where the tool
    stops before the plunge, so the record nearest to it is typically taken in the stop; the
    paper's Fig. 9 shows its G0 targets as fast feeds, below 30,000 mm/min but not near zero, so
    a rapid is paired with the nearest of the records taken while the tool was on it (the
    nearest of all if the logger took none then). The paper does not say how; this is the
    chapter's choice.
    """
    parsed = parse(text, start_mm=start, source=f"pocket {number}")
    tp = parsed.take(parsed.lengths_mm > 0)
    machine = profile.machine
    motion = fir.run(tp, machine, profile.control("fir"))
    junction = block_targets(motion, tp).junction_sample
    passage = junction[1:]
    dt = np.diff(junction)[:, None] * motion.period_s
    moved = np.diff(motion.pos_mm[junction], axis=0)
    block_avg = np.divide(moved, dt, out=np.zeros_like(moved), where=dt > 0)
    records = controller_samples(motion, rate_hz=rate_hz, jitter_s=jitter_s, seed=seed)
    rapid = tp.kind == MotionKind.RAPID
    since = np.where(rapid, motion.t_s[junction[:-1]], np.nan)
    nearest = nearest_sample(records, tp.end_mm, motion.t_s[passage], since_s=since)
    commanded = np.where(rapid, machine.rapid_feed_mm_s, tp.feed_mm_s)
    return PocketRun(
        number=number,
        toolpath=tp,
        motion=motion,
        records=records,
        features=sun.features(tp, machine.rapid_feed_mm_s),
        measured_feed_mm_s=records.vel_mm_s[nearest],
        true_feed_mm_s=block_avg,
        commanded_mm_s=commanded,
        cam_s=cam(tp, machine).cycle_time_s,
    )


def run_pockets(
    profile: Profile, *, seed: int = 0, n_jobs: int = 1, **kwargs
) -> dict[int, PocketRun]:
    """All eight pockets, in parallel (``n_jobs``), each from its :func:`start_mm`; each pocket's
    record jitter is seeded with ``seed + number``. ``kwargs`` go to :func:`run_pocket`."""
    tasks = (
        (pocket_program(spec), spec.number, profile, seed + spec.number, start_mm(spec))
        for spec in POCKETS
    )
    runs = run_tasks(functools.partial(_run_pocket_from, **kwargs), tasks, n_jobs=n_jobs)
    return {r.number: r for r in runs}


def _run_pocket_from(text, number, profile, seed, start, **kwargs) -> PocketRun:
    return run_pocket(text, number, profile, seed, start=start, **kwargs)


def part_stats(
    runs: dict[int, PocketRun], paper3: pd.DataFrame, summary: pd.DataFrame
) -> pd.DataFrame:
    """The part beside the paper's: per pocket the cutter locations, records, rapids, path
    length, the calibrated trochoid radius and advance, CAD/CAM and measured times, and the
    paper's numbers where it gives them (Table 3; cutter locations and records of pocket 1
    only, Sec. 4.1).

    Parameters
    ----------
    runs : dict of PocketRun
    paper3 : pandas.DataFrame
        ``data/papers/sun2022_table3.csv``.
    summary : pandas.DataFrame
        ``data/papers/sun2022_summary.csv``.
    """
    quantity = summary.set_index("quantity")["value"]
    paper = paper3.set_index("pocket")
    spec = {p.number: p for p in POCKETS}
    rows = []
    for k, r in runs.items():
        rows.append({
            "pocket": k,
            "cutter_locations": len(r.toolpath),
            "records": len(r.records.t_s),
            "rapids": int((r.toolpath.kind == MotionKind.RAPID).sum()),
            "length_mm": r.toolpath.length_mm,
            "mean_cl_spacing_mm": r.toolpath.length_mm / len(r.toolpath),
            "trochoid_radius_mm": spec[k].trochoid_radius_mm,
            "trochoid_advance_mm": spec[k].trochoid_advance_mm,
            "cam_s": r.cam_s,
            "measured_s": r.measured_s,
            "paper_cutter_locations": quantity["pocket1_commanded_points"] if k == 1 else np.nan,
            "paper_records": quantity["pocket1_measured_points"] if k == 1 else np.nan,
            "paper_cam_s": paper.loc[k, "cam_s"],
            "paper_measured_s": paper.loc[k, "measured_s"],
        })  # fmt: skip
    return pd.DataFrame(rows)


def machine_check(runs: dict[int, PocketRun], paper3: pd.DataFrame) -> pd.DataFrame:
    """The machine against what the paper states: per pocket the programmed G1 feed, the fastest
    rapid (the paper's G0 at 30,000 mm/min is never reached) and the CAD/CAM error beside the
    paper's (signed; negative: CAD/CAM under the measured time)."""
    paper = paper3.set_index("pocket")
    rows = []
    for k, r in runs.items():
        rapid = np.isin(r.motion.block, np.flatnonzero(r.toolpath.kind == MotionKind.RAPID))
        cutting = r.toolpath.kind == MotionKind.LINEAR
        rows.append({
            "pocket": k,
            "g1_feed_mm_min": 60 * float(r.toolpath.feed_mm_s[cutting].max()),
            "fastest_rapid_mm_min": 60 * float(r.motion.speed_mm_s[rapid].max(initial=0.0)),
            "g0_mm_min": 60 * float(r.commanded_mm_s.max()),
            "cam_err_pct": error_pct(r.cam_s, r.measured_s, signed=True),
            "paper_cam_err_pct": -float(paper.loc[k, "cam_err_pct"]),
        })  # fmt: skip
    return pd.DataFrame(rows)


def _train_task(
    data: dict[int, tuple[np.ndarray, np.ndarray]],
    train_pockets: tuple[int, ...],
    validation: tuple[np.ndarray, np.ndarray],
    target: str,
    seed: int,
) -> list[Trained]:
    """One network per axis on plain arrays (what a worker receives)."""
    cfg = TrainConfig(**{**TRAIN_CONFIG.to_dict(), "seed": seed})
    vx, vy = validation
    name = f"sun2022-{target}-{'-'.join(map(str, train_pockets))}"
    return [
        fit(
            sun.MODEL_CONFIG,
            cfg,
            [data[p][0][:, a] for p in train_pockets],
            [data[p][1][:, a : a + 1] for p in train_pockets],
            validation=([vx[:, a]], [vy[:, a : a + 1]]),
            name=f"{name}-{'xyz'[a]}",
            progress=False,
        )
        for a in range(3)
    ]


def _task_args(runs, train_pockets, target, seed, validation_pocket):
    val = runs[validation_pocket]
    first = slice(0, len(val.toolpath) // 2)  # the first half validates, the rest is the test set
    data = {p: (runs[p].features, runs[p].target(target)) for p in train_pockets}
    return (
        data,
        tuple(train_pockets),
        (val.features[first], val.target(target)[first]),
        target,
        seed,
    )


def train_ensembles(
    runs: dict[int, PocketRun],
    *,
    seeds: tuple[int, ...] = SEEDS,
    targets: tuple[str, ...] = TARGETS,
    n_jobs: int = 2,
) -> dict[tuple[str, str], list[list[Trained]]]:
    """Every model of :data:`MODELS` on every target, once per seed, the seeds in parallel.

    Returns
    -------
    dict
        ``(model name, target) -> [per seed: [X, Y, Z network]]``.
    """
    keys = [(name, target, seed) for name in MODELS for target in targets for seed in seeds]
    # the models with the most training rows first, so that no long task runs alone at the end
    rows = {name: sum(len(runs[p].toolpath) for p in pockets) for name, pockets in MODELS.items()}
    order = sorted(keys, key=lambda key: -rows[key[0]])
    tasks = [_task_args(runs, MODELS[name], target, seed, 4) for name, target, seed in order]
    trained = dict(zip(order, run_tasks(_train_task, tasks, n_jobs=n_jobs), strict=True))
    out: dict[tuple[str, str], list[list[Trained]]] = {}
    for name, target, seed in keys:
        out.setdefault((name, target), []).append(trained[name, target, seed])
    return out


def training_table(ensembles: dict[tuple[str, str], list[list[Trained]]]) -> pd.DataFrame:
    """Per model, target, seed and axis: the best (kept) epoch, the epochs run, and whether early
    stopping ended the training (``stopped_early``; otherwise the epoch cap did)."""
    rows = []
    for (name, target), members in ensembles.items():
        for models in members:
            for axis, m in zip("xyz", models, strict=True):
                run = len(m.history["val"])
                rows.append({
                    "model": name, "target": target, "seed": m.train_config.seed, "axis": axis,
                    "best_epoch": m.best_epoch, "epochs_run": run,
                    "stopped_early": run < m.train_config.max_epochs,
                })  # fmt: skip
    return pd.DataFrame(rows)


def predict_feeds(members: list[list[Trained]], run: PocketRun) -> np.ndarray:
    """Predicted axis feeds at every cutter location, shape (N, 3): the mean over the members
    (one member per seed, each ``[X, Y, Z network]``; a one-member list is one seed)."""
    return predict_all_feeds(members, [run])[0]


def predict_all_feeds(members: list[list[Trained]], runs: list[PocketRun]) -> list[np.ndarray]:
    """:func:`predict_feeds` of several pockets, each network run once over all of them."""
    return _mean_feeds(members, _axis_inputs(runs), runs)


def member_feeds(members: list[list[Trained]], runs: list[PocketRun]) -> list[list[np.ndarray]]:
    """Each member's (seed's) :func:`predict_all_feeds` of the pockets, their features gathered
    once for all members."""
    xs = _axis_inputs(runs)
    return [_mean_feeds([models], xs, runs) for models in members]


def _axis_inputs(runs: list[PocketRun]) -> list[np.ndarray]:
    """The pockets' features, one contiguous (N, 9) array per axis."""
    x = np.concatenate([r.features for r in runs])
    return [np.ascontiguousarray(x[:, a]) for a in range(x.shape[1])]


def _mean_feeds(
    members: list[list[Trained]], xs: list[np.ndarray], runs: list[PocketRun]
) -> list[np.ndarray]:
    feeds = np.mean(
        [np.column_stack([m.predict(xs[a])[:, 0] for a, m in enumerate(models)])
         for models in members],
        axis=0,
    )  # fmt: skip
    return np.split(feeds, np.cumsum([len(r.features) for r in runs])[:-1])


def predict_time(members: list[list[Trained]], run: PocketRun) -> tuple[float, np.ndarray]:
    """Machining time of the ensemble (eq. 9-10, every block, rapids included).

    Each member (seed) turns its axis feeds into block times (eq. 9-10); the ensemble's block
    time is the mean of the members' times, not the time of their mean feed vector (whose
    resultant is shorter than every member's where the members disagree on direction).

    Returns the time (s) and the ensemble's resultant feed at each cutter location, the block's
    length over its mean time, shape (N,).
    """
    return predict_times(members, [run])[0]


def predict_times(
    members: list[list[Trained]], runs: list[PocketRun]
) -> list[tuple[float, np.ndarray]]:
    """:func:`predict_time` of several pockets, each network run once over all of them."""
    per_member = member_feeds(members, runs)
    out = []
    for k, run in enumerate(runs):
        lengths = run.toolpath.lengths_mm
        t = np.mean([sun.block_times_s(feeds[k], lengths, run.commanded_mm_s)
                     for feeds in per_member], axis=0)  # fmt: skip
        out.append((float(t.sum()), lengths / t))
    return out


def time_table(runs: dict[int, PocketRun], members: list[list[Trained]]) -> pd.DataFrame:
    """Per pocket: measured, CAD/CAM and network (ensemble) machining times with errors
    (Tables 3-4). Errors are signed, (predicted - measured) / measured * 100."""
    rows = []
    for k, run in runs.items():
        nn_s, _ = predict_time(members, run)
        rows.append({
            "pocket": k, "measured_s": run.measured_s, "cam_s": run.cam_s,
            "cam_err_pct": error_pct(run.cam_s, run.measured_s, signed=True),
            "nn_s": nn_s, "nn_err_pct": error_pct(nn_s, run.measured_s, signed=True),
        })  # fmt: skip
    return pd.DataFrame(rows)


def logger_variant(
    profile: Profile, rate_hz: float, *, seed: int = 0, seeds: tuple[int, ...] = SEEDS,
    n_jobs: int = 2, **kwargs,
) -> pd.DataFrame:  # fmt: skip
    """Both models on a logger of another rate (a labelled variant of the paper's set-up): the
    pockets run and recorded at ``rate_hz``, the networks trained on those records as the
    chapter's are, and each model's ensemble error and the target bias per pocket.

    Parameters
    ----------
    profile : Profile
    rate_hz : float
        The logger's records per second.
    seed, seeds, n_jobs
        As for :func:`run_pockets` and :func:`train_ensembles`.
    **kwargs
        To :func:`run_pocket` (``jitter_s``).

    Returns
    -------
    pandas.DataFrame
        ``pocket, rate_hz, bias_err_pct, records_per_s, m1_err_pct, m2_err_pct``; signed, %.
    """
    runs = run_pockets(profile, seed=seed, n_jobs=n_jobs, rate_hz=rate_hz, **kwargs)
    ensembles = train_ensembles(runs, seeds=seeds, targets=("measured",), n_jobs=n_jobs)
    rows = []
    for k, run in runs.items():
        bias = error_pct(target_time(run), run.measured_s, signed=True)
        row = {"pocket": k, "rate_hz": rate_hz, "bias_err_pct": bias,
               "records_per_s": len(run.records.t_s) / run.measured_s}  # fmt: skip
        for name, short in (("model #1", "m1"), ("model #2", "m2")):
            t, _ = predict_time(ensembles[name, "measured"], run)
            row[f"{short}_err_pct"] = error_pct(t, run.measured_s, signed=True)
        rows.append(row)
    return pd.DataFrame(rows)


def seed_table(runs: dict[int, PocketRun], members: list[list[Trained]]) -> pd.DataFrame:
    """Per pocket, each seed's signed error (``seed_<s>_err_pct``), the ensemble's
    (``ensemble_err_pct``: the mean of the seeds' times, eq. 9-10, the reported network)
    and the spread of the seeds (mean, standard deviation, min, max)."""
    rows = []
    for k, run in runs.items():
        errs = {
            f"seed_{models[0].train_config.seed}_err_pct": error_pct(
                predict_time([models], run)[0], run.measured_s, signed=True
            )
            for models in members
        }
        e = np.array(list(errs.values()))
        rows.append({
            "pocket": k, **errs,
            "ensemble_err_pct": error_pct(predict_time(members, run)[0], run.measured_s,
                                          signed=True),
            "seed_mean_err_pct": e.mean(), "seed_std_err_pct": e.std(ddof=1) if len(e) > 1 else 0.0,
            "seed_min_err_pct": e.min(), "seed_max_err_pct": e.max(),
        })  # fmt: skip
    return pd.DataFrame(rows)


def your_program(
    path, members: list[list[Trained]], profile: Profile, runs: dict[int, PocketRun]
) -> ProgramResult:
    """Sun's per-axis networks on a reader's program beside the machine's time for it (the FIR
    kernel of ``profile``, the chapter's simulated Siemens, from the origin) and CAD/CAM.

    Parameters
    ----------
    path : str or path-like
        A G-code file.
    members : list of [X, Y, Z network]
        The chapter's model, one member per seed (:func:`predict_time`), never retrained here.
    profile : Profile
        The chapter's machine.
    runs : dict of PocketRun
        The chapter's pockets, for where the program leaves the training data.
    """

    def method(text: str, source: str) -> ProgramResult:
        parse(text, source=source)  # a program the reader cannot read is named by its file
        run = run_pocket(text, 0, profile)
        nn_s, _ = predict_time(members, run)
        lengths = run.toolpath.lengths_mm
        nn_block_s = sun.block_times_s(predict_feeds(members, run), lengths, run.commanded_mm_s)
        true_block_s = np.diff(block_targets(run.motion, run.toolpath).junction_sample)
        feeds = block_feeds(lengths, {"true_mm_s": true_block_s * run.motion.period_s,
                                      "model_mm_s": nn_block_s})  # fmt: skip
        names = tuple(f"{a} {f}" for a in "XYZ" for f in sun.FEATURES)
        train = np.concatenate([r.features for r in runs.values()]).reshape(-1, len(names))
        arcs = int(np.isin(run.toolpath.kind, (MotionKind.ARC_CW, MotionKind.ARC_CCW)).sum())
        notes = (f"{len(run.toolpath)} cutter locations, {arcs} of them ends of arcs, which the "
                 "networks' features read as chords (the paper's programs are lines).",
                 *domain_notes(run.features.reshape(len(run.toolpath), -1), train, names,
                               rows="cutter locations"))  # fmt: skip
        times = program_times(("machine", run.measured_s), {"model": nn_s, "CAD/CAM": run.cam_s})
        return ProgramResult(Path(source).name, times, feeds, notes)

    return run_program(path, method)


def target_time(run: PocketRun, target: str = "measured", kinds=None) -> float:
    """Eq. 10 fed with the targets themselves, over the blocks of ``kinds`` (all if None).

    Its error against the measured time is the bias of the target definition: what the
    targets, not a network, put into eq. 10.
    """
    t = sun.block_times_s(run.target(target), run.toolpath.lengths_mm, run.commanded_mm_s)
    if kinds is not None:
        t = t[np.isin(run.toolpath.kind, kinds)]
    return float(t.sum())


def error_sources(
    runs: dict[int, PocketRun], ensembles: dict[tuple[str, str], list[list[Trained]]]
) -> pd.DataFrame:
    """Per pocket and target: the bias of the target definition (eq. 10 fed with the targets;
    ``bias_<t>_err_pct``), the share of it in the rapids (``bias_<t>_rapids_s``: the targets'
    rapid time minus the machine's) and the ensembles' errors (``m1_<t>_err_pct``,
    ``m2_<t>_err_pct``); ``<t>`` is ``logger`` or ``1khz``."""
    rows = []
    for k, run in runs.items():
        row = {"pocket": k, "measured_s": run.measured_s}
        rapid = np.isin(run.motion.block, np.flatnonzero(run.toolpath.kind == MotionKind.RAPID))
        for target, label in (("measured", "logger"), ("true", "1khz")):
            row[f"bias_{label}_err_pct"] = error_pct(
                target_time(run, target), run.measured_s, signed=True
            )
            row[f"bias_{label}_rapids_s"] = (
                target_time(run, target, [MotionKind.RAPID]) - rapid.sum() * run.motion.period_s
            )
            for name, short in (("model #1", "m1"), ("model #2", "m2")):
                if (name, target) in ensembles:
                    t, _ = predict_time(ensembles[name, target], run)
                    row[f"{short}_{label}_err_pct"] = error_pct(t, run.measured_s, signed=True)
        rows.append(row)
    return pd.DataFrame(rows)


#: Blocks at least this long (mm) are the part's straight moves (one G1 line each), its links
#: and most of its rapids; the chords of its curves and its plunges are shorter.
LONG_BLOCK_MM = 10.0


def time_by_block_length(runs: dict[int, PocketRun], members: list[list[Trained]]) -> pd.DataFrame:
    """Where eq. 10's time goes: per pocket, over its long blocks (at least
    :data:`LONG_BLOCK_MM`: straight moves, links, most rapids) and over the others (chords of
    curves, plunges), the machine's time and eq. 10's.

    Parameters
    ----------
    runs : dict of PocketRun
    members : list of [X, Y, Z network]
        An ensemble (:func:`predict_time`), trained on the logger's targets.

    Returns
    -------
    pandas.DataFrame
        Per pocket and ``blocks`` (``"long"``, ``"short"``): ``count``, ``length_share_pct``
        (of the pocket's path), ``machine_s`` (between the junction points, 1 kHz), eq. 10's
        time fed with the logger's targets (``logger_eq10_s``), with the 1 kHz block averages
        (``khz_eq10_s``) and with the ensemble's feeds (``model_s``), all in s.
    """
    rows = []
    for k, run in runs.items():
        lengths = run.toolpath.lengths_mm
        machine = np.diff(block_targets(run.motion, run.toolpath).junction_sample)
        machine = machine * run.motion.period_s
        _, feed = predict_time(members, run)
        times = {
            "machine_s": machine,
            "logger_eq10_s": sun.block_times_s(run.measured_feed_mm_s, lengths,
                                               run.commanded_mm_s),
            "khz_eq10_s": sun.block_times_s(run.true_feed_mm_s, lengths, run.commanded_mm_s),
            "model_s": lengths / feed,
        }  # fmt: skip
        for name, on in (("long", lengths >= LONG_BLOCK_MM), ("short", lengths < LONG_BLOCK_MM)):
            rows.append({
                "pocket": k, "blocks": name, "count": int(on.sum()),
                "length_share_pct": 100 * lengths[on].sum() / lengths.sum(),
                **{key: float(t[on].sum()) for key, t in times.items()},
            })  # fmt: skip
    return pd.DataFrame(rows)


#: Pockets on which the paper's model #2 improved on model #1 (Sec. 4.2: "though the error for
#: pocket #1 and #4 was slightly increased, the error for other pockets was improved").
IMPROVED_POCKETS = (2, 3, 5, 6, 7, 8)
