"""The command line on a 200,000-line program: wall time and peak memory of ``nctwin simulate``
and ``nctwin estimate --method kernel``, as a user runs them (a new process each: start-up,
imports, reading, parsing, the FIR kernel and, for the estimate, the junction search of
:func:`nctwin.targets.block_targets`).

The program is ``contour.ngc`` (shipped in ``data/programs/public``, 10,000 feed moves) 20 times
over, each pass 0.01 in higher in Z after a rapid back to its start: 200,024 lines, all absolute
coordinates. Time: the shortest of :data:`REPEAT` runs. Peak memory: the largest resident set
of the command's process (``getrusage(RUSAGE_CHILDREN).ru_maxrss`` of a fresh process that runs
only it). Targets: at most 5 s and 1.5 GB each. The CPU time (user and system) of the command
is recorded too: on a busy machine it says what the wall time would be on an idle one.

The estimate's memory must not grow with the motion's duration: ``raster`` is a 200,000-line
raster of 0.25 mm moves (:func:`raster_program`), run at F3000 (about 1,100 s of motion on
``linuxcnc_sim``) and at F80 (about 10.5 hours); each ``nctwin estimate --method kernel`` at most
1.5 GB.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from _common import record

from nctwin.paths import public_programs_dir

REPEAT = 3
PASSES = 20

#: Runs one command in a child and prints its wall time, CPU time and peak RSS (kB on Linux).
_MEASURE = """
import resource, subprocess, sys, time
t0 = time.perf_counter()
proc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
t = time.perf_counter() - t0
if proc.returncode:
    sys.exit(proc.stderr.decode())
use = resource.getrusage(resource.RUSAGE_CHILDREN)
print(t, use.ru_utime + use.ru_stime, use.ru_maxrss)
"""


def long_program(passes: int = PASSES) -> str:
    """``contour.ngc``'s feed moves ``passes`` times, each pass 0.01 in higher (G20, G90)."""
    lines = (public_programs_dir() / "contour.ngc").read_text().splitlines()
    body = [line for line in lines if line.startswith("G01")]
    out = ["G20 G90", "G64", "F9999"]
    for i in range(passes):
        out.append(f"G0 X0 Y0 Z{0.01 * i:.4f}")
        out += body
    out.append("M02")
    return "\n".join(out) + "\n"


def raster_program(feed_mm_min: float, rows: int = 500, moves: int = 400) -> str:
    """A zig-zag raster of ``rows`` rows of ``moves`` 0.25 mm moves, 0.5 mm apart (G21, G90,
    ``G64 P0.01``), at ``feed_mm_min``: ``rows * (moves + 1) + 5`` lines."""
    out = ["G21 G90 G64 P0.01", f"F{feed_mm_min:g}", "G0 X0 Y0 Z1", "G1 Z0"]
    x, d = 0.0, 1
    for row in range(rows):
        for _ in range(moves):
            x += 0.25 * d
            out.append(f"G1 X{x:.3f}")
        out.append(f"G1 Y{0.5 * (row + 1):.3f}")
        d = -d
    out.append("M2")
    return "\n".join(out) + "\n"


def measure(args: list[str], repeat: int = REPEAT) -> tuple[float, float, float]:
    """Shortest wall time (s) and CPU time (s) of ``nctwin *args`` over ``repeat`` runs, and
    its peak resident memory (GB)."""
    times, cpu, peaks = [], [], []
    for _ in range(repeat):
        cmd = [sys.executable, "-c", _MEASURE, sys.executable, "-m", "nctwin.cli", *args]
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.split()
        times.append(float(out[0]))
        cpu.append(float(out[1]))
        peaks.append(float(out[2]) * 1024 / 1e9)  # ru_maxrss is in kB on Linux
    return min(times), min(cpu), max(peaks)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        prog = Path(tmp) / "contour_x20.ngc"
        text = long_program()
        prog.write_text(text)
        record("cli_program_lines", text.count("\n"), "lines", "~200000")
        cases = {
            "simulate": ["simulate", str(prog), "--json"],
            "estimate_kernel": ["estimate", str(prog), "--method", "kernel", "--json"],
        }
        for name, args in cases.items():
            t, cpu, peak = measure(args)
            record(f"cli_{name}_200k_s", round(t, 3), "s", "<= 5")
            record(f"cli_{name}_200k_cpu_s", round(cpu, 3), "s", "")
            record(f"cli_{name}_200k_peak_gb", round(peak, 3), "GB", "<= 1.5")
        blocks = json.loads(
            subprocess.run(
                [sys.executable, "-m", "nctwin.cli", *cases["simulate"]],
                capture_output=True,
                text=True,
                check=True,
            ).stdout
        )["blocks"]
        record("cli_program_blocks", blocks, "blocks", "")
        for label, feed in (("1100s", 3000.0), ("10h", 80.0)):
            raster = Path(tmp) / f"raster_{label}.ngc"
            raster.write_text(raster_program(feed))
            args = ["estimate", str(raster), "--machine", "linuxcnc_sim", "--method", "kernel"]
            t, cpu, peak = measure(args, repeat=1)
            record(f"cli_estimate_kernel_raster_{label}_s", round(t, 3), "s", "")
            record(f"cli_estimate_kernel_raster_{label}_peak_gb", round(peak, 3), "GB", "<= 1.5")


if __name__ == "__main__":
    main()
