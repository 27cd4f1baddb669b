r"""The learned cycle-time methods on a real machine: Chien et al. (2023)'s BiLSTM and Sun et
al. (2022)'s per-axis networks trained on the MTConnect logs of NIST's Hurco VMX 24s
(:mod:`nctwin.mtconnect`), each program held out in turn within its machine, the folds of
:func:`nctwin.calibrate.leave_one_program_out`.

**What a log resolves** (:mod:`nctwin.chapters.nist_targets`). ``Block_Number`` is logged on
change, so a short line may never show and an event may lag the line's start: the log times
*spans*, never single lines. Over the motion window (:func:`nctwin.runtimes.motion_window`, what
``Verdict.motion_s`` times), the span from the event of line :math:`a` to the event of the next
observed line :math:`b` times the moves of lines :math:`a \ldots b-1`. Each move of a span gets
the span's average feed, its moves' length over its time: Chien's target, with its log time
ratio :math:`\ln(F_k \tilde t_k / l_k)` as :func:`nctwin.estimate.learned.move_data` forms it
(:math:`F_k` the feed feature, :math:`\tilde t_k` the move's share of the span's time at the
span's average feed). A span that holds a line of non-motion time (a tool change, a spindle
start, an optional stop, a dwell, an M-code the control waits at) or whose time is not positive
is left NaN, out of the loss. Sun's per-axis target is the ``Feed_Rate`` record nearest in time
to the move's interval (the span's time laid over its moves in proportion to their length) among
the records within the move's span, times the move's direction; NaN where the span holds no
record (or is left NaN above). The moves and features are
:func:`~nctwin.estimate.learned.move_data`'s (arcs cut into chords by
:func:`~nctwin.estimate.learned.model_blocks`) on the fold's machine
(:func:`nctwin.calibrate.base_machine` at the fold's axis rapid, its rapids at the run's rapid
override, :func:`nctwin.identify.at_rapid_override`) with :data:`CONTROL`.

**One** :class:`~nctwin.estimate.learned.MoveData` **per program and rapid override**
(:func:`program_move_data`): the targets are the median, move by move, of its runs' targets
(NaN ones left out). The runs of one program at one override run the same text at the same
features (Hurco02's OP1 and OP3 repeat their motion time to 0.3 s in 1750 s and 0.2 s in
370 s): the median keeps that and drops a single run's lagging event, and the training set stays
one copy of the program, not 10-16 copies of the same inputs. As in
:func:`nctwin.calibrate.calibrate`, runs of an assumed rapid override are predicted but never
trained on.

**Pieces.** Hurco02 has two programs (OP1, OP3) and Hurco04 seven plates, one run each:
training on one program would leave no whole program to validate on. Each training program is
cut at its tool changes (:func:`tool_sections`): each tool's section is a sub-program, and
validation holds out whole sections (``TrainConfig.val_share`` of them, at least one). The
held-out program's data take part in neither training nor validation (:func:`fold_data`).

**Budget.** Each network trains on at most :data:`MAX_TRAIN_ROWS` moves of its fold's pieces
(:func:`learned_predictions` says why and what it costs).
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..calibrate import axis_rapid_mm_s, base_machine, run_overrides
from ..controls import PlannerControl
from ..estimate.learned import (
    BILSTM_CONFIG,
    FEATURES,
    MoveData,
    axis_nn_move_times,
    bilstm_move_times,
    model_blocks,
    move_data,
    train_configs,
)
from ..identify import at_rapid_override
from ..learn.train import TrainConfig, Trained, _split, fit
from ..methods import sun2022
from ..mtconnect import Run
from ..runner import run_tasks
from ..runtimes import ProgramLines, RunTimes, logged_runs, motion_window
from ..toolpath import Toolpath
from .nist_targets import axis_targets, block_spans, non_motion_lines, span_targets
from .your_program import domain_notes

__all__ = [
    "CONTROL",
    "MAX_EPOCHS",
    "MAX_TRAIN_ROWS",
    "MAX_VAL_ROWS",
    "METHODS",
    "MIN_PIECE_MOVES",
    "Fold",
    "HeldOutRun",
    "LoggedRun",
    "configs",
    "fold_data",
    "learned_predictions",
    "move_feeds",
    "program_move_data",
    "run_move_data",
    "sample_windows",
    "tool_sections",
    "train_folds",
    "training_sets",
]

#: The control the features are computed with (the calibration's planner settings).
CONTROL = PlannerControl(period_s=0.001, blend_tol_mm=0.0254)

#: Tool sections shorter than this many moves join the next (:func:`tool_sections`).
MIN_PIECE_MOVES = 256


@dataclass(frozen=True, eq=False)
class LoggedRun:
    """A valid run of a machine's logs: the :class:`~nctwin.mtconnect.Run` (its events) and its
    :class:`~nctwin.runtimes.RunTimes` (what :func:`nctwin.runtimes.machine_runs` returns)."""

    run: Run
    times: RunTimes


@functools.cache
def _nist_runs(machine_name: str) -> tuple[tuple[LoggedRun, ...], dict, pd.DataFrame]:
    """:func:`nctwin.runtimes.logged_runs` of the shipped logs."""
    pairs, programs, rapids = logged_runs(machine_name)
    return tuple(LoggedRun(run, times) for run, times in pairs), programs, rapids


def run_move_data(
    run: Run, lines: ProgramLines, tp: Toolpath, machine, name: str | None = None
) -> MoveData:
    """The moves of one run's motion window with the targets its log resolves.

    Parameters
    ----------
    run : Run
        A valid run of the program.
    lines, tp : ProgramLines, Toolpath
        The program (:func:`nctwin.runtimes.program_lines`); only the motion window's blocks,
        ``tp.take(motion_window(tp, lines))``, are moves.
    machine : Machine
        The machine at the run's rapid override (features: :data:`CONTROL`).
    name : str, optional
        The data's name (default: the run's log).

    Returns
    -------
    MoveData
        :func:`~nctwin.estimate.learned.move_data` of the window (M moves) with ``targets``
        (M, 2) of :func:`span_targets` and ``axis_targets`` (M, 3) of :func:`axis_targets`;
        ``measured_s`` the window's time from the first to the last span event (the run's
        ``Verdict.motion_s``).
    """
    data = move_data(name or run.log, tp.take(motion_window(tp, lines)), machine, CONTROL)
    spans = block_spans(run.block_t_s, run.block, lines.first_cut, lines.m30)
    y, span, move_t = span_targets(
        data.moves.line, data.features[:, 1], data.features[:, 0], spans,
        non_motion_lines(lines, tp),
    )  # fmt: skip
    ax = axis_targets(data.moves.directions, span, move_t, spans, run.feed_mm_s)
    measured = float(spans.t1_s[-1] - spans.t0_s[0]) if len(spans.t0_s) else np.nan
    return dataclasses.replace(data, targets=y, axis_targets=ax, measured_s=measured)


def program_move_data(
    runs_: Sequence[Run], lines: ProgramLines, tp: Toolpath, machine, name: str
) -> MoveData:
    """One program at one rapid override: the median over ``runs_`` of :func:`run_move_data`'s
    targets, move by move (NaN ones left out; NaN where every run's is), shape (M, 2) and
    (M, 3); ``measured_s`` the median of the runs' (see the module docstring for why)."""
    each = [run_move_data(r, lines, tp, machine, name) for r in runs_]
    if len(each) == 1:
        return each[0]
    with warnings.catch_warnings():  # "All-NaN slice": a move no run resolves stays NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        y = np.nanmedian(np.stack([d.targets for d in each]), axis=0)
        ax = np.nanmedian(np.stack([d.axis_targets for d in each]), axis=0)
    measured = float(np.median([d.measured_s for d in each]))
    return dataclasses.replace(each[0], targets=y, axis_targets=ax, measured_s=measured)


def tool_sections(data: MoveData, lines: ProgramLines) -> list[MoveData]:
    """A program's moves cut at its tool changes inside the motion window: one piece per tool.

    Parameters
    ----------
    data : MoveData
        A program's window (M moves).
    lines : ProgramLines
        Its tool changes; a cut falls at each one's first (``G28``) line, so its moves go with
        the tool that follows (their targets are NaN: the span holds the change).

    Returns
    -------
    list of MoveData
        In program order, named ``"{name}#{k}"`` (k from 0); each with its rows of
        ``features`` (m_k, 7), ``targets`` (m_k, 2), ``axis_features`` (m_k, 3, 9),
        ``axis_targets`` (m_k, 3); ``dwell_s`` 0, ``measured_s`` NaN. A section of fewer than
        :data:`MIN_PIECE_MOVES` moves joins the next (the last one the one before): a
        validation piece of a few moves would decide early stopping on noise (the plates'
        first tools drill 9-14 moves). Pieces without a finite target are dropped.
    """
    piece = np.searchsorted(np.sort(lines.tool_changes[:, 0]), data.moves.line, side="right")
    ids, counts = np.unique(piece, return_counts=True)
    groups: list[list[int]] = []
    pending: list[int] = []
    size = 0
    for i, c in zip(ids.tolist(), counts.tolist(), strict=True):
        pending.append(i)
        size += c
        if size >= MIN_PIECE_MOVES:
            groups.append(pending)
            pending, size = [], 0
    if pending and groups:
        groups[-1] += pending
    elif pending:
        groups.append(pending)
    out = []
    for g in groups:
        m = np.isin(piece, g)
        if not np.isfinite(data.targets[m]).any():
            continue
        out.append(
            dataclasses.replace(
                data,
                name=f"{data.name}#{len(out)}",
                moves=data.moves.take(m),
                features=data.features[m],
                targets=data.targets[m],
                axis_features=data.axis_features[m],
                axis_targets=data.axis_targets[m],
                dwell_s=0.0,
                measured_s=np.nan,
            )
        )
    return out


@dataclass(frozen=True, eq=False)
class HeldOutRun:
    """A run of the held-out program, as its fold predicts it.

    Parameters
    ----------
    log : str
    override_pct : float
        Its rapid override (:func:`nctwin.calibrate.run_overrides`; where assumed, the median
        of the fold's training runs of a known override, as
        :func:`nctwin.calibrate.predict_runs` does).
    override_source : str
    measured_s : float
        Its ``Verdict.motion_s``.
    data : MoveData
        :func:`run_move_data` on the fold's machine at ``override_pct`` (its targets are for
        figures only: nothing trains on them).
    run : Run
        Its events.
    """

    log: str
    override_pct: float
    override_source: str
    measured_s: float
    data: MoveData
    run: Run


@dataclass(frozen=True, eq=False)
class Fold:
    """One held-out program of one machine and what its networks may learn from.

    Parameters
    ----------
    machine_name, program : str
        The machine and the held-out program's file.
    rapid_mm_s : float
        The axis rapid read from the other programs' runs (:func:`nctwin.calibrate.
        axis_rapid_mm_s`).
    train_programs : tuple of str
        The other programs.
    pieces : tuple of MoveData
        Their tool sections (:func:`tool_sections`) of :func:`program_move_data` per program
        and rapid override, runs of an assumed override left out.
    held_out : tuple of HeldOutRun
        The held-out program's runs.
    """

    machine_name: str
    program: str
    rapid_mm_s: float
    train_programs: tuple[str, ...]
    pieces: tuple[MoveData, ...]
    held_out: tuple[HeldOutRun, ...]


def fold_data(machine_name: str, program: str) -> Fold:
    """The :class:`Fold` of ``program`` held out of ``machine_name``'s valid runs, as
    :func:`nctwin.calibrate.leave_one_program_out` builds it: the axis rapid from the other
    programs' rapid plateaus, the training runs' overrides from it.

    Raises
    ------
    ValueError
        ``program`` has no valid run, or no other program a run of a known rapid override.
    """
    logged, programs, rapids = _nist_runs(machine_name)
    train = [r for r in logged if r.times.program != program]
    test = [r for r in logged if r.times.program == program]
    if not test:
        raise ValueError(f"{program} has no valid run of {machine_name}")
    rapid_mm_s, _ = axis_rapid_mm_s(rapids[rapids["program"] != program], [r.times for r in train])
    pct, source = run_overrides([r.times for r in train], rapid_mm_s)
    known = source != "assumed"
    if not known.any():
        raise ValueError(f"no run of {machine_name} but {program}'s has a known rapid override")
    machine = base_machine(machine_name, rapid_mm_s)
    groups: dict[tuple[str, float], list[Run]] = {}
    for r, o, k in zip(train, pct, known, strict=True):
        if not k:
            continue
        groups.setdefault((r.times.program, float(o)), []).append(r.run)
    pieces = []
    for (file, o), runs_ in sorted(groups.items()):
        lines, tp = programs[file]
        at = at_rapid_override(machine, o / 100)
        pieces += tool_sections(program_move_data(runs_, lines, tp, at, f"{file}@{o:g}"), lines)
    test_pct, test_source = run_overrides(
        [r.times for r in test], rapid_mm_s, float(np.median(pct[known]))
    )
    lines, tp = programs[program]
    held_out = tuple(
        HeldOutRun(
            r.run.log, float(o), str(s), r.times.motion_s,
            run_move_data(r.run, lines, tp, at_rapid_override(machine, o / 100)), r.run,
        )
        for r, o, s in zip(test, test_pct, test_source, strict=True)
    )  # fmt: skip
    return Fold(machine_name, program, rapid_mm_s, tuple(sorted({f for f, _ in groups})),
                tuple(pieces), held_out)  # fmt: skip


#: The most training rows (moves) a network of a fold sees, and validation rows it checks.
MAX_TRAIN_ROWS = 16384
MAX_VAL_ROWS = 4096
#: The epoch cap: far above where early stopping ends every training (``converged`` reports
#: it), so that it never decides.
MAX_EPOCHS = 5000
#: The learned methods (:func:`learned_predictions`' ``method``).
METHODS = ("bilstm", "axis_nn")


def _columns(piece: MoveData, net: str) -> tuple[np.ndarray, np.ndarray]:
    """A piece's inputs and targets for ``net``: ``"bilstm"`` or an axis, ``"x"``, ``"y"``,
    ``"z"``."""
    if net == "bilstm":
        return piece.features, piece.targets
    a = "xyz".index(net)
    return piece.axis_features[:, a], piece.axis_targets[:, a : a + 1]


def sample_windows(
    xs: Sequence[np.ndarray], ys: Sequence[np.ndarray], window: int, max_rows: int
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """At most ``max_rows`` rows of pieces, as windows of ``window`` consecutive rows.

    Parameters
    ----------
    xs, ys : sequences of numpy.ndarray, shapes (N_i, n_in) and (N_i, n_out)
        The pieces' inputs and targets.
    window, max_rows : int

    Returns
    -------
    xs, ys : lists of numpy.ndarray, shapes (w_j, n_in) and (w_j, n_out)
        The windows: each piece cut into consecutive windows of ``window`` rows from its
        start (a shorter tail dropped; a piece shorter than ``window``, one window of its
        rows), those with a finite target kept, and of these, evenly spaced over the pieces in
        order, as many whole windows as ``max_rows`` holds (all where they fit). The same
        rows for every seed.
    """
    cuts = []
    for i, (x, y) in enumerate(zip(xs, ys, strict=True)):
        starts = range(0, max(len(x) - window, 0) + 1, window)
        cuts += [(i, s) for s in starts if np.isfinite(y[s : s + window]).any()]
    rows = [min(window, len(xs[i])) for i, _ in cuts]
    if sum(rows) > max_rows:
        n = max(max_rows // window, 1)
        keep = np.unique(np.linspace(0, len(cuts) - 1, n).round().astype(int))
        cuts = [cuts[k] for k in keep]
    return (
        [xs[i][s : s + window] for i, s in cuts],
        [ys[i][s : s + window] for i, s in cuts],
    )


def training_sets(fold: Fold, net: str, config: TrainConfig) -> dict:
    """What one network of ``fold`` trains on: ``xs``, ``ys`` (training windows of the
    training pieces) and ``validation`` (windows of the validation pieces), from a split of the
    pieces into training and validation pieces as :func:`nctwin.learn.train.fit` splits
    programs (``config.seed``, ``config.val_share``, at least one), each side subsampled by
    :func:`sample_windows` (:data:`MAX_TRAIN_ROWS`, :data:`MAX_VAL_ROWS`); ``train_pieces``,
    ``val_pieces``: the pieces' names; ``n_rows``: the training pieces' rows before subsampling."""
    train_idx, val_idx = _split(len(fold.pieces), config)
    cols = [_columns(p, net) for p in fold.pieces]
    w = config.window_lines
    xs, ys = sample_windows(*zip(*(cols[i] for i in train_idx), strict=True), w, MAX_TRAIN_ROWS)
    vx, vy = sample_windows(*zip(*(cols[i] for i in val_idx), strict=True), w, MAX_VAL_ROWS)
    return {
        "xs": xs,
        "ys": ys,
        "validation": (vx, vy),
        "train_pieces": tuple(fold.pieces[i].name for i in train_idx),
        "val_pieces": tuple(fold.pieces[i].name for i in val_idx),
        "n_rows": int(sum(len(fold.pieces[i].features) for i in train_idx)),
    }


def configs(seed: int) -> tuple[TrainConfig, TrainConfig]:
    """The BiLSTM's and the per-axis networks' training: :func:`nctwin.estimate.learned.
    train_configs` (the LinuxCNC chapter's), the epoch cap raised to :data:`MAX_EPOCHS`."""
    bilstm, axis = train_configs(seed)
    return (dataclasses.replace(bilstm, max_epochs=MAX_EPOCHS),
            dataclasses.replace(axis, max_epochs=MAX_EPOCHS))  # fmt: skip


def _fit_task(net: str, sets: dict, config: TrainConfig, name: str) -> Trained:
    """One network (a worker's task)."""
    model = BILSTM_CONFIG if net == "bilstm" else sun2022.MODEL_CONFIG
    return fit(model, config, sets["xs"], sets["ys"], validation=sets["validation"],
               name=name, progress=False)  # fmt: skip


def _nets(method: str) -> tuple[str, ...]:
    return ("bilstm",) if method == "bilstm" else ("x", "y", "z")


def _move_times(method: str, models: Sequence[Trained], data: MoveData) -> np.ndarray:
    """The networks' own predicted time of each move (no floor), shape (M,)."""
    if method == "bilstm":
        return bilstm_move_times(models[0], data)
    return axis_nn_move_times(models, data)


def train_folds(
    machine_name: str,
    seeds: Sequence[int] = (0, 1, 2, 3, 4),
    programs: Sequence[str] | None = None,
    *,
    n_jobs: int = 2,
) -> tuple[list[Fold], dict]:
    """The folds of ``machine_name`` (those holding out ``programs``; default every program)
    and their networks, one per method, seed and net, trained in ``n_jobs`` processes.

    Returns
    -------
    folds : list of Fold
        One per held-out program, in file-name order.
    models : dict
        ``(program, method, seed)`` to ``(models, sets)``: the trained networks (one for
        ``"bilstm"``, X, Y, Z for ``"axis_nn"``) and their :func:`training_sets`' summaries.
    """
    if programs is None:
        programs = sorted({r.times.program for r in _nist_runs(machine_name)[0]})
    folds = [fold_data(machine_name, p) for p in sorted(programs)]
    tasks, keys, summaries = [], [], {}
    for fold in folds:
        for seed in seeds:
            for method, config in zip(METHODS, configs(seed), strict=True):
                for net in _nets(method):
                    sets = training_sets(fold, net, config)
                    name = f"nist_{machine_name}_{net if net == 'bilstm' else 'axis_' + net}"
                    tasks.append((net, sets, config, name))
                    keys.append((fold.program, method, seed))
                    summaries.setdefault(keys[-1], []).append(
                        {k: sets[k] for k in ("val_pieces", "n_rows")}
                        | {"n_train_rows": int(sum(len(x) for x in sets["xs"]))}
                    )
    trained = run_tasks(_fit_task, tasks, n_jobs=n_jobs)
    models: dict = {}
    for key, model in zip(keys, trained, strict=True):
        models.setdefault(key, []).append(model)
    return folds, {k: (models[k], summaries[k]) for k in models}


def learned_predictions(
    machine_name: str, seeds: Sequence[int] = (0, 1, 2, 3, 4), *, n_jobs: int = 2
) -> pd.DataFrame:
    """Each program of ``machine_name`` held out and predicted by the BiLSTM and the per-axis
    networks trained on the other programs' runs, once per seed.

    **Budget.** Every fold of both machines, five seeds, trains in 100-120 s from an empty cache
    on two cores shared with other work (98 s and 119 s measured, two worker processes,
    :func:`nctwin.runner.run_tasks`; 20 s from a full cache). A Hurco04 fold's training
    programs hold 250,000-315,000 moves (four or five plates of 63,000 moves, arcs in chords,
    one geometry at other feeds), Hurco02's OP1 35,000; a BiLSTM step took about 5 ms per
    32 windows of 128 moves on one core, so one epoch over all of a Hurco04 fold's moves would
    take about 0.3 s, and its networks stop after 25-400 epochs.
    Each network therefore sees at most :data:`MAX_TRAIN_ROWS` training moves, whole windows of
    ``window_lines`` consecutive moves evenly spaced over its training pieces, and
    :data:`MAX_VAL_ROWS` of its validation pieces (:func:`sample_windows`), the same rows for
    every seed. The training settings are the LinuxCNC chapter's (:func:`configs`), the epoch
    cap far above where early stopping ends every one (``converged``). Same seed, same numbers,
    bit for bit (two runs from empty caches agree).

    Returns
    -------
    pandas.DataFrame
        A row per held-out run, method and seed: ``program``, ``log``, ``start_s`` (the run's
        start: a log may hold two runs), ``method``
        (:data:`METHODS`), ``seed``, ``override_pct``, ``override_source``, ``measured_s`` (the
        run's ``motion_s``), ``predicted_motion_s`` (the networks' own time of the motion
        window's moves, no floor: no tool change, spindle start or optional stop time),
        ``error_pct`` (signed, of the run), ``n_train_moves`` (the training pieces' moves),
        ``n_train_rows`` (the rows trained on, per net), ``n_pieces`` (training and validation
        pieces), ``val_pieces``, ``epochs`` and ``best_epoch`` (the most over the nets),
        ``converged`` (every net stopped early), ``train_s`` (summed over the nets, as
        recorded with the checkpoint).
    """
    folds, models = train_folds(machine_name, seeds, n_jobs=n_jobs)
    rows = []
    for fold in folds:
        for method in METHODS:
            for seed in seeds:
                nets, sums = models[(fold.program, method, seed)]
                cache: dict = {}
                for run in fold.held_out:
                    if run.override_pct not in cache:
                        cache[run.override_pct] = float(_move_times(method, nets, run.data).sum())
                    predicted = cache[run.override_pct]
                    rows.append({
                        "program": fold.program, "log": run.log,
                        "start_s": run.run.start_s, "method": method,
                        "seed": seed, "override_pct": run.override_pct,
                        "override_source": run.override_source, "measured_s": run.measured_s,
                        "predicted_motion_s": predicted,
                        "error_pct": 100 * (predicted / run.measured_s - 1),
                        "n_train_moves": sums[0]["n_rows"],
                        "n_train_rows": sums[0]["n_train_rows"],
                        "n_pieces": len(fold.pieces),
                        "val_pieces": " ".join(sums[0]["val_pieces"]),
                        "epochs": max(len(m.history["train"]) for m in nets),
                        "best_epoch": max(m.best_epoch for m in nets),
                        "converged": all(m.converged for m in nets),
                        "train_s": sum(m.train_seconds for m in nets),
                    })  # fmt: skip
    return pd.DataFrame(rows)


def move_feeds(
    machine_name: str, program: str, seeds: Sequence[int] = (0, 1, 2, 3, 4), *, n_jobs: int = 2
) -> pd.DataFrame:
    """The per-move logged and predicted feeds of one held-out program (for a figure), on its
    run of median ``motion_s`` (the lower middle one of an even count).

    Returns
    -------
    pandas.DataFrame
        A row per move of the motion window, in order: ``move``, ``line``, ``kind``
        (:class:`~nctwin.toolpath.MotionKind`), ``length_mm``, ``feed_mm_s`` (the feed
        feature: programmed, rapid at the run's override, within the axis limits),
        ``t0_s`` (the move's start from the window's start, its span's time laid over its moves;
        NaN where unresolved), ``logged_feed_mm_s`` (the span's average feed, Chien's target),
        ``logged_axis_feed_mm_s`` (the norm of Sun's target, the nearest record),
        ``bilstm_feed_mm_s`` and ``axis_nn_feed_mm_s`` (the move's length over its predicted
        time, averaged over ``seeds``); ``attrs``: ``log``, ``measured_s``.
    """
    folds, models = train_folds(machine_name, seeds, [program], n_jobs=n_jobs)
    fold = folds[0]
    order = np.argsort([r.measured_s for r in fold.held_out], kind="stable")
    run = fold.held_out[order[(len(order) - 1) // 2]]
    d = run.data
    length = d.features[:, 1]
    out = {"move": np.arange(len(length)), "line": d.moves.line, "kind": d.moves.kind,
           "length_mm": length, "feed_mm_s": d.features[:, 0]}  # fmt: skip
    lines, tp = _nist_runs(machine_name)[1][program]
    spans = block_spans(run.run.block_t_s, run.run.block, lines.first_cut, lines.m30)
    _, _, move_t = span_targets(d.moves.line, length, d.features[:, 0], spans,
                                non_motion_lines(lines, tp))  # fmt: skip
    out["t0_s"] = move_t[:, 0] - (spans.t0_s[0] if len(spans.t0_s) else np.nan)
    out["logged_feed_mm_s"] = d.targets[:, 0]
    out["logged_axis_feed_mm_s"] = np.linalg.norm(d.axis_targets, axis=1)
    for method in METHODS:
        t = np.mean([_move_times(method, models[(program, method, s)][0], d) for s in seeds], 0)
        out[f"{method}_feed_mm_s"] = length / t
    frame = pd.DataFrame(out)
    frame.attrs.update(log=run.log, measured_s=run.measured_s)
    return frame


def program_times(
    machine_name: str, tp: Toolpath, window: np.ndarray, seeds: Sequence[int] = (0, 1, 2, 3, 4)
) -> tuple[dict[tuple[str, str], np.ndarray], tuple[str, ...]]:
    """A reader's program as every fold's networks predict it, never retrained for it.

    Parameters
    ----------
    machine_name : str
    tp : Toolpath
        The program (N blocks).
    window : ndarray of bool, shape (N,)
        The blocks the networks time (:func:`nctwin.runtimes.motion_window`: the first cut to
        the M30); features at rapid and feed 100 % on the fold's machine (:data:`CONTROL`).

    Returns
    -------
    times : dict
        ``(held-out program, method)`` to the networks' own time of each block, ndarray of
        shape (N,) (s, no floor): a block of the window the sum of its moves' (an arc's
        chords, :func:`~nctwin.estimate.learned.model_blocks`), each move's time the mean of
        ``seeds``' (the ensemble, as :func:`learned_predictions`' rows are averaged in the
        chapter's table); 0 outside the window, for a dwell and a block of no length. Empty
        where the window has no move.
    notes : tuple of str
        :func:`~nctwin.chapters.your_program.domain_notes` of the moves' features against every
        fold's training moves.
    """
    folds, models = train_folds(machine_name, seeds)
    blocks = np.flatnonzero(window)
    part = tp.take(blocks)
    source = blocks[model_blocks(part)[1]]
    times, x = {}, None
    for fold in folds:
        machine = base_machine(machine_name, fold.rapid_mm_s)
        data = move_data(fold.program, part, machine, CONTROL)
        if not len(data.moves):
            return {}, ()
        x = data.features
        for method in METHODS:
            each = [_move_times(method, models[(fold.program, method, s)][0], data)
                    for s in seeds]  # fmt: skip
            times[(fold.program, method)] = np.bincount(
                source, weights=np.mean(each, axis=0), minlength=len(tp)
            )
    train = np.concatenate([p.features for f in folds for p in f.pieces])
    return times, domain_notes(x, train, FEATURES, rows=f"moves, {machine_name}")
