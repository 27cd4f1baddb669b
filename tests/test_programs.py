"""Real part programs written by others (../shared/programs): each parses, or is rejected
with a GCodeError naming its line and construct. Skipped where ../shared is absent."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import SHARED_PROGRAMS

from nctwin import GCodeError, dump, parse, parse_file
from nctwin.estimate import estimate
from nctwin.gcode import interpreter_available
from nctwin.machine import load_profile

SUFFIXES = (".ngc", ".nc", ".gcode")
PROGRAMS = sorted(p.name for p in SHARED_PROGRAMS.glob("*") if p.suffix in SUFFIXES)
#: The programs the native reader rejects, and the construct it must name (the default reader
#: then reads them through LinuxCNC's interpreter, where it is installed).
REJECTED = {"3D_Chips.ngc": (9, "#-parameter needs LinuxCNC's interpreter: run make linuxcnc")}


@pytest.mark.parametrize("name", PROGRAMS or ["<none>"])
def test_program_parses_or_is_rejected_clearly(shared_programs, name):
    path = shared_programs / name
    if name in REJECTED:
        line, reason = REJECTED[name]
        with pytest.raises(GCodeError) as info:
            parse_file(path, reader="native")
        assert (info.value.line, info.value.reason) == (line, reason)
        assert info.value.text == path.read_text().splitlines()[line - 1]
        if not interpreter_available():
            return
    tp = parse_file(path)
    assert len(tp) > 0
    assert np.isfinite(tp.end_mm).all() and np.isfinite(tp.lengths_mm).all()
    # blocks are contiguous: each starts where the previous one ended
    np.testing.assert_array_equal(tp.start_mm[1:], tp.end_mm[:-1])
    # writing it back and reading it again gives the same tool path (the native reader reads
    # what dump writes: plain moves, whatever the program's own constructs were)
    assert parse(dump(tp), reader="native").allclose(tp)
    cam = estimate(tp, load_profile(), "cam")
    assert np.isfinite(cam.cycle_time_s) and cam.cycle_time_s > 0


def test_known_facts_of_programs(shared_programs):
    contour = parse_file(shared_programs / "contour.ngc")
    assert len(contour) == 10001  # one rapid, 10,000 G1 lines
    assert contour.kind_counts()["linear"] == 10000
    assert contour.end_mm[-1, 1] == pytest.approx(25.4)  # Y1.0000 in, in mm
    flat = parse_file(shared_programs / "test_12mmflat.ngc")
    assert flat.blend_tol_mm[0] == pytest.approx(0.5)  # G64 P.5 in mm
    assert (flat.plane[flat.is_arc] == 1).all()  # arcs in G18 (ZX)
