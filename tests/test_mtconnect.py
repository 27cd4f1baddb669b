"""nctwin.mtconnect: reading MTConnect logs, splitting them into runs, judging the runs.

Hand-written logs of a 15-line program, built so that the answer is known, cover the reader
(plain and gzip alike, a value broken over two lines, foreign files refused in one line), the
run splitting (a log that begins inside a run, a feed hold resumed, a stop and a new start) and
every reason code; the shipped NIST logs are checked for facts established by looking at them.
"""

from __future__ import annotations

import gzip
import time
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest

from nctwin import mtconnect as mtc
from nctwin.paths import nist_dir

#: A small program: T1 change on line 6, a single-axis rapid on 8, the first cut (F60 in/min =
#: 25.4 mm/s) on 9, cuts on 10-11, M30 on 14; logged as TEST_PART.NC.
PROGRAM = """%
O0001(TEST PART)
(T1| 1/4 FLAT ENDMILL|H0)
N100G20
N110G0G17G40G49G80G90
N120T1M6
N130G0G90G54X0.Y0.S1000M3
N140Z.1
N150G1Z0.F60.
N160X10.
N170Y10.
N180G0Z1.
N190M5
N200M30
%
"""
FEED_MM_S = 60 * 25.4 / 60
PROGRAMS = {"TEST PART (Top).NC": PROGRAM}
T0 = datetime(2017, 2, 7, 10, 0, 0, tzinfo=UTC)


def _stamp(t_s: float) -> str:
    return (T0 + timedelta(seconds=t_s)).strftime("%Y-%m-%dT%H:%M:%S.%f") + "0Z"


def _run_events(
    t0: float = 0.0,
    *,
    name: str | None = "TEST_PART.NC",
    end: str = "PROGRAM_COMPLETED",
    blocks: tuple[int, ...] = (6, 7, 8, 9, 10, 11, 12, 14),
    feed_scale: float = 1.0,
    feed_override: float | None = 100.0,
    rapid_override: float | None = 50.0,
    samples: int = 6,
) -> list[tuple[float, str, str]]:
    """One run of PROGRAM, started at ``t0``: a block every 2 s, steady feed samples in the
    cutting blocks 10 and 11, the run-time counter at one count a second."""
    ev = [(t0, "Program_Status", "ACTIVE"), (t0 + 0.02, "Program_Runtime_Seconds", "300")]
    ev.append((t0 + 0.03, "Program_Runtime_Seconds", "0"))
    if name:
        ev.append((t0 + 0.1, "Program_Name_Running", name))
    if feed_override is not None:
        ev.append((t0 + 0.2, "Feed_Override", f"{feed_override:f}"))
    if rapid_override is not None:
        ev.append((t0 + 0.2, "Rapid_Override", f"{rapid_override:f}"))
    ev.append((t0 + 0.5, "Spindle_Speed", "1000.000000"))
    for k, line in enumerate(blocks):
        tb = t0 + 1 + 2 * k
        ev.append((tb, "Block_Number", str(line)))
        if line in (10, 11):
            for j in range(samples):
                ev.append((tb + 0.1 + 0.2 * j, "Feed_Rate", repr(FEED_MM_S * feed_scale)))
    t_end = t0 + 1 + 2 * len(blocks)
    ev += [(t0 + s, "Program_Runtime_Seconds", str(s)) for s in range(1, int(t_end - t0))]
    ev.append((t_end, "Program_Status", end))
    return ev


def _write(tmp_path, events, name="Box-OP9-Hurco02-01of01.txt", *, gz=False):
    """Write ``events`` (time, item, value) in time order as a log; returns its path."""
    text = "".join(f"{_stamp(t)}|{item}|{value}\n" for t, item, value in sorted(events))
    path = tmp_path / (name + (".gz" if gz else ""))
    path.write_bytes(gzip.compress(text.encode()) if gz else text.encode())
    return path


def _verdict(tmp_path, events) -> mtc.Verdict:
    (run,) = mtc.runs(mtc.read_log(_write(tmp_path, events)))
    return mtc.validate(run, PROGRAMS)


