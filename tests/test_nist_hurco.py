"""The real-machine chapter's tables (nctwin.chapters.nist_hurco) on numbers worked by hand, and
its split and verdicts on the shipped logs."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from nctwin.chapters import nist_hurco as nh
from nctwin.mtconnect import REASONS


def _table(errors: dict[tuple[str, str], float], method: str = "calibrated") -> pd.DataFrame:
    """A held-out table of one method: motion and cycle errors as given, measured 100 s."""
    rows = [{"machine": m, "program": p, "method": method, "runs": 1, "measured_s": 100.0,
             "predicted_s": 100.0 + e, "measured_cycle_s": 100.0,
             "predicted_cycle_s": 100.0 + e, "error_pct": e, "cycle_error_pct": e}
            for (m, p), e in errors.items()]  # fmt: skip
    return pd.DataFrame(rows)


def test_the_jackknife_interval_by_hand():
    table = _table({("A", "p1"): 1.0, ("A", "p2"): -3.0, ("A", "p3"): 0.5})
    out = nh.interval_table(table)
    motion = out[out.time == "motion"].set_index("program")
    # p1: the others' largest |error| is 3 %: 101 +- 3.03 holds 100
    assert motion.loc["p1", "half_width_pct"] == 3.0
    assert motion.loc["p1", ["low_s", "high_s"]].tolist() == pytest.approx([97.97, 104.03])
    # p2: the others' largest is 1 %: 97 +- 0.97 misses 100
    assert motion.loc["p2", "half_width_pct"] == 1.0 and not motion.loc["p2", "covered"]
    assert motion.loc["p3", "covered"]
    assert motion.nominal_pct.tolist() == pytest.approx([200 / 3] * 3)


def test_a_machine_of_one_program_has_no_interval():
    out = nh.interval_table(_table({("A", "p1"): 1.0}))
    assert out.half_width_pct.isna().all() and not out.covered.any()


def test_the_held_out_table_means_seeds_then_takes_medians_over_runs():
    base = {"machine": "A", "program": "p", "method": "bilstm", "measured_cycle_s": 110.0}
    rows = pd.DataFrame([
        base | {"log": "r1", "measured_s": 100.0, "seed": 0, "predicted_s": 98.0,
                "predicted_cycle_s": 108.0},
        base | {"log": "r1", "measured_s": 100.0, "seed": 1, "predicted_s": 106.0,
                "predicted_cycle_s": 116.0},
        base | {"log": "r2", "measured_s": 102.0, "seed": 0, "predicted_s": 100.0,
                "predicted_cycle_s": 110.0},
        base | {"log": "r2", "measured_s": 102.0, "seed": 1, "predicted_s": 104.0,
                "predicted_cycle_s": 114.0},
    ])  # fmt: skip
    row = nh.held_out_table(rows).iloc[0]
    assert row.runs == 2 and row.measured_s == 101.0
    assert row.predicted_s == 102.0  # runs 102 and 102 (the means of their seeds)
    assert row.error_pct == pytest.approx(100 * (102 / 101 - 1))
    assert row.cycle_error_pct == pytest.approx(100 * (112 / 110 - 1))


def test_claims_read_the_papers_bars_and_count_single_networks():
    bars = nh.paper_bars()
    assert bars["block_overlap"] == pytest.approx(1.0)  # Lee: 99 % or more
    errors = {("A", "p1"): 0.5, ("A", "p2"): -0.9}
    table = pd.concat([_table(errors, m) for m in ("calibrated", "block_overlap")])
    # five seeds of one run per program, measured 100 s: seed s misses by (s - 2) * 0.6 bar %,
    # so seeds 1-3 are within the bar (-0.6, 0, 0.6 of it) and the ensemble is exact
    rows = pd.DataFrame([{"machine": "A", "program": p, "method": m, "log": p, "seed": s,
                          "measured_s": 100.0, "predicted_s": 100 + (s - 2) * 0.6 * bars[m],
                          "measured_cycle_s": 100.0, "predicted_cycle_s": 100.0,
                          "epochs": 1, "converged": True}
                         for m in ("bilstm", "axis_nn") for s in range(5)
                         for p in ("p1", "p2")])  # fmt: skip
    table = pd.concat([table, nh.held_out_table(rows)], ignore_index=True)
    seeds = nh.learned_seed_table(rows, bars)
    claims = {c.id: c for c in nh.claims(table, seeds, rows)}
    assert claims["block_overlap_real_machine"].holds
    assert claims["block_overlap_real_machine"].value == pytest.approx(0.9)
    bilstm = claims["bilstm_real_machine"]
    assert bilstm.holds and bilstm.value == pytest.approx(0.0)
    assert (bilstm.seeds_passing, bilstm.seeds) == (3, 5)
    # a resample's ensemble errs by the mean of its draws: 0 to 1.2 bar
    low, high = bilstm.interval
    assert 0.0 <= low <= high <= 1.2 * bars["bilstm"]
    assert claims["axis_nn_real_machine"].seeds_passing == 3
    assert claims["calibrated_cycle_2pct"].holds


def test_the_runs_and_the_split():
    counts = nh.verdict_counts().set_index("machine")
    assert counts.to_numpy().sum() == 90  # every run of the 80 logs
    assert set(counts.columns) <= {"valid", *REASONS}
    assert counts.loc["Hurco02", "valid"] == 26 and counts.loc["Hurco04", "valid"] == 7
    split = nh.split_table()
    for _, g in split.groupby("machine"):
        total = g.held_out_runs.sum()
        assert (g.held_out_runs + g.calibration_runs == total).all()
        for row in g.itertuples():
            assert row.held_out not in row.calibration_programs.split("; ")


def test_the_repeatability_floor_is_a_fraction_of_a_percent():
    floor = nh.repeatability()
    assert set(floor.program.str.contains("BOX")) == {True} and (floor.runs >= 10).all()
    assert (floor.range_motion_pct < 0.2).all()
    assert np.isfinite(floor.sd_cycle_s).all()


def test_the_bootstrap_statistic_is_the_claimed_value():
    # two runs of p1 and one of p2, three seeds, uneven predictions
    rows = pd.DataFrame([{"machine": "A", "program": p, "method": "bilstm", "log": log,
                          "seed": s, "measured_s": m, "predicted_s": m + d + s * k,
                          "measured_cycle_s": m, "predicted_cycle_s": m}
                         for p, log, m, d, k in (("p1", "r1", 100.0, 3.0, 1.0),
                                                 ("p1", "r2", 104.0, -1.0, 2.0),
                                                 ("p2", "r3", 50.0, 2.0, -0.5))
                         for s in range(3)])  # fmt: skip
    per_seed, worst = nh._ensemble_worst(rows)
    assert per_seed.shape == (3, 3)
    table = nh.held_out_table(rows)
    assert worst(per_seed) == pytest.approx(table.error_pct.abs().max())
    # p2: 50 + 2 - 0.5 = 51.5 s on the mean seed, 3 %; p1: runs 104 and 105 s, measured 102
    assert worst(per_seed) == pytest.approx(3.0)
