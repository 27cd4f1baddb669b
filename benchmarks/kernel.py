"""FIR kernel throughput: the 5000-line pocket (about 220 s of motion at 1 ms) and the
10,000-line ``contour.ngc``.

Targets: at least 10 million output samples per second where samples decide the time; the
pocket in under 0.3 s; ``contour.ngc`` at 100,000 blocks per second or more (the planner's
target, 0.1 s per 10,000 blocks), since its blocks, not its samples, decide its time. The
throughput is end to end: output samples over the wall time of
``fir.run(toolpath, machine, settings)``
(planning included), best of 5, each run on a fresh copy of the parsed tool path so that no
property the tool path caches (lengths, tangents) is reused between runs. Per stage, on the
pocket: ``kernel_pocket5000_plan_s`` times the look-ahead (``fir.plan``) alone,
``kernel_sample_stage_samples_per_s`` divides the output samples by what the run takes beyond
the plan (the speed command, sampling it, the filters and the axis-limit passes) and
``kernel_filter_samples_per_s`` times the O(n) filter stage alone (``FirFilter.apply``).
``contour.ngc`` runs its 10,000 blocks in about 1,300 samples, so per-block work decides its
time: ``kernel_contour_blocks_per_s`` gives its rate in blocks.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

import numpy as np
from _common import SHARED_PROGRAMS, best_time_s, record

from nctwin import parse, parse_file
from nctwin.kernel import fir
from nctwin.machine import load_profile
from nctwin.programs.pocket import pocket_program
from nctwin.toolpath import Toolpath

REPEAT = 5
#: Programmed feed of the benchmark pocket (mm/s).
POCKET_FEED_MM_S = 50.0


def cold_time_s(fn: Callable[[Toolpath], object], toolpath: Toolpath) -> float:
    """Shortest wall time of ``fn(copy)`` over :data:`REPEAT` runs after one warm-up, each on a
    new copy of ``toolpath`` (made outside the timing) whose cached properties are empty."""
    times = []
    for _ in range(REPEAT + 1):
        fresh = toolpath.take(np.arange(len(toolpath)))
        t0 = time.perf_counter()
        fn(fresh)
        times.append(time.perf_counter() - t0)
    return min(times[1:])


def main() -> None:
    profile = load_profile("paper1_sim")
    machine, settings = profile.machine, profile.control("fir")
    # the pocket: about 5000 G-lines and 220 s of motion; at the programmed 50 mm/s
    # the package's pocket runs 4682 lines in 214.5 s (at its default 92 mm/s, 123 s)
    pocket = parse(pocket_program(feed_mm_s=POCKET_FEED_MM_S, tol_mm=0.3))
    samples = len(fir.run(pocket, machine, settings))
    t = cold_time_s(lambda tp: fir.run(tp, machine, settings), pocket)
    record("kernel_pocket5000_s", round(t, 4), "s", "< 0.3")
    flt = fir.FirFilter.of(settings)
    tplan = cold_time_s(lambda tp: fir.plan(tp, machine, settings), pocket)
    record("kernel_pocket5000_plan_s", round(tplan, 4), "s", "")
    record("kernel_sample_stage_samples_per_s", round(samples / (t - tplan)), "samples/s", "")
    x = fir.run(pocket, machine, settings).pos_mm.T.copy()  # (3, n) samples to filter
    tf = best_time_s(lambda: flt.apply(x), repeat=REPEAT, warmup=1)
    record("kernel_filter_samples_per_s", round(x.shape[1] / tf), "samples/s", ">= 1e7")
    total_samples, total_time = samples, t
    contour = SHARED_PROGRAMS / "contour.ngc"
    if contour.exists():
        tp = parse_file(contour)
        n = len(fir.run(tp, machine, settings))
        tc = cold_time_s(lambda tp: fir.run(tp, machine, settings), tp)
        record("kernel_contour_samples_per_s", round(n / tc), "samples/s", "")
        record("kernel_contour_blocks_per_s", round(len(tp) / tc), "blocks/s", ">= 1e5")
        total_samples += n
        total_time += tc
    else:
        print(f"kernel: {contour} not found, skipped", file=sys.stderr)
    record("kernel_samples_per_s", round(total_samples / total_time), "samples/s", ">= 1e7")
    record("kernel_pocket5000_lines", len(pocket), "G-lines", "~5000")
    record("kernel_pocket5000_motion_s", samples * settings.period_s, "s", "~220")


if __name__ == "__main__":
    main()
