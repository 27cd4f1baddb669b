"""LinuxCNC's interpreter as nctwin's second reader (``reader="linuxcnc"``).

The two readers must agree on every program both read: the public programs, programs of
nctwin's generators, the programs ``test_gcode_linuxcnc.py`` checks the native reader with, and
hypothesis-generated ones. Start, end and centre to 1e-6 mm; kind, plane (of arcs), source line
and dwell exactly; feed to 1e-9 relative; path mode exactly. Where they legitimately differ,
:func:`assert_agree` says why and compares what both mean:

* Tolerances: LinuxCNC keeps P = 0 for a ``G64`` without P and Q = P where Q is not given; the
  native reader keeps NaN for both. They are compared as the tolerances a block runs with
  (:meth:`Toolpath.effective_tolerance_mm`, :meth:`Toolpath.effective_naive_tol_mm`).
* Events (M, S, T): LinuxCNC's preview module never reports them (its spindle, coolant and stop
  calls are empty stubs): not compared.
* A G0/G1 line without axis words: LinuxCNC's interpreter makes a zero-length move of it (its
  planner drops it), the native reader no block. Zero-length lines and rapids (outside canned
  cycles, whose zero-length moves both readers make) are left out on both sides.
* What only the native reader reads (Fanuc's ``G4 X`` dwell): LinuxCNC refuses it; the test
  says so and compares the program with the dwell written as LinuxCNC reads it.

Also: numbers worked out by hand for what only LinuxCNC reads (parameters, subroutines, cycles,
cutter compensation, tool lengths, units), and every way a program can fail, each as one
``file:line: reason``. Skipped where LinuxCNC's ``gcode`` module is missing (``make linuxcnc``),
failed there under ``NCTWIN_REQUIRE_LINUXCNC=1`` (``make test``).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_gcode import programs
from test_gcode_linuxcnc import PROGRAMS, _random_program

from nctwin import MotionKind, PathMode, Toolpath
from nctwin.gcode import (
    GCodeError,
    _interp,
    complete_tool_table,
    interpreter_available,
    parse,
    parse_file,
    read,
    read_file,
)
from nctwin.programs import iso10791
from nctwin.programs.camblend import cam_blend_program
from nctwin.programs.camstyle import cam_program
from nctwin.programs.finishing3d import finishing3d_program
from nctwin.programs.language import LANGUAGE_PROGRAMS

PUBLIC = sorted(
    p
    for p in (Path(__file__).resolve().parents[1] / "data" / "programs" / "public").iterdir()
    if p.suffix in (".ngc", ".nc", ".gcode")
)
SHARED = Path(__file__).resolve().parents[2] / "shared" / "programs"
#: Agreement: coordinates (mm), feed (relative).
ATOL_MM, FEED_RTOL = 1e-6, 1e-9


def _moving(tp: Toolpath) -> Toolpath:
    """The blocks but zero-length lines and rapids outside canned cycles (see the module
    docstring: LinuxCNC moves nowhere on a G0/G1 line without axis words). Zero is to 1e-9 mm:
    LinuxCNC's inch positions of a millimetre point come back with a rounding error."""
    still = (tp.kind <= MotionKind.LINEAR) & np.all(np.abs(tp.start_mm - tp.end_mm) <= 1e-9, axis=1)
    in_cycle = tp.path_mode == PathMode.EXACT_PATH
    return tp.take(~(still & ~in_cycle))


def assert_agree(native: Toolpath, linuxcnc: Toolpath) -> float:
    """Assert the two readers' tool paths agree (see the module docstring); return the largest
    deviation of a point (mm)."""
    a, b = _moving(native), _moving(linuxcnc)
    assert len(a) == len(b)
    for name in ("kind", "line", "path_mode", "dwell_s"):
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name), err_msg=name)
    np.testing.assert_array_equal(b.plane[a.is_arc], a.plane[a.is_arc], err_msg="plane")
    dev = 0.0
    for name in ("start_mm", "end_mm", "center_mm"):
        d = np.abs(getattr(b, name) - getattr(a, name))
        assert np.array_equal(np.isnan(d), np.isnan(getattr(a, name))), name
        dev = max(dev, float(np.nanmax(d, initial=0.0)))
    assert dev <= ATOL_MM
    np.testing.assert_allclose(b.feed_mm_s, a.feed_mm_s, rtol=FEED_RTOL, atol=0, equal_nan=True)
    for machine_tol_mm in (0.0, 0.05):
        np.testing.assert_allclose(
            b.effective_tolerance_mm(machine_tol_mm), a.effective_tolerance_mm(machine_tol_mm)
        )
    np.testing.assert_allclose(b.effective_naive_tol_mm(), a.effective_naive_tol_mm())
    return dev


