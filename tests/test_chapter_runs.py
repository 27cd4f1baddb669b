"""Every chapter run through papermill on a reader's input, as `make chapter` runs it: the
"Your ..." section is there, the rest of the chapter ran, and ``results/`` is unchanged.

Marked ``chapter`` and left out of a plain ``pytest`` (``addopts``); ``make test`` runs them after
nbval, whose executions leave the chapters' networks in the cache (``make chapters``).
"""

from __future__ import annotations

import hashlib
import json

import pytest

from nctwin.paths import repo_root, results_dir
from nctwin.report import chapter

pytestmark = pytest.mark.chapter

ROOT = repo_root()
EXAMPLE = ROOT / "data" / "programs" / "examples" / "bracket.ngc"

#: Cycle-time chapters: the program parameter, and words of the section's table.
PROGRAM_CHAPTERS = {
    "chien2023_bilstm": ("cycle_time_s",),
    "sun2022_axis_nn": ("cycle_time_s",),
    "lee2022_block_overlap": ("cycle_time_s",),
    "linuxcnc_real_kernel": ("cycle_time_s",),
    "nist_hurco_real_machine": ("half_width_pct", "calibrated", "bilstm", "axis_nn"),
}


def _results_digest() -> dict[str, str]:
    folder = results_dir()
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def _outputs(executed) -> tuple[list[str], list[str]]:
    """The executed notebook's text outputs of its last cell, and every error's name."""
    nb = json.loads(executed.read_text(encoding="utf-8"))
    errors = [o["ename"] for c in nb["cells"] for o in c.get("outputs", [])
              if o["output_type"] == "error"]  # fmt: skip
    texts = []
    for o in nb["cells"][-1]["outputs"]:
        data = o.get("data", {})
        texts.append("".join(data.get("text/markdown", data.get("text/plain", o.get("text", "")))))
    return texts, errors


def _run(stem: str, parameters: dict, tmp_path) -> tuple[list[str], list[str]]:
    before = _results_digest()
    chapter.execute(chapter.resolve_notebook(stem, ROOT), tmp_path, parameters, ROOT)
    assert _results_digest() == before, "the chapter changed results/"
    assert (tmp_path / stem / "results").is_dir()  # its tables went to the run's folder
    assert (tmp_path / f"{stem}.html").stat().st_size > 0
    return _outputs(tmp_path / f"{stem}.ipynb")


@pytest.mark.parametrize("stem", list(PROGRAM_CHAPTERS))
def test_chapter_runs_your_program(stem, tmp_path):
    texts, errors = _run(stem, {"program": str(EXAMPLE)}, tmp_path)
    assert errors == []
    assert texts[0] == "## Your program: `bracket.ngc`"
    assert all(word in texts[1] for word in PROGRAM_CHAPTERS[stem])
    assert not any(t.startswith("not run:") for t in texts)


def test_denkena_runs_your_process(tmp_path):
    texts, errors = _run("denkena2020_force_lstm", {"process": "groove,+x,10,1,600,5000"},
                         tmp_path)  # fmt: skip
    assert errors == []
    assert texts[0] == ("## Your process: groove milling +x, ae 10 mm, ap 1 mm, vf 600 mm/min, "
                        "n 5000 1/min")  # fmt: skip
    assert "lstm_cutting_rmse_n" in texts[1]
    assert not any(t.startswith("not run:") for t in texts)


def test_zhang_runs_your_surface(tmp_path):
    surface = ROOT / "data" / "surfaces" / "examples" / "saddle.csv"
    texts, errors = _run("zhang2023_step_error", {"surface": str(surface)}, tmp_path)
    assert errors == []
    assert texts[0] == "## Your surface: `saddle.csv`"
    assert "share_below_0.5um_pct" in texts[1]
    assert not any(t.startswith("not run:") for t in texts)


def test_a_program_the_chapter_cannot_run_gets_one_line(tmp_path):
    bad = tmp_path / "tolerance.ngc"
    bad.write_text("G21 G90\nG64 P0.05\nG1 X10 F600\nM30\n", encoding="utf-8")
    texts, errors = _run("lee2022_block_overlap", {"program": str(bad)}, tmp_path / "out")
    assert errors == []
    # the first move under the tolerance is named (line 3), as the estimator checks moves
    assert texts == ["## Your program: `tolerance.ngc`",
                     f"not run: {bad}:3: G64 P blending tolerance: the block-overlap method has "
                     "no path tolerance\n"]  # fmt: skip
