"""Reference-point returns G28 and G30 in the native reader, as LinuxCNC's ``convert_home``
(interp_convert.cc) runs them: a rapid to the intermediate point of the line's axis words, in
the distance mode in force, then a rapid of the named axes (all, without axis words) to the
reference point, #5161-#5163 (G28) or #5181-#5183 (G30), given in machine coordinates and
therefore not moved by a G92 offset. The positions are worked out by hand; the two readers are
compared on programs both read; and the NIST SMS Test Bed's Mastercam programs (Fanuc style,
inch, a ``G91G28Z0.`` before every tool change) are read natively and agree with LinuxCNC's
interpreter.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_gcode_interp import assert_agree

from nctwin import GCodeError, MotionKind, parse
from nctwin.gcode import parse_file, read_file
from nctwin.paths import data_dir
from nctwin.toolpath import PathMode

R, F = MotionKind.RAPID, MotionKind.LINEAR
G28_MM, G30_MM = (10.0, 20.0, 30.0), (-1.0, -2.0, -3.0)
#: The NIST SMS Test Bed's 23 programs: shipped in data/nist/nc, or beside the clone.
NIST_FOLDERS = (
    data_dir() / "nist" / "nc",
    Path(__file__).resolve().parents[2] / "shared" / "nist-smstestbed" / "nc",
)


def assert_moves(tp, expected, first=0):
    """The blocks from ``first`` on are ``expected``, (kind, x, y, z) each (to 1e-9 mm)."""
    assert tp.kind[first:].tolist() == [m[0] for m in expected]
    np.testing.assert_allclose(tp.end_mm[first:], [m[1:] for m in expected], rtol=0, atol=1e-9)


def home(text: str, **kwargs):
    return parse(text, reader="native", g28_reference_mm=G28_MM, g30_reference_mm=G30_MM, **kwargs)


# ---------------------------------------------------------------------------------------------
# Positions worked out by hand
# ---------------------------------------------------------------------------------------------
def test_fanuc_g91_g28_z0_before_a_tool_change():
    """A Mastercam post's tool change, in inch: Z0. in G91 is where Z is, so the intermediate
    rapid has zero length and only Z goes to the reference; M9 runs before the line's moves,
    M01 after them, and the tool change needs no tool table."""
    text = (
        "%\nO0000(PART)\nN100G20\nN110G0G17G40G49G80G90\nN130G0G90G54X1.Y2.S750M3\n"
        "N140Z.1M8\nN210G91G28Z0.M9\nN220M01\nN230T15M6\nN240G0G90G54X3.Y-1.5\nN250M30\n%\n"
    )
    tp = parse(text, reader="native", g28_reference_mm=(0.0, 0.0, 250.0))
    expected = [
        (R, 25.4, 50.8, 0.0),
        (R, 25.4, 50.8, 2.54),
        (R, 25.4, 50.8, 2.54),
        (R, 25.4, 50.8, 250.0),
        (R, 76.2, -38.1, 250.0),
    ]
    assert_moves(tp, expected)
    assert tp.line.tolist() == [5, 6, 7, 7, 10]
    words = [(f"{e['word']}{e['value']:g}", int(e["block"])) for e in tp.events]
    # G43: the G49 of N110, a tool length offset (OFFSET_EVENTS)
    assert words == [
        ("G43", 0), ("S750", 0), ("M3", 0), ("M8", 1), ("M9", 2), ("M1", 4), ("T15", 4),
        ("M6", 4), ("M30", 5),
    ]  # fmt: skip
    # LinuxCNC's reference point by default: machine zero
    assert parse(text, reader="native").end_mm[3].tolist() == [25.4, 50.8, 0.0]


def test_g90_axis_words_are_the_intermediate_point():
    tp = home("G21 G0 X1 Y2 Z3\nG28 X4 Z5")
    assert_moves(tp, [(R, 4, 2, 5), (R, 10, 2, 30)], first=1)
    assert tp.line.tolist() == [1, 2, 2]


def test_g91_axis_words_are_steps_to_the_intermediate_point():
    tp = home("G0 X1 Y2 Z3\nG91 G28 X1 Z-1")
    assert_moves(tp, [(R, 2, 2, 2), (R, 10, 2, 30)], first=1)


def test_without_axis_words_every_axis_goes_to_the_reference():
    tp = home("G0 X1 Y2 Z3\nG28\nG30")
    expected = [(R, 1, 2, 3), (R, 10, 20, 30), (R, 10, 20, 30), (R, -1, -2, -3)]
    assert_moves(tp, expected, first=1)
    assert tp.line.tolist() == [1, 2, 2, 3, 3]


def test_inch_words_and_mm_reference_points():
    tp = home("G20 G0 X1 Y1 Z1\nG28 X2\nG91 G30 Y0.5")
    expected = [(R, 50.8, 25.4, 25.4), (R, 10, 25.4, 25.4), (R, 10, 38.1, 25.4), (R, 10, -2, 25.4)]
    assert_moves(tp, expected, first=1)


def test_a_g92_offset_moves_the_intermediate_point_not_the_reference():
    """G92 X0 Y0 Z0 at (5, 5, 5): the offset is 5 on each axis. The intermediate point X1 is
    machine X6; the reference stays machine X10 (program X5). After G92.1 the program
    coordinates are the machine's again."""
    tp = home("G0 X5 Y5 Z5\nG92 X0 Y0 Z0\nG28 X1\nG0 X1 Y1\nG92.1\nG28 Y0")
    expected = [(R, 6, 5, 5), (R, 10, 5, 5), (R, 6, 6, 5), (R, 6, 0, 5), (R, 6, 20, 5)]
    assert_moves(tp, expected, first=1)


