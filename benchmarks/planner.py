"""Speed of the blend-arc planner (``nctwin estimate --machine linuxcnc_sim``, the LinuxCNC
chapter's best method) on every shipped public program, already parsed: each program's shortest
of the runs and its blocks, then the throughput over all of them in seconds per 10,000 blocks,
and the worst rate of a program of at least :data:`MIN_BLOCKS` blocks (on a program of a hundred
blocks the rate is the estimate's fixed cost, a few milliseconds, not the planner's speed).

Targets: at most 0.1 s per 10,000 blocks, over all programs and on each long one.
"""

from __future__ import annotations

from _common import best_time_s, record

from nctwin import parse_file
from nctwin.estimate import estimate
from nctwin.machine import load_profile
from nctwin.paths import public_programs_dir

#: The shipped public programs' file endings.
ENDINGS = (".ngc", ".nc", ".gcode")
#: Programs this long count for the per-program rate.
MIN_BLOCKS = 1000


def main() -> None:
    profile = load_profile("linuxcnc_sim")
    total_s, total_blocks, worst = 0.0, 0, 0.0
    for path in sorted(p for p in public_programs_dir().iterdir() if p.suffix in ENDINGS):
        tp = parse_file(path)
        t = best_time_s(lambda tp=tp: estimate(tp, profile, "planner"), repeat=5, warmup=1)
        record(f"planner_{path.stem}_s", round(t, 5), "s", "")
        record(f"planner_{path.stem}_blocks", len(tp), "blocks", "")
        total_s, total_blocks = total_s + t, total_blocks + len(tp)
        if len(tp) >= MIN_BLOCKS:
            worst = max(worst, t / len(tp) * 10_000)
    record("planner_s_per_10k_blocks", round(total_s / total_blocks * 10_000, 4), "s", "<= 0.1")
    record("planner_worst_long_s_per_10k_blocks", round(worst, 4), "s", "<= 0.1")


if __name__ == "__main__":
    main()
