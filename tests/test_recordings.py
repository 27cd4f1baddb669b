"""Shipped LinuxCNC recordings (nctwin.recordings): consistent as shipped, and reproduced live.

The live test records two short programs of the shipped set on LinuxCNC and compares them with
the shipped recordings bit for bit (SHA-256 of the full position trace, per-block targets); it
is skipped where LinuxCNC cannot run (``make linuxcnc``).
"""

import numpy as np
import pytest

from nctwin import recordings
from nctwin.gcode import parse
from nctwin.machine import load_machine
from nctwin.toolpath import MotionKind

SHIPPED = recordings.load_recordings()
MACHINE = load_machine(recordings.MACHINE)
PERIOD_S = MACHINE.period_s
#: The two shortest programs of the set (global training programs of 200 short lines, ~2 s).
LIVE = sorted(SHIPPED, key=lambda name: SHIPPED[name].n_samples)[:2]


def test_shipped_set_is_the_specified_set():
    programs = recordings.recording_programs()
    assert sorted(SHIPPED) == sorted(programs)
    for name, text in programs.items():
        assert SHIPPED[name].program == text
        assert SHIPPED[name].machine == recordings.MACHINE


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_recording_is_consistent(name):
    rec = SHIPPED[name]
    tp = parse(rec.program)
    t = rec.targets
    assert len(t.time_s) == len(tp) == len(t.length_mm) == len(t.junction_sample) - 1
    # the junctions cover the whole trace: the block times add up to the recorded duration
    assert t.junction_sample[0] == 0 and t.junction_sample[-1] == rec.n_samples - 1
    assert np.isclose(rec.cycle_time_s, (rec.n_samples - 1) * PERIOD_S, rtol=0, atol=1e-9)
    step = round(recordings.TRACE_PERIOD_S / PERIOD_S)
    assert len(rec.feed_mm_s) == -(-rec.n_samples // step)
    cut = tp.kind != MotionKind.RAPID
    limit = MACHINE.rapid_feed_mm_s if not cut.all() else np.max(tp.feed_mm_s)
    assert rec.feed_mm_s.max() <= limit * (1 + 1e-4)  # never above F (or the rapid feed)
    # blending cuts corners: the blended path is no longer than the programmed one
    assert t.length_mm.sum() <= tp.lengths_mm.sum() + 1e-6
    # CAM time of the cutting moves (length / F) is a lower bound of the real cycle time
    assert rec.cycle_time_s >= (tp.lengths_mm[cut] / tp.feed_mm_s[cut]).sum() - 1e-9


@pytest.mark.usefixtures("linuxcnc_live")
@pytest.mark.parametrize("name", LIVE)
def test_live_recording_equals_shipped(name):
    shipped = SHIPPED[name]
    live = recordings.record_program(name, shipped.program, MACHINE)
    assert live.n_samples == shipped.n_samples
    assert live.trace_sha256 == shipped.trace_sha256
    np.testing.assert_array_equal(live.targets.junction_sample, shipped.targets.junction_sample)
    np.testing.assert_array_equal(live.feed_mm_s, shipped.feed_mm_s)
