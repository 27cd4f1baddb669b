"""nctwin.report.claims: a chapter's claims written to claims.json and printed."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from nctwin.report.claims import format_claim, report_claims
from nctwin.report.tables import Claim, format_table, write_claims

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
