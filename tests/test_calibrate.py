"""nctwin.calibrate: the timed lines of a program, spans between block events, the non-motion
times fitted on hand-made runs whose answer is known, and the calibration of the shipped
Hurco logs."""

from __future__ import annotations

import dataclasses
from datetime import date

import numpy as np
import pandas as pd
import pytest

from nctwin.calibrate import (
    axis_rapid_mm_s,
    calibrate,
    leave_one_program_out,
    run_overrides,
    write_profile,
)
from nctwin.cli import main
from nctwin.controls import SequenceControl
from nctwin.estimate import cam
from nctwin.machine import Machine, Profile
from nctwin.runtimes import RunTimes, machine_runs, program_lines, span_s

#: A hand-made program (file lines 1-21): a tool change before the first cut (line 5) and one
#: after it, two spindle starts (1000 and 3000 rev/min) whose lines move nothing, an optional
#: stop outside the tool change.
PROGRAM = """%
O0001(HAND)
G20
T1M6
G1X0.Y0.Z0.F60.
S1000M3
G0X0.
G1X4.
G1X0.
M5
G91G28Z0.
M01
T2M6
G90
S3000M3
G0X0.
G1Y4.F60.
M01
G1Y0.
M30
%
"""


@pytest.fixture
def hand_program(tmp_path):
    path = tmp_path / "HAND.NC"
    path.write_text(PROGRAM)
    return program_lines(path)


def test_program_lines_finds_the_timed_lines(hand_program):
    lines, _ = hand_program
    assert (lines.first_cut, lines.m30) == (5, 20)
    assert lines.tool_changes.tolist() == [[4, 4], [11, 13]]  # G28 two lines before M6
    assert lines.spindle_starts.tolist() == [[6, 7], [15, 16]]
    assert lines.spindle_rpm.tolist() == [1000.0, 3000.0]
    assert lines.optional_stops.tolist() == [18]  # the M01 at line 12 is in the tool change


def test_span_s_runs_between_events():
    t = np.array([0.0, 1.0, 3.0, 6.0])
    block = np.array([5, 7, 9, 12])
    assert span_s(t, block, 7, 9) == 5.0  # event of 7 to the first past 9
    assert span_s(t, block, 6, 7) == 2.0  # line 6 never logged: from the event of 7
    assert span_s(t, block, 8, 8) == 0.0  # a line the log never shows takes no time
    assert np.isnan(span_s(t, block, 13, 13))


def _runs(lines, cut_s: float, n: int = 3) -> list[RunTimes]:
    """Runs of the hand program: first tool change 3 s, the other 12 s, spindle starts 2 + 1
    s/krpm, optional stop 0.5 s, program start 4 s, end 1 s, each +-0.1 s around it; motion
    ``cut_s`` + those."""
    out = []
    for k in range(n):
        d = 0.1 * (k - 1)
        tc = 12.0 + d
        spindle = 2.0 + lines.spindle_rpm / 1000.0 + d
        motion = cut_s + tc + spindle.sum() + 0.5
        out.append(RunTimes(f"run{k}", lines.file, 500.0, np.nan, motion, motion + 8.0 + 3 * d,
                            4.0 + d, 1.0 + d, np.array([3.0 + d, tc]), spindle,
                            np.array([0.5 + d]), 4, 7.0 + 2 * d))  # fmt: skip
    return out


