"""The fanuc dialect of the reader (M29 rigid tapping, G76 fine boring, P in milliseconds), and a
machine profile's ``dialect`` key as ``nctwin estimate`` reads it. The expected moves are worked
out by hand from the cycle's description in nctwin.gcode._cycles (after Fanuc's manuals)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from nctwin import GCodeError, MotionKind, parse
from nctwin.cli import main
from nctwin.gcode import DIALECTS, interpreter_available, read
from nctwin.machine import Profile, load_profile, profile_path
from nctwin.programs.iso10791 import shipped_test_piece_path

R, F, D = MotionKind.RAPID, MotionKind.LINEAR, MotionKind.DWELL


def moves(tp, first=0):
    """(kind, x, y, z) of each block from ``first`` on."""
    return [
        (int(k), *map(float, e)) for k, e in zip(tp.kind[first:], tp.end_mm[first:], strict=True)
    ]


def fanuc(text: str, **kwargs):
    return parse(text, dialect="fanuc", source="part.nc", **kwargs)


# --- G76: fine boring ----------------------------------------------------------------------------
G76 = "G0 X0 Y0 Z10\nM3 S800 F60\n{mode} G76 X10 Y5 R2 Z-3 Q0.5 P1500\nG80\nM30\n"


def test_g76_g98_bores_dwells_shifts_out_to_the_initial_level_and_back():
    tp = fanuc(G76.format(mode="G98"))
    # over the hole at the initial level Z10, down to R2, feed to Z-3, dwell P1500 ms = 1.5 s,
    # shift +Q 0.5 along X at the bottom, rapid out to Z10 (G98), shift back to X10
    assert moves(tp, 1) == [
        (R, 10, 5, 10),
        (R, 10, 5, 2),
        (F, 10, 5, -3),
        (D, 10, 5, -3),
        (R, 10.5, 5, -3),
        (R, 10.5, 5, 10),
        (R, 10, 5, 10),
    ]
    assert list(tp.line) == [1] + [3] * 7
    np.testing.assert_allclose(tp.dwell_s, [0, 0, 0, 0, 1.5, 0, 0, 0])
    # the one feed: 5 mm (Z2 to Z-3) at F60 = 1 mm/s, 5 s
    assert tp.lengths_mm[3] / tp.feed_mm_s[3] == pytest.approx(5.0)
    # rapids: 10 up, hypot(10, 5) over, 8 down, 0.5 shift, 13 out, 0.5 back
    rapids = tp.lengths_mm[tp.kind == R]
    np.testing.assert_allclose(rapids, [10, np.hypot(10, 5), 8, 0.5, 13, 0.5])


def test_g76_g99_comes_out_to_r():
    tp = fanuc(G76.format(mode="G99"))
    assert moves(tp, 1)[-3:] == [(R, 10.5, 5, -3), (R, 10.5, 5, 2), (R, 10, 5, 2)]
    assert moves(fanuc(G76.format(mode=""))) == moves(tp)  # retract mode starts as G99


def test_g76_l_repeats_under_g91_step_from_hole_to_hole():
    # G91: R from the initial level (5 - 3 = 2), Z from R (2 - 4 = -2); two holes 10 mm apart,
    # each shifted by Q1 (its sign ignored) at the bottom; no P: no dwell
    tp = fanuc("G0 X0 Y0 Z5\nM3 S800\nG91 G99 G76 X10 R-3 Z-4 Q-1 L2 F60\nG80")
    expected = [(R, 10, 0, 5), (R, 10, 0, 2)]
    expected += [(F, 10, 0, -2), (R, 11, 0, -2), (R, 11, 0, 2), (R, 10, 0, 2)]
    expected += [(R, 20, 0, 2), (F, 20, 0, -2), (R, 21, 0, -2), (R, 21, 0, 2), (R, 20, 0, 2)]
    assert moves(tp, 1) == expected


def test_g76_needs_q_and_is_refused_in_the_default_dialect():
    with pytest.raises(GCodeError, match=r"^part\.nc:2: Q word \(the shift at the bottom\) m"):
        fanuc("G0 Z5\nG76 X1 R1 Z-1 F60")
    with pytest.raises(GCodeError, match=r"^<string>:1: G76 threading cycle needs LinuxCNC's"):
        parse("G76 X1 R1 Z-1 Q1 F60", reader="native")


# --- M29: rigid tapping --------------------------------------------------------------------------
TAP = "G0 X0 Y0 Z10\nM3 S500 F100\n{m29}\nG99 G84 X5 Y5 R2 Z-5 P200\nX8\nG80\nG0 Z20\n"


def test_g84_after_m29_moves_as_without_it():
    rigid, floating = fanuc(TAP.format(m29="M29 S500")), fanuc(TAP.format(m29=""))
    assert moves(rigid) == moves(floating)
    # one hole: over at Z10, down to R2, feed 7 mm to Z-5, dwell P200 ms, feed back to R2
    assert moves(rigid, 1)[:5] == [
        (R, 5, 5, 10),
        (R, 5, 5, 2),
        (F, 5, 5, -5),
        (D, 5, 5, -5),
        (F, 5, 5, 2),
    ]
    np.testing.assert_array_equal(rigid.dwell_s, floating.dwell_s)
    assert rigid.dwell_s[4] == pytest.approx(0.2)
    np.testing.assert_array_equal(rigid.feed_mm_s, floating.feed_mm_s)
    assert ("M", 29.0) in zip(rigid.events["word"], rigid.events["value"], strict=True)


def test_rigid_tapping_needs_no_turning_spindle_until_g80():
    # the control turns the spindle in rigid tapping; after G80, a floating tap needs it turning
    text = "G0 X0 Y0 Z10\nF100\nM29 S500\nG84 X5 R2 Z-5\nX8\nG80\nG84 X9 R2 Z-5\n"
    with pytest.raises(GCodeError, match=r"^part\.nc:7: spindle not turning in G84$"):
        fanuc(text)
    # without it: the G0, then 5 blocks at X5 (over, to R, feed in, dwell 0 s, feed out) and 4
    # at X8 (over at R, feed in, dwell, feed out)
    rigid = fanuc(text.replace("G84 X9 R2 Z-5\n", ""))
    assert [int(k) for k in rigid.kind] == [R, R, R, F, D, F, R, F, D, F]


def test_m29_before_a_cycle_other_than_tapping_is_refused_in_one_line():
    with pytest.raises(GCodeError) as info:
        fanuc("G0 X0 Y0 Z10\nM3 S500 F100\nM29 S500\nG81 X5 R2 Z-5\nG80\n")
    assert str(info.value) == (
        "part.nc:4: G81 after M29 (rigid tapping, line 3): M29 must be followed by G84 or G74"
    )
    # a G80 between them cancels the M29
    assert len(fanuc("G0 Z10\nM3 S500 F100\nM29 S500\nG80\nG81 X5 R2 Z-5\nG80\n").kind) == 5


def test_m29_in_the_default_dialect_is_read_as_today():
    text = "G0 X0 Y0 Z10\nM3 S500 F100\nM29 S500\nG84 X5 R2 Z-5\nG80\n"
    # the native reader keeps an M-code it does not know as an event, as before
    tp = parse(text, reader="native")
    assert ("M", 29.0) in zip(tp.events["word"], tp.events["value"], strict=True)
    if not interpreter_available():
        pytest.skip("LinuxCNC's interpreter is not installed (make linuxcnc)")
    with pytest.raises(GCodeError, match=r"^part\.nc:3: Unknown m code used: M29$"):
        parse(text, reader="linuxcnc", source="part.nc")


# --- P in milliseconds, the default dialect, bad values ----------------------------------------
def test_p_is_in_milliseconds_unless_dwell_p_unit_says_otherwise():
    assert fanuc("G4 P1500").dwell_s[0] == pytest.approx(1.5)
    assert fanuc("G0 Z5\nG82 X1 R2 Z-1 P250 F60").dwell_s[-2] == pytest.approx(0.25)
    assert fanuc("G4 P2", dwell_p_unit="s").dwell_s[0] == 2.0
    assert parse("G4 P2").dwell_s[0] == 2.0  # the default dialect: seconds


def test_the_default_dialect_reads_a_program_as_before():
    text = shipped_test_piece_path().read_text()
    default, named = parse(text), parse(text, dialect="rs274ngc")
    for field in ("start_mm", "end_mm", "kind", "feed_mm_s", "dwell_s", "line", "path_mode"):
        np.testing.assert_array_equal(getattr(default, field), getattr(named, field))
    # a program only LinuxCNC's interpreter reads still goes to it in the default dialect only
    assert read("G0 X1", reader="auto", dialect="fanuc").reader == "native"


def test_an_unknown_dialect_is_refused_naming_the_parameter_and_the_allowed_values():
    assert DIALECTS == ("rs274ngc", "fanuc")
    for reader in ("native", "auto", "linuxcnc"):
        with pytest.raises(ValueError, match=r"^dialect = 'haas' is not allowed: allowed "
                           r"'rs274ngc', 'fanuc'$"):  # fmt: skip
            parse("G0 X1", dialect="haas", reader=reader)
    with pytest.raises(ValueError, match=r"^dialect = 'fanuc' is not allowed with reader='linux"):
        parse("G0 X1", dialect="fanuc", reader="linuxcnc")


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("G0 Z5\nG87 X1 R1 Z-1 Q1 F60", "G87 (back boring, which a Fanuc control runs with a Q"),
        ("G92.1", "G92.1 (workpiece coordinate system preset on a Fanuc control) is not supp"),
        ("G5.1 Q1", "G5.1 (AI contour control) is not supported in the fanuc dialect"),
        ("M98 P100", "M98 (subprogram call) is not supported in the fanuc dialect"),
        ("G0 Z5\nG81 X1 R1 Z-1 K3 F60", "K (the repeats of a Fanuc canned cycle) is not suppo"),
        ("#1=2", "#-parameter is not supported in the fanuc dialect"),
    ],
)
def test_fanuc_codes_not_read_are_refused_in_one_line(text, reason):
    with pytest.raises(GCodeError) as info:
        fanuc(text)
    assert len(info.value.errors) == 1
    n = text.count("\n") + 1
    assert str(info.value).startswith(f"part.nc:{n}: {reason}")


# --- the profile's dialect -----------------------------------------------------------------------
def _profile(tmp_path, dialect: str):
    toml = tmp_path / "fanuc_mill.toml"
    base = profile_path("generic_mill").read_text()
    toml.write_text(f'dialect = "{dialect}"\n{base}')
    return toml


def test_a_profile_reads_its_dialect_and_estimate_uses_it(tmp_path, capsys):
    assert load_profile("generic_mill").dialect == "rs274ngc"  # the default
    toml = _profile(tmp_path, "fanuc")
    assert Profile.from_toml(toml).dialect == "fanuc"
    prog = tmp_path / "bore.nc"
    prog.write_text(G76.format(mode="G98"))
    code = main(["estimate", str(prog), "--machine", str(toml), "--method", "cam", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["reader"] == "native"
    # the feed of 5 mm at 1 mm/s and the dwell of 1.5 s (P1500 in ms), as by hand above
    assert out["by_kind"]["linear"]["time_s"] == pytest.approx(5.0)
    assert out["by_kind"]["dwell"]["time_s"] == pytest.approx(1.5)
    assert out["by_kind"]["rapid"]["length_mm"] == pytest.approx(10 + np.hypot(10, 5) + 22)
    # the same program on the default profile: G76 is not fine boring there
    assert main(["estimate", str(prog), "--reader", "native"]) == 2
    assert "G76 threading cycle" in capsys.readouterr().err


def test_a_profile_with_a_bad_dialect_is_refused_in_one_line(tmp_path, capsys):
    toml = _profile(tmp_path, "heidenhain")
    with pytest.raises(ValueError, match="dialect = 'heidenhain' is out of range: allowed "):
        Profile.from_toml(toml)
    prog = tmp_path / "part.nc"
    prog.write_text("G0 X1\n")
    assert main(["estimate", str(prog), "--machine", str(toml)]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"nctwin: {toml}: dialect = 'heidenhain' is out of range: allowed 'rs274ngc', 'fanuc'\n"
    )
