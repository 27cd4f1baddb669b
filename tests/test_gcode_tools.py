"""The tool table: LinuxCNC's sim table as ``linuxcnc_sim``'s, the native reader's tool length
offsets (G43 H, G49) beside LinuxCNC's interpreter, and programs whose tools no table lists."""

from __future__ import annotations

import json

import numpy as np
import pytest

from nctwin.cli import main
from nctwin.gcode import GCodeError, complete_tool_table, parse, read
from nctwin.machine import Profile, load_profile, read_tool_table
from nctwin.paths import public_programs_dir

SIM = load_profile("linuxcnc_sim").tool_table


def test_the_sim_profiles_table_is_linuxcncs_sim_mm_table():
    # sim_mm.tbl as LinuxCNC ships it: 24 tools, T1 the 3 mm end mill 0.511 mm long, T4 the
    # 16 mm one 10 mm long, T6-T24 of diameter and length n mm
    assert SIM.tools == tuple(range(1, 25))
    assert SIM.offset_of(1) == (0.0, 0.0, 0.511)
    assert SIM.diameter_mm[:5] == (3.0, 1.5, 5.0, 16.0, 25.0)
    assert [o[2] for o in SIM.offset_mm[:5]] == [0.511, 0.1, 1.273, 10.0, 25.0]
    assert all(SIM.diameter_mm[n - 1] == SIM.offset_mm[n - 1][2] == n for n in range(6, 25))
    shipped = public_programs_dir() / "tool_tables" / "sim_mm.tbl"
    assert SIM.text == shipped.read_text(encoding="utf-8")
    assert SIM.offset_of(0) == (0.0, 0.0, 0.0) and SIM.offset_of(25) is None
    # the other machines keep the readers' own table
    assert load_profile("generic_mill").tool_table is None


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("T1 P1 Z1\nT2 P2 Z0.5 E3\n", "t.tbl:2: cannot read 'E3'"),
        ("T1 P1 Z1\n\n; note\nP3 Z2\n", "t.tbl:4: no tool number"),
        ("T1 P1 Z1\nT1 P2 Z2 ;again\n", "t.tbl:2: tool 1 listed twice"),
        ("T1 P1 Z1 Z2\n", "t.tbl:1: Z given twice"),
        ("T1 P1 D-3\n", "t.tbl:1: diameter D must be >= 0"),
    ],
)
def test_a_bad_table_line_is_named(text, reason):
    with pytest.raises(ValueError, match=f"^{reason}"):
        read_tool_table(text, "t.tbl")


