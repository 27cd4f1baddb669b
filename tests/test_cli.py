"""The command line: output, JSON, exit codes and one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys

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


def test_estimate_default_method_is_the_chapters(program, capsys):
    # linuxcnc_sim defaults to its chapter's best method, the blend-arc planner.
    # LinuxCNC by hand: the 5 mm Z rapid is a triangle at Z's 500 mm/s^2, 2 sqrt(5 / 500) =
    # 0.2 s; then 5 mm and 30 mm at 10 mm/s with near-stops at the corners (0.0254 mm
    # tolerance), each plus F / a: 0.5 + 0.02 + 3.0 + 0.01 = 3.53 s; 3.73 s in all (LinuxCNC
    # recorded 3.71 s).
    assert main(["estimate", str(program), "--json", "--machine", "linuxcnc_sim"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["method"] == "planner"
    assert data["cycle_time_s"] == pytest.approx(3.73, rel=0.05)


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
