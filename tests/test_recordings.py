"""Shipped LinuxCNC recordings (nctwin.recordings): consistent as shipped, and reproduced live.

The live test records two short programs of the shipped set on LinuxCNC and compares them with
the shipped recordings bit for bit (SHA-256 of the full position trace, per-block targets); it
is skipped where LinuxCNC cannot run (``make linuxcnc``). Public programs (not shipped) are
checked where ``../shared/programs`` lies beside the clone. Every sample program LinuxCNC installs
is either shipped and recorded or named in the public programs' README with the reason it is
not (where LinuxCNC is installed).
"""

import json
import re
from fnmatch import fnmatch
from pathlib import Path

import numpy as np
import pytest

from nctwin import record, recordings
from nctwin.gcode import parse
from nctwin.machine import load_profile
from nctwin.paths import linuxcnc_samples_dir, public_programs_dir
from nctwin.toolpath import MotionKind

SHIPPED = recordings.load_recordings()
PROFILE = load_profile(recordings.MACHINE)
MACHINE = PROFILE.machine
PERIOD_S = PROFILE.control("planner").period_s
OWN = sorted(n for n, r in SHIPPED.items() if r.source == "nctwin")
PUBLIC = sorted(n for n, r in SHIPPED.items() if r.source != "nctwin")
#: The two shortest of nctwin's own programs (a few seconds each).
LIVE = sorted(OWN, key=lambda name: SHIPPED[name].n_samples)[:2]


def test_shipped_set_is_the_specified_set():
    programs = record.recording_programs()
    assert OWN == sorted(programs)
    for name, text in programs.items():
        assert SHIPPED[name].program == text
        assert SHIPPED[name].program_sha256 == recordings.text_sha256(text)
        assert SHIPPED[name].machine == recordings.MACHINE
    assert len([n for n in OWN if n.startswith("train_")]) >= 60


def test_public_recordings_ship_no_program_text():
    assert PUBLIC, "the public programs' recordings are shipped"
    rejected = json.loads((recordings.recording_dir() / recordings.PUBLIC_REJECTED).read_text())
    for name in PUBLIC:
        rec = SHIPPED[name]
        assert rec.program == "" and rec.source.startswith("public/")
        assert rec.source.removeprefix("public/") not in rejected


def test_public_program_absent_or_changed(tmp_path):
    rec = SHIPPED[PUBLIC[0]]
    assert recordings.public_program_text(rec, tmp_path) is None
    (tmp_path / rec.source.removeprefix("public/")).write_text("G1 X1\n")
    with pytest.raises(ValueError, match="SHA-256 differs"):
        recordings.public_program_text(rec, tmp_path)


def test_public_program_nctwin_rejects_needs_no_linuxcnc(tmp_path):
    (tmp_path / "bad.ngc").write_text("G1 X1 A5\n")  # no reader reads a rotary axis
    recorded, rejected = record.record_public(tmp_path, tmp_path / "out")
    assert recorded == [] and list(rejected) == ["bad.ngc"]
    assert "bad.ngc:1:" in rejected["bad.ngc"]
    saved = json.loads((tmp_path / "out" / recordings.PUBLIC_REJECTED).read_text())
    assert saved == rejected


def _text(name: str) -> str:
    rec = SHIPPED[name]
    if rec.source == "nctwin":
        return rec.program
    text = recordings.public_program_text(rec)
    if text is None:
        pytest.skip(f"{rec.source} is not beside this clone")
    return text


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_recording_is_consistent(name):
    rec = SHIPPED[name]
    tp = parse(_text(name), tool_table=PROFILE.tool_table)
    t = rec.targets
    assert len(t.time_s) == len(tp) == len(t.length_mm) == len(t.junction_sample) - 1
    # the junctions cover the whole trace: the block times add up to the recorded duration
    assert t.junction_sample[0] == 0 and t.junction_sample[-1] == rec.n_samples - 1
    assert np.isclose(rec.cycle_time_s, (rec.n_samples - 1) * PERIOD_S, rtol=0, atol=1e-9)
    step = round(recordings.TRACE_PERIOD_S / PERIOD_S)
    assert len(rec.feed_mm_s) == -(-rec.n_samples // step)
    cut = tp.kind != MotionKind.RAPID
    limit = MACHINE.rapid_feed_mm_s if not cut.all() else np.max(tp.feed_mm_s)
    # never above F (or the rapid feed); halsampler prints positions to 1e-6 mm, so a speed
    # from two of them is known to sqrt(3) * 1e-3 mm/s at 1 ms
    assert rec.feed_mm_s.max() <= limit * (1 + 1e-4) + 2e-3
    # blending cuts corners: the blended path is no longer than the programmed one (to the
    # 1e-6 mm of halsampler's positions per block: an exact path, G61, keeps every block's
    # length), and the recording reaches the program's last move (LinuxCNC did not stop early)
    assert t.length_mm.sum() <= tp.lengths_mm.sum() + 1e-6 * len(tp)
    last = np.flatnonzero(tp.lengths_mm > 0)[-1]
    assert t.time_s[last] > 0
    # the blended length at the commanded feed (clipped to the machine's) is a lower bound of
    # the cycle time (CAM's own bound uses the programmed length, which blending shortens)
    feed = np.where(cut, tp.feed_mm_s, MACHINE.rapid_feed_mm_s)
    feed = np.minimum(feed, MACHINE.max_feed_mm_s)
    moving = tp.lengths_mm > 0
    assert rec.cycle_time_s >= (t.length_mm[moving] / feed[moving]).sum() - 1e-6


@pytest.mark.usefixtures("linuxcnc_live")
@pytest.mark.parametrize("name", LIVE)
def test_live_recording_equals_shipped(name):
    shipped = SHIPPED[name]
    live = record.record_program(name, shipped.program, PROFILE)
    assert live.n_samples == shipped.n_samples
    assert live.trace_sha256 == shipped.trace_sha256
    np.testing.assert_array_equal(live.targets.junction_sample, shipped.targets.junction_sample)
    np.testing.assert_array_equal(live.feed_mm_s, shipped.feed_mm_s)


#: Where Debian's linuxcnc-uspace installs LinuxCNC's sample programs.
LINUXCNC_NC_FILES = Path("/usr/share/linuxcnc/ncfiles")


@pytest.mark.usefixtures("linuxcnc_interpreter")
def test_every_linuxcnc_sample_is_shipped_or_named_with_its_reason():
    if not LINUXCNC_NC_FILES.is_dir():
        pytest.skip(f"{LINUXCNC_NC_FILES} is missing")
    shipped = sorted(p.name for p in linuxcnc_samples_dir().glob("*.ngc"))
    assert {n for n in PUBLIC if n.startswith("sample_")} == {
        "sample_" + Path(n).stem for n in shipped
    }
    readme = (public_programs_dir() / "README.md").read_text()
    section = readme.split("## LinuxCNC's sample programs")[1].split("\n## ")[0]
    reasons = section.split("not shipped, for one of these reasons:")[1].split("\n| file")[0]
    named = re.findall(r"`([^`\s]+)`", reasons)
    for path in sorted(LINUXCNC_NC_FILES.glob("*.ngc")):
        if path.name in shipped:
            continue
        assert any(
            fnmatch(path.name, n) or fnmatch(path.stem, n) or n in path.stem for n in named
        ), f"{path.name}: neither shipped nor named in the public programs' README"