def test_the_motion_and_distance_modes_are_kept():
    """G28 is non-modal: the next line without a G-word feeds in G1, and the G91 of the G28 line
    stays in force."""
    tp = parse("G21 G1 X1 Y0 Z5 F60\nG91 G28 Z0\nX1", g28_reference_mm=(0, 0, 50))
    assert_moves(tp, [(F, 1, 0, 5), (R, 1, 0, 5), (R, 1, 0, 50), (F, 2, 0, 50)])
    assert tp.feed_mm_s[-1] == 1.0


def test_words_sharing_the_line():
    """N, M, S, T and F words run with the return (F stays modal); G80 may share its line."""
    tp = parse("G1 X1 F10\nN20 G28 F30 S100 M9 Z1\nX2\nG80 G30 Z2", reader="native")
    expected = [(F, 1, 0, 0), (R, 1, 0, 1), (R, 1, 0, 0), (F, 2, 0, 0), (R, 2, 0, 2), (R, 2, 0, 0)]
    assert_moves(tp, expected)
    assert tp.feed_mm_s[3] == 0.5


def test_a_canned_cycle_keeps_its_initial_level_across_a_return():
    """G28 is no motion of the motion group: the next hole of the G98 cycle still retracts to
    the initial level of the first (Z10), as LinuxCNC's cycle_il stays set. The return's rapids
    run in the path mode in force (G64 P0.1), not in the cycle's exact-path mode."""
    tp = parse("G64 P0.1\nG0 X0 Y0 Z10\nF60\nG98 G81 X1 R2 Z-1\nG28 Z5\nX3\nG80")
    expected = [(R, 1, 0, 5), (R, 1, 0, 0), (R, 3, 0, 10), (R, 3, 0, 2), (F, 3, 0, -1)]
    assert_moves(tp, [*expected, (R, 3, 0, 10)], first=5)
    assert tp.path_mode[5:7].tolist() == [PathMode.BLEND] * 2
    assert tp.blend_tol_mm[5:7].tolist() == [0.1, 0.1]
    assert (tp.path_mode[7:] == PathMode.EXACT_PATH).all()


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("G28 G1 X1", "G28 and G1 cannot share a line: both use the axis words"),
        ("G30 G81 X1 R1 Z0 F60", "G30 and G81 cannot share a line: both use the axis words"),
        ("G28 G92 X0", "two G-codes of the non-modal group in one line"),
        ("G28 G4 P1", "two G-codes of the non-modal group in one line"),
        ("G2 X2 I1 F60\nG28 I1", "I/J/K/R words without an arc (G2/G3) or a canned cycle"),
        ("G28 R1", "I/J/K/R words without an arc (G2/G3) or a canned cycle"),
        ("G28 P1", "P word without G2, G3, G4, G64 or a canned cycle"),
    ],
)
def test_refusals(text, reason):
    with pytest.raises(GCodeError, match=re.escape(reason)) as info:
        parse(text, reader="native")
    assert info.value.line == text.count("\n") + 1