# --- reading --------------------------------------------------------------------------------


def test_plain_and_gzip_read_the_same(tmp_path):
    events = _run_events()
    plain = mtc.read_log(_write(tmp_path, events))
    packed = mtc.read_log(_write(tmp_path, events, gz=True))
    assert plain.equals(packed)
    assert list(plain.columns) == ["t_s", "item", "value", "line"]
    assert plain["t_s"].iloc[0] == T0.timestamp()
    assert plain.attrs["source"] == "Box-OP9-Hurco02-01of01.txt"


def test_a_number_broken_over_two_lines_is_joined(tmp_path):
    path = tmp_path / "log.txt"
    path.write_text(f"{_stamp(0)}|Block_Number|\n2017\n{_stamp(1)}|Spindle_Speed|1\n2017.5\n")
    log = mtc.read_log(path)
    assert list(log["value"]) == ["2017", "12017.5"]
    assert list(log["line"]) == [1, 3]


@pytest.mark.parametrize(
    ("content", "line", "why"),
    [
        (b"", 1, "empty"),
        (b"a,b,c\n1,2,3\n", 1, "not a 'timestamp|item|value' record"),
        (b"2017-02-07T10:00:00.0Z|Block_Number|1\nno pipes here\n", 2, "not a 'timestamp"),
        (b"2017-02-07T10:00:00.0Z|Block_Number|1\n2017-02-07T10:00:01.0Z|Feed_Rate\n", 2, "not"),
        (b"2017-02-07T10:00:00.0Z|Block_Number|1\nnoon|Feed_Rate|3\n", 2, "not an ISO-8601"),
        (b"2017-02-07T10:00:01.0Z|A|1\n2017-02-07T10:00:00.0Z|A|2\n", 2, "goes back in time"),
        (b"2017-02-07T10:00:00.0Z||1\n", 1, "an empty item"),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", 3, "binary data"),
        (b"2017-02-07T10:00:00.0Z|A|\xff\xfe\n", 1, "not UTF-8"),
        (b"\x1f\x8b\x08\x00garbage", 1, "broken gzip"),
    ],
)
def test_a_foreign_file_is_refused_in_one_line_with_file_and_line(tmp_path, content, line, why):
    path = tmp_path / "foreign.txt"
    path.write_bytes(content)
    with pytest.raises(ValueError) as err:
        mtc.read_log(path)
    message = str(err.value)
    assert message.startswith(f"{path}:{line}: ") and why in message
    assert "\n" not in message
    # raised by the reader itself, not from deep inside pandas or gzip, and nothing chained
    assert err.traceback[-1].path.name == "mtconnect.py"
    assert err.value.__cause__ is None
    assert err.value.__context__ is None or err.value.__suppress_context__


def test_a_numeric_item_that_is_no_number_is_refused_with_its_line(tmp_path):
    events = [*_run_events(), (3.05, "Feed_Rate", "UNAVAILABLE")]
    path = _write(tmp_path, events)
    line = next(i for i, t in enumerate(path.read_text().splitlines(), 1) if "UNAVAIL" in t)
    with pytest.raises(ValueError, match=rf"^{path.name}:{line}: Feed_Rate is not a number$"):
        mtc.runs(mtc.read_log(path))


# --- the program ----------------------------------------------------------------------------


def test_the_program_is_read_for_the_checks():
    p = mtc.parse_program("TEST PART (Top).NC", PROGRAM)
    assert p.name == "TEST_PART.NC"  # the O line's comment, as the control logs it
    assert (p.n_lines, p.m30, p.first_cut) == (15, 14, 9)
    assert np.flatnonzero(p.is_block).tolist() == [2, *range(4, 15)]  # O0001 is a block
    assert np.flatnonzero(p.cuts).tolist() == [9, 10, 11]
    np.testing.assert_allclose(p.feed_mm_s[[9, 10, 11]], FEED_MM_S)
    assert np.isnan(p.feed_mm_s[[7, 8, 12]]).all()
    assert np.flatnonzero(p.single_axis_rapid).tolist() == [8, 12]
    assert p.spindle_rpm.tolist() == [1000.0]


