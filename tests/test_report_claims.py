"""nctwin.report.claims: a chapter's claims written to claims.json and printed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from nctwin.report.claims import Claim, bootstrap_interval, format_claim, report_claims, with_seeds
from nctwin.report.conditions import (
    CONDITION_COLUMNS,
    Condition,
    conditions_table,
    report_conditions,
)
from nctwin.report.display import format_table
from nctwin.report.results import write_claims

CLAIMS = [
    Claim("a", "first claim", 3.14159, "<=", 3.0),
    Claim("b", "second claim", 0.5, "<", 1),
    Claim("c", "not reproduced", float("nan"), ">", 0.0),
]


def test_writes_what_write_claims_writes(tmp_path):
    report_claims("nb", CLAIMS, results_dir=tmp_path / "new")
    write_claims("nb", CLAIMS, results_dir=tmp_path / "old")
    new = (tmp_path / "new" / "nb" / "claims.json").read_bytes()
    assert new == (tmp_path / "old" / "nb" / "claims.json").read_bytes()
    assert [r["holds"] for r in json.loads(new)] == [False, True, False]


def test_prints_one_line_each_and_returns_nothing(tmp_path, capsys):
    assert report_claims("nb", iter(CLAIMS), results_dir=tmp_path) is None
    assert capsys.readouterr().out == (
        "FAILS  a: 3.14 <= 3\nholds  b: 0.50 < 1\nFAILS  c: nan > 0\n"
    )


@pytest.mark.parametrize(
    ("line", "verdicts", "expected"),
    [
        ("{verdict} {id} {value:.4g} {op} {threshold:g}", ("PASS", "FAIL"), "FAIL a 3.142 <= 3"),
        ("{verdict} {id} {value:.4g} {op} {threshold:g}", ("HOLDS", "FAILS"), "FAILS a 3.142 <= 3"),
        ("{verdict:5}  {text}: {value:.3g} {op} {threshold:g}", ("holds", "FAILS"),
         "FAILS  first claim: 3.14 <= 3"),
    ],
)  # fmt: skip
def test_line_formats(line, verdicts, expected):
    assert format_claim(CLAIMS[0], line, verdicts) == expected


def test_table(tmp_path, capsys):
    report_claims("nb", CLAIMS, table=True, results_dir=tmp_path)
    expected = format_table(pd.DataFrame([c.to_dict() for c in CLAIMS]))
    assert capsys.readouterr().out == expected + "\n"


def test_duplicate_ids_write_and_print_nothing(tmp_path, capsys):
    with pytest.raises(ValueError, match="unique"):
        report_claims("nb", [CLAIMS[0], CLAIMS[0]], results_dir=tmp_path)
    assert capsys.readouterr().out == ""
    assert not (tmp_path / "nb" / "claims.json").exists()


def test_a_claim_under_an_unmet_condition_is_not_tested(tmp_path, capsys):
    conditions = [
        Condition("lines", "G-lines (paper Sec. 3)", 5000, 4993, tol_pct=1.0),
        Condition("rate", "sampling rate (paper Sec. 2)", 1000, 5, "Hz", tol_pct=10.0),
    ]
    claims = [Claim("a", "needs the lines", 1.0, "<", 2.0, requires=("lines",)),
              Claim("b", "needs both", 1.0, "<", 2.0, requires=("lines", "rate")),
              Claim("c", "ours, fails", 3.0, "<", 2.0, whose="ours")]  # fmt: skip
    report_claims("nb", claims, conditions=conditions, results_dir=tmp_path)
    assert capsys.readouterr().out == (
        "holds  a: 1.00 < 2\nnot tested  b: 1.00 < 2  [unmet: rate]\nFAILS  c: 3.00 < 2\n"
    )
    records = json.loads((tmp_path / "nb" / "claims.json").read_text())
    assert [r["status"] for r in records] == ["holds", "not tested", "fails"]
    assert records[1]["unmet"] == ["rate"] and "unmet" not in records[0]
    assert [r["whose"] for r in records] == ["paper", "paper", "ours"]


def test_a_claim_requiring_an_unknown_condition_writes_nothing(tmp_path):
    claim = Claim("a", "t", 1.0, "<", 2.0, requires=("nowhere",))
    with pytest.raises(ValueError, match=r"claim 'a' requires conditions not given: \['nowhere'\]"):
        report_claims("nb", [claim], results_dir=tmp_path)
    assert not (tmp_path / "nb").exists()


def test_conditions_by_tolerance_or_bounds(tmp_path):
    # 4993 lines against the paper's 5000 within 1 %: [4950, 5050]
    within = Condition("lines", "t", 5000, 4993, tol_pct=1.0)
    assert within.bounds == (4950.0, 5050.0) and within.met
    assert not Condition("rate", "t", 2.9, 5.0, "Hz", tol_pct=25.0).met  # 5 > 3.625
    assert Condition("data", "t", float("nan"), 90, "programs", low=80).met
    assert not Condition("data", "t", float("nan"), float("nan"), low=80).met  # not measured
    with pytest.raises(ValueError, match="give tol_pct or low/high"):
        Condition("x", "t", 1.0, 1.0)
    with pytest.raises(ValueError, match="needs a finite paper value"):
        Condition("x", "t", float("nan"), 1.0, tol_pct=5.0)
    table = conditions_table([within])
    assert list(table.columns) == list(CONDITION_COLUMNS) and table.met.tolist() == [True]


def test_report_conditions_writes_the_csv_and_refuses_repeated_ids(tmp_path, capsys):
    c = Condition("lines", "G-lines", 5000, 4993, tol_pct=1.0)
    assert report_conditions("nb", [c], results_dir=tmp_path) == [c]
    text = (tmp_path / "nb" / "conditions.csv").read_text()
    assert text == (
        "id,text,paper,ours,unit,low,high,met,why\nlines,G-lines,5000,4993,,4950,5050,True,\n"
    )
    assert "4993" in capsys.readouterr().out
    with pytest.raises(ValueError, match=r"condition ids repeat: \['lines'\]"):
        report_conditions("nb", [c, c], results_dir=tmp_path)


def test_an_unmet_conditions_why_is_written_and_shown_as_a_footnote(tmp_path, capsys):
    why = "the paper does not publish it"
    met = Condition("lines", "G-lines", 5000, 4993, tol_pct=1.0, why=why)
    unmet = Condition("rate", "records per s", 2.9, 5.0, "1/s", tol_pct=25.0, why=why)
    report_conditions("nb", [met, unmet], results_dir=tmp_path)
    table = pd.read_csv(tmp_path / "nb" / "conditions.csv", keep_default_na=False)
    assert table.why.tolist() == ["", why]  # a met condition needs no reason
    shown = capsys.readouterr().out
    assert "False [1]\\n[1] the paper does not publish it'" in shown
    assert "<li>the paper does not publish it</li>" in shown


def test_with_seeds_counts_the_single_networks_that_pass(tmp_path, capsys):
    claim = with_seeds(Claim("e", "error within 3 %", 2.0, "<", 3.0), [1.0, 4.0, 2.9, float("nan")],
                       (1.5, 2.5))  # fmt: skip
    assert (claim.seeds_passing, claim.seeds, claim.interval) == (2, 4, (1.5, 2.5))
    report_claims("s", [claim], results_dir=tmp_path)
    record = json.loads((tmp_path / "s" / "claims.json").read_text())[0]
    assert (record["seeds_passing"], record["seeds"], record["interval"]) == (2, 4, [1.5, 2.5])
    assert "[2 of 4 single networks pass]" in capsys.readouterr().out


@pytest.mark.parametrize("passing, seeds", [(3, 2), (-1, 2), (1, None)])
def test_seed_counts_out_of_range_are_refused(passing, seeds):
    with pytest.raises(ValueError, match="seeds_passing"):
        Claim("e", "t", 1.0, "<", 2.0, seeds_passing=passing, seeds=seeds)


def test_bootstrap_interval_of_the_mean_by_hand():
    # every resample of identical seeds gives the same mean: a point interval
    assert bootstrap_interval(np.full(5, 2.0), np.mean) == (2.0, 2.0)
    # two seeds 0 and 10: resampled means are 0, 5 or 10 with probabilities 1/4, 1/2, 1/4
    low, high = bootstrap_interval(np.array([0.0, 10.0]), np.mean, level=0.4)
    assert (low, high) == (5.0, 5.0)
    low, high = bootstrap_interval(np.array([0.0, 10.0]), np.mean, level=0.98)
    assert (low, high) == (0.0, 10.0)
    # the same seed, the same interval
    x = np.arange(7.0)
    assert bootstrap_interval(x, np.mean, seed=3) == bootstrap_interval(x, np.mean, seed=3)


def test_in_a_notebook_the_chapter_status_is_glued(tmp_path, monkeypatch, capsys):
    import IPython
    import myst_nb

    glued = {}
    monkeypatch.setattr(IPython, "get_ipython", lambda: object())
    monkeypatch.setattr(myst_nb, "glue", lambda name, value, display: glued.update({name: value}))
    report_claims("s", CLAIMS[:2], results_dir=tmp_path)
    assert glued == {"chapter_status": "partly reproduced",
                     "chapter_status_why": "1 of the paper's 2 claims hold, 1 fail."}  # fmt: skip


def test_every_unmet_condition_of_a_chapter_says_why():
    """The shipped chapters' conditions: each one unmet names why it cannot be met."""
    results = Path(__file__).resolve().parents[1] / "results"
    files = sorted(results.glob("*/conditions.csv"))
    assert files, "no chapter wrote conditions.csv"
    for path in files:
        table = pd.read_csv(path, keep_default_na=False)
        assert list(table.columns) == list(CONDITION_COLUMNS), path
        silent = table[(table.met.astype(str) == "False") & (table.why.str.strip() == "")]
        assert silent.empty, f"{path.parent.name}: unmet without a why: {silent.id.tolist()}"
