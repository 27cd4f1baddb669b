"""LinuxCNC's interpreter as a reader: canonical moves per second, end to end into a Toolpath
(the child process started, the program interpreted, its tables sent back and converted).

Target: at least 100,000 moves/s on a large program (500,000 moves). ``contour.ngc`` (10,000
moves) is timed too, where the startup of the child (about 40 ms) still counts. Skipped, with a
note on stderr, where LinuxCNC is not installed (``make linuxcnc``).
"""

from __future__ import annotations

import sys
from functools import partial
from pathlib import Path

import numpy as np
from _common import record

from nctwin.checks import best_time_s
from nctwin.gcode import interpreter_available, parse

TARGET = ">= 100000"
CONTOUR = Path(__file__).resolve().parents[1] / "data" / "programs" / "public" / "contour.ngc"


def large(n_moves: int = 500_000, seed: int = 0) -> str:
    """A CAM-like program of ``n_moves`` moves: G1 lines with arcs every tenth move."""
    rng = np.random.default_rng(seed)
    xy = np.cumsum(rng.normal(0, 0.5, (n_moves, 2)), axis=0)
    lines = [f"G1 X{x:.4f} Y{y:.4f}" for x, y in xy]
    lines[::10] = [f"G2 X{x:.4f} Y{y:.4f} R50" for x, y in xy[::10]]
    return "G21 G90 G64 P0.01\nF3000\n" + "\n".join(lines) + "\nM2\n"


def main() -> None:
    if not interpreter_available():
        print("interp_reader: LinuxCNC is not installed (make linuxcnc), skipped", file=sys.stderr)
        return
    texts = {"contour": CONTOUR.read_text(), "large500k": large()}
    for name, text in texts.items():
        n = len(parse(text, reader="linuxcnc"))
        repeat = 5 if n < 100_000 else 3
        t = best_time_s(partial(parse, text, reader="linuxcnc"), repeat=repeat, warmup=1)
        record(f"interp_reader_{name}_moves_per_s", round(n / t), "moves/s", TARGET)


if __name__ == "__main__":
    main()
