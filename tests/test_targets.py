"""Junction points and per-block targets (nctwin.targets): the chunked search gives the same bits
as the search over all junctions at once, and hand-checkable times."""

from __future__ import annotations

import numpy as np
import pytest

from nctwin import parse
from nctwin.controls import AccDecControl
from nctwin.kernel import accdec, fir
from nctwin.machine import load_profile
from nctwin.motion import Motion
from nctwin.paths import public_programs_dir
from nctwin.programs.camstyle import cam_program
from nctwin.programs.pocket import pocket_program
from nctwin.targets import BlockTargets, block_targets
from nctwin.toolpath import MotionKind, Toolpath


def reference_block_targets(
    motion: Motion, toolpath: Toolpath, *, search_samples: int = 250
) -> BlockTargets:
    """``block_targets`` before the chunked search (commit 3893021): all junctions at once, a
    (N - 1, 2 w + 1, 3) array of candidate differences."""
    n = len(toolpath)
    n_samples = len(motion)
    pos, label = motion.pos_mm, motion.block
    junction = np.zeros(n + 1, dtype=np.int64)
    junction[n] = n_samples - 1
    if n > 1:
        points = toolpath.end_mm[:-1]
        switch = np.clip(np.searchsorted(label, np.arange(1, n), side="left"), 1, n_samples - 1)
        before, after = label[switch - 1], label[switch]
        offsets = np.arange(-search_samples, search_samples + 1)
        cand = np.clip(switch[:, None] + offsets[None, :], 0, n_samples - 1)
        d2 = ((pos[cand] - points[:, None, :]) ** 2).sum(axis=2)
        lab = label[cand]
        d2[(lab < before[:, None]) | (lab > after[:, None])] = np.inf
        first = np.argmin(d2, axis=1)
        last = d2.shape[1] - 1 - np.argmin(d2[:, ::-1], axis=1)
        leaving_dwell = toolpath.kind[:-1] == MotionKind.DWELL
        junction[1:n] = cand[np.arange(n - 1), np.where(leaving_dwell, last, first)]
        np.maximum.accumulate(junction, out=junction)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    travelled = np.concatenate([[0.0], np.cumsum(step)])
    return BlockTargets(
        junction_sample=junction,
        length_mm=np.diff(travelled[junction]),
        time_s=np.diff(junction) * motion.period_s,
    )


#: Rapids, exact stops (G61), dwells between moves, back-to-back dwells, a move that returns over
#: its own path, tiny moves far shorter than one sample and a program end right after a dwell.
STOPS_AND_DWELLS = """G21 G90 G64 P0.05
G0 X0 Y0 Z5
G1 Z0 F300
X20 F1200
G4 P0.25
Y10
G61
X0
Y0
G4 P0.1
G4 P0.05
G64 P0.2
X20 Y0.001
X20.0005
X20.001
X0
G0 Z5
G1 X5 Y5 Z5 F600
G4 P0.2
"""


def _contour_head(lines: int) -> str:
    text = (public_programs_dir() / "contour.ngc").read_text()
    return "\n".join(text.splitlines()[:lines]) + "\nM2\n"


def _cases():
    paper1 = load_profile("paper1_sim")
    generic = load_profile("generic_mill")
    yield "pocket", parse(pocket_program(feed_mm_s=50.0, tol_mm=0.3)), paper1
    yield "stops_dwells", parse(STOPS_AND_DWELLS), generic
    yield "contour_head", parse(_contour_head(3000)), generic
    for seed in (0, 1, 2):
        yield f"cam{seed}", parse(cam_program(seed)), generic


CASES = list(_cases())


@pytest.mark.parametrize(("name", "tp", "profile"), CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("kernel", ["fir", "accdec"])
def test_chunked_search_is_bit_identical_to_all_at_once(name, tp, profile, kernel):
    if kernel == "fir":
        motion = fir.run(tp, profile.machine, profile.control("fir"))
    else:
        motion = accdec.run(tp, profile.machine, profile.accdec or AccDecControl())
    ref = reference_block_targets(motion, tp)
    n_junctions = len(tp) - 1
    # chunks of one junction, chunks that split the junctions unevenly, one chunk exactly, and
    # more than all of them
    for chunk in (1, 7, 1024, n_junctions, n_junctions + 5):
        got = block_targets(motion, tp, chunk_junctions=max(chunk, 1))
        assert np.array_equal(got.junction_sample, ref.junction_sample), (name, chunk)
        assert np.array_equal(got.length_mm, ref.length_mm), (name, chunk)
        assert np.array_equal(got.time_s, ref.time_s), (name, chunk)
    # a narrow window clips at both ends of the motion and misses some junctions
    for w in (1, 3):
        got = block_targets(motion, tp, search_samples=w, chunk_junctions=5)
        ref_w = reference_block_targets(motion, tp, search_samples=w)
        assert np.array_equal(got.junction_sample, ref_w.junction_sample), (name, w)


def test_the_cases_have_dwells_stops_and_many_chunks():
    tp = dict((c[0], c[1]) for c in CASES)
    assert (tp["stops_dwells"].kind == MotionKind.DWELL).sum() == 4
    assert len(tp["pocket"]) > 4 * 1024  # crosses the default chunk's boundary four times
    assert len(tp["contour_head"]) > 2 * 1024


def test_dwell_times_are_read_between_first_and_last_tied_samples():
    # a 10 mm line at 10 mm/s, a 0.5 s dwell, back: on the FIR kernel the dwell's block takes
    # the dwell (to the servo period), and the cycle time is the motion's
    tp = parse("G21 G90 G61\nG1 X10 F600\nG4 P0.5\nX0\n")
    generic = load_profile("generic_mill")
    motion = fir.run(tp, generic.machine, generic.control("fir"))
    t = block_targets(motion, tp)
    assert t.time_s[1] == pytest.approx(0.5, abs=2 * motion.period_s)
    assert t.cycle_time_s == pytest.approx(motion.cycle_time_s, abs=motion.period_s)
    assert t.length_mm.sum() == pytest.approx(20.0, abs=1e-6)


def test_chunk_size_must_be_positive():
    tp = parse("G21 G90\nG1 X1 F600\nX2\n")
    generic = load_profile("generic_mill")
    motion = fir.run(tp, generic.machine, generic.control("fir"))
    with pytest.raises(ValueError, match="chunk_junctions = 0"):
        block_targets(motion, tp, chunk_junctions=0)
