"""The sweeps of the truth's assumed settings (arc clamp, block-processing time) on the Lee et al.
chapter's 3D program, against numbers computed by hand."""

from __future__ import annotations

import dataclasses
import math

import pytest

from nctwin import parse
from nctwin.chapters import lee2022 as lee
from nctwin.chapters import lee2022_sweeps as sw
from nctwin.kernel import fanuc
from nctwin.machine import load_machine
from nctwin.programs.finishing3d import FinishingParams, finishing3d_program
from nctwin.report.papers import load_paper_table

SETS = lee.parameter_sets("fanuc_0i_testbed", load_paper_table("lee2022_validation"))
MACHINE = load_machine("fanuc_0i_testbed")
NO_WAIT = (0.0, 0.0, 0.0)
#: The truth reduced to the estimator's model: no clamp, no block time, never waits.
MODEL_TRUTH = lee._effect_settings(SETS[1][1], lee.EFFECTS["none (the estimator's model)"])


def _sweep(text: str, **kw):
    programs = {"p": parse(text)}
    return sw.sweep_table(programs, MACHINE, SETS[1][0], MODEL_TRUTH, NO_WAIT, **kw)


def test_block_time_sweep_on_short_chords():
    # ten chords of 0.1 mm at F6000: 1 ms each; a block time b makes each last max(b, 1 ms);
    # the truth's 50 ms moving average stretches the stream by K - 1 = 49 periods
    text = "\n".join(f"G1 X{0.1 * (k + 1):.1f} F6000" for k in range(10))
    table = _sweep(text, arc_clamps_mm_s2=(), block_times_s=(0.0, 0.001, 0.002, 0.004, 0.008))
    want = [10 * max(b, 0.001) + 0.049 for b in (0.0, 0.001, 0.002, 0.004, 0.008)]
    assert table.measured_s.to_numpy() == pytest.approx(want)
    assert list(table.block_time_ms) == [0.0, 1.0, 2.0, 4.0, 8.0]
    # the estimate does not depend on the truth's settings: eq. 2 + A_T
    assert table.predicted_s.to_numpy() == pytest.approx([10 * 0.001 + 0.05] * 5)
    # a block time of 0 is the truth without the limit
    none = fanuc.simulate(parse(text), MACHINE, MODEL_TRUTH).cycle_time_s
    assert table.measured_s.iloc[0] == none
    assert table.testbed.tolist() == [True, False, False, False, False]


def test_arc_clamp_sweep_on_a_half_circle():
    # half circle of R2 at F6000 after a 0.001 mm line: the clamp gives sqrt(a R) mm/s
    text = "G1 X0.001 F6000\nG2 X4.001 I2"
    clamps = (50.0, 200.0, 800.0, math.inf)
    table = _sweep(text, arc_clamps_mm_s2=clamps, block_times_s=())
    for a, measured in zip(clamps, table.measured_s, strict=True):
        v = min(math.sqrt(a * 2.0), 100.0)
        stream_s = 0.001 / 100 + 2 * math.pi / v
        assert measured == pytest.approx(math.ceil(stream_s / 0.001 - 1e-9) * 0.001 + 0.049)
    # inf is the run without a clamp
    off = dataclasses.replace(MODEL_TRUTH, arc_radial_acc_mm_s2=math.inf)
    assert table.measured_s.iloc[-1] == fanuc.simulate(parse(text), MACHINE, off).cycle_time_s
    assert (table.varied == "arc clamp").all()
    assert table.err_pct.iloc[0] == pytest.approx(
        100 * (table.predicted_s.iloc[0] - table.measured_s.iloc[0]) / table.measured_s.iloc[0]
    )


def test_one_setting_at_a_time_the_other_at_the_truths():
    table = _sweep("G1 X1 F6000", arc_clamps_mm_s2=(100.0,), block_times_s=(0.002,))
    assert table.block_time_ms.tolist() == [0.0, 2.0]
    assert table.arc_radial_acc_mm_s2.tolist() == [100.0, math.inf]


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        (
            {"arc_clamps_mm_s2": (0.0,)},
            r"^arc_clamps_mm_s2 = 0.0 is out of range: allowed \(0, inf\]$",
        ),
        (
            {"block_times_s": (-0.001,)},
            r"^block_times_s = -0.001 is out of range: allowed \[0, 1\]$",
        ),
        ({"block_times_s": (2.0,)}, r"^block_times_s = 2.0 is out of range: allowed \[0, 1\]$"),
    ],
)
def test_values_out_of_range_are_refused(kw, message):
    with pytest.raises(ValueError, match=message):
        _sweep("G1 X1 F6000", **kw)


def test_feed_variants_are_the_real_programs_feeds():
    feeds = sw.real_cam_feeds(lee.REAL_CAM_PROGRAMS)
    assert feeds == {"LHchips4.ngc": 1300.0, "camotics_bear.nc": 6000.0}
    small = {"a": 1300.0, "b": 6000.0}
    texts = sw.feed_variants("f3", 0, small)
    assert list(texts) == ["f3", "f3_F6000"]
    assert texts["f3"] == finishing3d_program(0)
    one = dataclasses.replace(FinishingParams(), feed_mm_min=6000.0, steep_feed_mm_min=6000.0)
    assert texts["f3_F6000"] == finishing3d_program(0, one)
    assert " F1300" not in texts["f3_F6000"] and " F800" not in texts["f3_F6000"]
