"""A non-editable install carries the shipped data: ``pip install --target`` copies the package
with ``nctwin/data`` (machine profiles, NIST's logs, paper tables, programs, recordings; no
``cache``), and the copy, run from another folder, imports from there and estimates a program."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHIPPED = ("machines", "nist", "papers", "programs", "recordings")
PROGRAM = "G21 G90\nG0 X0 Y0\nG1 X10 Y0 F600\nG1 X10 Y10\nM2\n"


def _files(folder: Path) -> dict[str, int]:
    """Every file under ``folder``: its relative path and its size in bytes."""
    return {
        p.relative_to(folder).as_posix(): p.stat().st_size for p in folder.rglob("*") if p.is_file()
    }


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict:
    """The package installed with ``pip install --target`` into a temporary folder, an empty
    working folder elsewhere, and the environment that runs the copy."""
    target = tmp_path_factory.mktemp("target")
    work = tmp_path_factory.mktemp("work")
    staging = tmp_path_factory.mktemp("staging")
    # setuptools stages the build in build/ and src/nctwin.egg-info, and reuses what an earlier
    # build left there (files since deleted, an old file list); this build stages elsewhere,
    # from nothing, and leaves the clone as it was
    config = staging / "setup.cfg"
    config.write_text(
        f"[build]\nbuild_base = {staging / 'build'}\n\n[egg_info]\negg_base = {staging}\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NCTWIN_", "PIP_"))}
    env |= {
        "PIP_DISABLE_PIP_VERSION_CHECK": "1",
        "PYTHONNOUSERSITE": "1",
        "DIST_EXTRA_CONFIG": str(config),
    }
    env.pop("PYTHONPATH", None)
    pip = [sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation",
           "--no-index", "--quiet", "--target", str(target), str(REPO)]  # fmt: skip
    done = subprocess.run(pip, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    env |= {
        "PYTHONPATH": str(target),
        "NCTWIN_CACHE": str(work / "cache"),  # the per-user cache is not the test's to fill
    }
    return {"target": target, "work": work, "env": env}


def _run(installed: dict, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, *args], cwd=installed["work"], env=installed["env"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip


def test_the_installed_copy_holds_the_shipped_data_and_no_cache(installed):
    data = installed["target"] / "nctwin" / "data"
    assert (data / "machines" / "linuxcnc_sim.toml").is_file()
    assert not (data / "cache").exists()
    assert not [p for p in data.rglob("*") if p.is_symlink()]  # files, not links to the clone
    assert sorted(p.name for p in data.iterdir()) == sorted(SHIPPED)
    for name in SHIPPED:  # every file of the clone's data/<name>, byte counts included
        assert _files(data / name) == _files(REPO / "data" / name), name


def test_the_installed_copy_is_imported_and_finds_its_data(installed):
    code = (
        "import nctwin, sys; print(nctwin.__file__)\n"
        "from nctwin import paths; print(paths.data_dir()); print(paths.source_root())"
    )
    done = _run(installed, "-c", code)
    assert done.returncode == 0, done.stderr
    module, data, root = done.stdout.splitlines()
    package = (installed["target"] / "nctwin").resolve()
    assert Path(module).resolve() == package / "__init__.py"
    assert not Path(module).resolve().is_relative_to(REPO / "src")
    assert Path(data) == package / "data"
    assert root == "None"


def test_the_installed_cli_estimates_a_program(installed):
    (installed["work"] / "prog.ngc").write_text(PROGRAM)
    done = _run(installed, "-m", "nctwin.cli", "estimate", "prog.ngc", "--machine",
                "linuxcnc_sim", "--json")  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert summary["machine"] == "linuxcnc_sim"  # found in the copy's data/machines
    assert summary["cycle_time_s"] >= 20.0 / 10.0  # 20 mm of cutting at F600 = 10 mm/s