def test_calibrate_recovers_the_hand_made_times(hand_program):
    lines, tp = hand_program
    window = tp.take((tp.line >= lines.first_cut) & (tp.line < lines.m30))
    times = _runs(lines, cam(window, _machine500()).cycle_time_s)
    cal = calibrate("hand", times, {lines.file: (lines, tp)}, n_jobs=1)
    seq = cal.sequence
    assert cal.machine.rapid_feed_mm_s == 500.0
    # the tool change's G28 line moves Z from 0 to the reference at Z 0: no motion to remove
    assert seq.tool_change_s == pytest.approx(12.0)
    assert seq.first_tool_change_s == pytest.approx(3.0)  # T1 M6, before any spindle start
    # a run whose first event comes past the first M6 (the control changed the tool before it
    # logged a line) times the tool change in its opening, not in its program start
    late = [dataclasses.replace(r, program_start_s=r.opening_s, first_line=5) for r in times]
    seq2 = calibrate("hand", times + late, {lines.file: (lines, tp)}, n_jobs=1).sequence
    assert (seq2.program_start_s, seq2.first_tool_change_s) == pytest.approx((4.0, 3.0))
    assert seq.spindle_start_s == pytest.approx(2.0)
    assert seq.spindle_start_s_per_krpm == pytest.approx(1.0)
    assert seq.optional_stop_s == pytest.approx(0.5)
    assert (seq.program_start_s, seq.program_end_s) == pytest.approx((4.0, 1.0))
    assert np.abs(cal.residuals_s["tool_change"]).max() == pytest.approx(0.1)
    assert cal.fit_err_pct["cam"] == pytest.approx(0.0, abs=1e-9)  # the motion is CAM's here


def _machine500() -> Machine:
    """CAM's machine: the rapid at 500 mm/s (CAM reads no other limit)."""
    return Machine("hand", "", (500.0,) * 3, (1000.0,) * 3, (np.inf,) * 3, 500.0, 500.0)


def _run(plateau_mm_s: float, override_pct: float) -> RunTimes:
    empty = np.zeros(0)
    return RunTimes("log", "P.NC", plateau_mm_s, override_pct, 100.0, 110.0, 4.0, 1.0, empty,
                    empty, empty)  # fmt: skip


def test_the_rapid_override_of_a_run_by_hand():
    # the axis rapid from the plateaus at a logged override: 169.335 / 50 % and 254 / 75 % are
    # 338.67 mm/s, and the median ignores a rapid that never reached its plateau (15 / 65 %)
    rapids = pd.DataFrame({"plateau_mm_s": [169.335, 254.0025, 15.0],
                           "rapid_override_pct": [50.0, 75.0, 65.0]})  # fmt: skip
    rapid_mm_s, how = axis_rapid_mm_s(rapids, [])
    assert rapid_mm_s == pytest.approx(338.67) and how.startswith("3 plateaus at a logged")
    times = [_run(176.1, np.nan), _run(np.nan, 57.0), _run(212.67, np.nan), _run(np.nan, np.nan),
             _run(338.0, np.nan), _run(340.5, np.nan)]  # fmt: skip
    pct, source = run_overrides(times, rapid_mm_s)
    # 176.1 / 338.67 = 52.0 %, 212.67 / 338.67 = 62.8 %: whole per cent; at most 100 %; the
    # run that shows neither gets the median of the others'
    assert pct.tolist() == [52.0, 57.0, 63.0, 63.0, 100.0, 100.0]
    assert source.tolist() == ["plateau", "logged", "plateau", "assumed", "plateau", "plateau"]
    # no override logged anywhere: the plateaus are taken at 100 %
    assert axis_rapid_mm_s(None, [_run(500.0, np.nan), _run(np.nan, np.nan)])[0] == 500.0
    with pytest.raises(ValueError, match="no run shows a rapid plateau"):
        axis_rapid_mm_s(None, [_run(np.nan, np.nan)])
    assert run_overrides([_run(np.nan, np.nan)], 500.0)[0].tolist() == [100.0]


def test_sequence_control_is_validated():
    with pytest.raises(ValueError, match="tool_change_s = -1"):
        SequenceControl(tool_change_s=-1.0)
    assert SequenceControl(spindle_start_s=1.0, spindle_start_s_per_krpm=0.5).spindle_s(
        4000
    ) == pytest.approx(3.0)