def _both(text: str) -> tuple[Toolpath, Toolpath]:
    return parse(text, reader="native"), parse(text, reader="linuxcnc")


# ---------------------------------------------------------------------------------------------
# The two readers agree
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", PUBLIC, ids=lambda p: p.name)
def test_public_programs_agree(linuxcnc_interpreter, path):
    result = read_file(path)  # auto: the native reader, LinuxCNC's where only it reads it
    try:
        native = parse_file(path, reader="native")
    except GCodeError as err:
        assert all("needs LinuxCNC's interpreter" in e.reason for e in err.errors)
        assert result.reader == "linuxcnc" and len(result.toolpath) > 0
        return
    assert result.reader == "native"
    assert_agree(native, parse_file(path, reader="linuxcnc"))


def test_shared_programs_agree(linuxcnc_interpreter):
    if not SHARED.is_dir():
        pytest.skip("../shared/programs is not beside this clone")
    compared = 0
    for path in sorted(SHARED.iterdir()):
        if path.suffix not in (".ngc", ".nc", ".gcode"):
            continue
        try:
            native = parse_file(path, reader="native")
        except GCodeError:
            continue  # read by LinuxCNC only (checked on the public copy above)
        assert_agree(native, parse_file(path, reader="linuxcnc"))
        compared += 1
    assert compared >= 10


@pytest.mark.parametrize(
    "text",
    [
        *(cam_program(seed) for seed in range(3)),
        cam_blend_program(0, n_lines=300, feed_mm_s=50.0, tol_mm=0.05),
        finishing3d_program(0),
        LANGUAGE_PROGRAMS["drill_cycles"](),
        LANGUAGE_PROGRAMS["plane_arcs"](),
    ],
    ids=["cam0", "cam1", "cam2", "camblend", "finishing3d", "drill_cycles", "plane_arcs"],
)
def test_generated_programs_agree(linuxcnc_interpreter, text):
    assert_agree(*_both(text))


def test_g94_clears_the_feed_in_both_readers(linuxcnc_interpreter):
    """G94 runs before the F of its line and sets the feed to 0 (LinuxCNC's convert_feed_mode):
    the rapid after it has no feed, a feed move needs a new F, and an F on its own line wins."""
    text = "G21 F600\nG1 X1\nG94\nG0 X2\nG94 F300 G1 X3\n"
    native, linuxcnc = _both(text)
    assert_agree(native, linuxcnc)
    np.testing.assert_array_equal(native.feed_mm_s, [10.0, np.nan, 5.0])
    for reader in ("native", "linuxcnc"):
        with pytest.raises(GCodeError, match=r"^<string>:3: "):
            parse("G21 F600\nG1 X1\nG94 G1 X2\n", reader=reader)


def test_fanuc_dwell_is_native_only(linuxcnc_interpreter):
    """ISO 10791-7's test piece dwells with Fanuc's ``G04 X0.5``: the native reader reads it
    (its docstring says so), LinuxCNC refuses it; with ``G4 P0.5`` the two agree."""
    text = iso10791.test_piece_program()
    line = text.split("\n").index("G04 X0.5") + 1
    with pytest.raises(GCodeError, match=f"^<string>:{line}: Dwell time missing with g4"):
        parse(text, reader="linuxcnc")
    assert_agree(*_both(text.replace("G04 X0.5", "G4 P0.5")))


def test_language_programs_are_read_by_linuxcnc(linuxcnc_interpreter):
    """nctwin's programs in the whole language: auto reads them through LinuxCNC (but those
    the native reader reads, whose M-codes it keeps)."""
    for name, make in LANGUAGE_PROGRAMS.items():
        result = read(make())
        assert len(result.toolpath) > 10, name
        native = ("drill_cycles", "plane_arcs", "tool_pauses")
        expected = "native" if name in native else "linuxcnc"
        assert result.reader == expected, name