@pytest.mark.parametrize("reader", ["native", "linuxcnc"])
def test_bad_reference_points(reader):
    with pytest.raises(
        ValueError, match=r"g28_reference_mm must be 3 finite numbers, got \(0, 0\)$"
    ):
        parse("G28", reader=reader, g28_reference_mm=(0, 0))
    with pytest.raises(ValueError, match="g30_reference_mm must be 3 finite numbers, got"):
        parse("G30", reader=reader, g30_reference_mm=(0, np.nan, 0))


_coord = st.integers(-99999, 99999).map(lambda v: v / 1000)


@given(
    start=st.tuples(_coord, _coord, _coord),
    offset=st.none() | st.tuples(_coord, _coord, _coord),
    named=st.sets(st.sampled_from("XYZ"), min_size=1),
    reference=st.tuples(_coord, _coord, _coord),
    inch=st.booleans(),
    code=st.sampled_from(["G28", "G30"]),
)
def test_g91_zeros_send_only_the_named_axes_to_the_reference(
    start, offset, named, reference, inch, code
):
    """``G91 G28 X0 ...``: a zero-length rapid, then the named axes, and only they, go to the
    reference point (machine coordinates, whatever the units and the G92 offset)."""
    scale = 25.4 if inch else 1.0
    lines = ["G20" if inch else "G21", "G90 G0 X{} Y{} Z{}".format(*start)]
    if offset is not None:
        lines.append("G92 X{} Y{} Z{}".format(*offset))
    lines.append(f"G91 {code} " + " ".join(f"{a}0" for a in sorted(named)))
    key = "g28_reference_mm" if code == "G28" else "g30_reference_mm"
    tp = parse("\n".join(lines), reader="native", **{key: reference})
    here = np.array(start) * scale
    expected = np.where([a in named for a in "XYZ"], reference, here)
    assert len(tp) == 3 and (tp.kind == R).all()
    assert tp.line.tolist() == [2, len(lines), len(lines)]
    np.testing.assert_allclose(tp.end_mm[1], here, rtol=0, atol=1e-9)
    np.testing.assert_allclose(tp.end_mm[2], expected, rtol=0, atol=1e-9)


# ---------------------------------------------------------------------------------------------
# The two readers agree
# ---------------------------------------------------------------------------------------------
AGREE = [
    "G0 X1 Y2 Z3\nG91 G28 Z0 M9\nG90 X5\nM2",
    "G0 X1 Y2 Z3\nG28 X4\nY7\nG30 Z-1\nG91 G30 X2 Y0\nM2",
    "G0 X1 Y2 Z3\nG28\nG1 X1 F60\nG30\nX3 Y4\nM2",
    "G20 G0 X1 Y2 Z3\nG92 X0\nG28 X1\nX2\nG91 G28 Y1\nG90 G92.1\nG28 Z.5\nM2",
    "G20 G0 X1 Y2 Z3\nG92 X0 Y1 Z-1\nG30\nG92.2\nG28 Z.5\nG92.3\nG30 Y0\nM2",
    "G0 X0 Y0 Z5\nG98 G81 X1 R2 Z-1 F60\nG28 Z7\nX2\nG80\nM2",
    "G0 X0 Y0 Z5\nG91 G99 G81 X1 R-3 Z-2 F60\nG28 Z0\nX1\nG80 G28 X0\nM2",
    "G21 G0 X1 Y2 Z3\nG64 P0.1\nG28 X1 Y1\nG61\nG30 Z1\nG64\nG0 X0 Y0\nG2 X2 I1 F60\nG28 Z2\n"
    "X0 Y0 I-1\nM2",
    "%\nO0001(PART)\nN10G20\nN20G0G90G54X1.Y2.S750M3\nN30Z.1M8\nN40G91G28Z0.M9\nN50M01\n"
    "N60T1M6\nN70G0G90G54X3.Y-1.5\nN80G1Z-.1F10.\nN90G91G28Z0.M9\nN100G90G58X12.Y20.\nN110M30\n%",
]