# --- runs -----------------------------------------------------------------------------------


def test_a_log_is_split_into_its_runs(tmp_path):
    # the tail of a run begun before the log, then a run with a feed hold resumed, stopped;
    # then a new start that completes, then a start the log ends inside
    tail = [(0.0, "Program_Runtime_Seconds", "500"), (0.5, "Block_Number", "12")]
    tail += [(1.0, "Block_Number", "14"), (2.0, "Program_Status", "PROGRAM_COMPLETED")]
    first = _run_events(10.0, end="PROGRAM_STOPPED", blocks=(6, 7, 8))
    first += [(12.5, "Program_Status", "FEED_HOLD"), (13.5, "Program_Status", "ACTIVE")]
    second = _run_events(40.0, name=None)
    last = [(80.0, "Program_Status", "ACTIVE"), (81.0, "Block_Number", "6")]
    runs = mtc.runs(mtc.read_log(_write(tmp_path, tail + first + second + last)))
    assert [r.start_logged for r in runs] == [False, True, True, True]
    assert [r.end_status for r in runs] == [
        "PROGRAM_COMPLETED",
        "PROGRAM_STOPPED",
        "PROGRAM_COMPLETED",
        "",
    ]
    starts = [r.start_s - T0.timestamp() for r in runs]
    ends = [r.end_s - T0.timestamp() for r in runs]
    np.testing.assert_allclose(starts, [0.0, 10.0, 40.0, 80.0])
    np.testing.assert_allclose(ends, [2.0, 17.0, 57.0, 81.0])
    assert runs[0].block.tolist() == [12, 14]
    assert runs[1].status.tolist() == ["ACTIVE", "FEED_HOLD", "ACTIVE", "PROGRAM_STOPPED"]
    # the name logged in the first run is in force in the second (logged on change only)
    assert [r.program for r in runs] == [None, "TEST_PART.NC", "TEST_PART.NC", "TEST_PART.NC"]
    # a track starts from the value in force when the run started
    assert runs[2].rapid_override_pct.initial == 50.0
    assert np.isnan(runs[1].rapid_override_pct.initial)
    np.testing.assert_allclose(runs[2].feed_mm_s.value, FEED_MM_S)
    assert runs[2].block.dtype == np.int64 and runs[2].block_t_s.shape == runs[2].block.shape


# --- verdicts -------------------------------------------------------------------------------


def test_a_clean_run_is_valid_and_its_motion_time_runs_from_the_first_cut_to_m30(tmp_path):
    v = _verdict(tmp_path, _run_events())
    assert v.valid and v.reason == "" and v.reasons == ()
    assert (v.program, v.matched_by) == ("TEST PART (Top).NC", "name")
    assert (v.feed_override_pct, v.rapid_override_pct) == (100.0, 50.0)
    assert v.feed_scale == 1.0 and v.feed_samples == 10  # 5 steady samples in each of 2 blocks
    # blocks every 2 s: line 9 (the first cut) at 1 + 2*3 s, line 14 (M30) at 1 + 2*7 s
    assert v.motion_s == pytest.approx(8.0)


def test_not_completed(tmp_path):
    v = _verdict(tmp_path, _run_events(end="PROGRAM_STOPPED"))
    assert v.reasons == ("not_completed",) and not v.valid and np.isnan(v.motion_s)


def test_unknown_program_by_name_and_by_content(tmp_path):
    assert _verdict(tmp_path, _run_events(name="OTHER.NC")).reasons == ("unknown_program",)
    # no name logged, and the run visits line 20: no program fits
    v = _verdict(tmp_path, _run_events(name=None, blocks=(6, 7, 8, 9, 10, 20)))
    assert v.reason == "unknown_program" and "fits no program" in v.detail


