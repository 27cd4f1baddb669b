"""The notebooks are reports: their logic lives in the package, a cell only calls it and prints.

Static checks of every ``notebooks/*.ipynb`` (nothing is executed): no code cell defines a
function or a class, no code cell is longer than :data:`MAX_LINES` lines, the code of a notebook
parses, and the cell that writes the claims is one call of
:func:`nctwin.report.claims.report_claims` (besides comments such as ``# NBVAL_CHECK_OUTPUT``).
"""

from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))
#: Longest code cell allowed, in lines.
MAX_LINES = 25
CLAIM_WRITERS = {"report_claims", "write_claims"}
#: Notebooks of the book that are no paper's chapter: they check no claim.
NOT_CHAPTERS = {"paper_tables", "your_own_toolpath"}


def code_cells(path: Path) -> list[tuple[int, str]]:
    """(index, source) of every code cell."""
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    return [(i, "".join(c["source"])) for i, c in enumerate(cells) if c["cell_type"] == "code"]


def python_source(source: str) -> str:
    """``source`` with IPython magics and shell escapes blanked (line numbers kept)."""
    return "\n".join(
        "" if line.lstrip().startswith(("%", "!")) else line for line in source.splitlines()
    )


def called_name(node: ast.AST) -> str | None:
    """Name of the function a call node calls (``f(...)`` or ``module.f(...)``)."""
    if not isinstance(node, ast.Call):
        return None
    func = node.func
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return func.attr
    return None


def test_there_are_notebooks():
    assert len(NOTEBOOKS) >= 7


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_no_def_or_class_in_a_cell(path):
    offenders = []
    for i, source in code_cells(path):
        for node in ast.walk(ast.parse(python_source(source))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                offenders.append(f"cell {i}: {type(node).__name__} {node.name}")
    assert not offenders, offenders


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_no_long_cell(path):
    long = {i: n for i, s in code_cells(path) if (n := len(s.splitlines())) > MAX_LINES}
    assert not long, f"cells longer than {MAX_LINES} lines (index: lines): {long}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_code_parses(path):
    ast.parse("\n".join(python_source(s) for _, s in code_cells(path)), filename=str(path))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_claims_cell_is_one_call(path):
    claim_cells = []
    for i, source in code_cells(path):
        tree = ast.parse(python_source(source))
        if any(called_name(n) in CLAIM_WRITERS for n in ast.walk(tree)):
            claim_cells.append((i, tree))
    if path.stem in NOT_CHAPTERS:
        assert not claim_cells
        return
    assert len(claim_cells) == 1, f"cells writing claims: {[i for i, _ in claim_cells]}"
    i, tree = claim_cells[0]
    assert len(tree.body) == 1, f"cell {i} has {len(tree.body)} statements"
    (stmt,) = tree.body
    assert isinstance(stmt, ast.Expr), f"cell {i} is not a bare call"
    assert called_name(stmt.value) == "report_claims", f"cell {i} does not call report_claims"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_is_valid_nbformat(path):
    """nbconvert refuses an invalid notebook (a tag given twice is one), so the book would too."""
    nbformat = pytest.importorskip("nbformat")
    nbformat.validate(nbformat.read(path, as_version=4))


EXECUTED = sorted((Path(__file__).resolve().parents[1] / "book" / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", EXECUTED, ids=lambda p: p.stem)
def test_executed_notebook_shows_no_file_path(path):
    # a cell ending in a writer's call displays the path it wrote: the machine's, not the book's
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    for i, cell in enumerate(cells):
        for out in cell.get("outputs", []):
            text = "".join(out.get("data", {}).get("text/plain", [])) + "".join(out.get("text", []))
            assert "PosixPath(" not in text, f"{path.name}: cell {i} displays a file path"