@pytest.mark.parametrize(
    "references", [{}, {"g28_reference_mm": (10, 20, 300), "g30_reference_mm": (-1.5, 2.25, 40)}]
)
@pytest.mark.parametrize("text", AGREE)
def test_agrees_with_linuxcnc(linuxcnc_interpreter, text, references):
    native = parse(text, reader="native", **references)
    assert_agree(native, parse(text, reader="linuxcnc", **references))


@pytest.mark.parametrize(
    "text", ["G0 X1\nG28 G1 X1\nM2", "G0 X1\nG30 G81 X1 R1 Z0 F60\nM2", "G0 X1\nG28 I1\nM2"]
)
def test_linuxcnc_refuses_them_too(linuxcnc_interpreter, text):
    for reader in ("native", "linuxcnc"):
        with pytest.raises(GCodeError, match=r"^<string>:2: "):
            parse(text, reader=reader)


# ---------------------------------------------------------------------------------------------
# The NIST SMS Test Bed's programs
# ---------------------------------------------------------------------------------------------
def nist_programs() -> list[Path]:
    """The 23 programs, from data/nist/nc or beside the clone; the test is skipped without."""
    for folder in NIST_FOLDERS:
        if folder.is_dir():
            paths = sorted(folder.glob("*.NC"))
            assert len(paths) == 23, folder
            return paths
    pytest.skip("the NIST programs are in neither data/nist/nc nor ../shared/nist-smstestbed/nc")


def test_nist_programs_are_read_natively():
    """Every program reads natively (auto chooses the native reader); each G91G28Z0. line
    makes a zero-length rapid, then a rapid of Z alone to the reference (0 by default)."""
    for path in nist_programs():
        result = read_file(path)
        assert result.reader == "native", path.name
        tp = result.toolpath
        assert (tp.lengths_mm > 0).sum() > 500, path.name
        lines = path.read_text().splitlines()
        homes = [i + 1 for i, text in enumerate(lines) if "G91G28Z0." in text]
        assert len(homes) >= 2, path.name
        for number in homes:
            start, via, end = tp.start_mm[tp.line == number][0], *tp.end_mm[tp.line == number]
            np.testing.assert_array_equal(via, start)
            np.testing.assert_array_equal(end, [start[0], start[1], 0.0])


def test_nist_programs_agree_with_linuxcnc(linuxcnc_interpreter, tmp_path):
    """With a tool table that holds their tools (of length and diameter 0), LinuxCNC's
    interpreter reads the programs too, and the two readers agree, also with a G28 reference
    point 300 mm above the part's zero."""
    paths = nist_programs()
    tools = set()
    for path in paths:
        text = re.sub(r"\([^)]*\)", "", path.read_text())
        tools |= {int(t) for t in re.findall(r"T(\d+)", text)}
    table = tmp_path / "tool.tbl"
    table.write_text("".join(f"T{t} P{t} D0 Z0 ;\n" for t in sorted(tools)))
    for path in paths:
        for references in ({}, {"g28_reference_mm": (0.0, 0.0, 300.0)}):
            native = parse_file(path, reader="native", **references)
            linuxcnc = parse_file(path, reader="linuxcnc", tool_table=table, **references)
            assert_agree(native, linuxcnc)
