"""Chien, Sencer & Ward 2023: the paper's conditions beside ours, and its claims at its own bars.

The conditions (:func:`paper_conditions`) are measured from the kernel's runs and CAM alone,
before any network predicts: CAM's error on every row of Tables 1-3, the pockets' line count
and path length, the band of Fig. 9's average feeds, and the training budgets and families.
The claims (:func:`claims`) are the BiLSTM's accuracy on each table at the bar the paper
prints for it (``data/papers/chien2023_summary.csv``), each tested under its table's
conditions.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from ..programs.training import ProgramSpec
from ..report.claims import Claim, bootstrap_interval, with_seeds
from ..report.conditions import Condition
from ..report.papers import load_paper_table

__all__ = [
    "CAM_POINTS",
    "FIG9_MAX_TOL_PCT",
    "FIG9_MIN_FACTOR",
    "HOURS_TOL_PCT",
    "PAPER_FAMILIES",
    "TABLE_CLAIMS",
    "claims",
    "paper_conditions",
    "paper_numbers",
    "summary_value",
]

#: CAM's error on a row is the paper's within this many percentage points.
CAM_POINTS = 2.0
#: Fig. 9's lowest average feed (global blends): ours within this factor of the paper's.
FIG9_MIN_FACTOR = 2.0
#: Fig. 9's highest average feed (straight lines): ours within this tolerance (%).
FIG9_MAX_TOL_PCT = 10.0
#: The training families the paper describes (Sec. 3.1), as it writes them.
PAPER_FAMILIES = ("paper_global", "paper_mixed")
#: A training set's run time is the paper's within this tolerance (%; it prints "~2 h", "~3 h").
HOURS_TOL_PCT = 25.0
#: Why an unmet condition cannot be met from what the paper publishes (Condition.why).
_WHY_UNKNOWN_KERNEL = (
    "The paper publishes its kernel's feeds, tolerances and period, not its filters' time "
    "constants nor its axes' limits. On every machine of the calibration's grid CAM's error "
    "here falls less from the smaller tolerance to the larger than on the paper's kernel, a "
    "property of the kernel's corner speeds, not of the paths; no setting of the paths meets "
    "every row, and the one chosen puts the rows on either side of the paper's."
)
_WHY = {
    "table1": _WHY_UNKNOWN_KERNEL,
    "table2": _WHY_UNKNOWN_KERNEL,
    "table3": (
        "The paper publishes machine B's feeds and tolerances and the pocket's CAM times, not "
        "the machine's time constants or limits nor the pocket's shape. CAM's error on machine "
        "B grows with the feed where the paper's does not; at the widest band the pocket's path "
        "allows and a stepover of the tool's diameter, the rows at the lower feed lie near the "
        "paper's and those at the higher feed above."
    ),
    "fig9_min_avg_feed": (
        "The slowest G-lines of the zoom are the short chords of the links that turn the "
        "zig-zag around the island's corners: such a link is shorter than the path the filters "
        "average over, so it runs at the speed of the turn between two rows. The paper shows "
        "its pocket as a picture and three statistics (lines, path, measured time), which fix "
        "neither its links nor their feeds."
    ),
    "fig9_max_avg_feed": (
        "The zoom's rows are too short to reach the programmed feed, where the paper's zoom "
        "holds straights long enough to. The rows' length follows from the band, which CAM's "
        "error on Table 2's rows fixes; a wider band, with rows long enough, would miss them."
    ),
}
#: Per table: (summary quantity of the paper's accuracy, our runs' toolpaths or None for all,
#: training set).
TABLE_CLAIMS = {"table1": ("table1_bilstm_accuracy", ("I", "II"), "sim"),
                "table2": ("table2_bilstm_accuracy", ("pocketing",), "sim"),
                "table3": ("table3_bilstm_accuracy", ("pocketing",), "b")}  # fmt: skip
#: Per training set: the summary quantities of the paper's program count and program size.
_BUDGETS = {"sim": ("sim_train_programs", "sim_train_glines_per_program", "sim_train_run_time",
                    "Sec. 4.1"),
            "b": ("exp_train_programs", "exp_train_blends_per_program", "exp_air_cutting_time",
                  "Sec. 4.2")}  # fmt: skip


def summary_value(quantity: str, column: str = "value") -> float:
    """A number of ``data/papers/chien2023_summary.csv`` (``column`` of row ``quantity``)."""
    summary = load_paper_table("chien2023_summary").set_index("quantity")
    return float(summary.loc[quantity, column])


def paper_numbers() -> dict[str, float]:
    """The paper's numbers the chapter's text quotes, by name (for ``glue``).

    Returns
    -------
    dict
        ``paper_<quantity>`` (and ``paper_<quantity>_max`` where a range) of every row of
        ``chien2023_summary.csv``; per table ``paper_<table>_<column>_min`` and ``_max`` of its
        ``cam_err``, ``bilstm_err``, ``cam_s``, ``feed`` and ``ratio`` (measured/CAM) and
        ``path_m`` (the path its CAM times imply, :math:`T_{CAM} F`), and
        ``paper_<table>_path_m_mean``.
    """
    out = {}
    for row in load_paper_table("chien2023_summary").itertuples():
        out[f"paper_{row.quantity}"] = float(row.value)
        if not np.isnan(row.value_max):
            out[f"paper_{row.quantity}_max"] = float(row.value_max)
    for table in TABLE_CLAIMS:
        p = load_paper_table(f"chien2023_{table}")
        path_m = p.cam_s * p.feed_mm_s / 1000
        columns = {
            "cam_err": p.cam_err_pct,
            "bilstm_err": p.bilstm_err_pct,
            "cam_s": p.cam_s,
            "feed": p.feed_mm_s,
            "ratio": p.measured_s / p.cam_s,
            "path_m": path_m,
        }
        for name, values in columns.items():
            out[f"paper_{table}_{name}_min"] = float(values.min())
            out[f"paper_{table}_{name}_max"] = float(values.max())
        out[f"paper_{table}_path_m_mean"] = float(path_m.mean())
    return out


def _row_id(table: str, toolpath: str, feed: float, tol: float) -> str:
    return f"{table}_cam_{toolpath}_F{feed:g}_P{tol:g}"


def _cam_conditions(table: str, rows: pd.DataFrame) -> list[Condition]:
    """One condition per row of a paper's table: our CAM error within :data:`CAM_POINTS`."""
    paper = load_paper_table(f"chien2023_{table}")
    merged = paper.merge(rows, on=["toolpath", "feed_mm_s", "tol_mm"], suffixes=("_paper", ""))
    label = table.replace("table", "Table ")
    return [Condition(_row_id(table, r.toolpath, r.feed_mm_s, r.tol_mm),
                      f"{label}: CAM's error, toolpath {r.toolpath}, F = {r.feed_mm_s:g} mm/s, "
                      f"eps = {r.tol_mm:g} mm (measured/CAM {r.measured_s / r.cam_s:.2f}, paper "
                      f"{r.measured_s_paper / r.cam_s_paper:.2f}; within {CAM_POINTS:g} points)",
                      r.cam_err_pct_paper, r.cam_err_pct, "%",
                      low=r.cam_err_pct_paper - CAM_POINTS, high=r.cam_err_pct_paper + CAM_POINTS,
                      why=_WHY[table])
            for r in merged.itertuples()]  # fmt: skip


