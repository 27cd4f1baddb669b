"""The G-code reader and writer: modal state, units, errors, round trips."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nctwin import GCodeError, MotionKind, dump, parse


def test_units_are_converted_to_mm():
    tp = parse("G20\nG1 X1 Y-0.5 F60\nG21 X10")
    np.testing.assert_allclose(tp.end_mm[0], [25.4, -12.7, 0])
    assert tp.feed_mm_s[0] == pytest.approx(25.4)  # 60 in/min = 1 in/s
    np.testing.assert_allclose(tp.end_mm[1], [10, -12.7, 0])
    assert tp.feed_mm_s[1] == pytest.approx(25.4)  # F keeps its value in mm/s after G21


def test_f_is_set_before_the_units_change_of_its_line():
    # LinuxCNC's order of execution: F (step 3) before G20/G21 (step 12), and
    # convert_length_units keeps the feed in mm/min: 6 mm/min = 0.1 mm/s, not 6 in/min
    tp = parse("G21\nG20 F6 G1 X1\nX2")
    assert tp.feed_mm_s[0] == 0.1
    assert tp.feed_mm_s[1] == 0.1
    np.testing.assert_allclose(tp.end_mm[:, 0], [25.4, 50.8])
    # the other way round: F6 in inch (2.54 mm/s) kept after G21; a later F is in mm/min
    tp = parse("G21 F6 G1 X1", units="inch")
    assert tp.feed_mm_s[0] == pytest.approx(6 * 25.4 / 60)
    assert parse("G20\nG21 F6 G1 X1\nF6 X2").feed_mm_s.tolist() == pytest.approx([2.54, 0.1])
    # G64 P runs after the units change: it is in the new units
    assert parse("G21\nG20 G64 P0.01 G1 X1 F6").blend_tol_mm[0] == pytest.approx(0.254)


def test_inch_arc_words_are_converted():
    tp = parse("G20 G0 X1 Y0\nG3 X0 Y1 I-1 J0 F10")
    np.testing.assert_allclose(tp.center_mm[1], [0, 0, 0], atol=1e-12)
    assert tp.lengths_mm[1] == pytest.approx(math.pi * 25.4 / 2)


def test_default_units_option():
    tp = parse("G1 X1 F60", units="inch")
    assert tp.end_mm[0, 0] == pytest.approx(25.4)


def test_incremental_and_absolute_modes():
    tp = parse("G91 G1 X1 Y1 F60\nX1\nG90 X0\nG91 Y-1")
    np.testing.assert_allclose(tp.end_mm[:, :2], [[1, 1], [2, 1], [0, 1], [0, 0]])


def test_absolute_arc_centres_g90_1():
    tp = parse("G90.1 G0 X10 Y0\nG3 X0 Y10 I0 J0 F60")
    np.testing.assert_allclose(tp.center_mm[1], [0, 0, 0])


def test_feed_is_modal_and_rapids_keep_it():
    tp = parse("G0 X1\nG1 X2 F120\nG0 X3\nG1 X4")
    assert np.isnan(tp.feed_mm_s[0])
    np.testing.assert_allclose(tp.feed_mm_s[1:], [2.0, 2.0, 2.0])


def test_lexical_freedom():
    text = "%\nn10 g1x1.5y-.5z+2.f600 (comment) ; rest\n/G0 X9\nN20G0X0Y0Z0\n%\nG1 X99\n"
    tp = parse(text)
    np.testing.assert_allclose(tp.end_mm, [[1.5, -0.5, 2.0], [9, -0.5, 2.0], [0, 0, 0]])
    assert list(tp.line) == [2, 3, 4]
    skipped = parse(text, block_delete=True)
    assert len(skipped) == 2


def test_events_and_program_end():
    tp = parse("T1 M6\nS12000 M3\nG1 X1 F60\nM5\nM30\nG1 X2\n")
    assert len(tp) == 1  # nothing after M30 runs
    words = [f"{e['word']}{e['value']:g}" for e in tp.events]
    assert words == ["T1", "M6", "S12000", "M3", "M5", "M30"]
    assert list(tp.events["block"]) == [0, 0, 0, 0, 1, 1]


def test_dwell_units():
    assert parse("G4 P1.5").dwell_s[0] == 1.5
    assert parse("G4 P1500", dwell_p_unit="ms").dwell_s[0] == 1.5
    assert parse("G4 X2").dwell_s[0] == 2.0
    tp = parse("G0 X3\nG4 P1")
    np.testing.assert_allclose(tp.start_mm[1], tp.end_mm[1])
    assert tp.kind[1] == MotionKind.DWELL


def test_prologue_codes_are_state_without_motion():
    tp = parse("G17 G21 G40 G49 G54 G80 G90 G94 G64 P0.1 Q0.01\nG0 G43 H1 Z5\nG53 X0\n")
    assert len(tp) == 2
    assert tp.blend_tol_mm[0] == pytest.approx(0.1)


def test_program_g64_p_in_inch_is_converted():
    tp = parse("G20 G64 P0.001 G1 X1 F10")
    assert tp.blend_tol_mm[0] == pytest.approx(0.0254)


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("G1 X1", 1, "no feed rate set"),
        ("G1 X1 X2 F60", 1, "word X given twice"),
        ("G0 X0\nG1 G0 X1", 2, "two G-codes of the motion group"),
        ("G0 X0\nG2 X10 Y0 I4 J0 F60", 2, "radius differs"),
        ("G0 X10\nG2 X0 Y10 R2 F60", 2, "smaller than half"),
        ("G0 X10\nG2 X10 Y0 R5 F60", 2, "full circle cannot be given with R"),
        ("G2 X1 Y1 F60", 1, "needs a centre"),
        ("G2 X1 Y1 R1 I1 F60", 1, "both R and I/J/K"),
        ("G17 G2 X1 I1 K1 F60", 1, "K is not an arc-centre word"),
        ("X1", 1, "without an active motion mode"),
        ("G80 X1", 1, "without an active motion mode"),
        ("G0 X1 I1", 1, "without an arc"),
        ("O100 sub", 1, "O-word (subroutine, loop or conditional) needs LinuxCNC's"),
        ("#1 = 5", 1, "#-parameter needs LinuxCNC's interpreter"),
        ("G0 X[1+2]", 1, "expression [...] needs LinuxCNC's interpreter"),
        ("G81 X0 Y0 Z-1 R1", 1, "G81 with no feed rate set (F)"),
        ("G41 D1", 1, "G41 cutter compensation needs LinuxCNC's interpreter: run make linuxcnc"),
        ("G0 A10", 1, "axis A"),
        ("G1 X1 F60\nG93", 2, "inverse-time"),
        ("G0 X1 (unclosed", 1, "unbalanced parentheses"),
        ("G0 X1 (a (nested) c)", 1, "unbalanced parentheses"),
        ("G0 X1.2.3", 1, "malformed number"),
        ("G0 X", 1, "malformed number"),
        ("G0 X-+1", 1, "malformed number"),
        ("G0 X1\n5", 2, "number without a word letter"),
        ("G0 X1\nG4", 2, "without a dwell time"),
        ("G4 X1 Y1", 1, "cannot share a line with motion"),
        ("G4 P1 X1 Y1", 1, "without an active motion mode"),
        ("G1 X1 F0", 1, "F must be > 0"),
        ("G1 X1 F60 P2", 1, "P word without G2, G3, G4, G64 or a canned cycle"),
        ("G0 X1é", 1, "non-ASCII"),
        ("G1.7 X1", 1, "G1.7 is not supported"),
        ("G0 X1" + "9" * 400, 1, "out of range"),
    ],
)
def test_errors_name_line_and_reason(text, line, reason):
    with pytest.raises(GCodeError) as info:
        parse(text, source="p.nc", reader="native")
    err = info.value
    assert err.line == line
    assert reason in err.reason
    assert err.text == text.split("\n")[line - 1]
    assert str(err).startswith(f"p.nc:{line}: ")


def test_earliest_error_wins_across_stages():
    # a modal error on line 2 is reported before a lexical error on line 3
    with pytest.raises(GCodeError) as info:
        parse("G0 X0\nG1 X1\n#1=2\n")
    assert info.value.line == 2


def test_errors_after_program_end_are_not_read():
    tp = parse("G0 X1\nM2\n#1 = 2\nG0 A5\n")
    assert len(tp) == 1


def test_bad_keyword_arguments():
    with pytest.raises(ValueError, match="units"):
        parse("G0 X1", units="furlong")
    with pytest.raises(ValueError, match="dwell_p_unit"):
        parse("G0 X1", dwell_p_unit="min")
    with pytest.raises(ValueError, match="arc_tol_mm"):
        parse("G0 X1", arc_tol_mm=-1)


def test_numbers_are_read_exactly_like_python_floats():
    values = ["0.1", "-.5", "+3.", "123456.789012345", "0.999999500000042", "1.23456789012345678"]
    tp = parse("\n".join(f"G0 X{v}" for v in values))
    assert list(tp.end_mm[:, 0]) == [float(v) for v in values]


# ------------------------------------------------------------------------- property tests
_coord = st.floats(-500, 500, allow_nan=False).map(lambda v: float(f"{v:.4f}"))


def _f(v: float) -> str:
    return f"{v:.6f}"


@st.composite
def programs(draw) -> str:
    """Random valid programs: lines, arcs (I/J/K and R), dwells, feeds, modes and events."""
    lines = ["G21 G90 G17", f"F{draw(st.integers(10, 20000))}"]
    x = y = 0.0
    for _ in range(draw(st.integers(1, 25))):
        op = draw(st.sampled_from(["G0", "G1", "G2", "G3", "G4", "F", "G91", "G64", "M"]))
        if op in ("G0", "G1"):
            x, y = draw(_coord), draw(_coord)
            lines.append(f"{op} X{_f(x)} Y{_f(y)} Z{_f(draw(_coord))}")
        elif op in ("G2", "G3"):
            r = draw(st.floats(0.5, 100))
            a0, a1 = draw(st.floats(0, 6.28)), draw(st.floats(0, 6.28))
            i, j = round(-r * math.cos(a0), 6), round(-r * math.sin(a0), 6)
            cx, cy = x + i, y + j
            ex, ey = round(cx + r * math.cos(a1), 6), round(cy + r * math.sin(a1), 6)
            end = f"X{_f(ex)} Y{_f(ey)} Z{_f(draw(_coord))}"
            if draw(st.booleans()) and math.hypot(ex - x, ey - y) > 1e-3:
                lines.append(f"{op} {end} R{'-' if draw(st.booleans()) else ''}{r * 1.001:.6f}")
            else:
                lines.append(f"{op} {end} I{_f(i)} J{_f(j)}")
            x, y = ex, ey
        elif op == "G4":
            lines.append(f"G4 P{draw(st.floats(0, 5)):.3f}")
        elif op == "F":
            lines.append(f"F{draw(st.integers(1, 20000))}")
        elif op == "G91":
            dx = draw(_coord)
            lines.append(f"G91 G1 X{_f(dx)}\nG90")
            x = x + dx
        elif op == "G64":
            lines.append(f"G64 P{draw(st.floats(0, 1)):.3f}" if draw(st.booleans()) else "G61")
        else:
            lines.append(f"S{draw(st.integers(0, 30000))} M{draw(st.sampled_from([3, 5, 8]))}")
    return "\n".join(lines)


@given(programs())
def test_round_trip_parse_dump_parse(text):
    tp = parse(text)
    again = parse(dump(tp))
    assert again.allclose(tp)
    assert again.length_mm == pytest.approx(tp.length_mm, rel=1e-9, abs=1e-9)


_GCODE_ALPHABET = "GXYZIJKRFPQLMSTNOgx0123456789.-+ \t\n()%;/#[]=é"


@pytest.mark.slow
@given(st.one_of(st.text(max_size=300), st.text(alphabet=_GCODE_ALPHABET, max_size=300)))
def test_any_text_parses_or_raises_gcode_error(text):
    try:
        tp = parse(text)
    except GCodeError as err:
        assert err.line >= 1
        assert err.reason
    else:
        assert np.isfinite(tp.end_mm).all()
        assert np.isfinite(tp.lengths_mm).all()


@pytest.mark.slow
@given(st.binary(max_size=300))
def test_random_bytes_parse_or_raise_gcode_error(data):
    try:
        parse(data.decode("latin-1"))
    except GCodeError:
        pass
