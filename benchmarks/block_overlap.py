"""Speed of Lee et al. 2022's analytic estimate on the shipped ISO 10791-7-style test piece
(its natural length: 405 blocks, about 7.5 minutes of cycle time), and of the ideal acc/dec
kernel it was derived for.

Targets: the analytic estimate in under 20 ms (the paper: under 1 s), the ideal kernel in under
2 s. The chapter's measured machine, :mod:`nctwin.kernel.fanuc`, has its own benchmark
(``benchmarks/fanuc.py``).
"""

from __future__ import annotations

from _common import best_time_s, record

from nctwin import parse_file
from nctwin.estimate.block_overlap import block_overlap
from nctwin.kernel.accdec import simulate
from nctwin.machine import load_profile
from nctwin.programs.iso10791 import shipped_test_piece_path


def main() -> None:
    tp = parse_file(shipped_test_piece_path())
    profile = load_profile("fanuc_0i_testbed")
    machine, control = profile.machine, profile.control("accdec")
    t = best_time_s(lambda: block_overlap(tp, machine, control))
    record("block_overlap_analytic_s", round(t, 6), "s", "< 0.02")
    t = best_time_s(lambda: simulate(tp, machine, control), repeat=3, warmup=1)
    record("accdec_kernel_s", round(t, 4), "s", "< 2")


if __name__ == "__main__":
    main()