def _budget_conditions(name: str, specs: Sequence[ProgramSpec], hours: float) -> list[Condition]:
    """A training set's program count and size (within 10 % of the paper's, which prints
    them as approximate), its run time (``hours``, within :data:`HOURS_TOL_PCT`) and its share
    of programs of the paper's families (all)."""
    programs, size, run_time, section = _BUDGETS[name]
    paper_share = 100.0 * np.mean([s.family in PAPER_FAMILIES for s in specs])
    label = {"sim": "simulation", "b": "machine B"}[name]
    return [
        Condition(f"{name}_train_programs", f"{section}: {label} training programs (within 10 %)",
                  summary_value(programs), len(specs), "programs", tol_pct=10.0),
        Condition(f"{name}_train_lines", f"{section}: G-lines per {label} training program "
                  "(within 10 %)", summary_value(size), float(np.mean([s.n_lines for s in specs])),
                  "G-lines", tol_pct=10.0),
        Condition(f"{name}_train_hours", f"{section}: run time of the {label} training programs "
                  f"(within {HOURS_TOL_PCT:g} %)", summary_value(run_time), hours, "h",
                  tol_pct=HOURS_TOL_PCT),
        Condition(f"{name}_train_families", f"Sec. 3.1: {label} training programs of the "
                  "paper's families, global and mixed (all)", 100.0, paper_share, "%", low=100.0),
    ]  # fmt: skip


