"""``make lab``: JupyterLab is in the environment and finds the project's kernel."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_jupyterlab_is_installed_and_sees_the_project_kernel():
    lab = subprocess.run([sys.executable, "-m", "jupyterlab", "--version"], capture_output=True,
                         text=True, check=True)  # fmt: skip
    assert lab.stdout.strip().split(".")[0] == "4"
    specs = subprocess.run([sys.executable, "-m", "jupyter", "kernelspec", "list", "--json"],
                           capture_output=True, text=True, check=True)  # fmt: skip
    names = {s["spec"]["display_name"] for s in json.loads(specs.stdout)["kernelspecs"].values()}
    assert "Python 3 (nctwin)" in names


def test_make_lab_opens_the_notebooks_folder_without_a_browser_where_there_is_no_display():
    dry = subprocess.run(["make", "-n", "lab"], cwd=ROOT, capture_output=True, text=True,
                         check=True, env={"PATH": "/usr/bin:/bin"})  # fmt: skip
    assert "jupyter lab" in dry.stdout and f"{ROOT}/notebooks" in dry.stdout
    assert "--no-browser" in dry.stdout  # the command line tests the display itself
