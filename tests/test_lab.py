"""``make lab``: JupyterLab is in the environment and finds the project's kernel."""

from __future__ import annotations

import json
import platform
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


def test_the_project_kernel_fixes_the_numbers_outside_make():
    """A notebook run outside make (papermill, JupyterLab) gets make's hash seed, time zone and
    CPU kernels from the kernelspec, so it computes make's numbers and finds its networks."""
    spec = json.loads((Path(sys.prefix) / "share" / "jupyter" / "kernels" / "python3"
                       / "kernel.json").read_text())  # fmt: skip
    assert spec["display_name"] == "Python 3 (nctwin)"
    assert spec["env"]["PYTHONHASHSEED"] == "0" and spec["env"]["TZ"] == "UTC"
    if platform.machine() == "x86_64":
        assert spec["env"]["ATEN_CPU_CAPABILITY"] == "avx2"
        assert spec["env"]["NPY_DISABLE_CPU_FEATURES"].startswith("X86_V4")


def test_make_lab_opens_the_notebooks_folder_without_a_browser_where_there_is_no_display():
    dry = subprocess.run(["make", "-n", "lab"], cwd=ROOT, capture_output=True, text=True,
                         check=True, env={"PATH": "/usr/bin:/bin"})  # fmt: skip
    assert "jupyter lab" in dry.stdout and f"{ROOT}/notebooks" in dry.stdout
    assert "--no-browser" in dry.stdout  # the command line tests the display itself
