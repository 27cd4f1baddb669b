"""Chien et al. (2023)'s conditions and claims: what the paper's experiment was run under, ours
beside it, and its accuracy claims at its own bars.

**Conditions** (:func:`paper_conditions`), measured on the truth (the FIR kernel, machine B) and
on CAM before any network is trained, each paper value read from ``data/papers/``:

* CAM's error on each table, the mean over its rows, within the BiLSTM's bar of the paper's
  (Table 1: 2 points, Table 2: 3, Table 3: 6): a test that is harder or easier for CAM by more
  than the method may miss is another test;
* the pocket's G-line count (within 1 %) and path length (within the range the paper's Table 2
  CAM times imply), and the lowest average feed of Fig. 9's zoom, G-lines 1700-1900 at
  92 mm/s and 0.32 mm (within half of the paper's, a value read off a figure);
* the training programs: as many as the paper's (within 10 %), all of its two families
  (Sec. 3.1: "global" and "mixed").

**Claims** (:func:`claims`): the BiLSTM's cycle-time accuracy on each table, "> 98 %" (Table 1),
"> 97 %" (Table 2), "> 94 %" (Table 3), judged on the ensemble of the seeds' networks on every
row, with how many single networks pass and a bootstrap interval over the seeds; each requires
its table's conditions. CAM underestimating every row is a property of any kernel that caps the
speed at F, so it is a check of ours.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..learn.train import Trained
from ..report.claims import bootstrap_interval, with_seeds
from ..report.conditions import Condition
from ..report.tables import Claim, error_pct, load_paper_table
from .chien2023 import ProgramRun, predict_run

__all__ = ["PAPER_FAMILIES", "TABLES", "claims", "paper_conditions"]

#: The paper's training families (Sec. 3.1).
PAPER_FAMILIES = ("global", "mixed")
#: Per table: the summary's accuracy quantity, and the test programs it covers.
TABLES = {
    "table1": ("table1_bilstm_accuracy", "toolpaths I and II"),
    "table2": ("table2_bilstm_accuracy", "the pocket"),
    "table3": ("table3_bilstm_accuracy", "the pocket on machine B"),
}

Runs = dict[tuple[str, float, float], ProgramRun]


def _summary(quantity: str) -> float:
    summary = load_paper_table("chien2023_summary").set_index("quantity")
    return float(summary.loc[quantity, "value"])


def bar_pct(table: str) -> float:
    """The largest error (%) a table's accuracy claim allows: 100 minus the accuracy."""
    return 100.0 - _summary(TABLES[table][0])


def _table_runs(test_runs: Runs, runs_b: Runs) -> dict[str, Runs]:
    return {
        "table1": {k: r for k, r in test_runs.items() if k[0] != "pocketing"},
        "table2": {k: r for k, r in test_runs.items() if k[0] == "pocketing"},
        "table3": runs_b,
    }


