"""Stops and rests of LinuxCNC's task around M-codes and dwells between moves
(nctwin.estimate.task_waits), on the blend planner."""

from __future__ import annotations

import dataclasses

import pytest

from nctwin.controls import PlannerControl
from nctwin.estimate.blend_planner import blend_planner
from nctwin.estimate.task_waits import pause_count
from nctwin.gcode import parse
from nctwin.machine import load_profile

PROFILE = load_profile("linuxcnc_sim")
MACHINE = PROFILE.machine
WAITS = dataclasses.replace(
    PROFILE.control("planner"),
    dwell_wait_s=0.003,
    spindle_wait_s=0.004,
    coolant_wait_s=0.12,
    tool_change_wait_s=0.276,
    offset_wait_s=0.0025,
)
NO_WAITS = PlannerControl(period_s=WAITS.period_s, blend_tol_mm=WAITS.blend_tol_mm,
                          word_stops=True)  # fmt: skip


def _time(between: str, control: PlannerControl = WAITS, before: str = "") -> float:
    """Two collinear 10 mm lines at 20 mm/s with ``between`` on a line between them."""
    text = f"G21 G90 G64 P0.05\n{before}G1 X10 F1200\n{between}\nG1 X20\nM2\n"
    return blend_planner(parse(text), MACHINE, control).cycle_time_s


def test_words_stop_the_tool_like_a_dwell():
    """M8 between the lines stops the tool as a zero dwell does; each adds its rest."""
    stop = _time("G4 P0", NO_WAITS)
    # a stop brakes and starts again at a / 2 = 500 mm/s^2 (LinuxCNC's lines that may blend
    # parabolically): v / (a / 2) = 20 / 500 = 0.04 s more than passing at 20 mm/s
    assert stop - _time("(nothing)", NO_WAITS) == pytest.approx(0.04, abs=1e-3)
    for word, rest in [("M8", 0.12), ("M9", 0.12), ("M5", 0.004), ("M3 S1000", 0.004),
                       ("T1 M6", 0.276), ("M0", 0.0), ("M1", 0.0)]:  # fmt: skip
        assert _time(word, NO_WAITS) == pytest.approx(stop, abs=1e-12), word
        assert _time(word) == pytest.approx(stop + rest, abs=1e-12), word
    assert _time("G4 P0.001") == pytest.approx(stop + 0.001 + 0.003, abs=1e-12)


def test_words_outside_the_motion_take_no_time():
    """A rest before the first move or after the last is no part of the motion; a T word
    alone (a tool prepare) waits for no motion."""
    plain = _time("(nothing)")
    assert _time("(nothing)", before="M3 S1000 M8\nT1 M6\n") == pytest.approx(plain, abs=1e-12)
    assert _time("T2") == pytest.approx(plain, abs=1e-12)
    text = "G21 G90 G64 P0.05\nG1 X10 F1200\n(nothing)\nG1 X20\nM5 M9\nT0 M6\nM0\nM2\n"
    assert blend_planner(parse(text), MACHINE, WAITS).cycle_time_s == pytest.approx(
        _time("(nothing)"), abs=1e-12
    )


def test_offsets_stop_the_tool_once_between_two_moves():
    """G92, G92.1, G43, G49 and a change of work system stop the tool and rest offset_wait_s;
    several on the lines between the same two moves are one stop; G54 in force, G20/G21 and
    G53 are none."""
    stop = _time("G4 P0", NO_WAITS)
    for word in ("G92 X10", "G92.1", "G43 H1", "G49", "G55", "G92.1\nG49\nG55 G92 X10"):
        assert _time(word, NO_WAITS) == pytest.approx(stop, abs=1e-12), word
        assert _time(word) == pytest.approx(stop + 0.0025, abs=1e-12), word
    for word in ("G54", "G21", "(nothing)"):
        assert _time(word) == pytest.approx(_time("(nothing)"), abs=1e-12), word


def test_two_words_on_a_line_add_their_rests():
    stop = _time("G4 P0", NO_WAITS)
    assert _time("M5 M9") == pytest.approx(stop + 0.004 + 0.12, abs=1e-12)


def test_pauses_counted_between_moves_only():
    text = "G21 M0\nG1 X10 F1200\nM0\nG1 X20\nM1\nG1 X30\nM0\nM2\n"
    assert pause_count(parse(text)) == 2


def test_profile_rests_are_the_measured_ones():
    """The linuxcnc_sim profile holds the rests measured live (see its comment)."""
    assert PROFILE.control("planner") == WAITS


def test_without_word_stops_words_take_no_time():
    """A control that runs M-codes on the fly (word_stops off, the default): M8 is nothing;
    a dwell still stops the tool."""
    on_the_fly = PlannerControl(period_s=WAITS.period_s, blend_tol_mm=WAITS.blend_tol_mm)
    passing = _time("M8", on_the_fly)
    assert passing < _time("G4 P0", NO_WAITS) - 0.03  # no stop (see above: 0.04 s)
    assert _time("T1 M6", on_the_fly) == pytest.approx(passing, abs=1e-12)  # nor a rest
    assert _time("G4 P0", on_the_fly) == pytest.approx(_time("G4 P0", NO_WAITS), abs=1e-12)
    with pytest.raises(ValueError, match="word_stops = 1 is not allowed"):
        PlannerControl(word_stops=1)