def test_no_name_logged_matches_by_content_and_two_identical_texts_stay_unknown(tmp_path):
    slow = PROGRAM.replace("TEST PART", "SLOW PART").replace("F60.", "F30.")
    programs = {**PROGRAMS, "SLOW PART.NC": slow}
    (run,) = mtc.runs(mtc.read_log(_write(tmp_path, _run_events(name=None))))
    v = mtc.validate(run, programs)  # both fit its lines; its feed is TEST PART's at 100 %
    assert v.valid and (v.program, v.matched_by) == ("TEST PART (Top).NC", "content")
    twin = {**PROGRAMS, "TWIN.NC": PROGRAM.replace("TEST PART", "TWIN")}
    assert mtc.validate(run, twin).reason == "unknown_program"


@pytest.mark.parametrize(
    ("blocks", "detail"),
    [
        ((6, 7, 8, 9, 10, 11, 12, 13), "ends at line 13, not at"),  # completed off its M30
        ((6, 7, 8, 9, 10, 11, 16, 14), "visits line 16"),  # past the file's 15 lines
        ((6, 7, 8, 9, 10, 11, 3, 14), "visits line 3, no block"),  # a comment line
    ],
)
def test_other_version_by_lines(tmp_path, blocks, detail):
    v = _verdict(tmp_path, _run_events(blocks=blocks))
    assert v.reason == "other_version" and detail in v.detail


def test_other_version_by_spindle_speed_and_by_feeds(tmp_path):
    events = [e for e in _run_events() if e[1] != "Spindle_Speed"]
    v = _verdict(tmp_path, [*events, (0.5, "Spindle_Speed", "1500.000000")])
    assert v.reason == "other_version" and "1500 rev/min" in v.detail
    # the last three of 8 samples in block 11 (from 11 s) at twice the programmed feed: 2 of
    # 13 steady samples faster than the program's (at most 2 % may be), a text it does not fit
    faster = [(t, i, repr(2 * FEED_MM_S)) if t > 12.0 and i == "Feed_Rate" else (t, i, v)
              for t, i, v in _run_events(samples=8)]  # fmt: skip
    v = _verdict(tmp_path, faster)
    assert v.reason == "other_version" and "faster than programmed" in v.detail


@pytest.mark.parametrize(
    ("blocks", "detail"),
    [
        ((6, 7, 8, 9, 10, 9, 11, 14), "line 10 is followed by line 9"),
        ((10, 11, 12, 14), "starts at line 10, past the first cut 9"),
    ],
)
def test_restart(tmp_path, blocks, detail):
    v = _verdict(tmp_path, _run_events(blocks=blocks))
    assert v.reason == "restart" and v.detail == detail


def test_feed_hold(tmp_path):
    events = [*_run_events(), (8.2, "Program_Status", "FEED_HOLD")]
    events.append((8.6, "Program_Status", "ACTIVE"))
    assert _verdict(tmp_path, events).reasons == ("feed_hold",)


def test_pause_is_the_run_time_counter_stopping_while_active(tmp_path):
    def stalled(lag_s: float):
        """The counter stops at 5 s for ``lag_s`` while the clock and the blocks go on."""
        events = [e for e in _run_events(rapid_override=None) if e[1] != "Program_Runtime_Seconds"]
        events += [(0.03, "Program_Runtime_Seconds", "0")]
        events += [(s if s <= 5 else s + lag_s, "Program_Runtime_Seconds", str(s))
                   for s in range(1, 17 - int(lag_s))]  # fmt: skip
        return _verdict(tmp_path, events)

    assert stalled(mtc.PAUSE_S + 1).reasons == ("pause",)
    assert stalled(mtc.PAUSE_S - 1).valid


def test_a_minute_glitch_of_the_counter_neither_makes_nor_hides_a_pause(tmp_path):
    def counter(stop_s: float):
        """The counter reads 51-59 s at 1-9 s, stops ``stop_s``, then turns the minute with the
        control's glitch (a sample of 0 s, then 60 s) and goes on."""
        events = [e for e in _run_events() if e[1] != "Program_Runtime_Seconds"]
        ticks = [(s, 50 + s) for s in range(1, 10)] + [(9.98 + stop_s, 0)]
        ticks += [(10 + stop_s + s, 60 + s) for s in range(2)]
        return _verdict(
            tmp_path, events + [(t, "Program_Runtime_Seconds", str(v)) for t, v in ticks]
        )

    assert counter(0.0).valid
    v = counter(6.0)
    assert v.reasons == ("pause",) and v.detail == "the run-time counter stops for 6 s while ACTIVE"