def test_native_oracle_programs_agree(linuxcnc_interpreter):
    """The programs test_gcode_linuxcnc.py checks the native reader's moves with (cycles, G92,
    dwells, turns, units) and its random ones, those both readers read."""
    rng = np.random.default_rng(7)
    texts = PROGRAMS + [_random_program(rng) for _ in range(40)]
    compared = 0
    for text in texts:
        try:
            native = parse(text, reader="native")
        except GCodeError:
            continue
        try:
            interp = parse(text, reader="linuxcnc")
        except GCodeError:
            continue  # LinuxCNC refuses some random programs (test_gcode_linuxcnc checks why)
        assert_agree(native, interp)
        compared += 1
    assert compared >= 40


_coord = st.floats(-50, 50).map(lambda v: round(v, 4))


@st.composite
def language_programs(draw) -> str:
    """Random programs in planes, units, distance modes, G92 offsets, path modes, helices and
    turns, dwells, G81/G83 cycles and G28/G30 returns."""
    lines = [draw(st.sampled_from(["G21", "G20"])), "G90 G17", f"F{draw(st.integers(5, 3000))}"]
    lines.append(f"G0 X{draw(_coord)} Y{draw(_coord)} Z{abs(draw(_coord))}")
    for _ in range(draw(st.integers(1, 12))):
        op = draw(st.integers(0, 9))
        if op == 0:
            lines.append(f"G{draw(st.sampled_from([0, 1]))} X{draw(_coord)} Z{draw(_coord)}")
        elif op == 1:
            plane, words = draw(st.sampled_from([("G17", "IJ"), ("G18", "KI"), ("G19", "JK")]))
            turns = draw(st.sampled_from(["", " P2", " P3"]))
            normal = {"G17": "Z", "G18": "Y", "G19": "X"}[plane]
            i, j = draw(st.floats(0.5, 10)), draw(st.floats(-10, 10))
            lines.append(
                f"{plane} G{draw(st.sampled_from([2, 3]))} {words[0]}{i:.4f} {words[1]}{j:.4f}"
                f" {normal}{draw(_coord)}{turns}\nG17"
            )
        elif op == 2:
            lines.append(draw(st.sampled_from(["G61", "G61.1", "G64", "G64 P0.02", "G64 P0.1 Q0"])))
        elif op == 3:
            lines.append(f"G92 X{draw(_coord)}" if draw(st.booleans()) else "G92.1")
        elif op == 4:
            lines.append(f"G4 P{draw(st.floats(0, 2)):.3f}")
        elif op == 5:
            lines.append(draw(st.sampled_from(["G20", "G21"])))
        elif op == 6:
            lines.append(f"G91 G1 X{draw(_coord)} Y{draw(_coord)}\nG90")
        elif op == 7:
            cycle = draw(st.sampled_from(["G81", "G83 Q1.5"]))
            retract = draw(st.sampled_from(["G98", "G99"]))
            lines.append(f"G0 Z5\n{retract} {cycle} X{draw(_coord)} R2 Z-4\nG80")
        elif op == 8:
            lines.append(f"F{draw(st.integers(5, 3000))}")
        else:
            mode = draw(st.sampled_from(["G90 G28", "G91 G28", "G90 G30", "G91 G30"]))
            axes = draw(st.sets(st.sampled_from("XYZ")))
            lines.append(mode + "".join(f" {a}{draw(_coord)}" for a in sorted(axes)))
            lines.append("G90")
    return "\n".join(lines) + "\nM2"


@settings(max_examples=25)
@given(text=st.one_of(programs(), language_programs()))
def test_random_programs_agree(linuxcnc_interpreter, text):
    try:
        native = parse(text, reader="native")
    except GCodeError:
        return  # a program the native reader refuses is not one both read
    assert_agree(native, parse(text, reader="linuxcnc"))


