"""nctwin.kernel.fir_stream: the FIR kernel's block times in chunks are those of a whole run,
bit for bit, with and without slow-downs at the axis limits, whatever the chunk size."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin import gcode
from nctwin.kernel import fir
from nctwin.kernel.fir_stream import SEARCH_SAMPLES, stream_block_targets
from nctwin.machine import load_profile
from nctwin.paths import public_programs_dir
from nctwin.targets import block_targets

#: A dwell, an arc, exact stops and a rapid: 7 s of motion, 7,000 samples at 1 ms.
HAND = "G21 G90 F600\nG1 X10\nG4 P0.3\nG2 X20 Y0 I5 J0\nG61\nG1 Y10\nG1 X0\nG4 P1\nG0 Z5\nM2\n"


def _assert_same(tp, machine, control, chunk):
    whole = block_targets(fir.run(tp, machine, control), tp)
    streamed = stream_block_targets(tp, machine, control, chunk_samples=chunk)
    for name in ("junction_sample", "length_mm", "time_s"):
        np.testing.assert_array_equal(getattr(streamed, name), getattr(whole, name), name)


@pytest.mark.parametrize("chunk", [2 * SEARCH_SAMPLES + 2, 777, 5000])
@pytest.mark.parametrize("profile", ["generic_mill", "linuxcnc_sim", "paper1_sim"])
def test_a_hand_program_streams_to_the_same_bits(profile, chunk):
    prof = load_profile(profile)
    _assert_same(gcode.parse(HAND), prof.machine, prof.control_for("kernel"), chunk)


@pytest.mark.parametrize("name", ["blur_torus.ngc", "3D_Chips.ngc"])
def test_public_programs_with_slow_downs_stream_to_the_same_bits(name):
    # both slow down at the axis limits on paper1_sim (blur_torus: 945 samples over a limit)
    prof = load_profile("paper1_sim")
    tp = gcode.parse_file(public_programs_dir() / name)
    machine = dataclasses.replace(prof.machine, axis_max_jerk_mm_s3=(2000.0,) * 3)
    for m in (prof.machine, machine):
        _assert_same(tp, m, prof.control_for("kernel"), 2999)


@settings(max_examples=15, deadline=None)
@given(
    lines=st.lists(
        st.tuples(st.sampled_from(["G0", "G1", "G4"]), st.floats(-20, 20), st.floats(-20, 20)),
        min_size=1, max_size=25,
    ),
    chunk=st.integers(2 * SEARCH_SAMPLES + 2, 3000),
)  # fmt: skip
def test_random_programs_stream_to_the_same_bits(lines, chunk):
    text = ["G21 G90 G64 P0.05 F900"]
    for code, x, y in lines:
        text.append(f"G4 P{abs(x) / 40:.3f}" if code == "G4" else f"{code} X{x:.3f} Y{y:.3f}")
    prof = load_profile("linuxcnc_sim")
    _assert_same(gcode.parse("\n".join(text) + "\n"), prof.machine, prof.control_for("kernel"),
                 chunk)  # fmt: skip


def test_a_leading_dwell_streams_to_the_same_bits():
    # the smallest program hypothesis found where the end's samples were the dwell's block
    prof = load_profile("linuxcnc_sim")
    tp = gcode.parse("G21 G90 G64 P0.05 F900\nG4 P0.275\nG0 X0 Y16\nG0 X0 Y0\n")
    _assert_same(tp, prof.machine, prof.control_for("kernel"), 2 * SEARCH_SAMPLES + 2)


def test_a_short_program_is_one_run_and_a_bad_chunk_is_refused():
    prof = load_profile("generic_mill")
    _assert_same(gcode.parse("G1 X1 F600\n"), prof.machine, prof.control_for("kernel"), 1 << 18)
    with pytest.raises(
        ValueError,
        match="chunk_samples = 10 is out of range: allowed integers >= 502",
    ):
        stream_block_targets(gcode.parse(HAND), prof.machine, prof.control_for("kernel"),
                             chunk_samples=10)  # fmt: skip