def paper_conditions(
    cam_rows: pd.DataFrame,
    cam_rows_b: pd.DataFrame,
    pocket_stats: pd.DataFrame,
    fig9_feed_mm_s: np.ndarray,
    sets: dict[str, Sequence[ProgramSpec]],
    train_hours: dict[str, float],
) -> list[Condition]:
    """The paper's conditions beside ours, the tolerances fixed in this module.

    Parameters
    ----------
    cam_rows, cam_rows_b : pandas.DataFrame
        :func:`~nctwin.chapters.chien2023.cycle_time_rows` (no model) of the simulation's test
        programs (Tables 1-2) and of machine B's (Table 3): ``toolpath, feed_mm_s, tol_mm,
        measured_s, cam_s, cam_err_pct``.
    pocket_stats : pandas.DataFrame
        The pockets' statistics, one row per ``pocket`` (``table2``, ``table3``) with ``lines``,
        ``path_m`` and the paths the paper's CAM times imply, ``paper_path_min_m`` and
        ``paper_path_max_m``.
    fig9_feed_mm_s : ndarray, shape (n_lines,)
        Measured average feed per G-line of the Table 2 pocket at Fig. 9's feed and tolerance.
    sets : dict
        ``"sim"`` and ``"b"`` -> the training programs' specs.
    train_hours : dict
        ``"sim"`` and ``"b"`` -> the measured run time of those programs (h).

    Returns
    -------
    list of Condition
    """
    lo, hi = (int(v) for v in (summary_value("fig9_zoom_gline_range"),
                               summary_value("fig9_zoom_gline_range", "value_max")))  # fmt: skip
    zoom = fig9_feed_mm_s[lo - 1 : hi]
    fig_min, fig_max = (summary_value(q) for q in ("fig9_global_blend_min_avg_feed",
                                                   "fig9_straight_max_avg_feed"))  # fmt: skip
    stats = pocket_stats.set_index("pocket")
    out = _cam_conditions("table1", cam_rows[cam_rows.toolpath != "pocketing"])
    out += _cam_conditions("table2", cam_rows[cam_rows.toolpath == "pocketing"])
    out += _cam_conditions("table3", cam_rows_b)
    out.append(Condition("table2_pocket_lines", "Sec. 4.1: G-lines of the pocket (within 2 %)",
                         summary_value("pocketing_glines"), stats.loc["table2", "lines"],
                         "G-lines", tol_pct=2.0))  # fmt: skip
    out += [
        Condition(
            f"{p}_pocket_path",
            f"{p.replace('table', 'Table ')}: the pocket's path, "
            "within the range the paper's CAM times imply (sum l_k / F)",
            np.nan,
            stats.loc[p, "path_m"],
            "m",
            low=stats.loc[p, "paper_path_min_m"],
            high=stats.loc[p, "paper_path_max_m"],
        )
        for p in ("table2", "table3")
    ]
    out += [
        Condition("fig9_min_avg_feed", f"Sec. 4.1, Fig. 9: lowest average feed of G-lines {lo}-"
                  f"{hi} of the pocket (within a factor {FIG9_MIN_FACTOR:g})", fig_min,
                  np.nanmin(zoom), "mm/s", low=fig_min / FIG9_MIN_FACTOR,
                  high=fig_min * FIG9_MIN_FACTOR, why=_WHY["fig9_min_avg_feed"]),
        Condition("fig9_max_avg_feed", f"Sec. 4.1, Fig. 9: highest average feed of G-lines {lo}-"
                  f"{hi} (within {FIG9_MAX_TOL_PCT:g} %)", fig_max, np.nanmax(zoom), "mm/s",
                  tol_pct=FIG9_MAX_TOL_PCT, why=_WHY["fig9_max_avg_feed"]),
    ]  # fmt: skip
    for name in ("sim", "b"):
        out += _budget_conditions(name, sets[name], train_hours[name])
    return out


