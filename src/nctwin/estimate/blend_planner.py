r"""Cycle time on a look-ahead planner with circular blend arcs and no jerk limit (LinuxCNC-like).

An analytic model of the kind of trajectory planner LinuxCNC 2.9 has (its "blend arc" planner):
the path is a queue of items, the moves and the circular arcs that round their junctions within
the blending tolerance; along every item the speed follows a trapezoid under a tangential
acceleration limit; look-ahead propagates every limit backward and forward. Nothing is fitted to
the recordings: the rules and constants are those of LinuxCNC's source (``emccanon.cc``,
``src/emc/tp/tp.c``, ``blendmath.c``, ``tc.c``; function names below), stated here as facts,
and where its behaviour was not clear from the source it was measured on LinuxCNC with short
test programs (below).

**What the planner receives.** LinuxCNC's canon first merges chains of straight feed moves that
lie within the naive-CAM tolerance ``G64 Q`` of one line (:func:`nctwin.naivecam.merge_naive_cam`).
The moves are the lines, rapids and arcs (whole) of non-zero length; feed and tangential
acceleration per move come from :func:`move_limits`: an arc keeps within the centripetal limit
of its plane's axes (in ``G18`` X and Z, in ``G19`` Y and Z: Z's 500 mm/s² on ``linuxcnc_sim``),
and splits its acceleration between tangent and normal at its speed limit, not at its feed.

**Junction** :math:`j` between moves of length :math:`L_1, L_2`, the first ending along the unit
tangent :math:`u_1`, the second starting along :math:`u_2`:

* the half supplement of the turn, :math:`\theta = \arccos(-u_1 \cdot u_2) / 2`
  (:math:`\pi/2` straight on, 0 for a reversal);
* the tolerance :math:`T = \min(P, r L_1, r L_2)` with :math:`r = 1/4`, where :math:`P` is the
  smaller ``G64 P`` of the two moves and a plain ``G64`` (no tolerance) means :math:`P = r L` of
  the move (``tcFindBlendTolerance``); the junction blends, stops or passes exactly as the mode
  of the move before it says (``tcSetupState``: a move keeps the mode in force when it is
  queued; checked live, ``G61`` then ``G64 P0.05`` round two corners 1.397 s (1.397), the other
  way round 1.356 s (1.356; 15 and 6 ms off with the mode of the move after));
* the largest distance from the corner along the moves the tolerance allows,
  :math:`d_{tol} = \cos\theta \, T / (1 - \sin\theta)`, and at most half of each move,
  :math:`d_g = \min(d_{tol}, L_1/2, L_2/2)`, the largest radius :math:`R_g = d_g \tan\theta`;
  the arc is only as large as its planned speed
  :math:`v_p = \min(\sqrt{a_n R_g}, \max(F_1, F_2))` needs (``blendComputeParameters``):
  :math:`R = \max(v_p^2 / a_n, \min(v_p t_b / (\pi - 2\theta), R_g))` with the blend time
  :math:`t_b = \min(\sqrt{a_j d_g}, v_p) / (a_j/2)`, so a slow or sharp corner gets a small arc;
  the arc length is :math:`R (\pi - 2\theta)`, and each move is shortened by
  :math:`d = R / \tan\theta`;
* the blend arc's acceleration is that of its plane (``blendParamKinematics``,
  ``calculateInscribedDiameter``): :math:`a_j = \min_i a_{i,\max} / \sqrt{1 - n_i^2}` with
  :math:`n` the unit normal of the plane of :math:`u_1, u_2` (:func:`blend_plane_acc`: 1000
  mm/s² for any turn in XY on ``linuxcnc_sim``, 500 in any plane that holds Z);
* the speed through the arc :math:`v_j = \min(\sqrt{a_n R}, F_1, F_2)` with
  :math:`a_n = \sqrt{1 - 0.5^2}\, a_j` and the tangential :math:`a_j/2` (``acc_ratio_tan``);
* first of all, a nearly tangent junction (:func:`tangent_junctions`, ``tpSetupTangent``) gets
  no arc: the tool passes it at the feed, both moves at :math:`1 - k` of their acceleration,
  in ``G64`` and in ``G61`` alike;
* ``G61`` stops at every other junction, with both moves at :math:`1 -` :data:`KINK_RATIO` of
  their acceleration (``tcSetKinkProperties``); ``G61.1``, a dwell, a change between rapid and
  feed motion (``tpCheckCanonType``, ``handleModeChange``; in ``G61`` too) and the program's
  ends stop the tool (:math:`v_j = 0`) at the full acceleration, and so does a turn within 2°
  of a reversal (:math:`2\theta` below
  :data:`STOP_TURN_RAD`, ``tpSetupTangent``'s sharp corner): measured on LinuxCNC, 13.7 mm and
  33.3 mm moves at 12.9 mm/s on a plain ``G64`` stop at turns of :math:`\pi` - 0.015 to
  :math:`\pi` - 0.032 rad (4.468 s with a 10 mm move after them) and are blended from
  :math:`\pi` - 0.035 rad on (3.558 s);
* a line's remainder between two arcs that the next arc would pass in under
  :data:`GAP_CYCLES` servo periods becomes part of that arc (``blendCheckConsume``);
* a junction with a programmed arc that is not tangent gets the blend arc LinuxCNC makes
  there (:mod:`~nctwin.estimate.blend_junctions`: the arc's limits on the blend's angle and
  size, the circle tangent to both moves, its failures), but only where that arc, whose speed
  is limited by its length per servo period, beats a tangent pass at the kink speed (both
  moves at :math:`1 -` :data:`KINK_RATIO` of their acceleration) and a parabolic blend
  (``tpChooseBestBlend``); out of the arc's plane the blend arc always fails. A parabolic
  blend (:func:`parabolic_junctions`) runs both moves at half their acceleration (on the arc:
  a speed limit :math:`1/\sqrt 2` lower and a tangential acceleration of :math:`a/4`), and
  the junction is passed at the speed of :func:`parabolic_blend_speeds`, from each move's
  length as the blends at its other end leave it.

**Items.** Along a line the tangential acceleration is the full :math:`a` the axes allow
(:math:`\min_i a_{i,\max} / |u_i|`), through straight-on junctions too (LinuxCNC halves it only
for a parabolic blend, ``tcGetOverallMaxAccel``), except on a move that keeps the parabolic end
condition it was queued with while blending is on: the move that ends the program or runs into
a dwell. That move accelerates and brakes at :math:`a/2`, and it is entered at most at its
triangle speed :math:`\sqrt{a L / 2}`. Every item runs at most at its length over
:data:`MIN_SEGMENT_CYCLES` servo periods (``tpComputeOptimalVelocity``), and the end of each is
no faster than LinuxCNC's look-ahead leaves it: it walks back from each newly queued move
through at most :data:`~nctwin.estimate.blend_speeds.OPTIMIZATION_DEPTH` items and, being
lazy, stops after :data:`~nctwin.estimate.blend_speeds.OPTIMIZATION_CUTOFF` items at their
peak (:func:`~nctwin.estimate.blend_speeds.optimised_end_speeds`, replayed move by move).
Then :math:`v_{j+1} \le \sqrt{v_j^2 + 2 a_k L_k}` forward and backward over the items.
Item time: the trapezoid (or triangle) from :math:`v_j` to :math:`v_{j+1}` under the feed.

Measured on LinuxCNC (``linuxcnc_sim``, recorded live; model in brackets): one 60 mm line at
50 mm/s in the default ``G64``: 1.301 s (1.300); a 90° corner of two 100 mm lines at 50 mm/s,
``G64 P0.1``: 4.131 s (4.130), with a 0.5 s dwell instead of the blend: 4.702-4.704 s (4.700),
under ``G61``: 4.112 s (4.112); six 10 mm lines with 90° corners at 100 mm/s, ``G64 P0.1``:
1.244 s (1.243); 120° and 90° corners at 150 mm/s, ``G64 P0.5``: 1.082 s (1.080); four 25.4 mm moves
that turn back within 0.002 rad, plain ``G64``: 1.519 s (1.519); collinear chains at 200 mm/s,
plain ``G64``: 300 x 1 mm 1.740 s (1.739), 10 x 5 mm 0.528 s (0.527), 3 x 20 mm 0.616 s
(0.615), 300 x 0.2 mm 0.583 s (0.583, held at 142 mm/s by the depth), 300 x 0.05 mm 0.364 s
(0.364, held at 49 mm/s by the item length); zigzags of 45° moves, 20 x 5 mm in XY at
``G64 P0.5``: 2.237 s (2.237), 20 x 1 mm in XZ: 1.109 s (1.109); a rapid then a feed move:
0.483 s (0.483); a G2 quarter circle of 10 mm radius under ``G61``: 0.355 s (0.355); 79 moves
of 0.4 mm round a 20 mm corner at 92 mm/s, ``G64 P0.3``, then a 40 mm line: 1.497 s (1.497, the
lazy look-ahead's dip to 50 mm/s); a line along Y into a G18 arc: 1.806 s (1.799). Naive-CAM
merging: 300 moves of 0.01-0.1 mm with 2° turns under ``G64 P0.01`` 0.407 s (0.412); the
public programs Cereal, Pasta and wheels, whose lines LinuxCNC reports are exactly those of the
merged moves. The model misses two collinear lines (1.301 s, model 1.275: LinuxCNC runs the
first at :math:`a/2` too) and 200 moves wiggling 0.004 mm about a line under ``G64 P0.01``,
merged into two lines (0.254 s, model 0.273). The live tests of :mod:`nctwin.kernel.linuxcnc`
check eight of these programs. Some model values here date from before stops were put on
whole servo periods (below), which adds less than 1 ms to a program that stops only at its end.

Not modelled: the parabolic blends LinuxCNC falls back to between two lines where no arc fits
(``tpChooseBestBlend`` is applied at junctions with an arc only), a line consumed by a blend
into the last move (LinuxCNC compares with the blend's planned speed; here with the junction's
speed, which is lower into a short last move). The stops and rests of LinuxCNC's task around
dwells and M-codes are :mod:`~nctwin.estimate.task_waits`'. The rules for junctions with an arc
(:mod:`~nctwin.estimate.blend_junctions`) came from the public programs ``blur_torus`` and
``LHchips4`` (-2.7 and -2.1 % before them, +0.07 and -0.48 % with them), each read in
LinuxCNC's source and checked live on 70 short programs of an arc, a line of 0.126 or 1 mm
and a 10 mm line with kinks of 0.5-10 degrees either way, in XY and YZ, in both orders, two
arcs, and an arc into the last line: 61 within 2.5 ms of LinuxCNC (before them 12); the
misses, within 52 ms, are 0.5 degree kinks before a 1 mm line and two arcs at a 1 degree kink.
Three rules were added after the CAM-style recordings (:mod:`nctwin.programs.camstyle`) had
shown the model wrong by up to 59 % (``G61`` 3D rasters, stopped at every 0.3 mm step where
LinuxCNC passes them as tangent) and 20 % (slow reversals on a plain ``G64``, whose arcs were
taken as large as the tolerance allows): the tangent junctions, the blend arc sized for its
speed, and ``G61``'s reduced acceleration, each read in LinuxCNC's source and checked live:
``G61``, 20 chords of 1 mm on a 500 mm radius at 30 mm/s (tangent): 0.699 s (0.702); 10
chords of 1 mm on a 20 mm radius (stops): 0.657 s (0.657); plain
``G64``, six 10 mm moves turning by 140 degrees at 20 mm/s: 2.673 s (2.673), by 160 degrees
at 6 mm/s: 9.713 s (9.713), by 170 degrees at 60 mm/s: 1.070 s (1.070); 20 mm moves turning
by 60 degrees at 30 mm/s: 5.332 s (5.331, 4.940 with the largest arcs).
A fourth rule came from the ``G61`` programs the planner still underestimated, by about half a
servo period per stop: the tool comes to rest on a whole servo period (:func:`stops_on_periods`,
``tpCheckEndCondition``). Checked live under ``G61``: 100 chords of 0.3 mm on a 50 mm radius
at 60 mm/s: 3.594 s (3.594; 3.541 as trapezoids); circles of 5 mm radius in 20, 100 and 400
chords at 50 mm/s: 1.580, 3.592 and 7.272 s (1.580, 3.592 and 7.272; 1.573, 3.540 and 7.082 as
trapezoids); under ``G61.1``, the 0.3 mm chords on a 500 mm radius: 3.500 s (3.500; 3.463).

Arcs outside the XY plane (``G18``, ``G19``) and helices: :func:`move_limits` (canon's
``ARC_FEED``, ``tcUpdateCircleAccRatio``, ``pmCircleActualMaxVel``,
``pmCircleEffectiveMinRadius``) and the directions of parabolic blends at arcs
(:func:`~nctwin.estimate.blend_junctions.parabolic_directions`). Checked live: half circles of
10 mm radius at 20 mm/s in XY, XZ and YZ as the last move, 1.651, 1.731 and 1.731 s (1.651, 1.731,
1.731; before these rules 1.611, 1.652, 1.652); half circles of 5, 40 and 100 mm radius between
lines, in XY and XZ, under ``G61`` and ``G64 P0.01``: all twelve within 1 ms (before: up to
-2.0 %); a ``G18`` helix of 10 mm radius and a ``G19`` helical turn of 5 mm radius between lines:
2.264 and 1.407 s under ``G61`` (2.264, 1.407; before 2.264, 1.524), 2.397 and 1.431 s under
``G64 P0.01`` (2.392, 1.428; before 2.349, 1.922); LinuxCNC's sample ``3dtest.ngc``, a circle in
each plane: 51.345 s (51.345; before 51.282).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from ..controls import PlannerControl
from ..limits import path_limits
from ..machine import Machine
from ..naivecam import merge_naive_cam
from ..toolpath import MotionKind, PathMode, Toolpath
from .blend_junctions import (
    ARC_BLEND,
    GAP_CYCLES,
    KINK_RATIO,
    PARABOLIC_BLEND,
    TANGENT_BLEND,
    arc_junctions,
    blend_plane_acc,
    parabolic_directions,
)
from .blend_speeds import optimised_end_speeds, segment_times, stops_on_periods
from .result import Estimate
from .task_waits import task_stops

__all__ = [
    "KINK_RATIO",
    "NORMAL_ACC_RATIO",
    "STOP_PERIODS",
    "STOP_TURN_RAD",
    "TANGENTIAL_ACC_RATIO",
    "TOLERANCE_RATIO",
    "blend_planner",
]

#: Share of the acceleration kept for the tangential direction in a blend arc, and on a move
#: with a parabolic end.
TANGENTIAL_ACC_RATIO = 0.5
#: Share of the acceleration available for the normal direction in a blend arc.
NORMAL_ACC_RATIO = math.sqrt(1.0 - TANGENTIAL_ACC_RATIO**2)
#: Largest blend tolerance as a share of each of the two moves' lengths.
TOLERANCE_RATIO = 0.25
#: A turn this close to a reversal (rad) stops the tool instead of being blended
#: (``SHARP_CORNER_DEG`` = 2 in ``tpSetupTangent``).
STOP_TURN_RAD = math.radians(2.0)
#: An item runs at most at its length over this many servo periods (``TP_MIN_SEGMENT_CYCLES``).
MIN_SEGMENT_CYCLES = 1.02
#: What a stop costs beyond its trapezoids (:func:`blend_planner`'s ``stop_periods``).
STOP_PERIODS = ("whole", "mean", "off")


def move_limits(
    moves: Toolpath,
    machine: Machine,
    acc_scale: np.ndarray | None = None,
    *,
    finalized: np.ndarray | None = None,
    arc_ratio: str = "max_speed",
) -> tuple[np.ndarray, np.ndarray]:
    r"""Feed and tangential acceleration of each move as LinuxCNC plans it, shapes (M,).

    Lines and rapids: the feed (the rapid feed for rapids) within the control's maximum and
    the axes' velocities, :math:`\min_i v_{i,\max} / |u_i|`, and the path acceleration the
    axes allow, :math:`a = \min_i a_{i,\max} / |u_i|` (canon's ``getStraightVelocity``,
    ``getStraightAcceleration``; :func:`nctwin.limits.path_limits`, whose rule for arcs is
    LinuxCNC's: the plane's two axes take the planar share :math:`r\phi/l` of the length and the
    third the helical share :math:`h/l`).

    Arcs (``arc_ratio="max_speed"``, LinuxCNC's rule), in three steps:

    * canon's ``ARC_FEED`` gives the arc the speed limit
      :math:`v_{\max} = \min(v_a, \sqrt{a_n a_p r}\; l / (r\phi))` with :math:`v_a` the
      axes' limit above and :math:`a_p` the smaller acceleration of the plane's two axes (X and
      Z in ``G18``, Y and Z in ``G19``), :math:`a_n` = :data:`NORMAL_ACC_RATIO`;
    * when the next move is queued the arc is finalized (``tcFinalizeLength``,
      ``tcUpdateCircleAccRatio``, ``pmCircleActualMaxVel``): with its overall acceleration
      :math:`a' = a s` (``tcGetOverallMaxAccel``: ``acc_scale`` :math:`s`) and its effective
      radius :math:`r_e = r + h^2/r` (``pmCircleEffectiveMinRadius``, with the whole rise
      :math:`h`), the normal acceleration at *the speed limit*, not at the feed,
      :math:`a_v = v_{\max}^2 / r_e`, decides: above :math:`a_n a'` the limit drops to
      :math:`\sqrt{a_n a' r_e}` and the tangential acceleration is :math:`a'/2`, else it is
      :math:`a' \sqrt{1 - (a_v / a')^2}`: a slow arc of small radius accelerates at
      :math:`a'/2` as a fast one does;
    * an arc never finalized (the program's last move, a move before a dwell; ``finalized``
      False) keeps the tangential acceleration :math:`a'/2` it was queued with (``tcInit``).

    The feed is the programmed one within :math:`v_{\max}`.
    ``arc_ratio="feed"`` is the rule as first written, from the programmed feed
    :math:`F` instead: a speed within :math:`\sqrt{a_n a' r}` and the tangential acceleration
    :math:`a' \sqrt{1 - (F^2 / (r a'))^2}` (:math:`a'/2` where that limit binds); the learned
    methods' features keep it (:mod:`nctwin.estimate.learned`).

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length (no dwells).
    machine : Machine
    acc_scale : ndarray, shape (M,), optional
        Share of the acceleration each move may use (LinuxCNC halves it on both moves of a
        parabolic blend, ``tcGetOverallMaxAccel``); 1 by default.
    finalized : ndarray of bool, shape (M,), optional
        The move is finalized (all but the last by default).
    arc_ratio : {"max_speed", "feed"}
        The rule for arcs (above).
    """
    if arc_ratio not in ("max_speed", "feed"):
        raise ValueError(f"arc_ratio = {arc_ratio!r} is not allowed: allowed max_speed, feed")
    limits = path_limits(moves, machine)
    v_axes, acc = limits.velocity_mm_s, limits.acceleration_mm_s2
    if acc_scale is not None:
        acc = acc * acc_scale
    rapid = moves.kind == MotionKind.RAPID
    feed = np.where(rapid, machine.rapid_feed_mm_s, moves.feed_mm_s)
    feed = np.minimum(np.minimum(feed, machine.max_feed_mm_s), v_axes)
    arc = np.flatnonzero(moves.is_arc)
    if not len(arc):
        return feed, acc
    r, a, f = moves.radius_mm[arc], acc[arc], feed[arc]
    if arc_ratio == "feed":
        a_normal = f**2 / r
        cut = a_normal > NORMAL_ACC_RATIO * a
        feed[arc] = np.where(cut, np.sqrt(NORMAL_ACC_RATIO * a * r), f)
        ratio = np.sqrt(np.maximum(1.0 - (a_normal / a) ** 2, 0.0))
        acc[arc] = a * np.where(cut, TANGENTIAL_ACC_RATIO, ratio)
        return feed, acc
    if finalized is None:
        finalized = np.arange(len(moves)) < len(moves) - 1
    ax = moves._plane_axes[arc]
    axis_acc = np.asarray(machine.axis_max_acceleration_mm_s2)
    plane_acc = np.minimum(axis_acc[ax[:, 0]], axis_acc[ax[:, 1]])
    length = moves.lengths_mm[arc]
    planar = r * np.abs(moves.sweep_rad[arc])
    v_max = np.minimum(v_axes[arc], np.sqrt(NORMAL_ACC_RATIO * plane_acc * r) * length / planar)
    rise_sq = np.maximum(length**2 - planar**2, 0.0)
    r_eff = r + rise_sq / r
    a_v = v_max**2 / r_eff
    done = finalized[arc]
    cut = done & (a_v > NORMAL_ACC_RATIO * a)
    v_max = np.where(cut, np.sqrt(NORMAL_ACC_RATIO * a * r_eff), v_max)
    ratio = np.sqrt(np.maximum(1.0 - (a_v / a) ** 2, 0.0))
    ratio = np.where(cut | ~done, TANGENTIAL_ACC_RATIO, ratio)
    feed[arc] = np.minimum(f, v_max)
    acc[arc] = a * ratio
    return feed, acc


def junction_blends(
    length_mm: np.ndarray,
    end_tangents: np.ndarray,
    start_tangents: np.ndarray,
    feed_mm_s: np.ndarray,
    tol_mm: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
    *,
    sized_arcs: bool = True,
    stop_turn_rad: float = STOP_TURN_RAD,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Blend arcs at the junctions of M moves: speed limit, consumed length, arc length and the
    arc's acceleration.

    Parameters
    ----------
    length_mm, feed_mm_s : ndarray, shape (M,)
        Length and feed of each move.
    end_tangents, start_tangents : ndarray, shape (M, 3)
        Unit tangent at the end and at the start of each move.
    tol_mm : ndarray, shape (M,)
        Blending tolerance the move starts with (``inf``: no tolerance, 0: exact stop).
    axis_acc_mm_s2 : ndarray, shape (3,)
        Acceleration limit of each axis.
    sized_arcs : bool
        Size each arc for its planned speed (LinuxCNC); False takes the largest arc the
        tolerance and the moves allow (the ablation of the chapter).
    stop_turn_rad : float
        A turn closer than this to a reversal stops the tool (:data:`STOP_TURN_RAD`).

    Returns
    -------
    v_mm_s : ndarray, shape (M - 1,)
        Speed limit at the junction after each move but the last (0: the tool stops).
    d_mm : ndarray, shape (M - 1,)
        Length the blend takes off the end of the move before and the start of the move after
        (0 where no arc is made).
    arc_mm : ndarray, shape (M - 1,)
        Length of the blend arc (0 where none is made).
    acc_mm_s2 : ndarray, shape (M - 1,)
        Acceleration of the blend arc (:func:`blend_plane_acc`; ``inf`` where none is made).
    """
    l1, l2 = length_mm[:-1], length_mm[1:]
    p = tol_mm[1:]
    limit = TOLERANCE_RATIO * np.minimum(l1, l2)
    tol = np.minimum(np.where(np.isinf(p), limit, p), limit)
    u1, u2 = end_tangents[:-1], start_tangents[1:]
    dot = np.clip(np.einsum("ij,ij->i", u1, u2), -1.0, 1.0)
    theta = np.arccos(-dot) / 2.0
    sin_t = np.sin(theta)
    straight = sin_t >= 1.0 - 1e-12
    acc = blend_plane_acc(u1, u2, axis_acc_mm_s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_tol = np.cos(theta) * tol / (1.0 - sin_t)
        d_geom = np.minimum(np.minimum(l1, l2) / 2.0, d_tol)
        r_plan = np.tan(theta) * d_geom
        a_n = NORMAL_ACC_RATIO * acc
        if sized_arcs:  # the arc is only as large as its planned speed needs
            v_plan = np.minimum(np.sqrt(a_n * r_plan), np.maximum(feed_mm_s[:-1], feed_mm_s[1:]))
            a_para = TANGENTIAL_ACC_RATIO * acc
            t_blend = np.minimum(np.sqrt(2.0 * a_para * d_geom), v_plan) / a_para
            r_blend = np.minimum(t_blend * v_plan / (np.pi - 2.0 * theta), r_plan)
            r_plan = np.maximum(v_plan**2 / a_n, r_blend)
        radius = np.where(straight, np.inf, r_plan)
        d = np.where(straight, d_geom, radius / np.tan(theta))
        v = np.minimum(np.sqrt(a_n * radius), np.minimum(feed_mm_s[:-1], feed_mm_s[1:]))
    v = np.where((p > 0) & (2.0 * theta >= stop_turn_rad), v, 0.0)
    arc = (v > 0) & ~straight
    arc_radius = np.where(arc, radius, 0.0)
    return v, np.where(arc, d, 0.0), arc_radius * (np.pi - 2.0 * theta), acc


def tangent_junctions(
    moves: Toolpath,
    feed_mm_s: np.ndarray,
    acc_mm_s2: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
    period_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Junctions of M moves that LinuxCNC passes as tangent (``tpSetupTangent``), (M - 1,).

    Before it makes a blend arc, LinuxCNC asks what the kink would cost: the change of
    direction at the speed :math:`v = \min(v_1, v_2)` (each move's feed within its limits and
    its length per :data:`MIN_SEGMENT_CYCLES` periods) in one servo period, plus the next
    move's acceleration, :math:`\Delta a = (v / T_s + a_2)(u_2 - u_1)`, as a share of each
    axis's limit, :math:`k = \max_i |\Delta a_i| / a_{i,\max}` (doubled where an arc takes
    part). Where :math:`k` < :data:`KINK_RATIO` the junction is tangent: no blend arc, no stop,
    in ``G61`` (exact path) too, and both moves accelerate at :math:`1 - k` of their limit
    (``tcGetOverallMaxAccel``).

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length.
    feed_mm_s, acc_mm_s2 : ndarray, shape (M,)
        Feed and acceleration of each move (:func:`move_limits`).
    axis_acc_mm_s2 : ndarray, shape (3,)
    period_s : float
        Servo period.

    Returns
    -------
    tangent : ndarray of bool, shape (M - 1,)
    kink_share : ndarray, shape (M - 1,)
        :math:`k` of each junction.
    """
    u1, u2 = moves.end_tangents[:-1], moves.start_tangents[1:]
    v = np.minimum(feed_mm_s, moves.lengths_mm / (MIN_SEGMENT_CYCLES * period_s))
    a_inst = np.minimum(v[:-1], v[1:]) / period_s + acc_mm_s2[1:]
    share = np.max(np.abs(a_inst[:, None] * (u2 - u1)) / np.asarray(axis_acc_mm_s2), axis=1)
    arc = moves.is_arc
    share = np.where(arc[:-1] | arc[1:], share / TANGENTIAL_ACC_RATIO, share)
    return share < KINK_RATIO, share


def parabolic_junctions(
    moves: Toolpath,
    tol_mm: np.ndarray,
    stop_turn_rad: float = STOP_TURN_RAD,
    *,
    in_plane: bool = False,
) -> np.ndarray:
    """Junctions of M moves that LinuxCNC joins with a parabolic blend, shape (M - 1,).

    A junction with a circular move gets a blend arc only if the other move lies in the arc's
    plane (two arcs: parallel planes); otherwise ``tpCreateLineArcBlend`` (``ArcLine``,
    ``ArcArc``) fails and ``tpChooseBestBlend`` falls back to a parabolic blend (or, with the
    planner's ``arc_blends``, to a tangent pass where that is faster). Straight-on junctions,
    stops (a tolerance of 0, a near-reversal) and line-line junctions are not parabolic.
    ``in_plane=True`` keeps the junctions in the arc's plane too: every junction with an arc
    that is blended somehow.
    """
    m = len(moves)
    arc = moves.is_arc
    normal = np.zeros((m, 3))
    normal[np.arange(m), moves._plane_axes[:, 2]] = 1.0  # of the arc's plane
    u1, u2 = moves.end_tangents[:-1], moves.start_tangents[1:]
    b = np.cross(u1, u2)
    size = np.linalg.norm(b, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = b / size[:, None]

    def parallel(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.abs(np.abs(np.einsum("ij,ij->i", x, y)) - 1.0) < 1e-6

    planar = (parallel(b, normal[:-1]) | ~arc[:-1]) & (parallel(b, normal[1:]) | ~arc[1:])
    planar &= ~(arc[:-1] & arc[1:]) | parallel(normal[:-1], normal[1:])
    dot = np.clip(np.einsum("ij,ij->i", u1, u2), -1.0, 1.0)
    straight = dot >= 1.0 - 1e-12
    reversal = np.arccos(-dot) < stop_turn_rad  # stops
    blended = (arc[:-1] | arc[1:]) & (tol_mm[1:] > 0) & ~straight & ~reversal
    return blended if in_plane else blended & ~planar


def parabolic_blend_speeds(
    length_mm: np.ndarray,
    feed_mm_s: np.ndarray,
    acc_mm_s2: np.ndarray,
    end_tangents: np.ndarray,
    start_tangents: np.ndarray,
    tol_mm: np.ndarray,
) -> np.ndarray:
    r"""Speed at the junctions of M moves if they were joined by parabolic blends, (M - 1,).

    ``tpComputeBlendVelocity`` with the halved accelerations :math:`a_1, a_2`: each move's
    reachable speed :math:`v_{r,i} = \min(\sqrt{a_i L_i}, F_i)`, the blend time
    :math:`t_b = \min(L_1/v_{r,1}, L_2/v_{r,2}, \max(v_{r,1}/a_1, v_{r,2}/a_2))`, and the
    speed :math:`v_i = \min(v_{r,i}, a_i t_b, 2\sqrt{a_1 T / \cos\theta})`. The move before
    stops over :math:`v_1/a_1` while the next speeds up (``tpUpdateBlend``), at most to
    :math:`v_2`: the junction is passed as if at :math:`\min(v_1, v_2, a_2 v_1 / a_1)`.
    """
    l1, l2, a1, a2 = length_mm[:-1], length_mm[1:], acc_mm_s2[:-1], acc_mm_s2[1:]
    vr1 = np.minimum(np.sqrt(a1 * l1), feed_mm_s[:-1])
    vr2 = np.minimum(np.sqrt(a2 * l2), feed_mm_s[1:])
    t_blend = np.minimum(np.minimum(l1 / vr1, l2 / vr2), np.maximum(vr1 / a1, vr2 / a2))
    dot = np.clip(np.einsum("ij,ij->i", end_tangents[:-1], start_tangents[1:]), -1.0, 1.0)
    cos_t = np.cos(np.arccos(-dot) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_tol = np.where(cos_t > 1e-3, 2.0 * np.sqrt(a1 * tol_mm[1:] / cos_t), np.inf)
    v1 = np.minimum(np.minimum(vr1, t_blend * a1), v_tol)
    v2 = np.minimum(np.minimum(vr2, t_blend * a2), v_tol)
    return np.minimum(v1, np.minimum(v2, a2 * v1 / a1))


def blend_planner(
    toolpath: Toolpath,
    machine: Machine,
    control: PlannerControl,
    *,
    kinks: bool = True,
    sized_arcs: bool = True,
    arc_blends: bool = True,
    arc_rules: bool = True,
    stop_periods: str = "whole",
    stop_turn_rad: float = STOP_TURN_RAD,
) -> Estimate:
    """Cycle time on the blend-arc look-ahead planner (see the module docstring).

    Parameters
    ----------
    toolpath : Toolpath
        N blocks (arcs are taken as chords).
    machine : Machine
        Axis velocity and acceleration limits, maximum and rapid feed.
    control : PlannerControl
        Servo period and the tolerance where the program sets none.
    kinks, sized_arcs : bool
        LinuxCNC's rules for nearly tangent junctions and G61's reduced acceleration
        (:func:`tangent_junctions`), and for the size of blend arcs (:func:`junction_blends`);
        both on by default, off only for the ablation that shows what each is worth.
    arc_blends : bool
        LinuxCNC's blend arcs at junctions with a programmed arc, and what replaces them where
        they fail or are slower (:func:`~nctwin.estimate.blend_junctions.arc_junctions`); on by
        default (needs ``kinks``), off for the ablation: the line-line formula on the tangents.
    arc_rules : bool
        LinuxCNC's rules for programmed arcs: the tangential acceleration from the arc's speed
        limit (:func:`move_limits`) and the directions of parabolic blends at arcs
        (:func:`~nctwin.estimate.blend_junctions.parabolic_directions`); on by default, off
        for the ablation: the acceleration from the feed and the blends on the tangents.
    stop_periods : {"whole", "mean", "off"}
        ``whole``: the tool comes to rest on a servo period (:func:`stops_on_periods`), as on
        LinuxCNC; ``mean``: each stop adds half a period instead, the mean of the same on
        average and a smooth function of the machine's limits (for fitting them, where whole
        periods make the cycle time a step function); ``off``: no time for it (the ablation).
    stop_turn_rad : float
        A turn closer than this to a reversal stops the tool: LinuxCNC's 2° by default
        (:data:`STOP_TURN_RAD`); the ablation's planner as first written used 0.02 rad.

    Returns
    -------
    Estimate
        ``method="planner"``, per-block times of shape (N,) (a dwell its own time; a blend arc's
        time is shared by the two moves it joins).
    """
    if stop_periods not in STOP_PERIODS:
        raise ValueError(
            f"stop_periods = {stop_periods!r} is not allowed: allowed {', '.join(STOP_PERIODS)}"
        )
    merged, merged_source = merge_naive_cam(toolpath)
    source = np.flatnonzero((merged.kind != MotionKind.DWELL) & (merged.lengths_mm > 0))
    if not len(source):
        return Estimate("planner", machine.name, toolpath.dwell_s.copy(), toolpath)
    moves = merged.take(source)
    length = moves.lengths_mm
    own = moves.effective_tolerance_mm(control.blend_tol_mm)
    # the junction after a move: that move's mode (tcSetupState, the term condition in force
    # when it was queued) and the smaller of the two moves' tolerances (tcFindBlendTolerance)
    given = np.where(np.isfinite(own) & (own > 0), own, np.inf)
    tol = own.copy()
    tol[1:] = np.where(own[:-1] == 0, 0.0, np.minimum(given[:-1], given[1:]))
    # a dwell or a word the task waits for (task_waits) stops the tool; the move before it keeps
    # its parabolic end, and, like the last move, is never finalized (an arc keeps a / 2)
    after, rest_block, rest_s = task_stops(toolpath, merged_source, source, control)
    parabolic_end = np.zeros(len(moves), bool)
    parabolic_end[after[(after > 0) & (after <= len(moves))] - 1] = True
    parabolic_end[-1] = True
    limits = functools.partial(
        move_limits, finalized=~parabolic_end, arc_ratio="max_speed" if arc_rules else "feed"
    )
    feed, acc = limits(moves, machine)
    parabolic_end &= own > 0
    tol[after[after < len(moves)]] = 0.0
    # LinuxCNC does not blend between a rapid and a feed move: the tool stops (tpCheckCanonType)
    rapid = moves.kind == MotionKind.RAPID
    tol[1:][rapid[1:] != rapid[:-1]] = 0.0
    axis_acc = np.asarray(machine.axis_max_acceleration_mm_s2)
    # nearly tangent junctions (but not into an exact stop): no blend arc, no stop, both moves
    # at 1 - k of their acceleration; the other G61 junctions stop with both moves at
    # 1 - KINK_RATIO (tcSetKinkProperties, kept where no blend arc replaces the kink); a change
    # between rapid and feed stops in G61 too, before any kink is set (handleModeChange)
    stop = (tol[1:] == 0) & (moves.path_mode[:-1] != PathMode.EXACT_PATH)
    stop |= rapid[1:] != rapid[:-1]
    tangent, kink = tangent_junctions(moves, feed, acc, axis_acc, control.period_s)
    tangent &= ~stop & kinks
    # a turn within stop_turn_rad of a reversal stops the tool before any kink is set
    # (tpSetupTangent's sharp corner): no reduced acceleration
    dot = np.einsum("ij,ij->i", moves.end_tangents[:-1], moves.start_tangents[1:])
    sharp = np.arccos(-np.clip(dot, -1.0, 1.0)) < stop_turn_rad
    exact = (tol[1:] == 0) & ~stop & ~tangent & ~sharp & kinks
    # a junction with an arc: a blend arc as LinuxCNC makes it, if it beats a tangent pass at
    # the kink speed and a parabolic blend (blend_junctions); the tangent pass keeps both
    # moves at 1 - KINK_RATIO
    candidates = parabolic_junctions(moves, tol, stop_turn_rad, in_plane=True) & ~tangent
    if not (arc_blends and kinks):
        candidates[:] = False
    speed = np.minimum(feed, length / control.period_s)
    path_acc = path_limits(moves, machine).acceleration_mm_s2
    axis_vel = np.asarray(machine.axis_max_velocity_mm_s)
    line_trim = np.zeros(len(moves))  # what the line-line blends take off the moves' starts
    if candidates.any():
        line_trim[1:] = junction_blends(
            length, moves.end_tangents, moves.start_tangents, feed, tol, axis_acc,
            sized_arcs=sized_arcs, stop_turn_rad=stop_turn_rad,
        )[1]  # fmt: skip
    req_speed = limits(moves, machine, finalized=np.zeros(len(moves), bool))[0]  # reqvel
    choice = arc_junctions(
        moves, candidates, speed, req_speed, path_acc, tol[1:], kink, line_trim, axis_acc,
        axis_vel, control.period_s, arc_rules,
    )  # fmt: skip
    kinked = choice["choice"] == TANGENT_BLEND
    reduce = np.where(tangent, kink, np.where(exact | kinked, KINK_RATIO, 0.0))
    kept = np.ones(len(moves))
    kept[:-1] = 1.0 - reduce
    kept[1:] = np.minimum(kept[1:], 1.0 - reduce)
    if (reduce > 0).any():
        feed, acc = limits(moves, machine, kept)
    v, d, arc, arc_acc = junction_blends(
        length,
        moves.end_tangents,
        moves.start_tangents,
        feed,
        tol,
        axis_acc,
        sized_arcs=sized_arcs,
        stop_turn_rad=stop_turn_rad,
    )
    # junctions with an arc that get no blend arc: a parabolic blend, both moves at half their
    # acceleration (halved once, with a parabolic end too)
    para = parabolic_junctions(moves, tol, stop_turn_rad) & ~tangent & ~candidates
    para |= choice["choice"] == PARABOLIC_BLEND
    made = choice["choice"] == ARC_BLEND
    d_end, d_start = np.where(made, choice["trim1"], d), np.where(made, choice["trim2"], d)
    v = np.where(made, np.minimum(choice["v_plan"], np.minimum(feed[:-1], feed[1:])), v)
    arc = np.where(made, choice["length"], arc)
    v = np.where(kinked, choice["kink_speed"], v)
    d_end, d_start, arc = (np.where(kinked, 0.0, x) for x in (d_end, d_start, arc))
    halved = np.zeros(len(moves), bool)
    halved[:-1] |= para
    halved[1:] |= para
    if para.any():
        share = kept * np.where(halved, TANGENTIAL_ACC_RATIO, 1.0)
        feed, acc = limits(moves, machine, share)
        u_end, u_start = parabolic_directions(moves, path_acc * share, req_speed, arc_rules)
        # each move as long as the blends at its other ends leave it (its target)
        d_end, d_start = (np.where(para, 0.0, x) for x in (d_end, d_start))
        target = length - np.concatenate([[0.0], d_start]) - np.concatenate([d_end, [0.0]])
        target = np.maximum(target, 1e-9)
        speed = parabolic_blend_speeds(target, feed, acc, u_end, u_start, tol)
        v = np.where(para, speed, v)
    v = np.where(tangent, np.minimum(feed[:-1], feed[1:]), v)
    d_end, d_start, arc = (np.where(tangent | para, 0.0, x) for x in (d_end, d_start, arc))
    # a move with a parabolic end runs at a / 2 and is entered at most at its triangle speed
    a_line = acc * np.where(parabolic_end & ~halved, TANGENTIAL_ACC_RATIO, 1.0)
    v = np.where(parabolic_end[1:], np.minimum(v, np.sqrt(a_line * length)[1:]), v)
    # the queue: line 0, arc 0, line 1, ..., line M-1; the arcs of unblended junctions empty
    m = len(moves)
    item_len = np.empty(2 * m - 1)
    item_len[0::2] = length - np.concatenate([[0.0], d_start]) - np.concatenate([d_end, [0.0]])
    item_len[1::2] = arc
    # a line remainder the next arc passes in under GAP_CYCLES periods becomes part of it
    rem = item_len[0:-1:2]
    with np.errstate(divide="ignore", invalid="ignore"):
        eat = (arc > 0) & (rem < GAP_CYCLES * control.period_s * v) & ~moves.is_arc[:-1]
    item_len[1::2] += np.where(eat, rem, 0.0)
    item_len[0:-1:2] = np.where(eat, 0.0, rem)
    item_acc = np.empty(2 * m - 1)
    item_acc[0::2] = a_line
    item_acc[1::2] = TANGENTIAL_ACC_RATIO * np.where(arc > 0, arc_acc, 0.0)
    item_feed = np.empty(2 * m - 1)
    item_feed[0::2] = feed
    item_feed[1::2] = v
    end_limit = np.append(np.repeat(v, 2), 0.0)  # at the end of each item
    # the items LinuxCNC queues: the non-empty ones; an empty one sits at the end of the kept
    # item before it, where its limit applies
    keep = np.flatnonzero(item_len > 0)
    at = np.searchsorted(keep, np.arange(2 * m - 1), side="right") - 1
    limit = np.full(len(keep), np.inf)
    np.minimum.at(limit, at[at >= 0], end_limit[at >= 0])
    q_len, q_acc = item_len[keep], item_acc[keep]
    cap = q_len / (MIN_SEGMENT_CYCLES * control.period_s)
    q_feed = np.minimum(item_feed[keep], cap)
    # the look-ahead plans with the speed limits of the machine, not the programmed feed
    item_max = np.empty(2 * m - 1)
    unfed = dataclasses.replace(moves, feed_mm_s=np.full(m, np.inf))
    item_max[0::2] = limits(unfed, machine)[0]
    item_max[1::2] = v
    blended = limit > 0
    blended[-1] = False
    queued = np.arange(1, m)  # move s is queued after the arc that joins it to move s - 1
    new_len = length[1:] - d_start
    if m > 1:
        new_len[-1] = length[-1]  # the last move: its measured entry, sqrt(a L / 2)
    end = optimised_end_speeds(
        q_len,
        q_acc,
        np.minimum(item_max[keep], cap),
        blended,
        np.searchsorted(keep, 2 * queued - 1, side="right") - 1,
        new_len,
        TANGENTIAL_ACC_RATIO * acc[1:],
        np.minimum(feed[1:], length[1:] / (MIN_SEGMENT_CYCLES * control.period_s)),
    )
    limit = np.minimum(limit, np.where(blended, end, 0.0))
    limit = np.minimum(limit[:-1], np.minimum(q_feed[:-1], q_feed[1:]))
    t = np.zeros(2 * m - 1)
    t[keep] = segment_times(q_len, q_feed, q_acc, limit)
    if stop_periods == "whole":
        t[keep] = stops_on_periods(t[keep], limit, control.period_s)
    elif stop_periods == "mean":
        t[keep] += np.append(limit == 0, True) * (0.5 * control.period_s)
    move_t = t[0::2] + np.concatenate([[0.0], t[1::2] / 2]) + np.concatenate([t[1::2] / 2, [0.0]])
    block_t = np.bincount(merged_source[source], weights=move_t, minlength=len(toolpath))
    block_t += toolpath.dwell_s + np.bincount(rest_block, rest_s, minlength=len(toolpath))
    return Estimate("planner", machine.name, block_t, toolpath)
