"""No paper number is typed in: a chapter's prose glues it, its code reads it from
``data/papers/``.

A *distinctive* number of a paper is one its tables or its summary's results print with at least
three significant digits (``20.8``, ``5383``, ``99.71``; not ``25``, ``1000`` or ``0.78``, which
prose uses for other things too). It may not appear in the Markdown of the paper's chapter, nor in
its modules (``chapters/<paper>*.py``, ``methods/<paper>.py``); the pages that quote every paper
(the papers' tables, the real-machine chapter) are checked against all five. The experiment's
settings (``kind`` ``setting`` in a summary) are left out: a method's definition holds them.
"""

from __future__ import annotations

import json
import re
from functools import cache
from pathlib import Path

import pandas as pd
import pytest

from nctwin.paths import repo_root

ROOT = repo_root()
PAPERS = ("chien2023", "sun2022", "lee2022", "denkena2020", "zhang2023")
#: Pages that quote every paper's numbers.
ALL_PAPERS = ("paper_tables", "nist_hurco_real_machine")


def distinctive(value: float) -> str | None:
    """The number as it would be typed, where it has three significant digits or more."""
    text = repr(abs(float(value)))
    text = text[:-2] if text.endswith(".0") else text
    digits = text.replace(".", "").strip("0")
    return text if len(digits) >= 3 and "e" not in text else None


@cache
def paper_numbers(paper: str) -> frozenset[str]:
    out = set()
    for path in sorted((ROOT / "data" / "papers").glob(f"{paper}_*.csv")):
        table = pd.read_csv(path)
        if "kind" in table.columns:
            table = table[table["kind"] != "setting"]
        for column in table.select_dtypes("number").columns:
            out |= {d for v in table[column].dropna() if (d := distinctive(v))}
    return frozenset(out)


def typed(text: str, numbers: frozenset[str]) -> list[str]:
    """The numbers of ``numbers`` that ``text`` holds as whole numbers."""
    return sorted(n for n in numbers
                  if re.search(rf"(?<![\w.]){re.escape(n)}(?!\w|\.\d)", text))  # fmt: skip


def test_the_detector_by_hand():
    assert [distinctive(v) for v in (20.8, 5383, 99.71, 25, 1000, 0.78, 0.075)] == [
        "20.8", "5383", "99.71", None, None, None, None]  # fmt: skip
    numbers = frozenset({"20.8", "5383"})
    assert typed("on average 20.8 % lower", numbers) == ["20.8"]
    assert typed("120.8 mm, 20.85 s, 25383 lines, x20.8", numbers) == []
    assert typed("5383.", numbers) == ["5383"]


def _pages() -> list[tuple[str, Path, frozenset[str]]]:
    out = []
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        paper = nb.stem.split("_")[0]
        if paper in PAPERS:
            out.append((nb.stem, nb, paper_numbers(paper)))
        elif nb.stem in ALL_PAPERS:
            out.append((nb.stem, nb, frozenset().union(*map(paper_numbers, PAPERS))))
    return out


@pytest.mark.parametrize("stem, path, numbers", _pages(), ids=[p[0] for p in _pages()])
def test_no_paper_number_in_a_chapters_prose(stem, path, numbers):
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    found = [f"cell {i}: {', '.join(hits)}" for i, c in enumerate(cells)
             if c["cell_type"] == "markdown"
             and (hits := typed("".join(c["source"]), numbers))]  # fmt: skip
    assert not found, f"{stem}: paper numbers typed in (glue them): {'; '.join(found)}"


@pytest.mark.parametrize("paper", PAPERS)
def test_no_paper_number_in_a_papers_code(paper):
    src = ROOT / "src" / "nctwin"
    files = sorted((src / "chapters").glob(f"{paper}*.py")) + sorted(
        (src / "methods").glob(f"{paper}.py")
    )
    found = [f"{f.relative_to(ROOT)}:{n}: {', '.join(hits)}" for f in files
             for n, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1)
             if (hits := typed(line, paper_numbers(paper)))]  # fmt: skip
    assert not found, "paper numbers typed in (read them from data/papers/):\n" + "\n".join(found)