# ---------------------------------------------------------------------------------------------
# What only LinuxCNC reads, worked out by hand
# ---------------------------------------------------------------------------------------------
def test_parameters_and_expressions(linuxcnc_interpreter):
    tp = parse("#1=5\nG1 X[#1*2] Y[#1-7] F[#1*12]\nM2", reader="linuxcnc")
    np.testing.assert_allclose(tp.end_mm, [[10.0, -2.0, 0.0]])
    assert tp.line.tolist() == [2] and tp.feed_mm_s.tolist() == pytest.approx([1.0])


def test_subroutine_called_twice(linuxcnc_interpreter):
    text = "o100 sub\nG91 G1 X1 Y2 F60\nG90\no100 endsub\nG0 X0 Y0\no100 call\no100 call\nM2"
    tp = parse(text, reader="linuxcnc")
    assert tp.kind.tolist() == [MotionKind.RAPID, MotionKind.LINEAR, MotionKind.LINEAR]
    np.testing.assert_allclose(tp.end_mm[1:], [[1.0, 2.0, 0.0], [2.0, 4.0, 0.0]])
    assert tp.line.tolist() == [5, 2, 2]  # the subroutine's line, at each call


#: A move between every M-word: M3, M8, M9, M6 run before their line's motion, M0 and M1
#: after it; the M5 after the tool change changes nothing (M6 stopped the spindle).
M_WORDS = """G21 G90 F600
G1 X1
S1000 M3
G1 X2
M8
G1 X3
M9
G1 X4
T1 M6
G1 X5
M0
G1 X6
M5
G1 X7
M1
G1 X8
M7
G1 X9
M2
"""


def test_task_words_from_the_modal_state(linuxcnc_interpreter):
    tp = parse(M_WORDS, reader="linuxcnc")
    ev = tp.events[tp.events["word"] == "M"]  # G: the offsets (test_offsets_are_events)
    got = list(zip(ev["block"].tolist(), ev["line"].tolist(), ev["value"].tolist(), strict=True))
    assert got == [(1, 3, 3.0), (2, 5, 8.0), (3, 7, 9.0), (4, 9, 6.0), (5, 11, 0.0), (7, 15, 1.0),
                   (8, 17, 7.0)]  # fmt: skip
    # the native reader keeps every word as written: the same, and the M5 and M2 besides
    native = parse(M_WORDS, reader="native").events
    native = native[(native["word"] == "M") & ~np.isin(native["value"], (2.0, 5.0))]
    assert native[["block", "line", "value"]].tolist() == ev[["block", "line", "value"]].tolist()


def test_offsets_are_events(linuxcnc_interpreter):
    """Each line that sets an offset LinuxCNC's task waits for is one G event, by the first it
    sets, in both readers: LinuxCNC's G55 sets three (G5x, G92, rotation), a G55 already in
    force none; LinuxCNC's M2 resets the system after the last move."""
    text = ("G21 G90 G54\nG0 X0 Y0 Z0\nG43 H1\nG1 X10 F600\nG55\nG55 G1 X20\nG92 X0\nG1 X5\n"
            "G92.1\nG54 G92 X3\nG49 G1 X0\nM2\n")  # fmt: skip
    expected = [(1, 3, 43.0), (2, 5, 54.0), (3, 7, 92.0), (4, 9, 92.0), (4, 10, 54.0),
                (4, 11, 43.0)]  # fmt: skip
    for reader, end in (("native", []), ("linuxcnc", [(5, 12, 54.0)])):
        ev = parse(text, reader=reader).events
        g = ev[ev["word"] == "G"]
        got = list(zip(g["block"].tolist(), g["line"].tolist(), g["value"].tolist(), strict=True))
        assert got == expected + end, reader


def test_task_words_in_a_subroutine_and_a_full_turn(linuxcnc_interpreter):
    """Words inside a subroutine come at each call; a two-turn circle is two blocks."""
    text = ("o1 sub\nM8\nG91 G1 X1 F60\nG90\nM9\no1 endsub\n"
            "G0 X0 Y0\nG2 X0 Y0 I1 P2 F60\no1 call\no1 call\nM2")  # fmt: skip
    tp = parse(text, reader="linuxcnc")
    assert len(tp) == 5  # rapid, two turns, two lines
    ev = tp.events[tp.events["word"] == "M"]
    assert ev["block"].tolist() == [3, 4, 4, 5] and ev["value"].tolist() == [8.0, 9.0, 8.0, 9.0]
    assert ev["line"].tolist() == [2, 5, 2, 5]


