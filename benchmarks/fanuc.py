"""Speed of the time-domain Fanuc-like control (:mod:`nctwin.kernel.fanuc`) on the two programs of
the chapter on Lee et al. 2022, and the cycle times it measures on both of the paper's parameter
sets.

Targets: the ISO 10791-7-style test piece (:mod:`nctwin.programs.iso10791`, 405 blocks and
about 7.5 minutes of motion) in under 2 s; the 3D finishing program
(:mod:`nctwin.programs.finishing3d`, seed 0, 22,497 blocks, about 9.3 minutes) in under 5 s.
The time is end to end (``simulate`` on a parsed program: feeds, interpolated points, the period
loop, the Motion); shortest of 3 runs after one warm-up that also loads the compiled loop. The
cycle times are records without a target, for the chapter.
"""

from __future__ import annotations

from _common import best_time_s, record

from nctwin.gcode import parse
from nctwin.kernel.fanuc import PAPER_SET_1, PAPER_SET_2, measure_inposition_times, simulate
from nctwin.machine import load_machine
from nctwin.programs.finishing3d import finishing3d_program
from nctwin.programs.iso10791 import test_piece_program


def main() -> None:
    machine = load_machine("fanuc_0i_testbed")
    programs = {
        "iso10791": (parse(test_piece_program()), "< 2"),
        "finishing3d": (parse(finishing3d_program(seed=0)), "< 5"),
    }
    for name, (tp, target) in programs.items():
        t = best_time_s(lambda tp=tp: simulate(tp, machine), repeat=3, warmup=1)
        record(f"fanuc_kernel_{name}_s", round(t, 4), "s", target)
        for set_name, control in (("set1", PAPER_SET_1), ("set2", PAPER_SET_2)):
            cycle = simulate(tp, machine, control).cycle_time_s
            record(f"fanuc_cycle_{name}_{set_name}_s", round(cycle, 3), "s", "")
    for axis, t in zip("xyz", measure_inposition_times(machine), strict=True):
        record(f"fanuc_inposition_{axis}_s", round(float(t), 4), "s", "")


if __name__ == "__main__":
    main()
