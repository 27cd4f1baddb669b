"""A reader's own program through a chapter: the shared pieces, and `make chapter`'s runner."""

from __future__ import annotations

import warnings

import nbformat
import numpy as np
import pandas as pd
import papermill
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


def test_chapter_runner_refuses_a_parameter_the_chapter_does_not_take(capsys, tmp_path):
    assert chapter.main(["lee2022_block_overlap", "-p", "sead", "3"]) == 2
    assert capsys.readouterr().err == (
        "chapter: -p sead = 3: lee2022_block_overlap takes no such parameter; its parameters "
        "are out_of_domain, program\n"
    )
    program = tmp_path / "part.ngc"
    program.write_text("G1 X1 F100\n")
    assert chapter.main(["your_own_toolpath", "--program", str(program)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("chapter: PROGRAM = ") and err.endswith("it has none\n")


def test_the_chapters_html_is_written_without_warnings(tmp_path):
    # myst-nb's glue(..., display=False) leaves a record that nbconvert cannot show
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("glue('x', 1.0, display=False)")
    cell.outputs = [nbformat.v4.new_output(
        "display_data", data={"application/papermill.record/text/plain": "1.0"},
        metadata={"scrapbook": {"name": "x"}})]  # fmt: skip
    nb.cells = [cell]
    executed = tmp_path / "chapter.ipynb"
    nbformat.write(nb, executed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        html = chapter.write_html(executed)
    assert html == tmp_path / "chapter.html" and "<html" in html.read_text()


def test_chapter_runner_reads_what_the_last_section_did_not_run(tmp_path):
    nb = nbformat.v4.new_notebook()
    last = nbformat.v4.new_code_cell("show_program(...)")
    last.outputs = [nbformat.v4.new_output("display_data", data={"text/markdown": "## Yours"}),
                    nbformat.v4.new_output("stream", name="stdout",
                                           text="not run: ae_mm = 99\nap_mm = -1\n")]  # fmt: skip
    nb.cells = [nbformat.v4.new_code_cell("print('not run: elsewhere')"), last]
    nbformat.write(nb, tmp_path / "c.ipynb")
    assert chapter.refused(tmp_path / "c.ipynb") == ["not run: ae_mm = 99", "ap_mm = -1"]
    last.outputs = last.outputs[:1]
    nbformat.write(nb, tmp_path / "c.ipynb")
    assert chapter.refused(tmp_path / "c.ipynb") == []


@pytest.mark.parametrize(("name", "value", "kind"), [
    ("n_seeds", "2.5", "a whole number"),
    ("n_seeds", "True", "a whole number"),
    ("duration_s", "long", "a number"),
])  # fmt: skip
def test_chapter_runner_refuses_a_value_of_another_kind(capsys, name, value, kind):
    notebook = repo_root() / "notebooks" / "denkena2020_force_lstm.ipynb"
    default = papermill.inspect_notebook(str(notebook))[name]["default"]
    assert chapter.main(["denkena2020_force_lstm", "-p", name, value]) == 2
    why = f"takes {kind} (default {default})"
    assert capsys.readouterr().err.endswith(f": denkena2020_force_lstm {why}\n")


def test_chapter_runner_reads_values_as_the_notebook_does():
    notebook = repo_root() / "notebooks" / "lee2022_block_overlap.ipynb"
    read = {"False": False, "None": None, "3": 3, "0.5": 0.5, "a.ngc": "a.ngc"}
    for text, value in read.items():
        assert chapter._value(text) == value and type(chapter._value(text)) is type(value)
    chapter.check_parameters(notebook, {"out_of_domain": False, "program": "part.ngc"})
    with pytest.raises(ValueError, match=r"-p out_of_domain = 'no': .* takes True or False"):
        chapter.check_parameters(notebook, {"out_of_domain": "no"})
    assert chapter._fits(chapter._literal("np.arange(3)"), "anything")  # an expression


def test_chapter_runner_finds_a_chapter_by_stem_or_path():
    root = repo_root()
    by_stem = chapter.resolve_notebook("lee2022_block_overlap", root)
    assert by_stem == chapter.resolve_notebook("notebooks/lee2022_block_overlap.ipynb", root)
    assert by_stem == chapter.resolve_notebook("lee2022_block_overlap.ipynb", root)


#: A spindle run of three cuts and a dwell, then a retract after the M5 (in the networks'
#: window, first cut to M30, but not in the motion time): blocks 0 (the approach) to 5.
NIST_PROGRAM = "G0 X0 Y5\nM3 S1000\nG1 Y0 F600\nG1 X10\nG4 P1\nG1 X20\nM5\nG0 Z10\nM30\n"


def test_nist_learned_times_replace_the_window_blocks_and_keep_the_rest(tmp_path, monkeypatch):
    """Each fold's network time of the window's blocks replaces the calibrated fold's; its
    dwell, the approach and the sequence stay; the table holds the median over the folds of
    each time, the figure the fold of the median cycle time."""
    from types import SimpleNamespace

    from nctwin.chapters import nist_hurco_yours as ny
    from nctwin.controls import SequenceControl
    from nctwin.estimate import CycleTime
    from nctwin.estimate.result import Estimate

    path = tmp_path / "p.ngc"
    path.write_text(NIST_PROGRAM)
    cal_blocks = np.array([0.5, 1.0, 1.0, 1.0, 1.0, 0.5])  # the dwell block holds its 1 s
    seq = SequenceControl(spindle_start_s=2.0, program_start_s=0.25)
    cals = {f"{k}.NC": SimpleNamespace(profile=lambda m: m, sequence=seq) for k in "ABC"}
    nets = {("A.NC", "bilstm"): np.array([0.0, 2, 3, 0, 2, 1]),
            ("B.NC", "bilstm"): np.array([0.0, 1, 1, 0, 1, 3]),
            ("C.NC", "bilstm"): np.array([0.0, 1, 2, 0, 1, 1])}  # fmt: skip
    nets |= {(f, "axis_nn"): np.array([0.0, 1, 1, 0, 1, 0.5]) for f in cals}
    monkeypatch.setattr(ny, "MACHINES", ("M",))
    monkeypatch.setattr(ny, "_held_out", lambda name: (None, cals))
    monkeypatch.setattr(ny, "cycle_time", lambda tp, profile: CycleTime.of(
        Estimate("planner", "M", cal_blocks, tp), seq))  # fmt: skip
    monkeypatch.setattr(ny.nist_learned, "program_times", lambda *a: (nets, ("note",)))
    table = pd.DataFrame({"machine": ["M"] * 2, "method": ["calibrated"] * 2,
                          "error_pct": [1.0, -2.0], "cycle_error_pct": [3.0, -4.0]})  # fmt: skip
    result = ny.your_program(path, table)
    assert result.reason is None and result.notes[-1] == "note"
    t = result.times.set_index(["time", "method"]).predicted_s
    # by hand: the calibrated cycle 5 s of blocks + 2 s spindle start + 0.25 s; its motion the
    # blocks 1-4 (the spindle run). bilstm folds: blocks 0.5 | net | 1 s dwell | net, cycles
    # 11.75, 9.75, 8.75 s (median B's), motions 8, 4, 5 s (median C's)
    assert t.to_dict() == pytest.approx({
        ("cycle", "calibrated"): 7.25, ("cycle", "block_overlap"): 7.25, ("cycle", "cam"): 7.25,
        ("cycle", "bilstm"): 9.75, ("cycle", "axis_nn"): 7.25,
        ("motion", "calibrated"): 4.0, ("motion", "block_overlap"): 4.0, ("motion", "cam"): 4.0,
        ("motion", "bilstm"): 5.0, ("motion", "axis_nn"): 4.0})  # fmt: skip
    row = result.times[(result.times.method == "calibrated") & (result.times.time == "cycle")]
    assert (row.half_width_pct.iloc[0], row.high_s.iloc[0]) == pytest.approx((4.0, 7.25 * 1.04))
    assert row.nominal_pct.iloc[0] == pytest.approx(100 * 2 / 3)
    # the figure: the moving blocks 0, 1, 2, 4, 5 (5, 5, 10, 10, 10 mm) over the median fold's
    feeds = result.feeds.set_index("line")
    assert list(feeds.columns) == ["M_mm_s", "M bilstm_mm_s", "M axis_nn_mm_s"]
    assert feeds["M bilstm_mm_s"].tolist() == pytest.approx([10, 5, 10, 10, 10 / 3])
    assert feeds["M_mm_s"].tolist() == pytest.approx([10, 5, 10, 10, 20])


def test_nist_program_times_sum_an_arcs_chords_per_block(monkeypatch):
    """Every fold's networks over the window's moves: the mean over the seeds, the chords of an
    arc summed into its block, nothing outside the window or for a dwell."""
    from types import SimpleNamespace

    from nctwin.chapters import nist_learned as nl
    from nctwin.runtimes import motion_window, timed_lines

    text = "G0 X0 Y0\nM3 S1000\nG1 X10 F600\nG2 X20 Y0 I5 J0\nG4 P1\nG1 X30\nM30\n"
    tp = gcode.parse(text, source="p.ngc")
    window = motion_window(tp, timed_lines(tp, text, "p.ngc"))
    train = SimpleNamespace(features=np.zeros((1, 7)))
    folds = [SimpleNamespace(program=p, rapid_mm_s=500.0, pieces=(train,)) for p in "AB"]
    seeds = (0, 1, 2)
    models = {(p, m, s): ([float(s) + (p == "B")], None)
              for p in "AB" for m in nl.METHODS for s in seeds}  # fmt: skip
    monkeypatch.setattr(nl, "train_folds", lambda name, seeds: (folds, models))
    # a move's time: its length over 10 mm/s times (1 + the net's number)
    monkeypatch.setattr(
        nl, "_move_times", lambda method, nets, data: data.features[:, 1] / 10 * (1 + nets[0])
    )
    times, notes = nl.program_times("M", tp, window, seeds)
    assert sorted(times) == [(p, m) for p in "AB" for m in sorted(nl.METHODS)]
    assert window.tolist() == [False, True, True, True, True]
    # the approach (outside the window) and the dwell (no length) 0; the half circle of 5 mm
    # radius in 32 chords of pi / 32 rad (at most 0.1 rad each), their summed length
    expect = np.array([0.0, 10, 32 * 2 * 5 * np.sin(np.pi / 64), 0, 10]) / 10
    for (p, _), t in times.items():
        # mean over seeds of (1 + s (+1 for B)): 2 for A, 3 for B
        assert t.shape == (len(tp),)
        np.testing.assert_allclose(t, expect * (2 if p == "A" else 3))
    assert notes  # every feature lies outside the all-zero training moves


def test_nist_program_without_moves_for_the_networks_says_so(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from nctwin.chapters import nist_hurco_yours as ny
    from nctwin.controls import SequenceControl
    from nctwin.estimate import CycleTime
    from nctwin.estimate.result import Estimate

    path = tmp_path / "dwell.ngc"
    path.write_text("G4 P1\nM30\n")
    cals = {"A.NC": SimpleNamespace(profile=lambda m: m, sequence=SequenceControl())}
    monkeypatch.setattr(ny, "MACHINES", ("M",))
    monkeypatch.setattr(ny, "_held_out", lambda name: (None, cals))
    monkeypatch.setattr(ny, "cycle_time", lambda tp, profile: CycleTime.of(
        Estimate("planner", "M", np.array([1.0]), tp)))  # fmt: skip
    monkeypatch.setattr(ny.nist_learned, "program_times", lambda *a: ({}, ()))
    table = pd.DataFrame({"machine": ["M"], "method": ["calibrated"], "error_pct": [1.0],
                          "cycle_error_pct": [1.0]})  # fmt: skip
    result = ny.your_program(path, table)
    assert set(result.times.method) == {"calibrated", "block_overlap", "cam"}
    assert result.notes[-1] == ("M: the learned methods not run: no move from the first cut to "
                                "the M30 for the networks to time.")  # fmt: skip
    assert list(result.feeds.columns) == ["line", "M_mm_s"]
