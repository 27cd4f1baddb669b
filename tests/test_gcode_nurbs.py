"""G5.2/G5.3 NURBS as LinuxCNC's task runs them (nctwin.gcode._splines): the rational B-spline
of LinuxCNC's knot vector, its biarcs, and the control points and weights recovered from the
preview's lines, checked against curves known by hand (a Bezier curve, a circle)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin import MotionKind
from nctwin.gcode import GCodeError, interpreter_available, parse
from nctwin.gcode._splines import (
    bezier,
    knot_vector,
    nurbs_fit,
    nurbs_points,
    nurbs_sizes,
    preview_u,
    task_moves,
)

needs_interp = pytest.mark.skipif(not interpreter_available(), reason="needs make linuxcnc")

#: A quarter circle of radius 30 about the origin as a rational quadratic: the middle control
#: point at the tangents' crossing, of weight cos 45 deg.
QUARTER = np.array([[30.0, 0.0], [30.0, 30.0], [0.0, 30.0]])
QUARTER_W = np.array([1.0, math.sqrt(0.5), 1.0])


def test_knot_vector_is_clamped_and_uniform():
    """5 control points of order 3: three 0s, 1, 2, three 3s (umax = n - k + 2 = 3)."""
    assert knot_vector(4, 3) == [0, 0, 0, 1, 2, 3, 3, 3]
    assert knot_vector(3, 4) == [0, 0, 0, 0, 1, 1, 1, 1]  # G5's Bezier


def test_weights_one_and_k_points_is_the_bezier_curve():
    """n + 1 = k control points, weights 1: the clamped knot vector makes the Bezier curve."""
    ctrl = np.array([[0.0, 0.0], [10.0, 40.0], [30.0, -20.0], [50.0, 10.0], [60.0, 0.0]])
    u = np.linspace(0.0, 1.0, 41)
    np.testing.assert_allclose(nurbs_points(u, ctrl, np.ones(5), 5), bezier(u, ctrl), atol=1e-12)


def test_weights_scale_free():
    """Multiplying every weight by 3 leaves the curve as it is (sum N w P / sum N w)."""
    ctrl = np.array([[0.0, 0.0], [10.0, 20.0], [30.0, -20.0], [40.0, 0.0]])
    w = np.array([1.0, 2.0, 0.5, 1.0])
    u = np.linspace(0.0, 2.0, 21)
    np.testing.assert_allclose(
        nurbs_points(u, ctrl, 3 * w, 3), nurbs_points(u, ctrl, w, 3), atol=1e-12
    )


def test_quadratic_bspline_at_its_inner_knot_is_the_midpoint():
    """A uniform quadratic B-spline (order 3, 4 points, knots 0 0 0 1 2 2 2) passes at u = 1
    through the middle of P1 P2; LinuxCNC's Nmix counts both spans there, the quotient does
    not change."""
    ctrl = np.array([[0.0, 0.0], [10.0, 20.0], [30.0, 20.0], [40.0, 0.0]])
    p = nurbs_points(np.array([1.0]), ctrl, np.ones(4), 3)[0]
    assert p == pytest.approx([20.0, 20.0], abs=1e-12)


def test_quarter_circle_is_on_the_circle():
    """The rational quadratic of weights 1, cos 45 deg, 1 lies on the circle of radius 30; its
    middle is the point at 45 deg."""
    u = np.linspace(0.0, 1.0, 101)
    p = nurbs_points(u, QUARTER, QUARTER_W, 3)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), 30.0, atol=1e-12)
    assert p[50] == pytest.approx([30 * math.sqrt(0.5)] * 2, abs=1e-12)


def test_quarter_circle_task_moves_are_the_circle():
    """12 biarcs (4 per control point) between points of the circle with its tangents: the
    arcs are the circle itself (centre 0, radius 30), 15 pi mm in all, ending at (0, 30). Inside,
    the tangents are central differences (angle error of order DU^2); at the two ends they are
    one-sided (``nurbs_tangent`` clips u to [0, umax]), an angle error of order DU = 1e-5 that
    moves the centres of the two short arcs at each end by some um: within 1e-2 mm."""
    rows = np.array(task_moves(QUARTER, 2.0, QUARTER_W, 3))
    assert len(rows) == 24 and (rows[:, 0] == 2).all()
    np.testing.assert_allclose(rows[2:-2, 4:6], 0.0, atol=1e-6)
    np.testing.assert_allclose(rows[:, 4:6], 0.0, atol=1e-2)
    assert (rows[:, 6] == 1).all()  # counter-clockwise
    assert rows[-1, 1:4] == pytest.approx([0.0, 30.0, 2.0], abs=1e-12)
    angles = np.r_[0.0, np.arctan2(rows[:, 2], rows[:, 1])]
    assert np.diff(angles).sum() * 30 == pytest.approx(15 * math.pi, rel=1e-9)


@pytest.mark.parametrize(("n", "k"), [(2, 3), (4, 3), (5, 4), (5, 5), (7, 4)])
def test_fit_recovers_control_points_and_weights(n, k):
    """The preview's 15 (n + 1) points of a NURBS give back its points, weights and size."""
    rng = np.random.default_rng(10 * n + k)
    ctrl = rng.uniform(-50, 50, (n + 1, 2))
    w = np.r_[1.0, rng.uniform(0.3, 3.0, n)]
    points = nurbs_points(preview_u(k, n), ctrl, w, k)
    assert (n, k) in nurbs_sizes(len(points))
    got_ctrl, got_w = nurbs_fit(points, n, k)
    np.testing.assert_allclose(got_ctrl, ctrl, atol=1e-8)
    np.testing.assert_allclose(got_w, w, rtol=1e-8)