def test_g81_cycle(linuxcnc_interpreter):
    """G98 G81 from Z5 to a hole at X10 Y5, R2, Z-3: over the hole, down to R, feed to the
    bottom, back up to the initial Z; all in exact-path mode."""
    tp = parse("G0 X0 Y0 Z5\nG64 P0.1\nG98 G81 X10 Y5 R2 Z-3 F60\nG80\nM2", reader="linuxcnc")
    kinds = [MotionKind.RAPID, MotionKind.RAPID, MotionKind.RAPID, MotionKind.LINEAR]
    assert tp.kind.tolist() == [*kinds, MotionKind.RAPID]
    expected = [[0, 0, 5], [10, 5, 5], [10, 5, 2], [10, 5, -3], [10, 5, 5]]
    np.testing.assert_allclose(tp.end_mm, expected)
    assert tp.line.tolist() == [1, 3, 3, 3, 3]
    assert (tp.path_mode[1:] == PathMode.EXACT_PATH).all()


def test_cutter_compensation_of_a_square(linuxcnc_interpreter, tmp_path):
    """A 20 mm square climbed clockwise with G41 and a tool of diameter 4 (tool table): the
    sides run 2 mm outside it, and the outside corners are arcs of radius 2 about the corners."""
    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 D4 Z0 ;\n")
    text = "G0 X-10 Y-10\nG41 D1\nG1 X0 Y0 F600\nY20\nX20\nY0\nX0\nG40 G0 X-10 Y-10\nM2"
    tp = parse(text, reader="linuxcnc", tool_table=table)
    sides = (tp.kind == MotionKind.LINEAR) & (tp.line >= 4) & (tp.line <= 7)
    on_offset = np.isclose(tp.end_mm[sides][:, :2], -2) | np.isclose(tp.end_mm[sides][:, :2], 22)
    assert on_offset.any(axis=1).all()
    corners = tp.center_mm[tp.is_arc][:, :2]
    assert len(corners) == 3
    np.testing.assert_allclose(sorted(map(tuple, corners)), [(0, 20), (20, 0), (20, 20)])
    np.testing.assert_allclose(tp.radius_mm[tp.is_arc], 2.0)
    assert (tp.kind[tp.is_arc] == MotionKind.ARC_CW).all()
    # with the table of nctwin's LinuxCNC configuration (diameter 0) the path is as programmed
    plain = parse(text, reader="linuxcnc")
    assert not plain.is_arc.any()
    np.testing.assert_allclose(plain.end_mm[plain.line == 5], [[20, 20, 0]])


def test_tool_length_offset(linuxcnc_interpreter, tmp_path):
    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 D0 Z5 ;\n")
    tp = parse("G43 H1\nG0 X1 Z2\nG49\nG0 Z2\nM2", reader="linuxcnc", tool_table=table)
    np.testing.assert_allclose(tp.end_mm, [[1, 0, 7], [1, 0, 2]])


def test_inch_program(linuxcnc_interpreter):
    tp = parse("G20\nG1 X1 Y2 F10\nG64 P0.001\nG1 X0\nM2", reader="linuxcnc")
    np.testing.assert_allclose(tp.end_mm, [[25.4, 50.8, 0.0], [0.0, 50.8, 0.0]])
    assert tp.feed_mm_s == pytest.approx([10 * 25.4 / 60] * 2, rel=1e-12)
    assert tp.path_mode.tolist() == [PathMode.DEFAULT, PathMode.BLEND]
    assert tp.blend_tol_mm[1] == pytest.approx(0.0254, rel=1e-12)


