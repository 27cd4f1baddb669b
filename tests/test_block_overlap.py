"""The analytic block-overlap estimator (Lee et al. 2022) against times computed by hand, and
against the acc/dec kernel on random programs."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_accdec import CONTROL, MACHINE, _program, segment

from nctwin import parse
from nctwin.estimate import METHODS, estimate
from nctwin.estimate.block_overlap import block_overlap
from nctwin.kernel.accdec import simulate
from nctwin.machine import Profile
from nctwin.methods.lee2022 import block_times

TI = CONTROL.period_s  # 1 ms
AT, ATR, AS = 0.05, 0.15, 0.03
FR = MACHINE.rapid_feed_mm_s
INPOS = (0.025, 0.025, 0.12)


def ceil_ti(t):
    return math.ceil(round(t / TI, 6)) * TI


def est(text, **kw):
    return block_overlap(parse(text), MACHINE, CONTROL, inposition_s=INPOS, **kw)


def test_one_normal_block():
    # eq. 1-3: T = ceilTI(l / F) + AT; 10.0005 mm at 10 mm/s -> 1.00005 s -> 1.001 s
    e = est("G1 X10.0005 F600")
    assert e.cycle_time_s == pytest.approx(1.001 + AT, abs=1e-12)
    assert e.cycle_time_s == pytest.approx(ceil_ti(10.0005 / 10.0) + AT, abs=1e-12)


def test_one_short_cutting_block():
    # eq. 4-5: 0.3 mm at 10 mm/s: Tb = AT, Ta = ceilTI(0.03 s); T = 80 ms
    bt = block_times(parse("G1 X0.3 F600"), MACHINE, CONTROL)
    assert bt["short"][0]
    assert bt["T"][0] == pytest.approx(0.05 + 0.03, abs=1e-12)


def test_one_short_rapid_without_bell():
    # eq. 9-11: a = Fr / ATR; 2 mm: sqrt(2 / 1111.1) = 42.43 ms -> 43 ms; T = 2 Ta = 86 ms
    c = dataclasses.replace(CONTROL, rapid_bell_s=0.0)
    e = block_overlap(parse("G0 X2"), MACHINE, c, inposition=False)
    a = FR / ATR
    assert e.cycle_time_s == pytest.approx(2 * ceil_ti(math.sqrt(2 / a)), abs=1e-12)
    assert e.cycle_time_s == pytest.approx(0.086, abs=1e-12)


def test_short_rapid_with_bell_and_normal_rapids():
    # eq. 15: T = 2 Ta + As; eq. 13: T = ceilTI(l / Fr) + ATR + As
    assert est("G0 X2", inposition=False).cycle_time_s == pytest.approx(0.086 + AS, abs=1e-12)
    assert est("G0 X100", inposition=False).cycle_time_s == pytest.approx(0.78, abs=1e-12)
    # eq. 14, non-linear type: the longest axis travel (100 mm) instead of the 100.499 mm line
    nonlinear = dataclasses.replace(CONTROL, rapid_type="nonlinear")
    e = block_overlap(parse("G0 X100 Y10"), MACHINE, nonlinear, inposition=False)
    assert e.cycle_time_s == pytest.approx(0.6 + ATR + AS, abs=1e-12)
    assert est("G0 X100 Y10", inposition=False).cycle_time_s == pytest.approx(0.783, abs=1e-12)


def test_two_overlapping_cutting_blocks():
    # Fig. 6: T = Tb1 + Tb2 + AT
    e = est("G1 X10 F600\nG1 Y10 F300")
    assert e.cycle_time_s == pytest.approx(1.0 + 2.0 + AT, abs=1e-12)
    np.testing.assert_allclose(e.block_times_s, [1.0, 2.0 + AT], atol=1e-12)
    assert est("G1 X10 F600\nG1 Y10 F300", overlap=False).cycle_time_s == pytest.approx(
        1.05 + 2.05, abs=1e-12
    )


def test_short_blocks_overlap_from_their_constant_velocity_part():
    # Fig. 7: three 30 ms blocks: each next one starts after Ta = 30 ms; the chain ends AT later
    e = est("G1 X0.3 F600\nG1 X0.6\nG1 X0.9")
    assert e.cycle_time_s == pytest.approx(0.09 + AT, abs=1e-12)


def test_no_overlap_across_rapids_and_dwells():
    text = "G1 X10 F600\nG0 X20\nG1 X30\nG4 X0.5\nG1 X40"
    e = est(text, inposition=False)
    # every block stands alone; the 10 mm rapid is short: 2 ceil(sqrt(10 / a)) + As = 0.22 s
    assert e.cycle_time_s == pytest.approx(1.05 + (0.19 + 0.03) + 1.05 + 0.5 + 1.05)
    np.testing.assert_allclose(
        est(text, overlap=False, inposition=False).block_times_s, e.block_times_s, atol=1e-12
    )


def test_inposition_of_the_slowest_moving_axis():
    bare = est("G0 X100 Z-10", inposition=False).cycle_time_s
    assert est("G0 X100 Z-10").cycle_time_s == pytest.approx(bare + 0.12, abs=1e-12)
    bare = est("G0 X100 Y5", inposition=False).cycle_time_s
    assert est("G0 X100 Y5").cycle_time_s == pytest.approx(bare + 0.025, abs=1e-12)
    # the control's own table is the default
    c = dataclasses.replace(CONTROL, inposition_time_s=(0.0, 0.0, 0.2))
    assert block_overlap(parse("G0 Z5"), MACHINE, c).cycle_time_s == pytest.approx(
        block_overlap(parse("G0 Z5"), MACHINE, c, inposition=False).cycle_time_s + 0.2
    )


def test_registered_as_a_method():
    assert "block_overlap" in METHODS
    # on a profile, the method runs on its [control.accdec] table
    e = estimate(parse("G1 X10 F600"), Profile(MACHINE, accdec=CONTROL), "block_overlap")
    assert e.method == "block_overlap" and e.machine == "hand"
    assert e.cycle_time_s == pytest.approx(1.05)


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match=r"inposition_s = .* is out of range"):
        block_overlap(parse("G0 X1"), MACHINE, CONTROL, inposition_s=(0.1, -0.1, 0.1))
    with pytest.raises(ValueError, match=r"cut_time_constant_s = 0\.0505 is out of range"):
        dataclasses.replace(CONTROL, cut_time_constant_s=0.0505)  # not a whole period


@given(
    st.lists(st.one_of(segment, st.floats(0.0, 0.3)), min_size=1, max_size=8),
    st.sampled_from([0.01, 0.05, 0.1]),
)
def test_estimator_agrees_with_kernel_within_one_period_per_block(items, at_s):
    # random programs of lines, arcs and dwells (no rapids): the kernel rounds chains, the
    # estimator every block, up to whole periods; nothing else differs
    chunks, seg = [], []
    for it in items:
        if isinstance(it, float):
            if seg:
                chunks.append(_program(seg)[0])
                seg = []
            chunks.append(f"G4 X{it:.3f}")
        else:
            seg.append(it)
    if seg:
        chunks.append(_program(seg)[0])
    # each chunk of segments starts from the origin in _program; join them with a G1 back there
    text = "\nG1 X0 Y0 Z0 F600\n".join(chunks)
    tp = parse(text)
    c = dataclasses.replace(CONTROL, cut_time_constant_s=at_s)
    measured = simulate(tp, MACHINE, c)
    predicted = block_overlap(tp, MACHINE, c)
    per_block = np.abs(measured.block_times_s - predicted.block_times_s)
    assert per_block.max() <= TI * (1 + 1e-6)
    assert abs(measured.cycle_time_s - predicted.cycle_time_s) <= len(tp) * TI * (1 + 1e-6)
    assert predicted.cycle_time_s >= measured.cycle_time_s - 1e-9  # rounding up per block


def test_fit_block_overlap_recovers_the_time_constant():
    from nctwin.identify import fit_block_overlap, identified_block_overlap

    programs = []
    for text in ("G21 G1 X10 F600\nY5\nX0\n", "G21 G1 X3 F1200\nX6 Y1\nX9\nG0 X0 Y0\n"):
        tp = parse(text)
        true = dataclasses.replace(identified_block_overlap(tp, MACHINE, TI),
                                   cut_time_constant_s=0.037)  # fmt: skip
        programs.append((tp, block_overlap(tp, MACHINE, true).cycle_time_s))
    fitted = fit_block_overlap(programs, MACHINE, TI)
    assert fitted.cut_time_constant_s == pytest.approx(0.037)
    assert (
        fitted.rapid_time_constant_s
        == identified_block_overlap(tp, MACHINE, TI).rapid_time_constant_s
    )