def test_fit_of_collinear_even_points_is_not_unique():
    """Three control points evenly on a line, weights 1: the point moves as x = 20 u, and for
    any linear w(u) > 0 the weights of w and the weighted points of x w give the same points,
    so no single NURBS is told (the reader refuses it)."""
    ctrl = np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0]])
    points = nurbs_points(preview_u(3, 2), ctrl, np.ones(3), 3)
    np.testing.assert_allclose(points[:, 0], 20 * preview_u(3, 2), atol=1e-12)
    assert nurbs_fit(points, 2, 3) is None


@needs_interp
def test_reader_runs_the_quarter_circle():
    """Through LinuxCNC's interpreter: G5.2/G5.3 of the quarter circle about X60 Y0 is 24 arcs
    about that centre, 15 pi mm long, ending at X60 Y30; the G1 after it starts there."""
    text = "G21 G90 G1 F600 X90 Y0\nG5.2 X90 Y30 P0.7071067811865476\nX60 Y30 P1\nG5.3\nG1 X0\nM2\n"
    tp = parse(text, reader="linuxcnc")
    arcs = tp.take(tp.line == 4)
    assert len(arcs) == 24 and (arcs.kind == MotionKind.ARC_CCW).all()
    np.testing.assert_allclose(arcs.center_mm[2:-2, :2], [[60.0, 0.0]] * 20, atol=1e-6)
    assert arcs.lengths_mm.sum() == pytest.approx(15 * math.pi, rel=1e-7)  # the end arcs' um
    assert arcs.end_mm[-1] == pytest.approx([60.0, 30.0, 0.0], abs=1e-9)
    assert tp.lengths_mm[-1] == pytest.approx(60.0, abs=1e-9)


@needs_interp
def test_reader_order_and_inches():
    """L4 sets the order: 5 control points make 20 biarcs; in inches the end is 25.4 mm per
    inch."""
    text = "G20 G90 G1 F20 X0 Y0\nG5.2 X0 Y1 P1 L4\nX1 Y1 P2\nX1 Y0 P1\nX2 Y0 P0.5\nG5.3\nM2\n"
    tp = parse(text, reader="linuxcnc")
    assert (tp.line == 6).sum() == 40
    assert tp.end_mm[-1] == pytest.approx([50.8, 0.0, 0.0], abs=1e-9)


@needs_interp
def test_reader_refuses_a_nurbs_it_cannot_tell():
    """Control points evenly on a line: one clear line naming the G5.3 block."""
    text = "G21 G90 G1 F600 X0 Y0\nG5.2 X10 Y0 P1\nX20 Y0 P1\nG5.3\nM2\n"
    with pytest.raises(GCodeError, match=r"^<string>:4: this NURBS's control points"):
        parse(text, reader="linuxcnc")


def _to_polyline_mm(points: np.ndarray, trace: np.ndarray) -> np.ndarray:
    """Distance of each of ``points`` (q, 3) to the polyline through ``trace`` (n, 3): (q,)."""
    a, d = trace[:-1], np.diff(trace, axis=0)
    dd = np.maximum((d * d).sum(axis=1), 1e-300)
    t = np.clip(((points[:, None] - a) * d).sum(axis=2) / dd, 0.0, 1.0)
    return np.linalg.norm(a + t[..., None] * d - points[:, None], axis=2).min(axis=1)


@pytest.mark.usefixtures("linuxcnc_live")
def test_live_linuxcnc_passes_through_the_biarc_ends():
    """LinuxCNC's task runs the reader's moves: in exact-path mode (G61) its trace passes through
    every end of the reader's biarcs of a quarter circle and an L4 NURBS within 1e-4 mm (the
    1 ms polyline's chord error at 30 mm/s on radii of millimetres is some 1e-5 mm; the
    preview's lines miss them by up to 2e-2 mm) and stops at the last block's end."""
    from nctwin.kernel import linuxcnc
    from nctwin.machine import load_profile

    profile = load_profile("linuxcnc_sim")
    text = (
        "G21 G17 G90 G61\nG0 X30 Y0\nG1 F1800 X30 Y0\nG5.2 X30 Y30 P0.7071067811865476\n"
        "X0 Y30 P1\nG5.3\nG5.2 X-10 Y40 P1 L4\nX-30 Y20 P3\nX-20 Y0 P0.5\nX-40 Y-10 P1\nG5.3\n"
        "M2\n"
    )
    tp = parse(text, tool_table=profile.tool_table)
    motion = linuxcnc.run(text, profile.machine, profile.control("planner"),
                          tool_table=profile.tool_table)  # fmt: skip
    ends = tp.end_mm[np.isin(tp.line, [6, 11])]
    assert len(ends) == 24 + 40
    assert _to_polyline_mm(ends, motion.pos_mm).max() < 1e-4
    assert motion.pos_mm[-1] == pytest.approx(tp.end_mm[-1], abs=1e-6)