def test_reference_points_are_the_interpreters_parameters(linuxcnc_interpreter):
    """g28_reference_mm and g30_reference_mm are written to #5161-#5163 and #5181-#5183 (mm,
    machine coordinates): G28 Z0 in G91 rises from where it is to the G28 point's Z; G30 with no
    axis word goes to the G30 point; under a G92 offset the points stay where they are."""
    text = "G0 X1 Y2 Z3\nG91 G28 Z0\nG90 G92 X0\nG30\nM2"
    tp = parse(text, reader="linuxcnc", g28_reference_mm=(10, 20, 30), g30_reference_mm=(4, 5, 6))
    np.testing.assert_allclose(tp.end_mm, [[1, 2, 3], [1, 2, 3], [1, 2, 30], [1, 2, 30], [4, 5, 6]])
    assert tp.line.tolist() == [1, 2, 2, 4, 4]
    assert (tp.kind == MotionKind.RAPID).all()


# ---------------------------------------------------------------------------------------------
# Bad input: one line, file:line: reason
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("G0 X1\nG0 A10\nM2", 2, "Bad character 'a' used: the A axis is not on this machine"),
        ("G1 X1 F100\nG1 W3\nM2", 2, "Bad character 'w' used: the W axis is not on this"),
        ("M3 S100\nG33 Z-1 K0.1\nM2", 2, "G33 is spindle-synchronised motion: not read"),
        ("M3 S100\nG33.1 Z-1 K0.1\nM2", 2, r"rigid tapping \(G33.1\) is spindle-synchronised"),
        ("M3 S100\nG0 X1 Z1\nG76 P0.1 Z-1 I-0.05 J0.05 K0.1\nM2", 3, "G76 is spindle-synch"),
        ("G0 X1\no<nosuch> call\nM2", 2, "subroutine o<nosuch> not found: no file nosuch.ngc"),
        ("G0 X1\n#1=[1/0]\nG0 X#1\nM2", 2, "Attempt to divide by zero"),
        ("G0 X1\nG93 G1 X2 F1\nM2", 2, r"inverse-time feed \(G93\) is not read"),
        ("G38.2 Z-1 F10\nM2", 1, r"probing \(G38.n\) has no tool path without a probe"),
    ],
)
def test_refusals_name_line_and_reason(linuxcnc_interpreter, text, line, reason):
    with pytest.raises(GCodeError, match=f"^<string>:{line}: {reason}") as err:
        parse(text, reader="linuxcnc", source=None)
    assert "\n" not in str(err.value)


def test_endless_loop_stops_at_the_move_limit(linuxcnc_interpreter):
    text = "o100 while [1]\nG1 X1 F10\nG1 X0\no100 endwhile\nM2"
    with pytest.raises(GCodeError, match=r"^<string>:[23]: more than 1000 canonical moves"):
        parse(text, reader="linuxcnc", max_moves=1000)


def test_endless_loop_without_moves_stops_at_the_time_limit(linuxcnc_interpreter):
    """The interpreter checks its clock about every 2 s: with 8 s it stops itself in time."""
    t0 = time.monotonic()
    with pytest.raises(GCodeError, match=r"^<string>:\d+: .* time limit of 8 s"):
        parse("o100 while [1]\no100 endwhile\nM2", reader="linuxcnc", timeout_s=8.0)
    assert time.monotonic() - t0 < 8.0


def test_interpreter_is_killed_at_the_time_limit(linuxcnc_interpreter, monkeypatch):
    monkeypatch.setattr(_interp, "_CHILD_MARGIN_S", -100.0)  # the child would not stop itself
    t0 = time.monotonic()
    with pytest.raises(GCodeError, match="did not finish within 2 s and was stopped"):
        parse("o100 while [1]\no100 endwhile\nM2", reader="linuxcnc", timeout_s=2.0)
    assert time.monotonic() - t0 < 3.5


def test_time_limit_grows_with_the_file():
    assert _interp.timeout_for(0) == _interp.TIMEOUT_BASE_S
    assert _interp.timeout_for(2_000_000) == pytest.approx(
        _interp.TIMEOUT_BASE_S + 2 * _interp.TIMEOUT_S_PER_MB
    )


def test_binary_file(linuxcnc_interpreter, tmp_path):
    path = tmp_path / "part.bin"
    path.write_bytes(b"G0 X1\n" + bytes(range(256)))
    with pytest.raises(GCodeError, match=r"part.bin:2: binary data \(NUL bytes\)"):
        parse_file(path, reader="linuxcnc")