def _requires(table: str, conditions: Sequence[Condition]) -> tuple[str, ...]:
    """The conditions a table's claim is tested under: its CAM rows, its pocket's (Tables 2-3)
    and Fig. 9's (Table 2), and its training set's."""
    train = TABLE_CLAIMS[table][2]
    prefixes = (f"{table}_", f"{train}_train_") + (("fig9_",) if table == "table2" else ())
    return tuple(c.id for c in conditions if c.id.startswith(prefixes))


def claims(
    rows: pd.DataFrame,
    rows_b: pd.DataFrame,
    seeds: pd.DataFrame,
    seeds_b: pd.DataFrame,
    conditions: Sequence[Condition],
) -> list[Claim]:
    """The paper's BiLSTM accuracy on each of Tables 1-3 at its own bar, and our check that CAM
    underestimates.

    A table's claim holds when the ensemble's cycle-time error (the mean of the seeds'
    predictions) is under the paper's bar, 100 minus the printed accuracy, on every row; each
    carries how many single networks pass and a 90 % bootstrap interval over the seeds of the
    ensemble's worst error (from the seeds' signed errors as tabulated: the ensemble's error is
    the mean of theirs, the measured time being common).

    Parameters
    ----------
    rows, rows_b : pandas.DataFrame
        :func:`~nctwin.chapters.chien2023.cycle_time_rows` with a ``bilstm`` model, of the
        simulation's test programs and of machine B's.
    seeds, seeds_b : pandas.DataFrame
        :func:`~nctwin.chapters.chien2023.seed_rows` of the same programs.
    conditions : sequence of Condition
        :func:`paper_conditions`.

    Returns
    -------
    list of Claim
    """
    out = []
    for table, (quantity, toolpaths, train) in TABLE_CLAIMS.items():
        r, s = (rows, seeds) if train == "sim" else (rows_b, seeds_b)
        r, s = r[r.toolpath.isin(toolpaths)], s[s.toolpath.isin(toolpaths)]
        bar = 100.0 - summary_value(quantity)
        per_seed = s.filter(regex=r"^seed_\d+_err_pct$").to_numpy().T  # (n_seeds, n_rows)
        source = f"Sec. 4.{2 if train == 'b' else 1}, {table.replace('table', 'Table ')}"
        claim = Claim(f"{table}_bilstm", f"Chien et al. 2023, {source}: "
                      f"BiLSTM accuracy > {100 - bar:g} %; ensemble's largest error over "
                      f"{len(r)} rows < {bar:g} %", float(r.bilstm_err_pct.max()), "<", bar,
                      requires=_requires(table, conditions))  # fmt: skip
        out.append(
            with_seeds(
                claim,
                np.abs(per_seed).max(axis=1),
                bootstrap_interval(per_seed, lambda a: np.abs(a.mean(0)).max()),
            )
        )
    return out
