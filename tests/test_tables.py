"""nctwin.report.papers, results, display and nctwin.metrics: errors, joins, claims, atomic results
files, and the paper CSVs."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from nctwin.metrics import accuracy_pct, error_pct
from nctwin.report.claims import Claim
from nctwin.report.display import format_paper_table, format_table
from nctwin.report.papers import (
    UnknownTableError,
    available_tables,
    load_paper_table,
    paper_tables,
    papers_dir,
    side_by_side,
)
from nctwin.report.results import write_claims, write_table

PAPERS = {
    "chien2023": "Chien, Sencer & Ward 2023",
    "sun2022": "Sun et al. 2022",
    "lee2022": "Lee et al. 2022",
    "denkena2020": "Denkena, Bergmann & Stoppel 2020",
    "zhang2023": "Zhang et al. 2023",
}
CSV_FILES = sorted(papers_dir().glob("*.csv"))


# ---------------------------------------------------------------------------------------------
# error_pct / accuracy_pct


def test_error_pct_by_hand():
    assert error_pct(110.0, 100.0) == pytest.approx(10.0)
    assert error_pct(90.0, 100.0) == pytest.approx(10.0)  # absolute value: under = over
    assert error_pct(3.0, 4.0) == pytest.approx(25.0)
    assert error_pct(5.0, 5.0) == 0.0


def test_error_pct_scalar_gives_float_and_arrays_broadcast():
    assert isinstance(error_pct(1, 2), float)
    out = error_pct([1.0, 3.0, 2.0], 2.0)
    assert isinstance(out, np.ndarray)
    np.testing.assert_allclose(out, [50.0, 50.0, 0.0])
    np.testing.assert_allclose(error_pct(pd.Series([8.0]), pd.Series([10.0])), [20.0])


def test_accuracy_is_hundred_minus_error():
    # Lee et al. 2022, set 1: |2172.4 - 2169.1| / 2169.1 = 0.152 % -> 99.848 %
    assert accuracy_pct(2172.4, 2169.1) == pytest.approx(100 - 3.3 / 2169.1 * 100)
    np.testing.assert_allclose(accuracy_pct([75.0, 125.0], [100.0, 100.0]), [75.0, 75.0])


@pytest.mark.parametrize("measured", [0.0, -1.0, [1.0, 0.0]])
def test_error_pct_rejects_non_positive_measured(measured):
    with pytest.raises(ValueError, match="measured"):
        error_pct(1.0, measured)


def test_error_pct_nan_propagates():
    assert math.isnan(error_pct(float("nan"), 10.0))


# ---------------------------------------------------------------------------------------------
# side_by_side


def _paper() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "paper": ["P 2023"] * 4,
            "table": ["Table 1"] * 4,
            "page_or_section": ["Sec. 4"] * 4,
            "feed_mm_s": [75, 75, 92, 92],
            "tol_mm": [0.3, 0.4, 0.3, 0.4],
            "measured_s": [45.4, 44.5, 39.6, 39.2],
            "note": [None, None, "garbled", None],
        }
    )


def test_side_by_side_keeps_every_paper_row_in_order_and_prefixes():
    ours = pd.DataFrame(
        {
            "feed_mm_s": [92.0, 75.0, 100.0],  # 100 mm/s has no paper row: dropped
            "tol_mm": [0.4, 0.3, 0.3],
            "measured_s": [39.0, 45.0, 30.0],
        }
    )
    out = side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])
    assert len(out) == 4
    assert list(out.columns) == [
        "feed_mm_s",
        "tol_mm",
        "measured_s",
        "paper_measured_s",
        "paper_source",
    ]
    assert out["feed_mm_s"].tolist() == [75, 75, 92, 92]
    assert out["tol_mm"].tolist() == [0.3, 0.4, 0.3, 0.4]
    assert out["paper_measured_s"].tolist() == [45.4, 44.5, 39.6, 39.2]
    np.testing.assert_array_equal(out["measured_s"].to_numpy(), [45.0, np.nan, np.nan, 39.0])
    assert set(out["paper_source"]) == {"P 2023, Table 1"}


def test_side_by_side_with_no_numbers_of_ours_still_lists_the_paper():
    ours = pd.DataFrame({"feed_mm_s": [], "tol_mm": [], "measured_s": []}, dtype=float)
    out = side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])
    assert len(out) == 4
    assert out["measured_s"].isna().all()


def test_side_by_side_selected_columns():
    ours = pd.DataFrame({"feed_mm_s": [75], "tol_mm": [0.3], "bilstm_s": [44.0]})
    out = side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"], columns=["note"])
    assert list(out.columns) == ["feed_mm_s", "tol_mm", "bilstm_s", "paper_note", "paper_source"]
    assert out["paper_note"].iloc[2] == "garbled"


@pytest.mark.parametrize(
    "tol", [0.30000001, float(np.float32(0.3)), 0.1 + 0.2, 0.29999999999999993]
)
def test_side_by_side_float_keys_match_within_rounding(tol):
    ours = pd.DataFrame({"feed_mm_s": [75.0], "tol_mm": [tol], "measured_s": [1.0]})
    out = side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])
    assert out["measured_s"].tolist()[:2] == [1.0, pytest.approx(np.nan, nan_ok=True)]
    assert out["measured_s"].notna().sum() == 1
    assert out["tol_mm"].iloc[0] == 0.3  # the paper's key is kept, not ours


def test_side_by_side_float32_column_and_int_feed_match():
    ours = pd.DataFrame(
        {
            "feed_mm_s": np.array([92, 92], dtype=np.int64),
            "tol_mm": np.array([0.3, 0.4], dtype=np.float32),
            "measured_s": [1.0, 2.0],
        }
    )
    out = side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])
    np.testing.assert_array_equal(out["measured_s"].to_numpy(), [np.nan, np.nan, 1.0, 2.0])


def test_side_by_side_does_not_merge_distinct_keys():
    ours = pd.DataFrame({"feed_mm_s": [75.0], "tol_mm": [0.3001], "measured_s": [1.0]})
    out = side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])
    assert out["measured_s"].isna().all()


def test_side_by_side_string_keys():
    paper = pd.DataFrame({"paper": ["P"] * 2, "table": ["T"] * 2, "toolpath": ["I", "II"]})
    paper["measured_s"] = [1.0, 2.0]
    ours = pd.DataFrame({"toolpath": ["II"], "ours_s": [2.5]})
    out = side_by_side(ours, paper, on=["toolpath"])
    np.testing.assert_array_equal(out["ours_s"].to_numpy(), [np.nan, 2.5])


def test_side_by_side_rejects_duplicate_keys_in_ours():
    ours = pd.DataFrame({"feed_mm_s": [75, 75.0000001], "tol_mm": [0.3, 0.3], "x": [1, 2]})
    with pytest.raises(ValueError, match="more than one row"):
        side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])


def test_side_by_side_rejects_numeric_against_text_key():
    ours = pd.DataFrame({"feed_mm_s": ["75"], "tol_mm": [0.3], "x": [1]})
    with pytest.raises(TypeError, match="feed_mm_s"):
        side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])


def test_side_by_side_missing_key_names_it():
    ours = pd.DataFrame({"feed_mm_s": [75], "x": [1]})
    with pytest.raises(KeyError, match="tol_mm"):
        side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])


def test_side_by_side_rejects_clashing_column_names():
    ours = pd.DataFrame({"feed_mm_s": [75], "tol_mm": [0.3], "paper_measured_s": [1.0]})
    with pytest.raises(ValueError, match="clash"):
        side_by_side(ours, _paper(), on=["feed_mm_s", "tol_mm"])


# ---------------------------------------------------------------------------------------------
# Claim


@pytest.mark.parametrize(
    ("value", "op", "threshold", "expected"),
    [
        (1.0, "<", 2.0, True),
        (2.0, "<", 2.0, False),
        (2.0, "<=", 2.0, True),
        (2.1, "<=", 2.0, False),
        (3.0, ">", 2.0, True),
        (2.0, ">", 2.0, False),
        (2.0, ">=", 2.0, True),
        (1.9, ">=", 2.0, False),
        (5.0, "==", 5.0, True),
        (5.0, "==", 5.000001, False),
    ],
)
def test_claim_holds_for_each_op(value, op, threshold, expected):
    assert Claim("c", "text", value, op, threshold).holds is expected


@pytest.mark.parametrize("op", ["<", "<=", ">", ">=", "=="])
def test_claim_with_nan_never_holds(op):
    assert Claim("c", "t", float("nan"), op, 1.0).holds is False
    assert Claim("c", "t", 1.0, op, float("nan")).holds is False


def test_claim_unknown_op_lists_the_allowed_ones():
    with pytest.raises(ValueError, match=r"'<', '<=', '>', '>=', '=='"):
        Claim("c", "t", 1.0, "!=", 1.0)


def test_claim_is_frozen_and_converts_numpy_numbers():
    claim = Claim("c", "t", np.float32(0.5), "<", np.int64(1))
    assert type(claim.value) is float and type(claim.threshold) is float
    with pytest.raises(AttributeError):
        claim.value = 2.0  # type: ignore[misc]


def test_claim_to_dict_is_the_results_contract():
    d = Claim("bilstm_err", "BiLSTM err < 2.5 %", 1.25, "<", 2.5).to_dict()
    assert d == {
        "id": "bilstm_err",
        "text": "BiLSTM err < 2.5 %",
        "value": 1.25,
        "op": "<",
        "threshold": 2.5,
        "holds": True,
        "whose": "paper",
        "status": "holds",
    }
    nan = Claim("x", "t", float("nan"), "<", 1.0).to_dict()
    assert nan["value"] is None and nan["holds"] is False and nan["status"] == "fails"
    json.dumps(nan, allow_nan=False)  # valid JSON
    # a claim whose conditions are unmet is not tested: it neither holds nor fails
    untested = Claim("y", "t", 1.0, "<", 2.0, whose="ours", requires=("a", "b"), unmet=("b",))
    assert untested.holds and untested.status == "not tested"
    assert untested.to_dict()["unmet"] == ["b"] and untested.to_dict()["whose"] == "ours"
    with pytest.raises(ValueError, match="whose = 'mine' is out of range: allowed paper, ours"):
        Claim("z", "t", 1.0, "<", 2.0, whose="mine")


# ---------------------------------------------------------------------------------------------
# write_table / write_claims


def test_write_table_round_trips_and_leaves_no_temp_file(tmp_path):
    df = pd.DataFrame({"pocket": [1, 2], "nn_s": [310.0, 1 / 3], "label": ["a", "b,c"]})
    path = write_table("nb_stem", "table3", df, results_dir=tmp_path)
    assert path == tmp_path / "nb_stem" / "table3.csv"
    assert sorted(p.name for p in path.parent.iterdir()) == ["table3.csv"]
    assert path.read_bytes() == b'pocket,nn_s,label\n1,310,a\n2,0.333333,"b,c"\n'
    back = pd.read_csv(path)
    assert back["pocket"].tolist() == [1, 2]
    assert back["nn_s"].tolist() == [310.0, 0.333333]
    assert back["label"].tolist() == ["a", "b,c"]


def test_write_table_is_deterministic_and_overwrites(tmp_path):
    df = pd.DataFrame({"x": [0.1 + 0.2, 2.0 / 3.0]})
    first = write_table("s", "t", df, results_dir=tmp_path).read_bytes()
    second = write_table("s", "t", df, results_dir=tmp_path).read_bytes()
    assert first == second == b"x\n0.3\n0.666667\n"
    write_table("s", "t", pd.DataFrame({"x": [1]}), results_dir=tmp_path)
    assert (tmp_path / "s" / "t.csv").read_text() == "x\n1\n"


def test_interrupted_write_keeps_old_file_and_no_temp(tmp_path, monkeypatch):
    path = write_table("s", "t", pd.DataFrame({"x": [1]}), results_dir=tmp_path)

    def broken_replace(src, dst):
        raise OSError("disk gone")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk gone"):
        write_table("s", "t", pd.DataFrame({"x": [2]}), results_dir=tmp_path)
    assert path.read_text() == "x\n1\n"
    assert [p.name for p in path.parent.iterdir()] == ["t.csv"]


@pytest.mark.parametrize("bad", ["../escape", "a/b", "", ".hidden"])
def test_write_table_rejects_names_leaving_the_folder(tmp_path, bad):
    with pytest.raises(ValueError):
        write_table(bad, "t", pd.DataFrame({"x": [1]}), results_dir=tmp_path)
    with pytest.raises(ValueError):
        write_table("s", bad, pd.DataFrame({"x": [1]}), results_dir=tmp_path)


def test_write_claims_json(tmp_path):
    claims = [
        Claim("b", "second", 3.0, ">", 2.0),
        Claim("a", "first", 3.0, "<", 2.0),
    ]
    path = write_claims("nb", claims, results_dir=tmp_path)
    assert path == tmp_path / "nb" / "claims.json"
    text = path.read_text()
    assert text.endswith("}\n]\n")
    assert text.startswith('[\n  {\n    "holds": true,\n    "id": "b",')  # sorted keys, indent 2
    records = json.loads(text)
    assert [r["id"] for r in records] == ["b", "a"]  # the caller's order
    assert [r["holds"] for r in records] == [True, False]
    assert set(records[0]) == {"id", "text", "value", "op", "threshold", "holds", "whose",
                               "status"}  # fmt: skip
    assert sorted(p.name for p in path.parent.iterdir()) == ["claims.json"]


def test_write_claims_rejects_duplicate_ids(tmp_path):
    with pytest.raises(ValueError, match="unique"):
        write_claims("nb", [Claim("a", "t", 1, "<", 2)] * 2, results_dir=tmp_path)


def test_results_root_env_override(tmp_path, monkeypatch):
    monkeypatch.setenv("NCTWIN_RESULTS", str(tmp_path))
    path = write_claims("nb", [], results_dir=None)
    assert path == tmp_path / "nb" / "claims.json"
    assert json.loads(path.read_text()) == []


# ---------------------------------------------------------------------------------------------
# format_table


def test_format_table_is_fixed_plain_text():
    df = pd.DataFrame({"f": [75, 92], "t": [0.1 + 0.2, np.nan], "s": ["I", "II"]})
    assert format_table(df) == " f   t  s\n75 0.3  I\n92   - II"


def test_format_paper_table_title_and_footnotes():
    text = format_paper_table(_paper(), name="demo")
    lines = text.splitlines()
    assert lines[0] == "demo | P 2023 | Table 1 | Sec. 4"
    assert lines[-1] == "[1] garbled"
    assert "paper" not in lines[1].split()
    assert lines[4].rstrip().endswith("[1]")  # third data row carries the note


# ---------------------------------------------------------------------------------------------
# Paper tables on disk


def test_there_are_tables_for_every_paper():
    names = available_tables()
    for key in PAPERS:
        assert paper_tables(key), f"no table for {key}"
    assert set(names) == {p.stem for p in CSV_FILES}
    assert paper_tables("chien2023", selected=["sun2022"]) == []
    assert paper_tables("chien2023", selected=None)[0].startswith("chien2023_")


@pytest.mark.parametrize("path", CSV_FILES, ids=lambda p: p.stem)
def test_every_paper_csv_cites_its_source(path: Path):
    raw = pd.read_csv(path, dtype=str, keep_default_na=False)
    for column in ("paper", "table", "page_or_section"):
        assert column in raw.columns, f"{path.name} lacks {column}"
    assert (raw["table"].str.strip() != "").all(), f"{path.name} has an empty table cell"
    assert (raw["paper"].str.strip() != "").all()
    key = path.stem.split("_", 1)[0]
    assert set(raw["paper"]) == {PAPERS[key]}
    assert len(raw) > 0
    load_paper_table(path.stem)  # passes the loader's own checks


def test_unknown_table_error_lists_available_names():
    with pytest.raises(KeyError) as info:
        load_paper_table("chien2023_table9")
    assert isinstance(info.value, UnknownTableError)
    message = str(info.value)
    assert "chien2023_table9" in message
    assert "chien2023_table1" in message and "zhang2023_table8" in message


def test_load_accepts_csv_suffix_and_rejects_paths():
    assert len(load_paper_table("chien2023_table3.csv")) == 4
    with pytest.raises(ValueError):
        load_paper_table("../papers/chien2023_table1")


def test_load_rejects_a_table_without_citations(tmp_path):
    (tmp_path / "bad.csv").write_text("paper,table,x\nP,,1\n")
    with pytest.raises(ValueError, match="empty 'table'"):
        load_paper_table("bad", directory=tmp_path)
    (tmp_path / "worse.csv").write_text("x\n1\n")
    with pytest.raises(ValueError, match="missing citing"):
        load_paper_table("worse", directory=tmp_path)


def test_data_env_override(tmp_path, monkeypatch):
    (tmp_path / "papers").mkdir()
    (tmp_path / "papers" / "own_table1.csv").write_text("paper,table,v\nMe 2024,Table 1,3\n")
    monkeypatch.setenv("NCTWIN_DATA", str(tmp_path))
    assert available_tables() == ["own_table1"]
    assert load_paper_table("own_table1")["v"].tolist() == [3]


# Cross-checks between numbers transcribed independently of each other: they catch typing errors
# in data/papers without restating any number.


def test_chien_tables_cover_the_stated_grids():
    for name in ("chien2023_table1", "chien2023_table2"):
        df = load_paper_table(name)
        grid = set(zip(df["feed_mm_s"], df["tol_mm"], strict=True))
        assert grid == {(75, 0.3), (75, 0.4), (92, 0.3), (92, 0.4)}
    df = load_paper_table("chien2023_table3")
    grid = set(zip(df["feed_mm_s"], df["tol_mm"], strict=True))
    assert grid == {(70, 0.075), (70, 0.1), (80, 0.075), (80, 0.1)}
    both = pd.concat([load_paper_table(f"chien2023_table{i}") for i in (1, 2, 3)])
    assert (both["cam_s"] < both["measured_s"]).all()  # CAM always underestimates


@pytest.mark.parametrize("name", ["sun2022_table3", "sun2022_table4"])
def test_sun_printed_errors_match_printed_times(name):
    df = load_paper_table(name)
    np.testing.assert_allclose(
        error_pct(df["nn_s"], df["measured_s"]), df["nn_err_pct"], atol=0.006
    )
    if "cam_s" in df:
        np.testing.assert_allclose(
            error_pct(df["cam_s"], df["measured_s"]), df["cam_err_pct"], atol=0.006
        )


def test_lee_printed_accuracy_matches_printed_times():
    df = load_paper_table("lee2022_validation")
    acc = accuracy_pct(df["predicted_s"], df["measured_s"])
    np.testing.assert_allclose(acc, df["accuracy_pct"], atol=0.05)


def test_zhang_histograms_count_the_test_sets():
    sizes = load_paper_table("zhang2023_table4").set_index("extract_pct")["n_test_samples"]
    assert sizes.equals(
        load_paper_table("zhang2023_table5").set_index("extract_pct")["n_test_samples"]
    )
    for name in ("zhang2023_table6", "zhang2023_table7"):
        df = load_paper_table(name)
        for _, panel in df.groupby("panel"):
            assert panel["count"].sum() == sizes[15]
    surface1 = load_paper_table("zhang2023_surfaces").set_index("surface").loc[1, "n_samples"]
    df = load_paper_table("zhang2023_table3")
    for _, panel in df.groupby("panel"):
        assert panel["count"].sum() == round(0.3 * surface1)  # the 30 % test split
        assert panel["ratio_pct"].sum() == pytest.approx(100.0, abs=0.02)


def test_zhang_dropout_sweep_minimum_is_the_chosen_p():
    df = load_paper_table("zhang2023_table2")
    chosen = load_paper_table("zhang2023_summary").set_index("quantity").loc["dropout_p", "value"]
    assert df.loc[df["mse"].idxmin(), "dropout_p"] == chosen


def test_denkena_training_grid_size():
    df = load_paper_table("denkena2020_table1")
    assert df.groupby("parameter").size().to_dict() == {
        "ae_mm": 6,
        "ap_mm": 4,
        "n_rpm": 5,
        "vf_mm_min": 5,
    }


def test_paper_tables_lists_numbered_tables_first():
    names = paper_tables("zhang2023")
    numbered = [n for n in names if "_table" in n]
    assert names[: len(numbered)] == numbered
    assert [int(n.rsplit("table", 1)[1]) for n in numbered] == sorted(
        int(n.rsplit("table", 1)[1]) for n in numbered
    )
    assert names[-1] == "zhang2023_summary"