def test_missing_subroutine_file_is_looked_up_beside_the_program(linuxcnc_interpreter, tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "square.ngc").write_text(
        "o<square> sub\nG1 X#1 F60\no<square> endsub\nM2\n"
    )
    program = tmp_path / "sub" / "main.ngc"
    program.write_text("o<square> call [4]\no<circle> call\nM2\n")
    with pytest.raises(GCodeError, match=r"main.ngc:2: subroutine o<circle> not found"):
        parse_file(program)
    program.write_text("o<square> call [4]\nM2\n")
    result = read_file(program)
    assert result.reader == "linuxcnc"
    np.testing.assert_allclose(result.toolpath.end_mm, [[4, 0, 0]])


def test_without_linuxcnc(monkeypatch):
    monkeypatch.setattr(_interp, "LINUXCNC_PYTHON", "/nonexistent/python3")
    interpreter_available.cache_clear()
    try:
        assert not interpreter_available()
        with pytest.raises(GCodeError, match=r"^<string>:0: .*run make linuxcnc$"):
            parse("G0 X1\nM2", reader="linuxcnc")
        with pytest.raises(GCodeError, match=r"O-word .* needs LinuxCNC's interpreter"):
            parse("o100 sub\no100 endsub\nM2")  # auto: the native error stands
    finally:
        monkeypatch.undo()
        interpreter_available.cache_clear()


def test_bad_reader_arguments():
    with pytest.raises(ValueError, match=r"reader = 'rs274' is not allowed: allowed 'native'"):
        parse("G0 X1", reader="rs274")
    with pytest.raises(GCodeError, match=r"tool table t\.tbl: No such file"):
        parse("G0 X1", reader="native", tool_table="t.tbl")
    with pytest.raises(ValueError, match="dwell_p_unit = 'ms' is not allowed with reader='lin"):
        parse("G0 X1", reader="linuxcnc", dwell_p_unit="ms")


def test_auto_reports_the_reader(linuxcnc_interpreter):
    assert read("G0 X1\nG1 Y1 F60").reader == "native"
    result = read("#1=2\nG0 X#1\nM2")
    assert result.reader == "linuxcnc"
    np.testing.assert_allclose(result.toolpath.end_mm, [[2, 0, 0]])
    with pytest.raises(GCodeError, match="axis A is not supported"):
        read("G0 X1 A2")  # the native reader refuses rotary axes itself: its error stands


def test_a_tool_table_is_completed_only_where_no_size_is_needed():
    table = "T1 P1 D0 Z0 ;\nT5 P7 D6 Z1 ;\n"
    # T2 and T9 are added after the largest pocket (7), of size 0; T0 and T1 are not
    assert complete_tool_table(table, "T2 M6\nT0\n(T3 in a comment)\nT1 G1 X1\nT9\n") == (
        table + "T2 P8 D0 Z0 ;not in the table\nT9 P9 D0 Z0 ;not in the table\n"
    )
    # cutter compensation or a length offset needs the table's sizes: nothing is added
    for code in ("G41 D2", "G42", "G43 H2", "G43.2 H2", "G041"):
        assert complete_tool_table(table, f"T2 M6\n{code} G1 X1\n") == table
    # dynamic compensation and offsets carry their size in the block; GT is an operator
    for code in ("G41.1 D4", "G43.1 Z2", "O100 if [#1 GT 2]"):
        assert complete_tool_table(table, f"T2 M6\n{code}\n") != table
    assert complete_tool_table("T1 P1 D0 Z0 ;", "T2") == (
        "T1 P1 D0 Z0 ;\nT2 P2 D0 Z0 ;not in the table\n"
    )


def test_linuxcnc_reads_a_tool_its_table_lacks(linuxcnc_interpreter):
    tp = parse("G21 G90 F600\nT4 M6\nG1 X10\nM2\n", reader="linuxcnc")
    assert tp.end_mm[-1].tolist() == [10.0, 0.0, 0.0]
    with pytest.raises(GCodeError, match=r"Requested tool 4 not found.*G41, G42, G43"):
        parse("G21 G90 F600\nT4 M6\nG41 D4 G1 X10 Y5\nG1 X20\nM2\n", reader="linuxcnc")
