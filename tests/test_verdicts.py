"""nctwin.report.verdicts: the Verdicts page from claims.json files and the notebooks' headings."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from nctwin.report import verdicts
from nctwin.report.claims import Claim
from nctwin.report.results import write_claims


def notebook(path: Path, cells: list[tuple[str, str]]) -> None:
    path.write_text(
        json.dumps({"cells": [{"cell_type": k, "source": s} for k, s in cells]}), encoding="utf-8"
    )


@pytest.fixture
def book(tmp_path: Path) -> Path:
    """results/ with two chapters' claims, their notebooks and a toc listing b before a."""
    write_claims("a_ch", [Claim("x_ok", "x <= 3 % (paper 0.8-2.2 %)", 1.0, "<=", 3.0)],
                 results_dir=tmp_path / "results")  # fmt: skip
    write_claims(
        "b_ch",
        [
            Claim("y_bad", "y | z >= 20 %", 4.0, ">=", 20.0),
            Claim("w", "w > 0", float("nan"), ">", 0),
        ],
        results_dir=tmp_path / "results",
    )
    (tmp_path / "notebooks").mkdir()
    notebook(tmp_path / "notebooks" / "a_ch.ipynb", [
        ("markdown", "# Paper A 2020: a method\n\nintro"),
        ("markdown", "## Claims"),
        ("code", "report_claims(STEM, ch.claims())"),
    ])  # fmt: skip
    notebook(tmp_path / "notebooks" / "b_ch.ipynb", [
        ("markdown", "# Paper B 2021: b\n"),
        ("markdown", "## Table 3 analogue: \"machine B\"\n\n```\n## not a heading\n```\n"),
        ("markdown", "### Why `y_bad` fails\n\nThe claim `y_bad` fails because ..."),
        ("markdown", "## Claims"),
        ("code", "report_claims(STEM, ch.claims())"),
    ])  # fmt: skip
    (tmp_path / "_toc.yml").write_text(
        "chapters:\n  - file: notebooks/b_ch\n  - file: notebooks/a_ch\n", encoding="utf-8"
    )
    return tmp_path


def test_slugify_as_myst():
    assert verdicts.slugify('Table 3 analogue: "machine B"') == "table-3-analogue-machine-b"
    assert verdicts.slugify("Why y_bad fails") == "why-y_bad-fails"


def test_paper_value_from_field_then_text():
    assert verdicts.paper_value({"text": "e <= 3 % (paper 0.8-2.2 %)"}) == "0.8-2.2 %"
    assert verdicts.paper_value({"text": "d (1 = yes; paper: Fig. 8, 88.6 N)"}) == "Fig. 8, 88.6 N"
    assert verdicts.paper_value({"text": "the paper's setting"}) == ""
    assert verdicts.paper_value({"text": "x (paper 1 %)", "paper": "2.2 %"}) == "2.2 %"


def test_section_is_where_the_prose_names_the_claim(book):
    ch = verdicts.chapter_claims("b_ch", book / "results", book / "notebooks")
    assert ch.title == "Paper B 2021: b"
    assert [h[3] for h in ch.headings] == [
        "paper-b-2021-b", "table-3-analogue-machine-b", "why-y_bad-fails", "claims"
    ]  # fmt: skip
    assert verdicts.section_of(ch, "y_bad") == ("Why y_bad fails", "why-y_bad-fails")
    # no prose names "w" as a word: the section of the report_claims cell
    assert verdicts.section_of(ch, "w") == ("Claims", "claims")


def test_page_has_one_row_per_claim_in_toc_order(book):
    chapters = verdicts.chapters_in_order(book / "_toc.yml", book / "results", book / "notebooks")
    assert [c.stem for c in chapters] == ["b_ch", "a_ch"]
    page = verdicts.render(chapters)
    rows = [ln for ln in page.splitlines() if ln.startswith("| ") and "---" not in ln
            and not ln.startswith("| claim |")]  # fmt: skip
    assert len(rows) == 3
    assert "3 in all: 1 hold, 2 fail and 0 are not tested" in page
    assert rows[0].startswith("| y \\| z >= 20 % (`y_bad`) | paper |")
    assert page.index("### Paper B 2021") < page.index("`y_bad`") < page.index("### Paper A 2020")
    assert "fails" in rows[0] and "(notebooks/b_ch.ipynb#why-y_bad-fails)" in rows[0]
    assert "| - | >&nbsp;0 |" in rows[1]  # NaN value: not reproduced, fails
    assert "| 0.8-2.2 % | 1 | <=&nbsp;3 |" in rows[2] and "holds" in rows[2]
    assert "(notebooks/a_ch.ipynb#claims)" in rows[2]
    # the status lines come first, in the same order
    assert (
        "- **[Paper B 2021: b](notebooks/b_ch.ipynb)**: not reproduced. 0 of the paper's 2 "
        "claims hold, 2 fail." in page
    )
    assert "- **[Paper A 2020: a method](notebooks/a_ch.ipynb)**: reproduced." in page