def test_feed_override_logged_measured_or_unknown(tmp_path):
    v = _verdict(tmp_path, [*_run_events(), (8.0, "Feed_Override", "90.000000")])
    assert v.reasons == ("feed_override",) and v.detail == "Feed_Override 90 % while feeding"
    # logged at 100 %, but the feed runs 2 % over the programmed: an override not logged
    v = _verdict(tmp_path, _run_events(feed_scale=1.02, feed_override=None))
    assert v.reasons == ("feed_override",) and "102.0%" in v.detail
    assert v.feed_scale == pytest.approx(1.02)
    # neither logged nor measurable
    v = _verdict(tmp_path, _run_events(feed_override=None, samples=1))
    assert v.reasons == ("feed_override",) and "no Feed_Override logged" in v.detail
    # an override other than 100 % before the first cut only does not count, 99 % while it does
    early = [*_run_events(feed_override=None), (0.1, "Feed_Override", "60")]
    early.append((4.0, "Feed_Override", "100"))
    assert _verdict(tmp_path, early).valid
    v = _verdict(tmp_path, _run_events(feed_override=99.0, feed_scale=0.99))
    assert v.reasons == ("feed_override",) and v.feed_scale == pytest.approx(1.0)


def test_rapid_override_changed_after_the_first_approach_only(tmp_path):
    # ridden during the first approach (lines 6-8): valid, its value when the approach ended
    ridden = [*_run_events(), (2.0, "Rapid_Override", "0.000000"), (6.5, "Rapid_Override", "75")]
    v = _verdict(tmp_path, ridden)
    assert v.valid and v.rapid_override_pct == 75.0
    v = _verdict(tmp_path, [*_run_events(), (9.0, "Rapid_Override", "51.000000")])
    assert v.reasons == ("rapid_override_changed",) and v.rapid_override_pct == 50.0
    # never logged: unchanged, its value unknown, the run valid
    v = _verdict(tmp_path, _run_events(rapid_override=None))
    assert v.valid and np.isnan(v.rapid_override_pct)


def test_every_reason_holding_is_listed_in_order(tmp_path):
    events = _run_events(end="PROGRAM_STOPPED", feed_override=90.0)
    events += [(8.2, "Program_Status", "FEED_HOLD"), (8.6, "Program_Status", "ACTIVE")]
    v = _verdict(tmp_path, events)
    assert v.reasons == ("not_completed", "feed_hold", "feed_override")
    assert v.reason == "not_completed" and set(v.reasons) <= set(mtc.REASONS)


def test_two_files_logged_under_one_name_are_refused(tmp_path):
    (run,) = mtc.runs(mtc.read_log(_write(tmp_path, _run_events())))
    with pytest.raises(ValueError, match=r"both logged as TEST_PART\.NC"):
        mtc.validate(run, {**PROGRAMS, "copy.NC": PROGRAM})


def test_the_table_has_a_row_per_run_sorted_with_the_machine_from_the_file_name(tmp_path):
    a = _write(tmp_path, _run_events(100.0), "Box-OP9-Hurco04-02of02.txt")
    b = _write(tmp_path, _run_events() + _run_events(30.0, end="STOPPED"))
    table = mtc.runs_table([a, b], PROGRAMS)
    assert table["log"].tolist() == [b.name, b.name, a.name]
    assert table["machine"].tolist() == ["Hurco02", "Hurco02", "Hurco04"]
    assert table["run"].tolist() == [0, 1, 0]
    assert table["valid"].tolist() == [True, False, True]
    assert table["reason"].tolist() == ["", "not_completed", ""]
    assert table["start"].iloc[0] == T0 and str(table["start"].dt.tz) == "UTC"
    assert table["motion_s"].iloc[0] == pytest.approx(8.0) and np.isnan(table["motion_s"][1])
    assert (table["first_block"].tolist(), table["last_block"].tolist()[0]) == ([6, 6, 6], 14)


