"""Every chapter's "Your ..." section, and a chapter run through papermill on a reader's input.

Each chapter ends with a section that runs its method on an input of the reader's (a program, a
process, a surface), or on a shipped example when none is given. The book's executed notebooks
(``book/notebooks/``, re-executed by ``make reproduce`` and checked by nbval in ``make test``)
show it on the examples: the first tests read them. The last ones run a chapter as
``make chapter`` runs it, through papermill on a reader's program: the parameter reaches the
chapter, its tables go to the run's folder, ``results/`` is unchanged, and a program the chapter
cannot run gets one line. They are marked ``chapter`` and left out of a plain ``pytest``
(``addopts``); ``make test`` runs them after nbval, whose executions leave the chapter's data in
the cache.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from nctwin.chapters.your_program import example_program
from nctwin.paths import repo_root, results_dir
from nctwin.report import chapter

ROOT = repo_root()
EXECUTED = ROOT / "book" / "notebooks"

#: Each chapter's section heading on its example, and words of the section's table.
SECTIONS = {
    "chien2023_bilstm": ("## Your program: `bracket.ngc`", ("cycle_time_s",)),
    "sun2022_axis_nn": ("## Your program: `bracket.ngc`", ("cycle_time_s",)),
    "lee2022_block_overlap": ("## Your program: `bracket.ngc`", ("cycle_time_s",)),
    "linuxcnc_real_kernel": ("## Your program: `bracket.ngc`", ("cycle_time_s",)),
    "nist_hurco_real_machine": (
        "## Your program: `bracket.ngc`",
        ("half_width_pct", "calibrated", "bilstm", "axis_nn"),
    ),
    "denkena2020_force_lstm": (
        "## Your process: groove milling +x, ae 10 mm, ap 1 mm, vf 600 mm/min, n 5000 1/min",
        ("lstm_cutting_rmse_n",),
    ),
    "zhang2023_step_error": ("## Your surface: `saddle.csv`", ("share_below_0.5um_pct",)),
}


def _outputs(executed: Path) -> tuple[list[str], list[str]]:
    """The executed notebook's text outputs of its last cell, and every error's name."""
    nb = json.loads(executed.read_text(encoding="utf-8"))
    errors = [o["ename"] for c in nb["cells"] for o in c.get("outputs", [])
              if o["output_type"] == "error"]  # fmt: skip
    texts = []
    for o in nb["cells"][-1]["outputs"]:
        data = o.get("data", {})
        texts.append("".join(data.get("text/markdown", data.get("text/plain", o.get("text", "")))))
    return texts, errors


@pytest.mark.parametrize("stem", list(SECTIONS))
def test_the_book_shows_each_chapter_on_its_example(stem):
    heading, words = SECTIONS[stem]
    texts, errors = _outputs(EXECUTED / f"{stem}.ipynb")
    assert errors == []
    assert texts[0] == heading
    assert all(word in texts[1] for word in words)
    assert not any(t.startswith("not run:") for t in texts)


def test_every_chapter_has_its_section():
    chapters = {p.stem for p in (ROOT / "notebooks").glob("*.ipynb")}
    assert chapters - set(SECTIONS) == {"paper_tables", "your_own_toolpath"}


def _results_digest() -> dict[str, str]:
    folder = results_dir()
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def _run(stem: str, parameters: dict, out: Path) -> tuple[list[str], list[str]]:
    before = _results_digest()
    chapter.execute(chapter.resolve_notebook(stem, ROOT), out, parameters, ROOT)
    assert _results_digest() == before, "the chapter changed results/"
    assert (out / stem / "results").is_dir()  # its tables went to the run's folder
    assert (out / f"{stem}.html").stat().st_size > 0
    return _outputs(out / f"{stem}.ipynb")


@pytest.mark.chapter
def test_a_chapter_runs_on_your_program(tmp_path):
    program = tmp_path / "part.ngc"
    program.write_bytes(example_program().read_bytes())
    texts, errors = _run("lee2022_block_overlap", {"program": str(program)}, tmp_path / "out")
    assert errors == []
    assert texts[0] == "## Your program: `part.ngc`"
    assert "cycle_time_s" in texts[1]


@pytest.mark.chapter
def test_a_program_the_chapter_cannot_run_gets_one_line(tmp_path):
    bad = tmp_path / "tolerance.ngc"
    bad.write_text("G21 G90\nG64 P0.05\nG1 X10 F600\nM30\n", encoding="utf-8")
    texts, errors = _run("lee2022_block_overlap", {"program": str(bad)}, tmp_path / "out")
    assert errors == []
    # the first move under the tolerance is named (line 3), as the estimator checks moves
    assert texts == ["## Your program: `tolerance.ngc`",
                     f"not run: {bad}:3: G64 P blending tolerance: the block-overlap method has "
                     "no path tolerance\n"]  # fmt: skip
    # the runner's line (make chapter), the chapter's HTML written all the same
    assert chapter.refused(tmp_path / "out" / "lee2022_block_overlap.ipynb") == [texts[1].strip()]