def test_write_profile_reads_back(hand_program, tmp_path):
    lines, tp = hand_program
    window = tp.take((tp.line >= lines.first_cut) & (tp.line < lines.m30))
    times = _runs(lines, cam(window, _machine500()).cycle_time_s)
    cal = calibrate("hand", times, {lines.file: (lines, tp)}, n_jobs=1)
    out = tmp_path / "hand.toml"
    write_profile(cal, out, today=date(2026, 11, 26))
    profile = Profile.from_toml(out)
    assert profile.sequence == cal.sequence
    assert profile.default_method == cal.best
    assert "Residuals: tool change 3 spans" in out.read_text()
    # the profile read back is the one Calibration.profile builds, machine and control alike
    assert profile == cal.profile()
    for method, kind in (("planner", "planner"), ("kernel", "fir"),
                         ("block_overlap", "accdec")):  # fmt: skip
        other = cal.profile(method)
        assert other.default_method == method and other.sequence == cal.sequence
        assert getattr(other, kind) is not None
    assert cal.profile("cam").machine == cal.machine
    with pytest.raises(ValueError, match="method = 'bilstm' is out of range"):
        cal.profile("bilstm")


@pytest.mark.slow
def test_hurco02_rapid_and_determinism():
    times, programs, rapids = machine_runs("Hurco02")
    assert len(times) == 26
    op3 = [r for r in times if "OP3" in r.program]
    a = calibrate("Hurco02", op3, programs, rapids)
    b = calibrate("Hurco02", op3, programs, rapids)
    assert a.machine.rapid_feed_mm_s == pytest.approx(500.0, abs=1.0)
    # the planner's axis velocities are the rapid plateau the logs show, not fitted
    plateau = np.nanmedian([r.rapid_plateau_mm_s for r in times])
    np.testing.assert_allclose(a.planner_machine.axis_max_velocity_mm_s, plateau, rtol=0.01)
    assert (a.override_source != "assumed").sum() == 11 and set(a.overrides_pct) == {100.0}
    assert a.sequence == b.sequence
    assert a.fir == b.fir and a.planner_machine == b.planner_machine
    assert 10.0 < a.sequence.tool_change_s < 20.0


@pytest.mark.slow
def test_leave_one_program_out_table():
    times, programs, rapids = machine_runs("Hurco04")
    # three plates whose runs show a rapid plateau (their rapid override known, so fitted)
    keep = sorted({r.program for r in times if np.isfinite(r.rapid_plateau_mm_s)})[:3]
    times = [r for r in times if r.program in keep]
    table = leave_one_program_out("Hurco04", times, programs, rapids)
    assert table.shape == (12, 11)
    assert sorted(set(table["program"])) == keep
    assert table.groupby("program")["chosen"].sum().tolist() == [1, 1, 1]


def test_calibrate_refuses_a_file_that_is_no_log(tmp_path, capsys):
    bad = tmp_path / "notes.txt"
    bad.write_text("these are notes\n")
    assert main(["calibrate", str(bad), "--output", str(tmp_path / "hurco02.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "notes.txt:1: not a 'timestamp|item|value' record" in err


def test_calibrate_refuses_a_program_not_in_the_folder(tmp_path, capsys):
    log = tmp_path / "other-Hurco02.txt"
    log.write_text(
        "2017-01-01T00:00:00.000000Z|Program_Name_Running|NOPE.NC\n"
        "2017-01-01T00:00:01.000000Z|Program_Status|ACTIVE\n"
        "2017-01-01T00:00:02.000000Z|Block_Number|3\n"
        "2017-01-01T00:00:09.000000Z|Program_Status|PROGRAM_COMPLETED\n"
    )
    out = tmp_path / "Hurco02.toml"
    assert main(["calibrate", str(log), "--programs", str(tmp_path), "--output", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "no valid run of Hurco02 in 1 log(s); other-Hurco02.txt: unknown_program" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--recordings", "linuxcnc", "x.log"], "give MTConnect logs or --recordings, not both"),
        (["--recordings", "linuxcnc"], "give MTConnect logs, or --recordings NAME --machine"),
        (["{log}", "--programs", "/no/such/dir"], "--programs /no/such/dir: no such folder"),
    ],
)
def test_calibrate_refuses_a_wrong_combination(tmp_path, capsys, args, message):
    log = tmp_path / "a.txt"
    log.write_text("")
    args = [a.replace("{log}", str(log)) for a in args]
    assert main(["calibrate", *args, "--output", str(tmp_path / "p.toml")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"nctwin: {message}") and err.count("\n") == 1
