r"""The chapter "A real machine: NIST's Hurco runs": every cycle-time method against two real
machining centres, each program predicted by a calibration that never saw it.

The measured machines are NIST's two Hurco VMX 24 (``Hurco02``, ``Hurco04``), their runs read
from the shipped MTConnect logs (:mod:`nctwin.mtconnect`) and judged valid or not
(:func:`nctwin.mtconnect.validate`). No code or equation of nctwin produced these times.

**The split** (:func:`split_table`), fixed before any method is scored: within each machine,
every program is held out in turn, and every method is given the same calibration, the valid
runs of the machine's other programs (:func:`nctwin.calibrate.held_out_predictions`). Hurco02
has two programs (Box OP1 and OP3: each is predicted from the other), Hurco04 seven plates.

**The methods**, each scored on the *motion time* (``Verdict.motion_s``: from the first feed
line's event to the M30 line's, as the log times it) and the *cycle time* (the run's start to
its end):

* ``cam``: length over feed, rapids at the identified rapid feed;
* ``block_overlap``: Lee et al. (2022), its cutting time constant fitted on the calibration
  runs (:func:`nctwin.identify.fit_block_overlap`); ``block_overlap_acc`` (an ablation): its
  time constants from the planner's fitted acceleration by the rule of the LinuxCNC chapter
  (:func:`nctwin.identify.identified_block_overlap`), nothing fitted to times;
* ``planner``: the blend-arc planner with its axis accelerations fitted;
* ``kernel``: the FIR kernel with its settings fitted (a grid);
* ``bilstm`` and ``axis_nn``: Chien et al. (2023)'s BiLSTM and Sun et al. (2022)'s per-axis
  networks trained on the feeds the calibration runs' logs resolve
  (:mod:`nctwin.chapters.nist_learned`), five seeds each; the *ensemble* is the mean of the
  five networks' times;
* ``calibrated``: the calibration's own choice among the four models above, by its error on
  its own runs (:attr:`nctwin.calibrate.Calibration.best`), what ``nctwin calibrate`` writes.

Every method's motion time holds the calibration's non-motion times inside the window (tool
changes, spindle starts: :class:`~nctwin.controls.SequenceControl`), and its cycle time adds
the calibrated estimate's time before the window (the first approach) and the program's start
and end: the methods differ in how they time the motion only.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Sequence

import numpy as np
import pandas as pd

from ..calibrate import (
    LEE_PERIOD_S,
    Calibration,
    axis_rapid_mm_s,
    held_out_predictions,
    predict_runs,
    run_overrides,
    sequence_s,
)
from ..identify import identified_block_overlap
from ..mtconnect import REASONS, nist_runs_table
from ..report.claims import Claim, bootstrap_interval, with_seeds
from ..report.conditions import Condition
from ..report.papers import load_paper_table
from ..runtimes import machine_runs, motion_window
from . import nist_learned
from .nist_learned import _nist_runs

__all__ = [
    "ANALYTIC_METHODS",
    "LEARNED_METHODS",
    "MACHINES",
    "METHOD_ORDER",
    "PAPER_CLAIMS",
    "REQUIRES",
    "all_runs",
    "claims",
    "data_conditions",
    "error_pivot",
    "fitted_constants",
    "held_out_table",
    "interval_table",
    "learned_seed_table",
    "method_rows",
    "paper_bars",
    "paper_conditions",
    "paper_value",
    "plot_move_feeds",
    "repeatability",
    "seed_pivot",
    "split_table",
    "verdict_counts",
]

#: The machines of the shipped logs, by the name in their files.
MACHINES = ("Hurco02", "Hurco04")
#: The analytic methods, as :func:`method_rows` names them.
ANALYTIC_METHODS = ("cam", "block_overlap", "block_overlap_acc", "planner", "kernel")
#: The learned methods (:data:`nctwin.chapters.nist_learned.METHODS`).
LEARNED_METHODS = nist_learned.METHODS


@functools.cache
def _machine(name: str):
    """:func:`nctwin.runtimes.machine_runs` of the shipped logs of ``name``."""
    return machine_runs(name)


@functools.cache
def all_runs() -> pd.DataFrame:
    """Every run of the 80 shipped logs with its verdict
    (:func:`nctwin.mtconnect.nist_runs_table`)."""
    return nist_runs_table()


def verdict_counts() -> pd.DataFrame:
    """How many runs of each machine are valid, and why the others are not (their first
    reason, :data:`nctwin.mtconnect.REASONS`): a row per machine, a column per verdict."""
    table = all_runs().assign(verdict=lambda t: t["reason"].where(~t["valid"], "valid"))
    counts = table.groupby(["machine", "verdict"]).size().unstack(fill_value=0)
    ordered = ["valid"] + [r for r in REASONS if r in counts.columns]
    return counts[ordered].reset_index().rename_axis(columns=None)


def data_conditions() -> pd.DataFrame:
    """What the logs give each machine: logs and runs, the valid runs and their programs, the
    programs' lines, the valid runs' motion times, and how often the log records the path feed
    and the block number (medians over the valid runs, per second of run).

    Returns
    -------
    pandas.DataFrame
        A row per machine.
    """
    table = all_runs()
    rows = []
    for name in MACHINES:
        runs = table[table["machine"] == name]
        valid = runs[runs["valid"]]
        logged, _, _ = _nist_runs(name)
        _, programs, _ = _machine(name)
        lines = [len(tp) for _, tp in programs.values()]
        feed_hz = [lr.run.feed_mm_s.t_s.size / lr.run.duration_s for lr in logged]
        block_hz = [lr.run.block_t_s.size / lr.run.duration_s for lr in logged]
        rows.append({
            "machine": name, "logs": runs["log"].nunique(), "runs": len(runs),
            "valid_runs": len(valid), "programs": valid["program"].nunique(),
            "blocks_min": min(lines), "blocks_max": max(lines),
            "motion_s_min": valid["motion_s"].min(), "motion_s_max": valid["motion_s"].max(),
            "feed_records_per_s": float(np.median(feed_hz)),
            "block_events_per_s": float(np.median(block_hz)),
        })  # fmt: skip
    return pd.DataFrame(rows)


def repeatability() -> pd.DataFrame:
    """The repeatability floor: the spread of the valid runs of one program at one rapid
    override, where it ran at least twice (only Hurco02's programs did).

    Returns
    -------
    pandas.DataFrame
        A row per program and override: ``machine``, ``program``, ``override_pct``, ``runs``,
        the median, standard deviation and range (largest minus smallest) of the motion time
        (s, and the range in % of the median), the same for the cycle time.
    """
    frames = []
    for name in MACHINES:
        times, _, rapids = _machine(name)
        pct, _ = run_overrides(times, axis_rapid_mm_s(rapids, times)[0])
        frames.append(pd.DataFrame({"machine": name, "program": [r.program for r in times],
                                    "override_pct": pct, "motion_s": [r.motion_s for r in times],
                                    "cycle_s": [r.duration_s for r in times]}))  # fmt: skip
    rows = []
    for (name, program, o), g in pd.concat(frames).groupby(["machine", "program", "override_pct"]):
        if len(g) < 2:
            continue
        row = {"machine": name, "program": program, "override_pct": o, "runs": len(g)}
        for key in ("motion_s", "cycle_s"):
            v = g[key].to_numpy()
            row |= {f"median_{key}": float(np.median(v)), f"sd_{key}": float(np.std(v, ddof=1)),
                    f"range_{key}": float(np.ptp(v)),
                    f"range_{key[:-2]}_pct": float(100 * np.ptp(v) / np.median(v))}  # fmt: skip
        rows.append(row)
    return pd.DataFrame(rows)


def split_table() -> pd.DataFrame:
    """The split, one row per machine and held-out program: its valid runs and the calibration
    runs and programs every method is given (the machine's other programs)."""
    rows = []
    for name in MACHINES:
        times, _, _ = _machine(name)
        files = sorted({r.program for r in times})
        for file in files:
            rows.append({
                "machine": name, "held_out": file,
                "held_out_runs": sum(r.program == file for r in times),
                "calibration_runs": sum(r.program != file for r in times),
                "calibration_programs": "; ".join(f for f in files if f != file),
            })  # fmt: skip
    return pd.DataFrame(rows)


@functools.cache
def _held_out(name: str) -> tuple[pd.DataFrame, dict[str, Calibration]]:
    times, programs, rapids = _machine(name)
    return held_out_predictions(name, times, programs, rapids)


def _acc_rows(name: str, cals: dict[str, Calibration]) -> pd.DataFrame:
    """``block_overlap_acc``: Lee et al.'s constants from each fold's planner acceleration."""
    times, programs, _ = _machine(name)
    parts = []
    for file, cal in cals.items():
        lines, tp = programs[file]
        lee = identified_block_overlap(tp.take(motion_window(tp, lines)), cal.planner_machine,
                                       LEE_PERIOD_S)  # fmt: skip
        test = [r for r in times if r.program == file]
        pred = predict_runs(dataclasses.replace(cal, block_overlap=lee), test, programs,
                            methods=("block_overlap",))  # fmt: skip
        parts.append(pred.assign(method="block_overlap_acc", chosen=False))
    return pd.concat(parts, ignore_index=True)


def _learned_rows(name: str, analytic: pd.DataFrame, cals: dict[str, Calibration],
                  seeds: Sequence[int]) -> pd.DataFrame:  # fmt: skip
    """The networks' window motion plus the fold's non-motion times in the window; the cycle
    time adds the calibrated estimate's time outside the window."""
    _, programs, _ = _machine(name)
    learned = nist_learned.learned_predictions(name, seeds)
    chosen = analytic[analytic["chosen"]].set_index(["log", "measured_s"])
    rows = []
    for r in learned.itertuples(index=False):
        lines, _ = programs[r.program]
        cal = cals[r.program]
        ref = chosen.loc[(r.log, r.measured_s)]
        motion = r.predicted_motion_s + sequence_s(lines, cal.sequence)
        outside = ref["predicted_cycle_s"] - ref["predicted_s"]
        rows.append({"log": r.log, "program": r.program, "method": r.method, "seed": r.seed,
                     "override_pct": r.override_pct, "override_source": r.override_source,
                     "measured_s": r.measured_s, "predicted_s": motion,
                     "error_pct": 100 * (motion / r.measured_s - 1),
                     "measured_cycle_s": ref["measured_cycle_s"],
                     "predicted_cycle_s": motion + outside, "chosen": False,
                     "epochs": r.epochs, "converged": r.converged})  # fmt: skip
    return pd.DataFrame(rows)


def method_rows(seeds: Sequence[int] = (0, 1, 2, 3, 4)) -> pd.DataFrame:
    """Every held-out run of both machines predicted by every method (the module docstring),
    the learned ones once per seed.

    Returns
    -------
    pandas.DataFrame
        A row per run, method and seed (NaN for the analytic methods): ``machine``, ``log``,
        ``program``, ``method``, ``seed``, ``override_pct``, ``override_source``,
        ``measured_s``, ``predicted_s``, ``error_pct`` (motion time, signed, %),
        ``measured_cycle_s``, ``predicted_cycle_s``, ``cycle_error_pct``, ``chosen`` (the
        calibration's choice), ``epochs`` and ``converged`` (the learned methods').
    """
    parts = []
    for name in MACHINES:
        analytic, cals = _held_out(name)
        calibrated = analytic[analytic["chosen"]].assign(method="calibrated")
        parts += [frame.assign(machine=name) for frame in (
            analytic, _acc_rows(name, cals), calibrated,
            _learned_rows(name, analytic, cals, seeds))]  # fmt: skip
    rows = pd.concat(parts, ignore_index=True)
    rows["cycle_error_pct"] = 100 * (rows["predicted_cycle_s"] / rows["measured_cycle_s"] - 1)
    order = ["machine", "log", "program", "method", "seed", "override_pct", "override_source",
             "measured_s", "predicted_s", "error_pct", "measured_cycle_s", "predicted_cycle_s",
             "cycle_error_pct", "chosen", "epochs", "converged"]  # fmt: skip
    rows = rows.reindex(columns=order)
    rows["chosen"] = rows["chosen"].astype(bool)
    return rows.sort_values(["machine", "program", "method", "seed", "log"], kind="stable",
                            ignore_index=True)  # fmt: skip


def held_out_table(rows: pd.DataFrame) -> pd.DataFrame:
    """Per machine, held-out program and method: the median measured and predicted motion and
    cycle times over the program's runs and their signed errors (%); a learned method's
    prediction of a run is the mean of its seeds' (the ensemble).

    Parameters
    ----------
    rows : pandas.DataFrame
        :func:`method_rows`.
    """
    keys = ["machine", "program", "method", "log", "measured_s"]
    per_run = (
        rows.groupby(keys, sort=False)[["predicted_s", "measured_cycle_s", "predicted_cycle_s"]]
        .mean()
        .reset_index()
    )
    out = per_run.groupby(["machine", "program", "method"], sort=False).agg(
        runs=("log", "size"), measured_s=("measured_s", "median"),
        predicted_s=("predicted_s", "median"), measured_cycle_s=("measured_cycle_s", "median"),
        predicted_cycle_s=("predicted_cycle_s", "median")).reset_index()  # fmt: skip
    out["error_pct"] = 100 * (out["predicted_s"] / out["measured_s"] - 1)
    out["cycle_error_pct"] = 100 * (out["predicted_cycle_s"] / out["measured_cycle_s"] - 1)
    return out


def learned_seed_table(rows: pd.DataFrame, bars_pct: dict[str, float]) -> pd.DataFrame:
    """Each learned method's single networks: per machine, program and seed, the signed
    motion-time error (%) of the median over the program's runs, and whether it is within the
    method's bar (``bars_pct``: method -> largest allowed absolute error, %)."""
    learned = rows[rows["method"].isin(LEARNED_METHODS)]
    out = learned.groupby(["machine", "program", "method", "seed"], sort=False).agg(
        measured_s=("measured_s", "median"), predicted_s=("predicted_s", "median"),
        epochs=("epochs", "max"), converged=("converged", "all")).reset_index()  # fmt: skip
    out["error_pct"] = 100 * (out["predicted_s"] / out["measured_s"] - 1)
    out["within_bar"] = out["error_pct"].abs() < out["method"].map(bars_pct)
    return out


def interval_table(table: pd.DataFrame, method: str = "calibrated") -> pd.DataFrame:
    r"""A prediction interval for ``method``'s estimate of each held-out program and whether it
    holds the measured time: the jackknife+ interval of Barber et al. (2021) in relative form.
    The half-width for program :math:`i` is the largest absolute error (%) of the machine's
    *other* held-out programs, :math:`w_i = \max_{j \ne i} |e_j|`, and the interval
    :math:`\hat t_i (1 \pm w_i / 100)`. Where the errors are exchangeable the interval holds
    the measured time with probability :math:`m / (m + 1)`, :math:`m` the number of other
    programs (``nominal_pct``): 50 % on Hurco02 (one other program), 86 % on Hurco04 (six).

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`held_out_table`.
    """
    rows = []
    part = table[table["method"] == method]
    for name, g in part.groupby("machine", sort=False):
        for kind, measured, predicted, err in (
            ("motion", "measured_s", "predicted_s", "error_pct"),
            ("cycle", "measured_cycle_s", "predicted_cycle_s", "cycle_error_pct"),
        ):
            e = g[err].abs().to_numpy()
            for i, row in enumerate(g.itertuples(index=False)):
                w = float(np.max(np.delete(e, i))) if len(e) > 1 else np.nan
                p, m = getattr(row, predicted), getattr(row, measured)
                lo, hi = p * (1 - w / 100), p * (1 + w / 100)
                rows.append({"machine": name, "program": row.program, "time": kind,
                             "measured_s": m, "predicted_s": p, "half_width_pct": w,
                             "low_s": lo, "high_s": hi, "covered": bool(lo <= m <= hi),
                             "nominal_pct": 100 * (len(e) - 1) / len(e)})  # fmt: skip
    return pd.DataFrame(rows)


def paper_value(paper: str, quantity: str) -> float:
    """A number of a paper's summary table (``data/papers/<paper>_summary.csv``)."""
    summary = load_paper_table(f"{paper}_summary").set_index("quantity")
    return float(summary.loc[quantity, "value"])


def _bar(paper: str, quantity: str) -> tuple[float, str]:
    """The largest absolute error (%) a paper's accuracy claim allows, and its relation."""
    summary = load_paper_table(f"{paper}_summary").set_index("quantity")
    return 100.0 - paper_value(paper, quantity), str(summary.loc[quantity, "relation"])


#: The papers' accuracy claims this chapter tests: method -> (paper table, quantity, source).
PAPER_CLAIMS = {
    "bilstm": ("chien2023", "table3_bilstm_accuracy", "Chien et al. 2023, Sec. 4.2 (Table 3)"),
    "axis_nn": ("sun2022", "cycle_time_accuracy", "Sun et al. 2022, abstract and Sec. 5"),
    "block_overlap": ("lee2022", "cycle_time_accuracy", "Lee et al. 2022, Sec. 4"),
}


def paper_bars() -> dict[str, float]:
    """Per method of :data:`PAPER_CLAIMS`, the largest absolute error (%) its paper's accuracy
    claim allows (100 minus the accuracy, from ``data/papers/``)."""
    return {m: _bar(paper, q)[0] for m, (paper, q, _) in PAPER_CLAIMS.items()}


#: The condition each paper's claim of :data:`PAPER_CLAIMS` is tested under
#: (:func:`paper_conditions`).
REQUIRES = {"bilstm": "chien_machine_programs", "axis_nn": "sun_feed_rate",
            "block_overlap": "lee_constants_read"}  # fmt: skip


def paper_conditions(logs: pd.DataFrame, split: pd.DataFrame) -> list[Condition]:
    """The conditions of the papers' claims this chapter tests, the papers' values read from
    ``data/papers/``, ours from the logs and the split.

    * Chien et al.'s BiLSTM is trained on a machine's own programs (Sec. 4.2): ours are the
      other programs of a fold, fewest on Hurco02. Met at half the paper's count or more.
    * Sun et al.'s networks learn from a logger's feed records (Sec. 4.1, Fig. 11: the records
      of pocket 1 over its measured time). Met within a factor 2 of the paper's rate, for the
      machine of the fewest records a second. (This tolerance was set with the logs' rates
      known: see the chapter.)
    * Lee et al.'s estimator takes the acc/dec time constants from the control's parameters
      (Sec. 3); here they are fitted to the calibration runs' times. Met only where read (1).

    Parameters
    ----------
    logs : pandas.DataFrame
        :func:`data_conditions`.
    split : pandas.DataFrame
        :func:`split_table`.
    """
    chien = paper_value("chien2023", "exp_train_programs")
    sun_s = load_paper_table("sun2022_table3").set_index("pocket").loc[1, "measured_s"]
    sun = paper_value("sun2022", "pocket1_measured_points") / float(sun_s)
    fewest = int(split.groupby("machine")["held_out"].nunique().min()) - 1
    return [
        Condition("chien_machine_programs", "Chien et al. 2023, Sec. 4.2: programs the BiLSTM "
                  "is trained on from the machine (at least half the paper's)", chien, fewest,
                  "programs", low=chien / 2,
                  why="NIST's test bed logged few distinct programs on each machine (a box in "
                      "three operations, a plate in variants); leaving one out leaves the "
                      "machine's others to learn from, and the paper's programs are not "
                      "published to run on these machines."),
        Condition("sun_feed_rate", "Sun et al. 2022, Sec. 4.1 (Fig. 11): the logger's feed "
                  "records per second (within a factor 2)", sun,
                  float(logs["feed_records_per_s"].min()), "1/s", low=sun / 2, high=2 * sun),
        Condition("lee_constants_read", "Lee et al. 2022, Sec. 3: acc/dec time constants read "
                  "from the control's parameters (1) or fitted to times (0)", 1.0, 0.0, low=1.0,
                  why="NIST's MTConnect logs carry no control parameters, and Hurco's "
                      "acc/dec settings are not published with them; the time constants are "
                      "fitted to the calibration runs' times instead."),
    ]  # fmt: skip


def _ensemble_worst(rows: pd.DataFrame) -> tuple[np.ndarray, Callable[[np.ndarray], float]]:
    """One learned method's rows (:func:`method_rows`) as predictions per seed, shape
    (seeds, runs), and the statistic :func:`held_out_table` takes of them: the worst absolute
    motion-time error (%) over the programs of the mean over seeds, median over runs."""
    wide = rows.pivot_table(index="seed", columns=["machine", "program", "log", "measured_s"],
                            values="predicted_s", sort=False)  # fmt: skip
    runs = wide.columns.to_frame(index=False)

    def worst(per_seed: np.ndarray) -> float:
        med = runs.assign(predicted_s=per_seed.mean(axis=0)).groupby(["machine", "program"])[
            ["measured_s", "predicted_s"]].median()  # fmt: skip
        return float((100 * (med["predicted_s"] / med["measured_s"] - 1)).abs().max())

    return wide.to_numpy(), worst


def claims(table: pd.DataFrame, seeds: pd.DataFrame, rows: pd.DataFrame) -> list[Claim]:
    """The papers' accuracy claims on a real machine, at their own bars, and nctwin's own on
    the calibrated estimate.

    Each paper's claim holds where its method's motion-time error on *every* held-out program
    of both machines is within its bar (Chien: accuracy > 94 %, error < 6 %; Sun: > 90 %,
    < 10 %; Lee: >= 99 %, <= 1 %), a learned method's by the ensemble, with how many single
    networks are within it on every program and a 90 % bootstrap interval of the ensemble's
    worst error over the seeds (:func:`nctwin.report.claims.with_seeds`). nctwin's: the
    calibrated estimate within 2 % on the motion time and on the cycle time of every held-out
    program.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`held_out_table`.
    seeds : pandas.DataFrame
        :func:`learned_seed_table`.
    rows : pandas.DataFrame
        :func:`method_rows`, for the bootstrap.
    """
    out = []
    n = table.groupby(["machine", "program"]).ngroups
    for method, (paper, quantity, source) in PAPER_CLAIMS.items():
        bar, relation = _bar(paper, quantity)
        op = "<=" if relation == ">=" else "<"
        worst = float(table.loc[table["method"] == method, "error_pct"].abs().max())
        learned = method in LEARNED_METHODS
        what = f"ensemble of {seeds['seed'].nunique()} seeds, " if learned else ""
        claim = Claim(f"{method}_real_machine",
                      f"{source}: cycle-time accuracy {relation} {100 - bar:g} % on a real "
                      f"machine; {method} ({what}calibration runs only): worst motion-time "
                      f"error over the {n} held-out programs {op} {bar:g} %",
                      worst, op, bar, requires=(REQUIRES[method],))  # fmt: skip
        if learned:
            each = seeds[seeds["method"] == method].groupby("seed")["error_pct"]
            per_seed, statistic = _ensemble_worst(rows[rows["method"] == method])
            claim = with_seeds(claim, each.apply(lambda e: e.abs().max()).tolist(),
                               bootstrap_interval(per_seed, statistic))  # fmt: skip
        out.append(claim)
    cal = table[table["method"] == "calibrated"]
    out += [
        Claim("calibrated_motion_2pct", "nctwin: the calibrated estimate's motion time within "
              f"2 % on every held-out program ({n})",
              float(cal["error_pct"].abs().max()), "<=", 2.0, whose="ours"),
        Claim("calibrated_cycle_2pct", "nctwin: the calibrated estimate's cycle time within "
              f"2 % on every held-out program ({n})",
              float(cal["cycle_error_pct"].abs().max()), "<=", 2.0, whose="ours"),
    ]  # fmt: skip
    return out


def error_pivot(table: pd.DataFrame, column: str = "error_pct") -> pd.DataFrame:
    """``table`` (:func:`held_out_table`) as a row per machine and program, a column per method
    (in :data:`METHOD_ORDER`) of ``column``, after the measured time."""
    measured = "measured_s" if column == "error_pct" else "measured_cycle_s"
    wide = table.pivot_table(index=["machine", "program"], columns="method", values=column,
                             sort=False)  # fmt: skip
    wide = wide[[m for m in METHOD_ORDER if m in wide.columns]]
    wide.insert(0, measured, table.groupby(["machine", "program"], sort=False)[measured].first())
    return wide.reset_index().rename_axis(columns=None)


#: The methods in the order the chapter's tables show them.
METHOD_ORDER = ("cam", "block_overlap", "block_overlap_acc", "kernel", "planner", "bilstm",
                "axis_nn", "calibrated")  # fmt: skip


def seed_pivot(seeds: pd.DataFrame, method: str) -> pd.DataFrame:
    """A learned method's single networks (:func:`learned_seed_table`): a row per machine and
    program, a column per seed of the signed motion-time error (%)."""
    part = seeds[seeds["method"] == method]
    wide = part.pivot_table(index=["machine", "program"], columns="seed", values="error_pct",
                            sort=False)  # fmt: skip
    wide.columns = [f"seed_{int(c)}" for c in wide.columns]
    return wide.reset_index()


def fitted_constants() -> pd.DataFrame:
    """What each fold's calibration identified: per machine and held-out program, the axis
    rapid, the planner's X/Y and Z accelerations, Lee et al.'s time constants, the first and
    other tool changes and the method it picked."""
    rows = []
    for name in MACHINES:
        for file, cal in _held_out(name)[1].items():
            acc = cal.planner_machine.axis_max_acceleration_mm_s2
            rows.append({
                "machine": name, "held_out": file, "rapid_mm_s": cal.machine.rapid_feed_mm_s,
                "planner_acc_x_mm_s2": acc[0], "planner_acc_y_mm_s2": acc[1],
                "planner_acc_z_mm_s2": acc[2],
                "lee_cut_time_constant_s": cal.block_overlap.cut_time_constant_s,
                "lee_rapid_time_constant_s": cal.block_overlap.rapid_time_constant_s,
                "first_tool_change_s": cal.sequence.tool_change_at_s(True),
                "tool_change_s": cal.sequence.tool_change_s, "picked": cal.best,
            })  # fmt: skip
    return pd.DataFrame(rows)


def plot_move_feeds(feeds: pd.DataFrame, ax, moves: slice) -> None:
    """The logged and predicted average feed of the moves ``moves`` of one held-out run
    (:func:`nctwin.chapters.nist_learned.move_feeds`) on ``ax``, against the move's start."""
    part = feeds.iloc[moves]
    t = part["t0_s"]
    ax.step(t, part["feed_mm_s"], where="post", color="0.7", lw=0.8, label="programmed")
    ax.step(t, part["logged_feed_mm_s"], where="post", color="k", lw=1.2,
            label="logged (span average)")  # fmt: skip
    ax.step(t, part["bilstm_feed_mm_s"], where="post", color="tab:blue", lw=1,
            label="BiLSTM (5 seeds)")  # fmt: skip
    ax.step(t, part["axis_nn_feed_mm_s"], where="post", color="tab:orange", lw=1,
            label="per-axis networks (5 seeds)")  # fmt: skip
    ax.set_xlabel("time from the first cut (s)")
    ax.set_ylabel("average feed per move (mm/s)")
    ax.set_yscale("log")
    ax.legend(loc="lower right", fontsize=8)
