"""A reader's own program through a chapter: the shared pieces, and `make chapter`'s runner."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from nctwin import gcode
from nctwin.chapters import your_program as yp
from nctwin.chapters.chien2023 import cutting_blocks
from nctwin.chapters.chien2023_yours import chains
from nctwin.paths import repo_root
from nctwin.report import chapter

EXAMPLE = repo_root() / "data" / "programs" / "examples" / "bracket.ngc"


def test_program_times_errors_against_the_truth():
    t = yp.program_times(("truth", 20.0), {"method": 21.0, "CAM": 15.0})
    assert list(t.source) == ["truth", "method", "CAM"]
    assert np.isnan(t.err_pct[0])
    assert t.err_pct[1:].tolist() == pytest.approx([5.0, -25.0])


def test_program_times_without_a_truth_has_no_errors():
    t = yp.program_times(None, {"method": 21.0})
    assert t.cycle_time_s.tolist() == [21.0] and t.err_pct.isna().all()


def test_block_feeds_are_length_over_time_of_the_moving_blocks():
    lengths = np.array([10.0, 0.0, 6.0, 4.0])
    feeds = yp.block_feeds(lengths, {"true_mm_s": np.array([0.5, 2.0, 0.2, 0.0])})
    assert feeds.line.tolist() == [1, 3, 4]  # the dwell (length 0) is left out
    assert feeds.true_mm_s[:2].tolist() == pytest.approx([20.0, 30.0])
    assert np.isnan(feeds.true_mm_s[2])  # no time, no average feed


def test_domain_notes_name_the_inputs_outside_the_training_range():
    train = np.array([[65.0, 1.0], [100.0, 5.0]])
    x = np.array([[50.0, 2.0], [80.0, 3.0], [90.0, 4.0], [120.0, 2.0]])
    notes = yp.domain_notes(x, train, ("feed", "length"))
    assert notes == ("outside the training range (share of the G-lines): feed 50 % (65 to 100)",)
    assert yp.domain_notes(x[1:3], train, ("feed", "length")) == ()


def test_run_program_names_a_file_it_cannot_read(tmp_path):
    def method(text, source):
        pytest.fail("ran")

    absent = yp.run_program(tmp_path / "absent.ngc", method)
    assert absent.reason == f"{tmp_path / 'absent.ngc'}: no such file"
    assert absent.name == "absent.ngc" and absent.times.empty and absent.feeds is None
    assert yp.run_program(tmp_path, method).reason == f"{tmp_path}: is a directory, not a program"


def test_run_program_turns_a_refused_program_into_one_line(tmp_path):
    path = tmp_path / "bad.ngc"
    path.write_text("G21 G90\nG1 X10 F100\nG1 X20 Y5 Q\n", encoding="utf-8")

    def method(text, source):
        gcode.parse(text, source=source)
        pytest.fail("parsed a bad program")

    result = yp.run_program(path, method)
    assert result.reason.startswith(f"{path}:3: ") and "\n" not in result.reason


def test_block_summary_counts_the_kinds_the_program_has():
    tp = gcode.parse(EXAMPLE.read_text(encoding="utf-8"), reader="native")
    assert yp.block_summary(tp) == "87 blocks: 8 rapid, 75 linear, 4 arc_ccw"


def test_chains_cut_the_g_lines_where_the_path_jumps():
    tp = cutting_blocks(gcode.parse(EXAMPLE.read_text(encoding="utf-8"), reader="native"))
    parts = chains(tp)
    assert sum(len(p) for p in parts) == len(tp)
    for p in parts:
        assert np.array_equal(p.start_mm[1:], p.end_mm[:-1])
    # the face's zig-zag, the contour's four lines (its arcs are not G-lines) and the slot
    assert [len(p) for p in parts] == [21, 1, 1, 1, 1, 47]


def test_chapter_runner_names_what_does_not_exist(capsys):
    assert chapter.main(["no_such_chapter"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("chapter: NB=no_such_chapter: no such notebook; the chapters are ")
    assert "chien2023_bilstm" in err and err.count("\n") == 1
    assert chapter.main(["chien2023_bilstm", "--program", "absent.ngc"]) == 2
    assert capsys.readouterr().err == "chapter: PROGRAM=absent.ngc: no such file\n"


def test_chapter_runner_finds_a_chapter_by_stem_or_path():
    root = repo_root()
    by_stem = chapter.resolve_notebook("lee2022_block_overlap", root)
    assert by_stem == chapter.resolve_notebook("notebooks/lee2022_block_overlap.ipynb", root)
    assert by_stem == chapter.resolve_notebook("lee2022_block_overlap.ipynb", root)


def test_nist_learned_rows_swap_the_window_moves_and_keep_the_rest(tmp_path, monkeypatch):
    """Each fold's network time of the window's moves replaces the calibrated estimate's; its
    dwell, sequence and approach times stay; the table holds the median over the folds."""
    from types import SimpleNamespace

    from nctwin.chapters import nist_hurco_yours as ny

    path = tmp_path / "p.ngc"  # line 1 before the window; lines 2-5 in it (the dwell too)
    path.write_text("G0 X0\nG1 X10 F600\nG1 X20\nG4 P1\nG1 X30\nM30\n")
    cal_blocks = np.array([0.5, 1.0, 1.0, 1.0, 1.0])  # the dwell block holds its 1 s
    fake = SimpleNamespace(
        motion_time_s=None, cycle_time_s=float(cal_blocks.sum()) + 2.0,  # 2 s of sequence
        estimate=SimpleNamespace(block_times_s=cal_blocks),
    )  # fmt: skip
    cals = {f"{k}.NC": SimpleNamespace(profile=lambda m: m) for k in "ABC"}
    nets = {("A.NC", "bilstm"): 5.0, ("B.NC", "bilstm"): 9.0, ("C.NC", "bilstm"): 7.0}
    nets |= {(f, "axis_nn"): 3.0 for f in cals}
    monkeypatch.setattr(ny, "MACHINES", ("M",))
    monkeypatch.setattr(ny, "_held_out", lambda name: (None, cals))
    monkeypatch.setattr(ny, "cycle_time", lambda tp, profile: fake)
    monkeypatch.setattr(ny.nist_learned, "program_times", lambda *a: (nets, ("note",)))
    table = pd.DataFrame({"machine": ["M"] * 2, "method": ["calibrated"] * 2,
                          "error_pct": [1.0, -2.0], "cycle_error_pct": [3.0, -4.0]})  # fmt: skip
    result = ny.your_program(path, table)
    assert result.reason is None and result.notes[-1] == "note"
    t = result.times.set_index("method").predicted_s
    # calibrated 6.5 s; its window moves 3 s; bilstm median over folds 7 s: 6.5 - 3 + 7
    assert t.to_dict() == pytest.approx(
        {"calibrated": 6.5, "block_overlap": 6.5, "cam": 6.5, "bilstm": 10.5, "axis_nn": 6.5}
    )
    row = result.times[result.times.method == "calibrated"].iloc[0]
    assert (row.half_width_pct, row.high_s) == pytest.approx((4.0, 6.5 * 1.04))
    assert row.nominal_pct == pytest.approx(100 * 2 / 3)
