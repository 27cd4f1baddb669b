"""nctwin.chapters.nist_learned: the per-move targets a log resolves, derived by hand on a
hand-made run, Sun's nearest record, the tool-change pieces, the folds' separation, and (slow)
the training's determinism."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from nctwin.calibrate import base_machine
from nctwin.chapters import nist_learned as nl
from nctwin.chapters import nist_targets as nt
from nctwin.learn.train import fit
from nctwin.mtconnect import Run, Track
from nctwin.runtimes import program_lines

#: File lines 1-17: tool changes at lines 4 and 10-12 (G28, M01, M6), spindle starts at 5-6
#: and 13-14; the window is lines 7-15 (first cut to before M30). At F600 (10 mm/s) the moves
#: are X+ 10, 20, 30 mm (lines 7-9), then 10 and 20 mm (lines 14, 15).
PROGRAM = """%
O0001(HAND)
G21 G90 G17
T1 M6
S1000 M3
G0 X0 Y0 Z0
G1 X10 F600
G1 X30
G1 X60
G91 G28 Z0
M01
T2 M6
S2000 M3
G90 G1 X70 F600
G1 X90
M30
%
"""

#: Block events: line 8 never shows, line 14 lags; M30 (line 16) at 125 s.
EVENTS = ((7, 100.0), (9, 106.0), (10, 109.0), (14, 120.0), (15, 121.0), (16, 125.0))
#: Feed_Rate records (time s, mm/s).
FEEDS = ((101.0, 4.0), (104.5, 6.0), (107.5, 9.5), (115.0, 0.0), (122.0, 5.0))


def _track(pairs=(), initial=np.nan) -> Track:
    t = np.array([p[0] for p in pairs], float)
    return Track(initial, t, np.array([p[1] for p in pairs], float))


def _run(events=EVENTS, feeds=FEEDS) -> Run:
    block = np.array([e[0] for e in events], np.int64)
    block_t = np.array([e[1] for e in events], float)
    empty = _track()
    return Run(
        "hand.txt", "HAND.NC", None, 90.0, 126.0, True, "PROGRAM_COMPLETED",
        np.array([90.0, 126.0]), np.array(["ACTIVE", "PROGRAM_COMPLETED"]),
        block_t, block, _track(feeds), empty, _track(initial=100.0), empty, empty, empty,
    )  # fmt: skip


@pytest.fixture
def hand(tmp_path):
    path = tmp_path / "HAND.NC"
    path.write_text(PROGRAM)
    return program_lines(path)


def test_non_motion_lines(hand):
    lines, tp = hand
    # tool changes 4 and 10-12, spindle starts 5-6 and 13-14, the M-codes that wait
    assert nt.non_motion_lines(lines, tp).tolist() == [4, 5, 6, 10, 11, 12, 13, 14]


def test_block_spans_from_the_first_cut_to_m30():
    run = _run(events=((6, 90.0), *EVENTS, (17, 130.0)))
    s = nt.block_spans(run.block_t_s, run.block, first_cut=7, m30=16)
    assert s.first_line.tolist() == [7, 9, 10, 14, 15]
    assert s.end_line.tolist() == [9, 10, 14, 15, 16]
    assert s.time_s.tolist() == [6.0, 3.0, 11.0, 1.0, 4.0]


def test_targets_by_hand(hand):
    lines, tp = hand
    data = nl.run_move_data(_run(), lines, tp, base_machine("hand", 500.0))
    assert data.moves.line.tolist() == [7, 8, 9, 14, 15]  # G28 Z0 moves nothing here
    assert data.features[:, 0].tolist() == [10.0] * 5
    # lines 7-8 (line 8 never shows): 30 mm in 6 s; line 9: 30 mm in 3 s; line 14 lies in the
    # span of the tool change (10-14) and its own spindle start (14-15): NaN; line 15: 20 mm in
    # 4 s
    avg = [5.0, 5.0, 10.0, np.nan, 5.0]
    np.testing.assert_allclose(data.targets[:, 0], avg)
    np.testing.assert_allclose(data.targets[:, 1], np.log(10.0 / np.array(avg)))
    assert data.measured_s == 25.0
    # Sun: the move's interval is its span's time laid over its length (line 7: 100-102 s,
    # line 8: 102-106 s, line 9: 106-109 s, line 15: 121-125 s); the nearest record within
    # the span: 101 s, 104.5 s (not 101 s), 107.5 s, 122 s; +X moves
    x = [4.0, 6.0, 9.5, np.nan, 5.0]
    np.testing.assert_allclose(data.axis_targets, np.array(x)[:, None] * [1.0, 0.0, 0.0])


def test_span_times_and_non_positive_spans():
    spans = nt.Spans(np.array([1, 3, 4]), np.array([3, 4, 6]), np.array([0.0, 2.0, 2.0]),
                     np.array([2.0, 2.0, 5.0]))  # fmt: skip
    y, span, t = nt.span_targets(
        np.array([1, 2, 2, 3, 5, 6]), np.array([1.0, 2.0, 1.0, 4.0, 3.0, 1.0]),
        np.full(6, 3.0), spans, np.array([], np.int64),
    )  # fmt: skip
    # span 0 holds lines 1-2 (4 mm in 2 s), span 1 (line 3) has no time, line 6 is in none
    assert span.tolist() == [0, 0, 0, -1, 2, -1]
    np.testing.assert_allclose(y[:, 0], [2.0, 2.0, 2.0, np.nan, 1.0, np.nan])
    np.testing.assert_allclose(t[:3], [[0.0, 0.5], [0.5, 1.5], [1.5, 2.0]])
    np.testing.assert_allclose(t[4], [2.0, 5.0])


def test_axis_targets_take_the_nearest_record_within_the_span():
    spans = nt.Spans(np.array([1, 2]), np.array([2, 3]), np.array([0.0, 1.0]),
                     np.array([1.0, 3.0]))  # fmt: skip
    feed = _track(((0.2, 7.0), (0.7, 8.0), (3.5, 9.0)))
    directions = np.array([[0.6, 0.8, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    move_t = np.array([[0.0, 0.3], [0.3, 1.0], [1.0, 3.0]])
    ax = nt.axis_targets(directions, np.array([0, 0, 1]), move_t, spans, feed)
    np.testing.assert_allclose(ax[0], [4.2, 5.6, 0.0])  # 0.2 s, in its interval
    np.testing.assert_allclose(ax[1], [0.0, 0.0, -8.0])  # 0.7 s nearest its middle, 0.65 s
    assert np.isnan(ax[2]).all()  # no record within 1-3 s (3.5 s is past the span)


def test_tool_sections_cut_at_the_tool_changes(hand, monkeypatch):
    lines, tp = hand
    data = nl.run_move_data(_run(), lines, tp, base_machine("hand", 500.0), name="HAND")
    monkeypatch.setattr(nl, "MIN_PIECE_MOVES", 1)
    pieces = nl.tool_sections(data, lines)
    assert [p.name for p in pieces] == ["HAND#0", "HAND#1"]
    assert [p.moves.line.tolist() for p in pieces] == [[7, 8, 9], [14, 15]]
    np.testing.assert_array_equal(np.concatenate([p.targets for p in pieces]), data.targets)
    assert pieces[1].axis_features.shape == (2, 3, 9)
    monkeypatch.setattr(nl, "MIN_PIECE_MOVES", 4)  # the first piece joins the next
    assert [p.moves.line.tolist() for p in nl.tool_sections(data, lines)] == [[7, 8, 9, 14, 15]]


def test_sample_windows_keeps_whole_windows_evenly():
    xs = [np.arange(10.0)[:, None], np.arange(3.0)[:, None], np.array([[7.0]])]
    ys = [np.r_[np.full(4, np.nan), np.ones(6)][:, None], np.ones((3, 1)), np.ones((1, 1))]
    wx, wy = nl.sample_windows(xs, ys, 2, 100)
    # windows from 0 and 2 (NaN targets only: dropped), 4, 6, 8; from 0 (the tail dropped);
    # the piece shorter than a window whole
    assert [w[:, 0].tolist() for w in wx] == [[4.0, 5.0], [6.0, 7.0], [8.0, 9.0], [0.0, 1.0],
                                              [7.0]]  # fmt: skip
    assert [len(y) for y in wy] == [2, 2, 2, 2, 1]
    wx, _ = nl.sample_windows(xs, ys, 2, 6)
    assert [w[0, 0] for w in wx] == [4.0, 8.0, 7.0]  # 3 of 5, evenly: the 1st, 3rd and 5th


def test_a_held_out_program_never_trains_nor_validates():
    plate = "NIST_MTC_CRADA_PLATE-14.NC"
    fold = nl.fold_data("Hurco04", plate)
    assert plate not in fold.train_programs
    assert fold.train_programs  # the others, runs of an assumed override left out
    assert not any(p.name.startswith(plate) for p in fold.pieces)
    assert {h.log for h in fold.held_out} == {"Plate-Op1-Hurco04-14of20.txt.gz"}
    bilstm, axis = nl.configs(0)
    for net, cfg in (("bilstm", bilstm), ("z", axis)):
        sets = nl.training_sets(fold, net, cfg)
        train, val = set(sets["train_pieces"]), set(sets["val_pieces"])
        assert val and train and not train & val
        assert train | val == {p.name for p in fold.pieces}
        assert not any(plate in name for name in train | val)
        assert 0 < sum(len(x) for x in sets["xs"]) <= nl.MAX_TRAIN_ROWS
        assert 0 < sum(len(x) for x in sets["validation"][0]) <= nl.MAX_VAL_ROWS


@pytest.mark.slow
def test_training_repeats_bit_for_bit(tmp_path, monkeypatch):
    monkeypatch.setenv("NCTWIN_CACHE", str(tmp_path))
    op1, op3 = "NIST_MTC_CRADA_BOX_REV-A OP1 (Bottom).NC", "NIST_MTC_CRADA_BOX_REV-A OP3 (Back).NC"
    folds, models = nl.train_folds("Hurco02", (0,), [op1], n_jobs=1)
    assert folds[0].train_programs == (op3,)
    (model,), _ = models[(op1, "bilstm", 0)]
    assert model.converged
    bilstm, _ = nl.configs(0)
    sets = nl.training_sets(folds[0], "bilstm", bilstm)
    again = fit(nl.BILSTM_CONFIG, bilstm, sets["xs"], sets["ys"], validation=sets["validation"],
                cache=False, progress=False)  # fmt: skip
    data = folds[0].held_out[0].data
    np.testing.assert_array_equal(again.predict(data.features), model.predict(data.features))
    assert dataclasses.asdict(again.train_config) == dataclasses.asdict(model.train_config)
    feeds = nl.move_feeds("Hurco02", op1, (0,), n_jobs=1)
    assert len(feeds) == len(data.features)
    assert feeds.attrs["log"] in {h.log for h in folds[0].held_out}
    np.testing.assert_allclose(
        feeds["bilstm_feed_mm_s"], data.features[:, 1] / nl.bilstm_move_times(model, data)
    )
    (shown,) = [h.data for h in folds[0].held_out if h.log == feeds.attrs["log"]]
    np.testing.assert_array_equal(feeds["logged_feed_mm_s"], shown.targets[:, 0])