def paper_conditions(
    test_runs: Runs, runs_b: Runs, fig9_run: ProgramRun, train_sets: dict[str, Sequence]
) -> list[Condition]:
    """The conditions of the module docstring.

    Parameters
    ----------
    test_runs, runs_b : dict
        ``(toolpath, feed_mm_s, tol_mm) -> ProgramRun``: Tables 1-2 on the simulation, Table 3
        on machine B.
    fig9_run : ProgramRun
        The Table 2 pocket at 92 mm/s and 0.32 mm (Fig. 9).
    train_sets : dict
        ``"sim"`` and ``"b"``: the training programs' specs (each with a ``family``).
    """
    out = []
    for table, runs in _table_runs(test_runs, runs_b).items():
        paper = float(load_paper_table(f"chien2023_{table}")["cam_err_pct"].mean())
        ours = float(np.mean([error_pct(r.cam_s, r.measured_s) for r in runs.values()]))
        bar = bar_pct(table)
        out.append(Condition(f"{table}_cam_err", f"Chien et al. 2023, {table.title()[:-1]} "
                             f"{table[-1]}: CAM's error on {TABLES[table][1]}, mean over the "
                             f"rows, within the BiLSTM's bar ({bar:g} points) of the paper's",
                             paper, ours, "%", low=paper - bar, high=paper + bar))  # fmt: skip
    pocket = next(r for k, r in test_runs.items() if k[0] == "pocketing")
    implied = load_paper_table("chien2023_table2").eval("cam_s * feed_mm_s / 1000")
    zoom = fig9_run.targets[1699:1900, 0]
    paper_min = _summary("fig9_global_blend_min_avg_feed")
    out += [
        Condition("pocket_glines", "Chien et al. 2023, Sec. 4.1: the pocket's G-lines (within 1 %)",
                  _summary("pocketing_glines"), len(pocket.features), "G-lines", tol_pct=1.0),
        Condition("pocket_path_m", "Chien et al. 2023, Table 2: the pocket's path, within the "
                  "range its CAM times imply", float(implied.mean()),
                  float(pocket.features[:, 1].sum()) / 1000, "m", low=float(implied.min()),
                  high=float(implied.max())),
        Condition("fig9_min_feed", "Chien et al. 2023, Fig. 9: lowest average feed of G-lines "
                  "1700-1900 at 92 mm/s, 0.32 mm (within half of the paper's, read off a figure)",
                  paper_min, float(np.nanmin(zoom)), "mm/s", tol_pct=50.0),
    ]  # fmt: skip
    for key, quantity, label in (("sim", "sim_train_programs", "simulation"),
                                 ("b", "exp_train_programs", "machine B")):  # fmt: skip
        specs = train_sets[key]
        share = 100.0 * np.mean([s.family in PAPER_FAMILIES for s in specs])
        out += [
            Condition(f"train_programs_{key}", f"Chien et al. 2023, Sec. 4: training programs "
                      f"({label}, within 10 %)", _summary(quantity), len(specs), "programs",
                      tol_pct=10.0),
            Condition(f"train_families_{key}", f"Chien et al. 2023, Sec. 3.1: share of the "
                      f"training programs ({label}) of the paper's families, global and mixed",
                      100.0, share, "%", low=100.0),
        ]  # fmt: skip
    return out


#: The conditions each table's claim is tested under.
REQUIRES = {
    "table1": ("table1_cam_err", "train_programs_sim", "train_families_sim"),
    "table2": ("table2_cam_err", "pocket_glines", "pocket_path_m", "fig9_min_feed",
               "train_programs_sim", "train_families_sim"),
    "table3": ("table3_cam_err", "train_programs_b", "train_families_b"),
}  # fmt: skip


def claims(
    test_runs: Runs, runs_b: Runs, nets_sim: Sequence[Trained], nets_b: Sequence[Trained]
) -> list[Claim]:
    """The paper's accuracy claims per table (the module docstring), and CAM's underestimate
    (ours).

    Parameters
    ----------
    test_runs, runs_b : dict
        As :func:`paper_conditions`.
    nets_sim, nets_b : sequence of Trained
        The seeds' BiLSTMs (simulation, machine B); the ensemble's prediction of a program is
        the mean of theirs (:func:`~nctwin.chapters.chien2023.predict_run`).
    """
    out = []
    for table, runs in _table_runs(test_runs, runs_b).items():
        nets = nets_b if table == "table3" else nets_sim
        measured = np.array([r.measured_s for r in runs.values()])
        per_seed = np.array([[predict_run(m, r)[2] for r in runs.values()] for m in nets])

        def worst(p: np.ndarray, measured: np.ndarray = measured) -> float:
            return float(np.max(np.abs(p.mean(axis=0) - measured) / measured) * 100)

        bar = bar_pct(table)
        accuracy = 100.0 - bar
        claim = Claim(f"{table}_bilstm", f"Chien et al. 2023, {table.title()[:-1]} {table[-1]}: "
                      f"cycle-time accuracy > {accuracy:g} % on {TABLES[table][1]}; the "
                      f"ensemble of {len(nets)} seeds' BiLSTMs, worst error over the "
                      f"{len(runs)} rows < {bar:g} %", worst(per_seed), "<", bar,
                      requires=REQUIRES[table])  # fmt: skip
        seeds = [worst(p[None]) for p in per_seed]
        out.append(with_seeds(claim, seeds, bootstrap_interval(per_seed, worst)))
    every = [*test_runs.values(), *runs_b.values()]
    out.append(Claim("cam_underestimates", "CAM underestimates on every row of Tables 1-3 (count "
                     "of rows where it does not)", sum(r.cam_s >= r.measured_s for r in every),
                     "==", 0, whose="ours"))  # fmt: skip
    return out
