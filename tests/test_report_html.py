"""nctwin.report.html and display.show: one table per result, HTML for the book, text for nbval."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from nctwin.report import display
from nctwin.report.html import format_value, html_table, short_header


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (99.95001796, "99.95"),
        (2282.82, "2283"),  # never fewer digits than the integer part
        (0.0026178, "0.002618"),
        (3.0, "3"),
        (-12.5, "-12.5"),
        (0.0, "0"),
        (1.5e-5, "1.500e-05"),
        (np.float32(0.25), "0.25"),
        (float("nan"), "-"),
        (None, "-"),
        (19800, "19800"),
        ("I", "I"),
    ],
)
def test_format_value(value, text):
    assert format_value(value) == text


def test_short_header():
    assert short_header("paper_cam_err_pct") == "cam err (%)"
    assert short_header("measured_s") == "measured (s)"
    assert short_header("median_feed_mm_s") == "median feed (mm/s)"
    assert short_header("pocket") == "pocket"
    assert short_header("s") == "s"  # a bare suffix is a name


def frame() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "toolpath": ["I", "II"],
            "bilstm_err_pct": [3.2345678, 2.0],
            "ok": [True, False],
            "paper_bilstm_err_pct": [1.2, np.nan],
            "paper_source": ["Chien et al. 2023, Table 1"] * 2,
        }
    )


def test_html_groups_the_paper_columns():
    page = html_table(frame())
    assert page.startswith('<div class="nctwin-table">\n<style type="text/css">')
    # the paper's column under one header naming the source (constant: not a column)
    assert '<th class="col_heading level0 col0" colspan="3"></th>' in page
    assert '<th class="col_heading level0 col3" >paper (Chien et al. 2023, Table 1)</th>' in page
    assert "paper_source" not in page
    # short headers, the full name as their title
    assert '<span title="paper_bilstm_err_pct">bilstm err (%)</span></th>' in page
    # the paper's column tinted and ruled off by the table's own rule, and only it
    table_id = re.search(r'<table id="(T_[0-9a-f]+)">', page).group(1)
    rule = f"#{table_id} .col3 {{\n  background: var(--nctwin-paper-bg);\n"
    assert rule + "  border-left: var(--nctwin-paper-rule);\n}" in page
    assert page.count("var(--nctwin-paper-bg)") == 1
    # numbers in cells that never break; booleans are not right-aligned numbers
    assert '<td class="data row0 col1 nctwin-num" >3.235</td>' in page
    assert '<td class="data row1 col3 nctwin-num" >-</td>' in page
    assert '<td class="data row0 col2" >True</td>' in page
    assert "row_heading" not in page  # no index


def test_html_is_the_same_for_the_same_table_only():
    page = html_table(frame())
    assert html_table(frame()) == page  # the id is derived from the content, not random
    other = frame().assign(bilstm_err_pct=[3.2345678, 2.5])
    ids = {re.search(r'<table id="(T_[0-9a-f]+)">', p).group(1) for p in (page, html_table(other))}
    assert len(ids) == 2  # two tables on one page keep their own style rules


def test_html_escapes_and_notes():
    page = html_table(pd.DataFrame({"a<b": ["x & y"]}), prefix="", caption="T | 1", notes=["n"])
    assert "a&lt;b" in page and "x &amp; y" in page and "<caption>T | 1</caption>" in page
    assert '<ol class="nctwin-notes"><li>n</li></ol>' in page
    assert "<caption>a&lt;b</caption>" in html_table(frame(), caption="a<b")
    assert "level1" not in page  # no paper column: one header row


def test_show_text_is_what_print_format_table_prints(monkeypatch):
    shown = []
    monkeypatch.setattr("IPython.display.display", lambda obj, raw: shown.append((obj, raw)))
    display.show(frame())
    ((obj, raw),) = shown
    assert raw and obj["text/plain"] == display.format_table(frame())
    assert obj["text/html"] == html_table(frame())


def test_show_transposed_html_keeps_the_text(monkeypatch):
    shown = []
    monkeypatch.setattr("IPython.display.display", lambda obj, raw: shown.append(obj))
    display.show(frame(), transpose=True)
    assert shown[0]["text/plain"] == display.format_table(frame())
    assert shown[0]["text/html"] == html_table(frame(), transpose=True)
    assert shown[0]["text/html"] != html_table(frame(), transpose=False)


def test_show_paper_keeps_format_paper_table_text(monkeypatch):
    shown = []
    monkeypatch.setattr("IPython.display.display", lambda obj, raw: shown.append(obj))
    paper = pd.DataFrame(
        {"paper": ["P"] * 2, "table": ["Table 1"] * 2, "x": [1.0, 2.0], "note": ["a", None]}
    )
    display.show_paper(paper, "p_table1")
    assert shown[0]["text/plain"] == display.format_paper_table(paper, "p_table1")
    page = shown[0]["text/html"]
    assert "<caption>p_table1 | P | Table 1</caption>" in page
    assert "<li>a</li>" in page and '<td class="data row0 col1" >[1]</td>' in page


def test_wide_short_tables_are_transposed():
    wide = pd.DataFrame(
        {f"c{i}_mm": [1.0 * i, 2.0 * i] for i in range(12)} | {"paper_c1_mm": [1.0, 2.0]}
    )
    page = html_table(wide)
    head = (
        '<th class="index_name level0" ><span title="c0_mm">c0 (mm)</span></th>\n'
        '      <th class="col_heading level0 col0" >0</th>\n'
        '      <th class="col_heading level0 col1" >0</th>\n    </tr>\n  </thead>'
    )
    assert head in page
    label = '<th class="row_heading level0 row11" ><span title="paper_c1_mm">c1 (mm) (paper)</span>'
    assert label in page
    assert ".row11 {\n  background: var(--nctwin-paper-bg);\n  border-top:" in page
    assert html_table(wide, transpose=False).count("<tr>") == 4  # group row, header, two rows
    assert "row_heading" not in html_table(wide.iloc[:, :12])  # 12 columns: as they are


def test_words_may_break_after_underscores():
    assert "iso10791_<wbr>7_<wbr>test" in html_table(pd.DataFrame({"p": ["iso10791_7_test"]}))
