"""G5/G5.1 splines as LinuxCNC's task runs them (nctwin.gcode._splines): biarcs of the Bezier
curve, checked against numbers worked by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin import MotionKind
from nctwin.gcode import interpreter_available, parse
from nctwin.gcode._splines import bezier, control_points, preview_u, task_moves
from nctwin.toolpath import arc_sweep

needs_interp = pytest.mark.skipif(not interpreter_available(), reason="needs make linuxcnc")


def _path(rows: np.ndarray, start) -> tuple[float, np.ndarray]:
    """Length of the task's moves from ``start`` and points along them (200 per arc)."""
    p0, length, points = np.asarray(start, float), 0.0, []
    for kind, x, y, _, cx, cy, rot in rows:
        end = np.array([x, y])
        if kind == 1:
            length += float(np.hypot(*(end - p0)))
            points.append(p0 + np.linspace(0, 1, 200)[:, None] * (end - p0))
        else:
            c = np.array([cx, cy])
            r = float(np.hypot(*(p0 - c)))
            assert np.hypot(*(end - c)) == pytest.approx(r, abs=1e-12)  # a true arc
            a0 = math.atan2(p0[1] - c[1], p0[0] - c[0])
            a1 = math.atan2(end[1] - c[1], end[0] - c[0])
            sweep = (a1 - a0) % (2 * math.pi) if rot > 0 else -((a0 - a1) % (2 * math.pi))
            length += r * abs(sweep)
            a = a0 + np.linspace(0, 1, 200) * sweep
            points.append(c + r * np.column_stack([np.cos(a), np.sin(a)]))
        p0 = end
    return length, np.vstack(points)


def test_straight_spline_is_the_chord():
    """Control point on the chord: 12 parts (4 per control point), each one line of 1/12 of
    the chord, 10 mm in all (biarc's 0/0 comes to a line)."""
    rows = np.array(task_moves(np.array([[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]]), 1.0))
    assert (rows[:, 0] == 1).all() and len(rows) == 12
    length, _ = _path(rows, (0.0, 0.0))
    assert length == pytest.approx(10.0, abs=1e-12)
    assert rows[-1, 1:4].tolist() == [10.0, 0.0, 1.0]


def test_straight_diagonal_spline_is_the_chord():
    """Control point on the chord off its middle: a chord of 5 mm (3-4-5) is 5 mm long."""
    rows = np.array(task_moves(np.array([[0.0, 0.0], [0.6, 0.8], [3.0, 4.0]]), 0.0))
    length, _ = _path(rows, (0.0, 0.0))
    assert length == pytest.approx(5.0, rel=1e-9)


def test_parabola_biarcs_lie_on_the_curve():
    """P0 (0, 0), P1 (5, 5), P2 (10, 0) is the parabola y = x - x^2/10 on [0, 10], of length
    5 (sqrt 2 + asinh 1) mm; 12 biarcs, 24 tangent arcs, follow it within 1 um."""
    ctrl = np.array([[0.0, 0.0], [5.0, 5.0], [10.0, 0.0]])
    rows = np.array(task_moves(ctrl, 0.0))
    assert len(rows) == 24 and (rows[:, 0] == 2).all()
    length, points = _path(rows, (0.0, 0.0))
    assert length == pytest.approx(5 * (math.sqrt(2) + math.asinh(1)), rel=1e-6)
    x = np.clip(points[:, 0], 0, 10)
    assert np.abs(points[:, 1] - (x - x**2 / 10)).max() < 1e-3
    # the ends of the biarcs are points of the curve at u = i / 12
    ends = rows[1::2, 1:3]
    assert np.abs(ends - bezier(np.arange(1, 13) / 12, ctrl)).max() < 1e-12


def test_cubic_spline_has_16_biarcs():
    """G5 (4 control points): 16 parts; the end is the last control point."""
    ctrl = np.array([[0.0, 0.0], [0.0, 5.0], [10.0, 5.0], [10.0, 0.0]])
    rows = np.array(task_moves(ctrl, 0.0))
    assert len(rows) == 32
    assert rows[-1, 1:3] == pytest.approx([10.0, 0.0], abs=1e-12)


@pytest.mark.parametrize("k", [3, 4])
def test_control_points_from_preview(k):
    """The preview's 15 k points (44 and 59 inside, then the end) give back the control points."""
    assert len(preview_u(k)) == 15 * k
    ctrl = np.random.default_rng(k).uniform(-50, 50, (k, 2))
    assert control_points(bezier(preview_u(k), ctrl), k) == pytest.approx(ctrl, abs=1e-9)


@needs_interp
def test_reader_runs_the_task_moves():
    """Through LinuxCNC's interpreter: a straight G5.1 is 12 lines of the 10 mm chord, a curved
    one 24 arcs of the parabola's length; a G5 in inches ends where it is told."""
    text = "G21 G90 G1 F600 X0 Y0\nG5.1 X10 Y0 I5 J0\nG5.1 X20 Y0 I5 J5\nG1 X30\nM2\n"
    tp = parse(text, reader="linuxcnc")
    line = tp.line
    assert (tp.kind[line == 2] == MotionKind.LINEAR).all()
    assert tp.lengths_mm[line == 2].sum() == pytest.approx(10.0, abs=1e-9)
    arcs = tp.take(line == 3)
    assert len(arcs) == 24 and (arcs.kind != MotionKind.LINEAR).all()
    assert arcs.lengths_mm.sum() == pytest.approx(5 * (math.sqrt(2) + math.asinh(1)), rel=1e-6)
    sweep = arc_sweep(arcs.start_mm, arcs.end_mm, arcs.center_mm, arcs.plane,
                      arcs.kind == MotionKind.ARC_CCW)  # fmt: skip
    assert np.abs(sweep).max() < math.pi / 4
    inch = parse("G20 G90 G1 F20 X0 Y0\nG5 X1 Y0 I0 J0.5 P0 Q0.5\nM2\n", reader="linuxcnc")
    assert len(inch.take(inch.line == 2)) == 32
    assert inch.end_mm[-1] == pytest.approx([25.4, 0.0, 0.0], abs=1e-9)
