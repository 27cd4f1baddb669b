"""Parser throughput on real programs: ``contour.ngc`` (10,000 lines) and ``trochoidal.ngc``.

Target: at least 300,000 lines/s. A synthetic 10,000-line program is timed too, so the benchmark
runs where ../shared/programs is absent.
"""

from __future__ import annotations

import sys

import numpy as np
from _common import SHARED_PROGRAMS, best_time_s, record

from nctwin import parse

TARGET = ">= 300000"


def synthetic(n_lines: int = 10_000, seed: int = 0) -> str:
    """A CAM-like program of short G1 moves with 4-decimal coordinates."""
    rng = np.random.default_rng(seed)
    xy = np.cumsum(rng.normal(0, 0.5, (n_lines, 2)), axis=0)
    return "G21 G90 G64 P0.01\nF3000\n" + "\n".join(f"G1 X{x:.4f} Y{y:.4f}" for x, y in xy)


def main() -> None:
    texts = {"synthetic10000": synthetic()}
    for name in ("contour.ngc", "trochoidal.ngc"):
        path = SHARED_PROGRAMS / name
        if path.exists():
            texts[path.stem] = path.read_text()
        else:
            print(f"parse: {path} not found, skipped", file=sys.stderr)
    for name, text in texts.items():
        lines = text.count("\n") + 1
        t = best_time_s(lambda text=text: parse(text))
        record(f"parse_{name}_lines_per_s", round(lines / t), "lines/s", TARGET)


if __name__ == "__main__":
    main()