# --- the shipped logs -----------------------------------------------------------------------

LOGS = sorted((nist_dir() / "logs").glob("*.txt.gz"))


@pytest.fixture(scope="module")
def table():
    return mtc.nist_runs_table()


def test_all_shipped_logs_read_fast():
    start = time.perf_counter()
    n = sum(len(mtc.read_log(p)) for p in LOGS)
    assert time.perf_counter() - start < 10.0
    assert (len(LOGS), n) == (80, 432494)


def test_the_shipped_runs_and_their_valid_measurements(table):
    assert len(table) == 90
    valid = table[table["valid"]]
    counts = valid.groupby(["machine", "program"]).size().to_dict()
    box, plate = "NIST_MTC_CRADA_BOX_REV-A", "NIST_MTC_CRADA_PLATE"
    assert counts == {
        ("Hurco02", f"{box} OP1 (Bottom).NC"): 10,
        ("Hurco02", f"{box} OP3 (Back).NC"): 16,
        **{("Hurco04", f"{plate}-{k}.NC"): 1 for k in (12, 13, 14, 15, 17, 18, 20)},
    }
    reasons = table["reason"].value_counts().to_dict()
    assert reasons == {
        "": 33,
        "feed_override": 19,
        "unknown_program": 13,
        "not_completed": 8,
        "rapid_override_changed": 6,
        "other_version": 5,
        "pause": 4,
        "feed_hold": 2,
    }


def test_repeated_valid_runs_take_the_same_motion_time_to_a_few_tenths(table):
    valid = table[table["valid"]]
    spread = valid.groupby("program")["motion_s"].agg(["count", "std", "min", "max"])
    repeated = spread[spread["count"] >= 10]
    assert len(repeated) == 2  # OP1 (about 1750 s) and OP3 (about 370 s)
    assert (repeated["std"] < 0.35).all()
    assert (repeated["max"] - repeated["min"] < 1.2).all()
    # from the start the same runs vary by seconds: the first tool change and the log's hole
    duration = valid.groupby("program")["duration_s"].agg(lambda d: d.max() - d.min())
    assert (duration[repeated.index] > 0.6).all()


def test_facts_of_the_shipped_logs(table):
    row = table.set_index(["log", "run"])
    plate = "Plate-Op1-Hurco04-{:02d}of20.txt.gz".format
    box = "Box-{}-Hurco02-{:02d}of20.txt.gz".format
    # logs "PLATE-5" but holds the spindle at 6000 rev/min: an earlier PLATE-5
    assert row.loc[(plate(5), 0), "reason"] == "other_version"
    assert "6000 rev/min" in row.loc[(plate(5), 0), "detail"]
    # names nothing; its content is the shipped PLATE-5's
    assert row.loc[(plate(6), 0), ["program", "matched_by"]].tolist() == [
        "NIST_MTC_CRADA_PLATE-5.NC",
        "content",
    ]
    # begins with the end of the run Plate-08 holds whole
    assert row.loc[(plate(9), 0), "reasons"] == "unknown_program restart"
    assert row.loc[(plate(9), 0), "end_status"] == "PROGRAM_COMPLETED"
    # an M01 waited on for 39 minutes
    assert row.loc[(plate(11), 0), "reason"] == "pause"
    # OP2 runs after the ninth at an unlogged feed override of 101 %
    op2 = [row.loc[(box("OP2", k), 0)] for k in range(10, 21)]
    scales = [r["feed_scale"] for r in op2 if r["feed_samples"]]
    assert len(scales) == 10 and all(1.007 < s < 1.011 for s in scales)
    # 99 % logged, and the feed measured at 0.990 of the programmed where it is not normalised
    assert row.loc[(box("OP1", 7), 0), "feed_override_pct"] == 99.0
    # the valid box runs log no rapid override, but reach Hurco02's 500 mm/s single-axis rapid
    box_valid = table[table["valid"] & (table["machine"] == "Hurco02")]
    assert box_valid["rapid_override_pct"].isna().all()
    assert ((box_valid["rapid_plateau_mm_s"].dropna() - 500).abs() < 2.5).all()
