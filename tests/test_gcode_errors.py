"""What the native reader refuses, and how: every error of a file, one ``file:line: reason``
line each; constructs LinuxCNC reads are sent to LinuxCNC's interpreter."""

from __future__ import annotations

import pytest

from nctwin import GCodeError, parse
from nctwin.gcode import MAX_ERRORS

NEEDS = "needs LinuxCNC's interpreter: run make linuxcnc"


def refusal(text: str) -> GCodeError:
    with pytest.raises(GCodeError) as info:
        parse(text, source="part.nc", reader="native")
    return info.value


def test_the_message_names_file_line_and_construct():
    text = "G21 G90\n" + "(setup)\n" * 10 + "G41 D1 G1 X1 F60\n"
    assert str(refusal(text)) == f"part.nc:12: G41 cutter compensation {NEEDS}"


@pytest.mark.parametrize(
    ("text", "construct"),
    [
        ("o100 sub", "O-word (subroutine, loop or conditional)"),
        ("O<probe> call", "O-word (subroutine, loop or conditional)"),
        ("N10 o100 while [#1 LT 3]", "O-word (subroutine, loop or conditional)"),
        ("#1 = 5", "#-parameter"),
        ("G0 X[1+2]", "expression [...]"),
        ("G0 X#<_x>", "#-parameter"),
        ("G42 D2", "G42 cutter compensation"),
        ("G10 L2 P1 X0", "G10 data setting"),
        ("G28.1", "G28.1 reference-point setting"),
        ("G93", "G93 inverse-time feed"),
        ("G33 Z-1 K1", "G33 spindle-synchronised motion"),
        ("G76 P1 Z-1", "G76 threading cycle"),
        ("G38.2 Z-1 F10", "G38.2 probing"),
        ("G52 X1", "G52 local coordinate offset"),
        ("G5.2 X1 Y1", "G5.2 spline"),
        ("G0 X1 @2", "polar coordinate word @"),
        ("G1 X1 D3", "D word (cutter compensation)"),
    ],
)
def test_constructs_left_to_linuxcnc(text, construct):
    err = refusal(text)
    assert err.reason == f"{construct} {NEEDS}"
    assert str(err) == f"part.nc:1: {construct} {NEEDS}"


def test_codes_linuxcnc_lacks_too_and_rotary_axes():
    assert refusal("G68 X0 Y0 R45").reason.endswith("LinuxCNC has no G68 either")
    assert refusal("G0 A10").reason == "axis A is not supported: nctwin reads 3-axis XYZ programs"


def test_a_mistyped_digit_o_is_a_malformed_number():
    err = refusal("G0 X0\nG1 X1O Y2 F60")
    assert (err.line, err.reason) == (2, "malformed number after word X")
    assert refusal("G1 Y2.O F60").reason == "malformed number after word Y"


def test_program_number_headers_are_skipped():
    for text in ("O1234\nG0 X1", "%\no0001 (PART 7)\nG0 X1\n%", "  O42 ; main\nG0 X1"):
        tp = parse(text)
        assert len(tp) == 1 and tp.end_mm[0, 0] == 1
    assert parse("O1234\nG0 X1").line.tolist() == [2]
    refusal("O1234 G0 X1")  # not a header: an O-word with other words


def test_every_error_is_reported_one_line_each():
    text = "G21\nG1 X1 A2\nG0 X1\n#5=1\nG1 X3 F60\nG1 X1.2.3\nG41\n"
    err = refusal(text)
    assert str(err).splitlines() == [
        "part.nc:2: axis A is not supported: nctwin reads 3-axis XYZ programs",
        f"part.nc:4: #-parameter {NEEDS}",
        "part.nc:6: malformed number after word X",
        f"part.nc:7: G41 cutter compensation {NEEDS}",
    ]
    assert [e.line for e in err.errors] == [2, 4, 6, 7]
    assert (err.line, err.text) == (2, "G1 X1 A2")  # the first error, as before
    assert err.errors[2].text == "G1 X1.2.3"


def test_at_most_20_errors_are_listed():
    text = "\n".join(f"G0 X{i} B1" for i in range(30))
    err = refusal(text)
    lines = str(err).splitlines()
    assert len(lines) == MAX_ERRORS + 1 == 21
    assert lines[-1] == "... and 10 more"
    assert len(err.errors) == 20 and err.n_more == 10


def test_a_bad_word_does_not_take_its_line_down():
    # the other words of the line are read: no cascade of "no feed rate" errors
    err = refusal("G1 X1.2.3 Y2 F60\nG1 X5\nG1 Y5")
    assert len(err.errors) == 1 and err.line == 1


def test_one_error_per_line_the_first_written_first():
    assert refusal("G41 D1").reason == f"G41 cutter compensation {NEEDS}"
    assert refusal("G0 X1.2.3 A4").reason == "malformed number after word X"


def test_errors_after_the_program_end_are_not_read():
    assert len(parse("G0 X1\nM30\nG41 D1\n#1=2")) == 1