def _chapter(*records: dict) -> verdicts.ChapterClaims:
    return verdicts.ChapterClaims("s", "T", list(records), [], [])


def test_chapter_status_reads_the_papers_claims_only():
    held = {"id": "a", "holds": True, "status": "holds", "whose": "paper"}
    failed = {"id": "b", "holds": False, "status": "fails", "whose": "paper"}
    untested = {"id": "c", "holds": True, "status": "not tested", "whose": "paper",
                "unmet": ["rate", "lines"]}  # fmt: skip
    ours = {"id": "d", "holds": False, "status": "fails", "whose": "ours"}
    assert verdicts.chapter_status(_chapter(held, ours))[0] == "reproduced"
    assert verdicts.chapter_status(_chapter(held, failed))[0] == "partly reproduced"
    assert verdicts.chapter_status(_chapter(failed, untested))[0] == "not reproduced"
    status, why = verdicts.chapter_status(_chapter(untested, ours))
    assert status == "not tested under the paper's conditions"
    assert why == "0 of the paper's 1 claims hold, 0 fail, 1 not tested (unmet: lines, rate)."
    assert verdicts.chapter_status(_chapter(ours))[0] == "checks of our own only"


def test_main_writes_the_page(book, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(verdicts.paths, "repo_root", lambda: book)
    monkeypatch.setenv("NCTWIN_RESULTS", str(book / "results"))
    (book / "book").mkdir()
    (book / "book" / "_toc.yml").write_text((book / "_toc.yml").read_text())
    out = tmp_path / "new" / "verdicts.md"  # a folder that does not exist yet
    assert verdicts.main([str(out)]) == 0
    assert out.read_text().startswith("# Verdicts\n")
    assert "3 claims of 2 chapters" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [["--help"], ["-o", "x.md"], ["a.md", "b.md"]])
def test_the_command_line_writes_no_file_named_by_an_option(argv, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit):
        verdicts.main(argv)
    assert not list(tmp_path.iterdir())


def test_the_repository_page_renders():
    """Every committed claims.json has its notebook, and every claim a row."""
    root = verdicts.paths.repo_root()
    chapters = verdicts.chapters_in_order(
        root / "book" / "_toc.yml", root / "results", root / "notebooks"
    )
    page = verdicts.render(chapters)
    n = sum(len(c.claims) for c in chapters)
    assert n > 0
    assert sum(ln.startswith("| ") for ln in page.splitlines()) == n + 2 * len(chapters)
    assert sum(ln.startswith("- **[") for ln in page.splitlines()) == len(chapters)


def test_a_learned_claim_shows_its_interval_and_single_networks():
    record = {"value": 2.5, "interval": [1.25, 3.5], "seeds_passing": 3, "seeds": 5}
    assert verdicts._ours(record) == "2.5<br>(1.25 to 3.5)<br>3 of 5 nets"
    assert verdicts._ours({"value": None}) == "-"


def test_the_intro_status_is_rewritten_between_its_markers():
    begin, end = verdicts.INTRO_MARKERS
    text = f"# Intro\n\nbefore\n{begin}\n- stale line\n{end}\nafter\n"
    out = verdicts.update_intro(text, ["- one", "- two"])
    assert out == f"# Intro\n\nbefore\n{begin}\n- one\n- two\n{end}\nafter\n"
    assert verdicts.update_intro(out, ["- one", "- two"]) == out
    with pytest.raises(ValueError, match="markers"):
        verdicts.update_intro("no markers", [])


def test_main_writes_the_intro_status(book, tmp_path, monkeypatch):
    monkeypatch.setattr(verdicts.paths, "repo_root", lambda: book)
    monkeypatch.setenv("NCTWIN_RESULTS", str(book / "results"))
    (book / "book").mkdir()
    (book / "book" / "_toc.yml").write_text((book / "_toc.yml").read_text())
    begin, end = verdicts.INTRO_MARKERS
    (tmp_path / "intro.md").write_text(f"# Intro\n{begin}\n{end}\n")
    verdicts.main([str(tmp_path / "verdicts.md")])
    lines = (tmp_path / "intro.md").read_text().splitlines()
    assert lines[0] == "# Intro" and lines[1] == begin and lines[-1] == end
    assert len(lines) == 2 + 2 + 1  # a line per chapter of the fixture (two)
    assert all(ln.startswith("- **[") for ln in lines[2:4])


def test_conditions_that_differ_only_in_numbers_are_named_once_with_their_count():
    ids = ["inpos_x_set1", "inpos_x_set2", "logger_rate", "table1_cam_F75_P0.3",
           "table2_cam_F92_P0.4", "table3_pocket_path", "inpos_x_set1"]  # fmt: skip
    assert verdicts.grouped(ids) == (
        "inpos_x_set* (2), logger_rate, table*_cam_F*_P* (2), table3_pocket_path"
    )