def test_a_bad_table_is_one_line_on_the_command_line(tmp_path, capsys):
    prog, table = tmp_path / "p.ngc", tmp_path / "t.tbl"
    prog.write_text("G1 X10 F600\nM2\n")
    table.write_text("T1 P1 Z0.5\nT2 P2 Z=4\n")
    assert main(["estimate", str(prog), "--tool-table", str(table)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"nctwin: {table}:2: cannot read 'Z=4'") and "\n" not in err


def test_a_profile_names_its_table_beside_it(tmp_path):
    (tmp_path / "tools.tbl").write_text("T3 P1 Z2.5 D6 ;\n")
    profile = tmp_path / "m.toml"
    limits = """[machine]
axis_max_velocity_mm_s = [100.0, 100.0, 100.0]
axis_max_acceleration_mm_s2 = [1000.0, 1000.0, 1000.0]
axis_max_jerk_mm_s3 = [inf, inf, inf]
rapid_feed_mm_s = 100.0
max_feed_mm_s = 100.0
"""
    profile.write_text('tool_table = "tools.tbl"\n' + limits)
    assert Profile.from_toml(profile).tool_table.offset_of(3) == (0.0, 0.0, 2.5)
    profile.write_text('tool_table = "none.tbl"\n' + limits)
    with pytest.raises(ValueError, match=r"m\.toml: tool_table: cannot read .*none\.tbl"):
        Profile.from_toml(profile)


def test_g43_h1_offsets_by_the_sims_tool_1_on_the_native_reader():
    # G43 shifts the program's coordinates, not the tool: the tool moves by 0.511 mm at the next
    # absolute Z, and an incremental one or a move without Z keeps the machine's Z
    text = "G0 Z5\nG43 H1\nG0 X1\nG0 Z2\nG91 G0 Z1\nG90 G49\nG0 X2\nG0 Z2\nM2\n"
    tp = parse(text, reader="native", tool_table=SIM)
    np.testing.assert_allclose(tp.end_mm[:, 2], [5, 5, 2.511, 3.511, 3.511, 2], atol=1e-12)
    # without a table (every other machine) the offsets are 0, as before
    np.testing.assert_allclose(parse(text, reader="native").end_mm[:, 2], [5, 5, 2, 3, 3, 2])


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_the_native_offsets_are_linuxcncs():
    text = (
        "G21 G90\nG0 Z5\nG43 H1\nG0 X1\nG0 Z2\nG91 G0 Z1\nG90 G49\nG0 X2\nG0 Z2\n"
        "G43 H4 G0 Z3\nG28\nG0 X1\nG92 Z0\nG0 Z1\nG20 G43 H2\nG0 Z1 X0\nM2\n"
    )
    native = parse(text, reader="native", tool_table=SIM)
    interp = parse(text, reader="linuxcnc", tool_table=SIM)
    np.testing.assert_allclose(native.end_mm, interp.end_mm, atol=1e-9)
    np.testing.assert_allclose(native.start_mm, interp.start_mm, atol=1e-9)
    assert native.end_mm[2, 2] == pytest.approx(2.511, abs=1e-12)


def test_what_the_native_reader_leaves_to_the_interpreter():
    with pytest.raises(GCodeError, match=r"G43 H7: tool 7 is not in the machine's tool table"):
        parse("G43 H7\nG0 Z1\nM2", reader="native", tool_table=read_tool_table("T1 P1 Z1\n"))
    for text in ("G43\nG0 Z1\nM2", "G43 H1\nG81 X1 Z-1 R1 F60\nM2"):
        with pytest.raises(GCodeError, match="needs LinuxCNC's interpreter"):
            parse(text, reader="native", tool_table=SIM)


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_a_tool_no_table_lists_is_still_estimated(tmp_path, capsys):
    # T99 is in no table: without a length offset or compensation it runs with size 0, on the
    # sim's table too (the interpreter reads the parameter)
    text = "#1=10\nT99 M6\nG1 X#1 F600\nM2\n"
    assert "T99 P25 D0 Z0 ;not in the table" in complete_tool_table(SIM.text, text)
    result = read(text, tool_table=SIM)
    assert result.reader == "linuxcnc"
    np.testing.assert_allclose(result.toolpath.end_mm, [[10, 0, 0]])
    prog = tmp_path / "t99.ngc"
    prog.write_text(text)
    args = ["estimate", str(prog), "--machine", "linuxcnc_sim", "--method", "cam", "--json"]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["reader"] == "linuxcnc" and out["cycle_time_s"] == pytest.approx(1.0)


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_m6_puts_its_tool_in_the_spindle():
    # the sim table's T2: D1.5, Z0.1. After T2 M6, G43 without H offsets by 0.1 mm and G41
    # without D offsets the path by the radius, 0.75 mm, as LinuxCNC's iocontrol loads it
    text = "G21 G90\nT2 M6\nG43\nG0 X0 Y0 Z5\nG41 G1 X10 Y0 F600\nG1 Y10\nG40 G1 X20 Y20\nM2\n"
    tp = parse(text, tool_table=SIM)
    np.testing.assert_allclose(tp.end_mm[:4], [[0, 0, 5.1], [9.25, 0.75, 5.1], [9.25, 10, 5.1],
                                               [20, 20, 5.1]], atol=1e-9)  # fmt: skip
    same = text.replace("G43\n", "G43 H2\n").replace("G41 ", "G41 D2 ")
    np.testing.assert_allclose(parse(same, tool_table=SIM).end_mm, tp.end_mm, atol=1e-12)
    # T0 M6 empties the spindle: size 0
    empty = parse(text.replace("T2 M6", "T2 M6\nT0 M6"), tool_table=SIM)
    np.testing.assert_allclose(empty.end_mm[1], [10, 0, 5], atol=1e-9)


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_the_tool_m61_sets_is_named_or_refused():
    # M61 calls nothing LinuxCNC's preview module passes on: a G41 without D after it would be
    # read with the old tool's size where LinuxCNC runs T1's 3 mm, so it is refused at its line
    text = "G21 G90\nM61 Q1\nG41 G1 X10 Y5 F600 (comp on)\nG1 X20\nG40 G1 X30\nM2\n"
    with pytest.raises(GCodeError, match=r":3: G41/G42 without D and G43 without H take the size"):
        parse(text, tool_table=SIM)
    named = parse(text.replace("G41 ", "G41 D1 "), tool_table=SIM)
    assert named.lengths_mm.sum() != pytest.approx(parse(text).lengths_mm.sum(), abs=1e-3)
    # with nctwin's own table every tool has size 0: nothing depends on the spindle's tool
    assert len(parse(text)) == 3
