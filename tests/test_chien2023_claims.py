"""Chien et al.'s conditions and claims (nctwin.chapters.chien2023_claims) on numbers worked by
hand: the bars read from the paper, CAM's error against it, the single networks' count."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from nctwin.chapters import chien2023_claims as cc
from nctwin.report.tables import load_paper_table


def _run(measured_s, cam_s, n=4, feed=50.0):
    features = np.column_stack([np.full(n, feed), np.full(n, 2.5), np.zeros((n, 3))])
    return SimpleNamespace(measured_s=measured_s, cam_s=cam_s, features=features,
                           targets=np.full((2000, 2), feed))  # fmt: skip


def test_the_bars_are_the_papers():
    assert [cc.bar_pct(t) for t in cc.TABLES] == pytest.approx([2.0, 3.0, 6.0])


def test_conditions_read_the_papers_cam_error_and_count_the_families():
    runs = {("I", 75.0, 0.3): _run(100.0, 70.0), ("pocketing", 75.0, 0.3): _run(100.0, 60.0)}
    runs_b = {("pocketing", 70.0, 0.1): _run(100.0, 87.0)}
    specs = {"sim": [SimpleNamespace(family=f) for f in ["global"] * 79 + ["cam"]],
             "b": [SimpleNamespace(family="mixed")] * 30}  # fmt: skip
    conds = {c.id: c for c in cc.paper_conditions(runs, runs_b, _run(1.0, 1.0, feed=12.0), specs)}
    paper1 = load_paper_table("chien2023_table1").cam_err_pct.mean()
    assert conds["table1_cam_err"].paper == pytest.approx(paper1)
    assert conds["table1_cam_err"].ours == pytest.approx(30.0)  # CAM 70 s of 100 s
    assert conds["table1_cam_err"].bounds == pytest.approx((paper1 - 2, paper1 + 2))
    assert conds["table2_cam_err"].ours == pytest.approx(40.0)
    assert conds["table3_cam_err"].ours == pytest.approx(13.0)
    assert conds["fig9_min_feed"].ours == 12.0 and conds["fig9_min_feed"].met
    assert conds["pocket_glines"].ours == 4 and not conds["pocket_glines"].met
    assert conds["train_families_sim"].ours == pytest.approx(100 * 79 / 80)
    assert not conds["train_families_sim"].met and conds["train_families_b"].met
    assert conds["train_programs_sim"].met and conds["train_programs_b"].met


def test_claims_judge_the_ensemble_and_count_single_networks(monkeypatch):
    # three seeds predict 101, 99 and 104 s of a 100 s row: the ensemble 101.33 s, 1.33 %
    preds = {0: 101.0, 1: 99.0, 2: 104.0}
    monkeypatch.setattr(cc, "predict_run", lambda m, r: (None, None, preds[m] * r.measured_s / 100))
    runs = {("I", 75.0, 0.3): _run(100.0, 70.0), ("pocketing", 75.0, 0.3): _run(50.0, 30.0)}
    runs_b = {("pocketing", 70.0, 0.1): _run(100.0, 87.0)}
    claims = {c.id: c for c in cc.claims(runs, runs_b, [0, 1, 2], [0, 1, 2])}
    t1 = claims["table1_bilstm"]
    assert t1.value == pytest.approx(4 / 3) and t1.threshold == pytest.approx(2.0) and t1.holds
    assert (t1.seeds_passing, t1.seeds) == (2, 3)  # 1 % and 1 % pass, 4 % does not
    assert 0.0 <= t1.interval[0] <= t1.value <= t1.interval[1] <= 4.0 + 1e-12  # 99-104 s
    assert claims["table3_bilstm"].seeds_passing == 3  # all within 6 %
    assert claims["table2_bilstm"].requires == cc.REQUIRES["table2"]
    assert claims["cam_underestimates"].value == 0 and claims["cam_underestimates"].whose == "ours"
