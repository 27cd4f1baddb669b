"""The command line: output, JSON, exit codes and one-line errors."""

from __future__ import annotations

import io
import json
import subprocess
import sys

import numpy as np
import pytest

from nctwin.cli import main

PROGRAM = "G21 G90\nG0 Z5\nG1 Z0 F600\nX30\nM30\n"


@pytest.fixture
def program(tmp_path):
    p = tmp_path / "part.nc"
    p.write_text(PROGRAM)
    return p


def test_estimate_prints_time_length_blocks_and_kinds(program, capsys):
    assert main(["estimate", str(program)]) == 0
    out = capsys.readouterr().out
    assert "cycle time" in out and "path length  40.000 mm" in out and "blocks       3" in out
    assert "linear" in out and "rapid" in out


def test_estimate_json(program, capsys):
    args = ["estimate", str(program), "--json", "--machine", "linuxcnc_sim", "--method", "cam"]
    assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["method"] == "cam" and data["machine"] == "linuxcnc_sim"
    assert data["blocks"] == 3
    assert data["length_mm"] == pytest.approx(40.0)
    # 5 mm rapid at 200 mm/s + 35 mm at 10 mm/s
    assert data["cycle_time_s"] == pytest.approx(5 / 200 + 3.5)


def test_estimate_default_method_is_the_profiles(program, capsys):
    # linuxcnc_sim's default_method is its chapter's best method, the blend-arc planner.
    # LinuxCNC by hand: the 5 mm Z rapid is a triangle at Z's 500 mm/s^2, 2 sqrt(5 / 500) =
    # 0.2 s; then 5 mm and 30 mm at 10 mm/s with near-stops at the corners (0.0254 mm
    # tolerance), each plus F / a: 0.5 + 0.02 + 3.0 + 0.01 = 3.53 s; 3.73 s in all (LinuxCNC
    # recorded 3.71 s).
    assert main(["estimate", str(program), "--json", "--machine", "linuxcnc_sim"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["method"] == "planner"
    assert data["cycle_time_s"] == pytest.approx(3.73, rel=0.05)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["bilstm", "axis_nn"])
def test_estimate_with_the_linuxcnc_networks(program, capsys, method):
    # trained once from the shipped recordings (then loaded from data/cache/models)
    args = ["estimate", str(program), "--json", "--machine", "linuxcnc_sim", "--method", method]
    assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["method"] == method
    assert data["cycle_time_s"] == pytest.approx(3.73, rel=0.25)


def test_bad_program_gives_file_line_reason_and_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.nc"
    bad.write_text("G0 X0\nG1 X1\n")
    assert main(["estimate", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"{bad}:2: G1 with no feed rate set (F)"]


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["estimate", "/no/such/file.nc"], "/no/such/file.nc: cannot read the file"),
        (["estimate", "{prog}", "--machine", "nope"], "machine = 'nope' is unknown"),
    ],
)
def test_bad_arguments_exit_2_without_traceback(program, capsys, args, needle):
    args = [a.replace("{prog}", str(program)) for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err


def test_installed_entry_point_runs(program):
    proc = subprocess.run(
        [sys.executable, "-m", "nctwin.cli", "estimate", str(program), "--json"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["blocks"] == 3


def test_machines_lists_profiles(capsys):
    assert main(["machines"]) == 0
    assert "generic_mill" in capsys.readouterr().out


def test_simulate_writes_plot_and_csv(program, tmp_path, capsys):
    png, csv = tmp_path / "feed.png", tmp_path / "motion.csv"
    assert main(["simulate", str(program), "--plot", str(png), "--csv", str(csv), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cycle_time_s"] > 0 and data["samples"] > 100
    assert png.stat().st_size > 1000
    header = csv.read_text().splitlines()[0]
    assert header.startswith("t_s,x_mm,y_mm,z_mm")


def test_kernel_estimate_is_slower_than_cam(program, capsys):
    assert main(["estimate", str(program), "--json"]) == 0
    cam = json.loads(capsys.readouterr().out)["cycle_time_s"]
    assert main(["estimate", str(program), "--json", "--method", "kernel"]) == 0
    kernel = json.loads(capsys.readouterr().out)
    assert kernel["method"] == "kernel"
    assert kernel["cycle_time_s"] > cam


# --- ordinary input, as a user meets it: one line on stderr, exit code 2 -----------------------


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize("text", ["", "(only a comment)\n; and another\n%\n", "G21 G90\nM30\n"])
@pytest.mark.parametrize("command", [["estimate"], ["estimate", "--json"], ["simulate"]])
def test_a_program_without_motion_is_an_error(tmp_path, capsys, text, command):
    prog, png = tmp_path / "empty.nc", tmp_path / "f.png"
    prog.write_text(text)
    args = [command[0], str(prog), *command[1:]]
    if command == ["simulate"]:
        args += ["--plot", str(png)]
    assert main(args) == 2
    assert _one_line_error(capsys) == f"{prog}: no motion"
    assert not png.exists()


def test_a_dwell_alone_is_timed(tmp_path, capsys):
    prog = tmp_path / "dwell.nc"
    prog.write_text("G4 P1.5\n")
    assert main(["estimate", str(prog), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["cycle_time_s"] == pytest.approx(1.5)


def _stdin(monkeypatch, text: str) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(text.encode())))


def test_estimate_reads_standard_input(monkeypatch, capsys):
    _stdin(monkeypatch, PROGRAM)
    assert main(["estimate", "-", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["program"] == "<stdin>"
    # 5 mm rapid at 500 mm/s + 35 mm at 10 mm/s (generic_mill, cam)
    assert data["cycle_time_s"] == pytest.approx(5 / 500 + 3.5)


def test_errors_on_standard_input_name_it(monkeypatch, capsys):
    _stdin(monkeypatch, "G0 X0\nG1 X1\n")
    assert main(["estimate", "-"]) == 2
    assert _one_line_error(capsys) == "<stdin>:2: G1 with no feed rate set (F)"
    _stdin(monkeypatch, "")
    assert main(["simulate", "-"]) == 2
    assert _one_line_error(capsys) == "<stdin>: no motion"


def test_machine_file_with_missing_keys_names_them(program, tmp_path, capsys):
    toml = tmp_path / "bad.toml"
    toml.write_text('[machine]\ndescription = "half a machine"\nrapid_feed_mm_s = 500.0\n')
    assert main(["estimate", str(program), "--machine", str(toml)]) == 2
    line = _one_line_error(capsys)
    assert line.startswith(f"nctwin: {toml}: [machine] missing key(s) ")
    assert "axis_max_velocity_mm_s" in line and "max_feed_mm_s" in line
    assert "rapid_feed_mm_s" not in line


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["estimate", "/no/such/file.nc"], "/no/such/file.nc: cannot read the file: "),
        (["estimate", "{dir}"], "{dir}: is a directory, not a program"),
        (["estimate", "{bin}"], "{bin}: binary data (NUL bytes), not a G-code program"),
        (["estimate", "{prog}", "--machine", "nope"], "nctwin: machine = 'nope' is unknown"),
        (["estimate", "{prog}", "--machine", "{badtoml}"], "nctwin: machine profile {badtoml}"),
        (["estimate", "{prog}", "--method", "nope"], "nctwin: argument --method: invalid choice"),
        (["estimate"], "nctwin: the following arguments are required: program"),
        (["simulate", "{prog}", "--units", "furlong"], "nctwin: argument --units: invalid"),
        (["simulate", "{prog}", "--plot", "{dir}/no/f.png"], "nctwin: {dir}/no/f.png: No such"),
        (
            ["estimate", "{prog}", "--method", "bilstm"],
            "nctwin: recordings = None of machine profile generic_mill names no shipped recordings",
        ),
        (
            ["estimate", "{prog}", "--machine", "paper1_sim", "--method", "planner"],
            "nctwin: "
            "method 'planner' needs a control: machine profile paper1_sim has no [control.planner]",
        ),
        (
            [
                "calibrate",
                "--recordings",
                "mtconnect",
                "--machine",
                "linuxcnc_sim",
                "--output",
                "{dir}/x.toml",
            ],
            "nctwin: recordings = 'mtconnect' is not the machine's: allowed 'linuxcnc'",
        ),
    ],
)
def test_ordinary_mistakes_give_one_line_and_exit_2(program, tmp_path, capsys, args, expected):
    binary = tmp_path / "part.bin"
    binary.write_bytes(bytes(range(256)) * 4)
    badtoml = tmp_path / "syntax.toml"
    badtoml.write_text("description = \n")
    names = {"{prog}": program, "{dir}": tmp_path, "{bin}": binary, "{badtoml}": badtoml}

    def fill(s: str) -> str:
        for key, value in names.items():
            s = s.replace(key, str(value))
        return s

    assert main([fill(a) for a in args]) == 2
    assert _one_line_error(capsys).startswith(fill(expected))


@pytest.mark.parametrize("command", [[], ["estimate"], ["simulate"], ["machines"]])
def test_help_is_plain_text_with_examples(capsys, command):
    assert main([*command, "--help"]) == 0
    out = capsys.readouterr().out
    assert "``" not in out and ":func:" not in out and ":mod:" not in out
    if command != ["machines"]:
        assert "examples:" in out
        assert "nctwin " + (command[0] if command else "estimate") + " part.nc" in out


# --- progress: a bar on a terminal only --------------------------------------------------------


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_no_progress_output_in_a_pipe(program, capsys):
    assert main(["estimate", str(program), "--method", "kernel"]) == 0
    assert capsys.readouterr().err == ""


def test_progress_bar_on_a_terminal_but_not_with_json(program, capsys, monkeypatch):
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    assert main(["simulate", str(program)]) == 0
    assert "simulate (FIR kernel)" in term.getvalue()
    assert "cycle time" in capsys.readouterr().out
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    assert main(["estimate", str(program), "--json"]) == 0
    assert term.getvalue() == ""
    json.loads(capsys.readouterr().out)


# --- learned estimates never below the physical floor ------------------------------------------


#: A 20 mm Z rapid (LinuxCNC sim: rapid 200 mm/s, Z at most 100 mm/s: 0.2 s), then a 100 mm
# --- a profile is its file's content, not its name ---------------------------------------------
def _profile_methods():
    from nctwin.machine import METHOD_CONTROLS, available_machines, load_profile

    for name in available_machines():
        profile = load_profile(name)
        for method in METHOD_CONTROLS:
            learned = method in ("bilstm", "axis_nn")
            if learned and profile.recordings is None:
                continue  # refused alike (test_ordinary_mistakes_give_one_line_and_exit_2)
            # the networks train once on an empty cache
            yield pytest.param(name, method, marks=[pytest.mark.slow] if learned else [])


@pytest.mark.parametrize(("name", "method"), list(_profile_methods()))
def test_a_copied_profile_estimates_as_the_shipped_one(program, tmp_path, capsys, name, method):
    from nctwin.machine import profile_path

    copy = tmp_path / "my_mill.toml"
    copy.write_bytes(profile_path(name).read_bytes())
    outputs = []
    for machine in (name, str(copy)):
        code = main(["estimate", str(program), "--json", "--machine", machine, "--method", method])
        captured = capsys.readouterr()
        outputs.append((code, captured.out, captured.err))
    assert outputs[0] == outputs[1]
    code, out, err = outputs[0]
    if code == 0:
        assert json.loads(out)["method"] == method
    else:  # a profile without the method's control: one line, the same for the copy
        assert code == 2 and err.startswith(f"nctwin: method {method!r} needs a control")


@pytest.mark.slow
def test_calibrate_writes_the_shipped_fir_control(tmp_path, capsys):
    """`nctwin calibrate` on the shipped recordings gives the [control.fir] that
    linuxcnc_sim.toml holds, with its provenance; nothing else in the file changes."""
    from nctwin.machine import load_profile, profile_path

    out = tmp_path / "calibrated.toml"
    args = ["calibrate", "--recordings", "linuxcnc", "--machine", "linuxcnc_sim"]
    assert main([*args, "--output", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "32 recordings, every 5th of the training sets" in printed
    calibrated, shipped = load_profile(out), load_profile("linuxcnc_sim")
    assert calibrated == shipped
    body = [ln for ln in out.read_text().splitlines() if not ln.startswith("# Written by nctwin")]
    ship = profile_path("linuxcnc_sim").read_text().splitlines()
    assert body == [ln for ln in ship if not ln.startswith("# Written by nctwin")]


#: square at 20 mm/s (F1200): 5 s a side. Floor: 0.2 + 4 x 5 = 20.2 s. Both networks predict
#: the sides faster than 20 mm/s (about 18 s for the four).
SQUARE = "G21 G90 G64 P0.1\nG0 Z-20\nG1 X100 F1200\nY100\nX0\nY0\nM2\n"


def test_move_floors_by_hand():
    from nctwin import parse
    from nctwin.estimate.learned import _floored_estimate, move_data, move_floors_s
    from nctwin.machine import load_profile

    profile = load_profile("linuxcnc_sim")
    machine = profile.machine
    tp = parse(SQUARE.replace("M2\n", "G4 P0.5\nM2\n"))
    data = move_data("square", tp, machine, profile.control("planner"))
    assert move_floors_s(data) == pytest.approx([0.2, 5.0, 5.0, 5.0, 5.0])
    # predictions: the rapid and one side above their floors, three sides below
    est = _floored_estimate(tp, data, np.array([0.3, 6.0, 4.0, 1.0, 4.9]), "bilstm", machine)
    assert est.clamped_moves == 3
    assert est.block_times_s == pytest.approx([0.3, 6.0, 5.0, 5.0, 5.0, 0.5])
    assert est.cycle_time_s == pytest.approx(21.8)
    assert est.unclamped_time_s == pytest.approx(16.2 + 0.5)
    assert est.floor_time_s == pytest.approx(20.7)
    summary = est.summary()
    assert summary["clamped_to_floor"] == 3 and summary["floor_time_s"] == pytest.approx(20.7)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["bilstm", "axis_nn"])
def test_learned_estimates_are_raised_to_the_floor(tmp_path, capsys, method):
    prog = tmp_path / "square.nc"
    prog.write_text(SQUARE)
    args = ["estimate", str(prog), "--machine", "linuxcnc_sim", "--method", method]
    assert main([*args, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["floor_time_s"] == pytest.approx(20.2)
    assert data["cycle_time_s"] >= 20.2 - 1e-9
    assert data["by_kind"]["linear"]["time_s"] >= 20.0 - 1e-9
    # the networks predict the sides too fast: each raised to 5 s exactly
    assert data["clamped_to_floor"] >= 4
    assert data["by_kind"]["linear"]["time_s"] == pytest.approx(20.0)
    assert data["unclamped_cycle_time_s"] < 20.0
    assert main(args) == 0
    out = capsys.readouterr().out
    n = data["clamped_to_floor"]
    assert f"{n} moves raised to the physical floor (length / feed)" in out


def test_other_methods_report_no_floor(program, capsys):
    assert main(["estimate", str(program), "--json", "--method", "block_overlap"]) == 0
    assert "clamped_to_floor" not in json.loads(capsys.readouterr().out)


# --- the feed plot -----------------------------------------------------------------------------


@pytest.fixture
def figures(monkeypatch):
    """The figures ``nctwin simulate --plot`` draws, kept for inspection."""
    from nctwin.report import plots

    drawn = []
    draw = plots.feed_figure

    def keep(plot):
        fig = draw(plot)
        drawn.append(fig)
        return fig

    monkeypatch.setattr(plots, "feed_figure", keep)
    return drawn


def _feed_axis_top(fig) -> float:
    return fig.axes[0].get_ylim()[1]


def test_feed_plot_scales_to_the_cutting_feed(program, tmp_path, capsys, figures):
    png = tmp_path / "feed.png"
    assert main(["simulate", str(program), "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000
    fig = figures[0]
    time_ax, xy_ax, colour_bar = fig.axes
    # F600 is the only cutting feed (mm/min in a G21 program)
    assert _feed_axis_top(fig) == pytest.approx(1.1 * 600)
    assert time_ax.get_ylabel() == "feed (mm/min)" and colour_bar.get_ylabel() == "feed (mm/min)"
    assert xy_ax.get_xlabel() == "X (mm)"


def test_feed_plot_with_a_long_rapid_clips_it(tmp_path, capsys, figures):
    prog, png = tmp_path / "rapid.nc", tmp_path / "feed.png"
    # a 500 mm rapid (generic_mill: 30000 mm/min), then 30 mm at F1200
    prog.write_text("G21 G90\nG0 X500 Y0 Z5\nG1 Z0 F600\nG1 X530 F1200\nM30\n")
    assert main(["simulate", str(prog), "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000
    fig = figures[0]
    assert _feed_axis_top(fig) <= 1.2 * 1200
    time_ax, xy_ax = fig.axes[:2]
    labels = [line.get_label() for line in time_ax.get_lines()]
    assert "rapid, clipped (rapid feed 30000 mm/min)" in labels
    rapid_xy = [line for line in xy_ax.get_lines() if line.get_label() == "rapid"]
    assert rapid_xy[0].get_linestyle() == "--"
    # the rapid's end is in the XY panel: X from 0 to 500
    assert np.nanmax(rapid_xy[0].get_xdata()) == pytest.approx(500.0)


@pytest.mark.parametrize(
    ("units_args", "ylabel", "top"),
    [([], "feed (in/min)", 1.1 * 20.0), (["--units", "mm/s"], "feed (mm/s)", 1.1 * 20 * 25.4 / 60)],
)
def test_feed_plot_units(tmp_path, capsys, figures, units_args, ylabel, top):
    prog = tmp_path / "inch.nc"
    prog.write_text("(an inch program)\nG20 G90\nG1 X2 F20\nY1\nM30\n")
    assert main(["simulate", str(prog), "--plot", str(tmp_path / "f.png"), *units_args]) == 0
    assert figures[0].axes[0].get_ylabel() == ylabel
    assert _feed_axis_top(figures[0]) == pytest.approx(top)
    assert figures[0].axes[1].get_xlabel() == ("X (in)" if not units_args else "X (mm)")


def test_program_units_reads_the_first_g20_or_g21_outside_comments():
    from nctwin.cli import program_units

    assert program_units("(G20 in a comment)\nG21 G90\n") == "mm"
    assert program_units("N10G20\nG1 X1 F10\n") == "inch"
    assert program_units("G1 X1 F10 ; G20\n", default="inch") == "inch"
    assert program_units("G1 X1 F10 G201\n") == "mm"


def test_the_command_line_does_not_import_torch_unless_a_network_runs():
    # torch takes seconds to import: only bilstm and axis_nn need it
    code = "import sys, nctwin.cli; print('torch' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


SUBROUTINE = """G21 G90 F600
o100 sub
  G1 X[#1] Y[#2]
o100 endsub
o100 call [10] [0]
o100 call [10] [20]
M2
"""


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_reader_auto_hands_what_only_linuxcnc_reads_to_its_interpreter(tmp_path, capsys):
    prog = tmp_path / "sub.ngc"
    prog.write_text(SUBROUTINE)
    assert main(["estimate", str(prog), "--json", "--method", "cam"]) == 0
    data = json.loads(capsys.readouterr().out)
    # 10 mm then 20 mm at 10 mm/s, the blocks on the subroutine's line
    assert data["reader"] == "linuxcnc" and data["blocks"] == 2
    assert data["cycle_time_s"] == pytest.approx(3.0)
    assert main(["estimate", str(prog), "--reader", "linuxcnc"]) == 0
    assert "reader       LinuxCNC's interpreter" in capsys.readouterr().out


def test_reader_native_refuses_what_only_linuxcnc_reads(tmp_path, capsys):
    prog = tmp_path / "sub.ngc"
    prog.write_text(SUBROUTINE)
    assert main(["estimate", str(prog), "--reader", "native"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith(f"{prog}:2: O-word")
    assert err[0].endswith("needs LinuxCNC's interpreter: run make linuxcnc")
    assert "Traceback" not in "".join(err)


def test_reader_of_a_plain_program_is_native(program, capsys):
    assert main(["estimate", str(program), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["reader"] == "native"
    assert main(["simulate", str(program), "--json", "--reader", "native"]) == 0
    assert json.loads(capsys.readouterr().out)["reader"] == "native"


@pytest.mark.usefixtures("linuxcnc_interpreter")
@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("G1 X1 A5 F600\n", ":1: axis A is not supported"),
        ("G21 F600\n#1 = [1 / 0]\nG1 X#1\n", ":2: "),
        ("G21 F600\no100 while [1]\nG1 X1\nG1 X0\no100 endwhile\n", ""),
        ("G21 F600\no<missing_sub> call\n", ":2: "),
    ],
)
def test_programs_linuxcnc_refuses_give_one_line_per_error(tmp_path, capsys, text, needle):
    prog = tmp_path / "bad.ngc"
    prog.write_text(text)
    assert main(["estimate", str(prog), "--method", "cam"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{prog}:") and needle in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_tool_table_gives_the_tools_of_a_programs_t_words(tmp_path, capsys):
    prog = tmp_path / "tool.ngc"
    # G41 with tool 2 of diameter 4 on a 10 mm line along X: the tool runs 2 mm to its left
    prog.write_text("G21 G90 F600\nT2 M6\nG41 D2 G1 X0 Y5\nG1 X10\nG40 G1 X10 Y20\nM2\n")
    assert main(["estimate", str(prog)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"{prog}:2: Requested tool 2 not found in the tool table")
    assert "--tool-table" in err and len(err.splitlines()) == 1
    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 D0 Z0 ;\nT2 P2 D4 Z0 ;\n")
    args = ["estimate", str(prog), "--tool-table", str(table), "--json", "--method", "cam"]
    assert main(args) == 0
    assert json.loads(capsys.readouterr().out)["reader"] == "linuxcnc"
    assert main(["estimate", str(prog), "--tool-table", str(tmp_path / "none.tbl")]) == 2
    assert capsys.readouterr().err.strip() == f"{tmp_path / 'none.tbl'}: no such tool table file"


# --- cycle time: [control.sequence], motion time, breakdown, overrides --------------------------

SEQUENCE_TABLE = """
[control.sequence]
tool_change_s = 9.5
spindle_start_s = 1.0
spindle_start_s_per_krpm = 0.3
optional_stop_s = 2.0
program_start_s = 1.5
program_end_s = 3.0
"""


def test_a_nist_plate_with_a_sequence_table(tmp_path, capsys):
    from nctwin.machine import profile_path
    from nctwin.paths import nist_dir

    machine = tmp_path / "with_sequence.toml"
    machine.write_text(profile_path("generic_mill").read_text() + SEQUENCE_TABLE)
    plate = str(nist_dir() / "nc" / "NIST_MTC_CRADA_PLATE-13.NC")
    assert main(["estimate", plate, "--machine", str(machine), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cycle_time_s"] > data["motion_time_s"] > 0
    assert data["counts"] == {"tool_changes": 7, "spindle_starts": 7, "optional_stops": 0,
                              "spindle_runs": 7}  # fmt: skip
    b = data["breakdown"]
    assert b["tool_changes"] == 7 * 9.5 and b["program_start_end"] == 4.5
    # S750, S3750 and five times S9000
    assert b["spindle_starts"] == pytest.approx(7 * 1.0 + 0.3 * (0.75 + 3.75 + 5 * 9.0))
    assert sum(b.values()) == pytest.approx(data["cycle_time_s"])
    assert data["rapid_override_pct"] == data["feed_override_pct"] == 100.0
    # the generic profile has no [control.sequence]: the blocks alone, as before
    assert main(["estimate", plate, "--json"]) == 0
    blocks = json.loads(capsys.readouterr().out)
    assert blocks["cycle_time_s"] == pytest.approx(data["cycle_time_s"] - 66.5 - b["spindle_starts"]
                                                   - 4.5)  # fmt: skip
    assert blocks["breakdown"]["tool_changes"] == 0.0


def test_estimate_text_has_motion_time_and_breakdown(program, capsys):
    assert main(["estimate", str(program), "--feed-override", "50"]) == 0
    out = capsys.readouterr().out
    assert "motion time  none (no spindle start)" in out
    assert "overrides    rapid 100 %, feed 50 %" in out
    assert "breakdown" in out and "feed_lines" in out and "program_start_end" in out


def test_feed_override_doubles_the_cutting_time(program, capsys):
    # 5 mm rapid at 200 mm/s + 35 mm at 10 mm/s, the 35 mm at half the feed
    args = ["estimate", str(program), "--json", "--machine", "linuxcnc_sim", "--method", "cam"]
    assert main([*args, "--feed-override", "50", "--rapid-override", "50"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cycle_time_s"] == pytest.approx(5 / 100 + 7.0)
    assert data["motion_time_s"] is None


@pytest.mark.parametrize("option", ["--rapid-override", "--feed-override"])
@pytest.mark.parametrize("value", ["0", "-10", "201", "nan", "fast"])
def test_overrides_out_of_range_give_one_line(program, capsys, option, value):
    assert main(["estimate", str(program), option, value]) == 2
    assert _one_line_error(capsys).startswith(
        f"nctwin: argument {option}: {value} is out of range: allowed (0, 200] %"
    )
