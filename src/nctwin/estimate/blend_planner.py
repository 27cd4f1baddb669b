r"""Cycle time on a look-ahead planner with circular blend arcs and no jerk limit (LinuxCNC-like).

An analytic model of LinuxCNC 2.9's trajectory planner (its "blend arc" planner): the path is a
queue of items, the moves and the circular arcs that round their junctions within the blending
tolerance; along every item the speed follows a trapezoid under a tangential acceleration limit;
look-ahead propagates every limit backward and forward. Nothing is fitted to recordings: the
rules and constants are those of LinuxCNC's source (``emccanon.cc``, ``src/emc/tp/tp.c``,
``blendmath.c``, ``tc.c``); what was measured on LinuxCNC to settle them is listed in
``benchmarks/README.md``.

:func:`blend_planner` runs in stages, each a function here:

1. **Moves** (:func:`_queue`): LinuxCNC's canon merges chains of straight feed moves within the
   naive-CAM tolerance ``G64 Q`` (:func:`nctwin.naivecam.merge_naive_cam`); the moves are the
   lines, rapids and whole arcs of non-zero length. Each junction takes the mode of the move
   before it (``tcSetupState``) and the smaller of the two moves' tolerances
   (``tcFindBlendTolerance``); a dwell or a word the task waits for
   (:mod:`~nctwin.estimate.task_waits`), a change between rapid and feed motion
   (``tpCheckCanonType``, ``handleModeChange``) and the program's ends stop the tool.
2. **Limits** (:class:`MoveLimits`, once per program): each move's feed and tangential
   acceleration (canon's ``getStraightVelocity``, ``getStraightAcceleration``, ``ARC_FEED``;
   ``tcUpdateCircleAccRatio``, ``pmCircleActualMaxVel``), under any share of its acceleration a
   later stage leaves it (``tcGetOverallMaxAccel``).
3. **Junction kinds** (:func:`_junction_kinds`): nearly tangent junctions pass at the feed
   (:func:`tangent_junctions`, ``tpSetupTangent``), a turn within :data:`STOP_TURN_RAD` of a
   reversal stops, ``G61`` stops at the others with both moves at :math:`1 -`
   :data:`KINK_RATIO` of their acceleration (``tcSetKinkProperties``); a junction with a
   programmed arc gets LinuxCNC's choice of a blend arc, a tangent pass at the kink speed or a
   parabolic blend (:func:`~nctwin.estimate.blend_junctions.arc_junctions`,
   ``tpChooseBestBlend``).
4. **Junctions** (:class:`Junctions`): the blend arcs between lines
   (:func:`junction_blends`, ``blendComputeParameters``), then the arc junctions' choices, the
   parabolic blends at half the moves' acceleration (:func:`parabolic_blend_speeds`,
   ``tpComputeBlendVelocity``) and the tangent passes.
5. **Items** (:class:`Items`): line, blend arc, line, ...; a blend arc runs at its own planned
   speed, up to the larger of its two moves' feeds (into a move with a parabolic end at most at
   that move's triangle speed), and its ends at the smaller of it and each move's feed
   (``tpGetRealFinalVel``); a line's remainder the next blend arc passes in under
   :data:`GAP_CYCLES` servo periods at the arc's speed becomes part of it
   (``blendCheckConsume``); a move with a parabolic end (the program's last, one before a
   dwell) runs at :math:`a/2` and is entered at most at its triangle speed.
6. **End speeds and times** (:func:`_item_times`): each item at most at its length over
   :data:`MIN_SEGMENT_CYCLES` periods (``tpComputeOptimalVelocity``); the end speeds LinuxCNC's
   lazy look-ahead leaves (:func:`~nctwin.estimate.blend_speeds.optimised_end_speeds`,
   ``tpRunOptimization``); trapezoids between them, stops on whole servo periods
   (:func:`~nctwin.estimate.blend_speeds.stops_on_periods`, ``tpCheckEndCondition``).

Not modelled: the parabolic blends LinuxCNC falls back to between two lines where no arc fits
(``tpChooseBestBlend`` is applied at junctions with an arc only), a line consumed by a blend into
the last move (LinuxCNC compares with the blend's planned speed; here with the speed the last
move's triangle allows, which is lower into a short last move). The stops and rests of
LinuxCNC's task around dwells and M-codes are :mod:`~nctwin.estimate.task_waits`'.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..controls import PlannerControl
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
    parabolic_directions,
)
from .blend_limits import (
    MIN_SEGMENT_CYCLES,
    STOP_TURN_RAD,
    TANGENTIAL_ACC_RATIO,
    MoveLimits,
    junction_blends,
    parabolic_blend_speeds,
    parabolic_junctions,
    tangent_junctions,
)
from .blend_speeds import optimised_end_speeds, segment_times, stops_on_periods
from .result import Estimate
from .task_waits import task_stops

__all__ = ["STOP_PERIODS", "blend_planner"]

#: What a stop costs beyond its trapezoids (:func:`blend_planner`'s ``stop_periods``).
STOP_PERIODS = ("whole", "mean", "off")


@dataclasses.dataclass(frozen=True)
class Queue:
    """The M moves LinuxCNC's planner receives and what each junction's mode asks of it.

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length.
    block : ndarray of int, shape (M,)
        The program's block each move comes from.
    tol_mm : ndarray, shape (M,)
        Blending tolerance each move starts with (``inf``: none, 0: the tool stops); the first
        is not used.
    stop : ndarray of bool, shape (M - 1,)
        Junctions that stop the tool before any kink is set: no tolerance outside ``G61``, or
        a change between rapid and feed motion.
    parabolic_end : ndarray of bool, shape (M,)
        Moves that keep the parabolic end they were queued with while blending is on.
    finalized : ndarray of bool, shape (M,)
        Moves finalized when the next is queued (not the last, not one before a stop of the
        task).
    rest_block : ndarray of int, shape (R,)
        Blocks at which the task rests for ``rest_s`` (:func:`~.task_waits.task_stops`).
    rest_s : ndarray, shape (R,)
    """

    moves: Toolpath
    block: np.ndarray
    tol_mm: np.ndarray
    stop: np.ndarray
    parabolic_end: np.ndarray
    finalized: np.ndarray
    rest_block: np.ndarray
    rest_s: np.ndarray


def _queue(toolpath: Toolpath, control: PlannerControl) -> Queue | None:
    """Stage 1: the moves, their junctions' tolerances and stops; None for a program that does
    not move."""
    merged, merged_source = merge_naive_cam(toolpath)
    source = np.flatnonzero((merged.kind != MotionKind.DWELL) & (merged.lengths_mm > 0))
    if not len(source):
        return None
    moves = merged.take(source)
    m = len(moves)
    own = moves.effective_tolerance_mm(control.blend_tol_mm)
    # the junction after a move: that move's mode (tcSetupState, the term condition in force
    # when it was queued) and the smaller of the two moves' tolerances (tcFindBlendTolerance)
    given = np.where(np.isfinite(own) & (own > 0), own, np.inf)
    tol = own.copy()
    tol[1:] = np.where(own[:-1] == 0, 0.0, np.minimum(given[:-1], given[1:]))
    # a dwell or a word the task waits for (task_waits) stops the tool; the move before it keeps
    # its parabolic end, and, like the last move, is never finalized (an arc keeps a / 2)
    after, rest_block, rest_s = task_stops(toolpath, merged_source, source, control)
    unfinalized = np.zeros(m, bool)
    unfinalized[after[(after > 0) & (after <= m)] - 1] = True
    unfinalized[-1] = True
    tol[after[after < m]] = 0.0
    # LinuxCNC does not blend between a rapid and a feed move: the tool stops (tpCheckCanonType)
    rapid = moves.kind == MotionKind.RAPID
    change = rapid[1:] != rapid[:-1]
    tol[1:][change] = 0.0
    # a change between rapid and feed stops in G61 too, before any kink is set (handleModeChange)
    stop = ((tol[1:] == 0) & (moves.path_mode[:-1] != PathMode.EXACT_PATH)) | change
    return Queue(
        moves=moves,
        block=merged_source[source],
        tol_mm=tol,
        stop=stop,
        parabolic_end=unfinalized & (own > 0),
        finalized=~unfinalized,
        rest_block=rest_block,
        rest_s=rest_s,
    )


@dataclasses.dataclass(frozen=True)
class Rules:
    """Which of LinuxCNC's rules the planner applies (:func:`blend_planner`'s switches):
    ``kinks``, ``sized_arcs``, ``arc_blends``, ``arc_ratio`` (:func:`move_limits`'s, from
    ``arc_rules``), ``stop_turn_rad`` and ``arc_speed``."""

    kinks: bool
    sized_arcs: bool
    arc_blends: bool
    arc_ratio: str
    stop_turn_rad: float
    arc_speed: bool


@dataclasses.dataclass(frozen=True)
class JunctionKinds:
    """How each of the M - 1 junctions is passed, shapes (M - 1,) (``choice``: arrays of that
    shape, :func:`~nctwin.estimate.blend_junctions.arc_junctions`'s answer).

    Parameters
    ----------
    tangent : ndarray of bool
        Passed as tangent at the feed, both moves at :math:`1 - k` of their acceleration.
    kink_share : ndarray
        :math:`k` of each junction (:func:`tangent_junctions`).
    exact : ndarray of bool
        ``G61`` stops with both moves at :math:`1 -` :data:`KINK_RATIO` of their acceleration.
    candidates : ndarray of bool
        Junctions with an arc whose blend LinuxCNC chooses (``tpChooseBestBlend``).
    parabolic : ndarray of bool
        Joined by a parabolic blend, both moves at half their acceleration.
    choice : dict of ndarray
    """

    tangent: np.ndarray
    kink_share: np.ndarray
    exact: np.ndarray
    candidates: np.ndarray
    parabolic: np.ndarray
    choice: dict[str, np.ndarray]

    @property
    def kinked(self) -> np.ndarray:
        """Junctions with an arc passed as tangent at the kink speed."""
        return self.choice["choice"] == TANGENT_BLEND

    def kept(self) -> np.ndarray:
        """Share of its acceleration each of the M moves keeps after the kinks, shape (M,)."""
        reduce = np.where(
            self.tangent, self.kink_share, np.where(self.exact | self.kinked, KINK_RATIO, 0.0)
        )
        kept = np.ones(len(reduce) + 1)
        kept[:-1] = 1.0 - reduce
        kept[1:] = np.minimum(kept[1:], 1.0 - reduce)
        return kept


def _junction_kinds(
    queue: Queue,
    limits: MoveLimits,
    machine: Machine,
    control: PlannerControl,
    rules: Rules,
) -> JunctionKinds:
    """Stage 3: tangent passes, stops, and LinuxCNC's choice at junctions with an arc."""
    moves, tol = queue.moves, queue.tol_mm
    length = moves.lengths_mm
    kinks, stop_turn_rad = rules.kinks, rules.stop_turn_rad
    feed, acc = limits.at(finalized=queue.finalized, arc_ratio=rules.arc_ratio)
    axis_acc = np.asarray(machine.axis_max_acceleration_mm_s2)
    # nearly tangent junctions (but not into an exact stop): no blend arc, no stop; the other
    # G61 junctions stop (tcSetKinkProperties, kept where no blend arc replaces the kink)
    tangent, kink = tangent_junctions(moves, feed, acc, axis_acc, control.period_s)
    tangent &= ~queue.stop & kinks
    # a turn within stop_turn_rad of a reversal stops the tool before any kink is set
    # (tpSetupTangent's sharp corner): no reduced acceleration
    dot = np.einsum("ij,ij->i", moves.end_tangents[:-1], moves.start_tangents[1:])
    sharp = np.arccos(-np.clip(dot, -1.0, 1.0)) < stop_turn_rad
    exact = (tol[1:] == 0) & ~queue.stop & ~tangent & ~sharp & kinks
    # a junction with an arc: a blend arc as LinuxCNC makes it, if it beats a tangent pass at
    # the kink speed and a parabolic blend (blend_junctions)
    candidates = parabolic_junctions(moves, tol, stop_turn_rad, in_plane=True) & ~tangent
    if not (rules.arc_blends and kinks):
        candidates[:] = False
    line_trim = np.zeros(len(moves))  # what the line-line blends take off the moves' starts
    if candidates.any():
        line_trim[1:] = junction_blends(
            length, moves.end_tangents, moves.start_tangents, feed, tol, axis_acc,
            sized_arcs=rules.sized_arcs, stop_turn_rad=stop_turn_rad,
        )[1]  # fmt: skip
    choice = arc_junctions(
        moves,
        candidates,
        speed_mm_s=np.minimum(feed, length / control.period_s),
        req_speed_mm_s=_requested_speed(limits, rules),
        path_acc_mm_s2=limits.acc_mm_s2,
        tol_mm=tol[1:],
        kink_share=kink,
        start_trim_mm=line_trim,
        axis_acc_mm_s2=axis_acc,
        axis_vel_mm_s=np.asarray(machine.axis_max_velocity_mm_s),
        period_s=control.period_s,
        arc_rules=rules.arc_ratio == "max_speed",
    )
    # junctions with an arc that get no blend arc: a parabolic blend
    para = parabolic_junctions(moves, tol, stop_turn_rad) & ~tangent & ~candidates
    para |= choice["choice"] == PARABOLIC_BLEND
    return JunctionKinds(tangent, kink, exact, candidates, para, choice)


def _requested_speed(limits: MoveLimits, rules: Rules) -> np.ndarray:
    """Each move's requested feed (``reqvel``: before it is finalized), shape (M,)."""
    unfinalized = np.zeros(len(limits.feed_mm_s), bool)
    return limits.at(finalized=unfinalized, arc_ratio=rules.arc_ratio)[0]


@dataclasses.dataclass(frozen=True)
class Junctions:
    """The M - 1 junctions of M moves as a stage leaves them, shapes (M - 1,).

    Parameters
    ----------
    speed_mm_s : ndarray
        Speed limit at the junction (0: the tool stops).
    end_trim_mm, start_trim_mm : ndarray
        Length the blend takes off the end of the move before and the start of the move after.
    arc_mm : ndarray
        Length of the blend arc (0: none).
    arc_acc_mm_s2 : ndarray
        Acceleration of the blend arc's plane (:func:`blend_plane_acc`).
    arc_speed_mm_s : ndarray
        Speed of the blend arc itself, up to the larger of the two moves' feeds (0: none).
    """

    speed_mm_s: np.ndarray
    end_trim_mm: np.ndarray
    start_trim_mm: np.ndarray
    arc_mm: np.ndarray
    arc_acc_mm_s2: np.ndarray
    arc_speed_mm_s: np.ndarray

    def where(self, mask: np.ndarray, **values: np.ndarray | float) -> Junctions:
        """These junctions with the fields ``values`` where ``mask`` holds."""
        changed = {k: np.where(mask, v, getattr(self, k)) for k, v in values.items()}
        return dataclasses.replace(self, **changed)

    def remaining_mm(self, length_mm: np.ndarray) -> np.ndarray:
        """What the blends at both ends leave of each of the M moves, shape (M,)."""
        start = np.concatenate([[0.0], self.start_trim_mm])
        return length_mm - start - np.concatenate([self.end_trim_mm, [0.0]])


def _junctions(
    queue: Queue,
    kinds: JunctionKinds,
    limits: MoveLimits,
    machine: Machine,
    rules: Rules,
) -> tuple[Junctions, np.ndarray, np.ndarray, np.ndarray]:
    """Stage 4: each junction's speed, trims and blend arc, with the moves' feed and tangential
    acceleration, shapes (M,), at the share of it the junctions leave them, and the tangential
    acceleration along each line (:math:`a/2` with a parabolic end)."""
    moves, tol, arc_ratio = queue.moves, queue.tol_mm, rules.arc_ratio
    length = moves.lengths_mm
    kept = kinds.kept()
    feed, _ = limits.at(kept, finalized=queue.finalized, arc_ratio=arc_ratio)
    axis_acc = np.asarray(machine.axis_max_acceleration_mm_s2)
    blends = junction_blends(
        length,
        moves.end_tangents,
        moves.start_tangents,
        feed,
        tol,
        axis_acc,
        sized_arcs=rules.sized_arcs,
        stop_turn_rad=rules.stop_turn_rad,
    )
    j = Junctions(blends[0], blends[1], blends[1], blends[2], blends[3], blends[4])
    choice, para = kinds.choice, kinds.parabolic
    j = j.where(
        choice["choice"] == ARC_BLEND,
        end_trim_mm=choice["trim1"],
        start_trim_mm=choice["trim2"],
        speed_mm_s=np.minimum(choice["v_plan"], np.minimum(feed[:-1], feed[1:])),
        arc_mm=choice["length"],
        arc_speed_mm_s=choice["v_plan"],
    )
    j = j.where(kinds.kinked, speed_mm_s=choice["kink_speed"])
    j = j.where(kinds.kinked, end_trim_mm=0.0, start_trim_mm=0.0, arc_mm=0.0)
    # both moves of a parabolic blend at half their acceleration (halved once, with a
    # parabolic end too)
    halved = np.zeros(len(moves), bool)
    halved[:-1] |= para
    halved[1:] |= para
    share = kept * np.where(halved, TANGENTIAL_ACC_RATIO, 1.0)
    feed, acc = limits.at(share, finalized=queue.finalized, arc_ratio=arc_ratio)
    if para.any():
        path_acc = limits.acc_mm_s2 * share
        u_end, u_start = parabolic_directions(
            moves, path_acc, _requested_speed(limits, rules), arc_ratio == "max_speed"
        )
        # each move as long as the blends at its other ends leave it (its target)
        j = j.where(para, end_trim_mm=0.0, start_trim_mm=0.0)
        target = np.maximum(j.remaining_mm(length), 1e-9)
        speed = parabolic_blend_speeds(target, feed, acc, u_end, u_start, tol)
        j = j.where(para, speed_mm_s=speed)
    j = j.where(kinds.tangent, speed_mm_s=np.minimum(feed[:-1], feed[1:]))
    j = j.where(kinds.tangent | para, end_trim_mm=0.0, start_trim_mm=0.0, arc_mm=0.0)
    # a move with a parabolic end runs at a / 2 and is entered at most at its triangle speed,
    # the blend arc before it too
    line_acc = acc * np.where(queue.parabolic_end & ~halved, TANGENTIAL_ACC_RATIO, 1.0)
    triangle = np.sqrt(line_acc * length)[1:]
    j = j.where(
        queue.parabolic_end[1:],
        speed_mm_s=np.minimum(j.speed_mm_s, triangle),
        arc_speed_mm_s=np.minimum(j.arc_speed_mm_s, triangle),
    )
    return j, feed, acc, line_acc


@dataclasses.dataclass(frozen=True)
class Items:
    """The 2M - 1 items of LinuxCNC's queue, line 0, arc 0, line 1, ..., line M - 1 (an
    unblended junction's arc empty), shapes (2M - 1,).

    Parameters
    ----------
    length_mm, acc_mm_s2, feed_mm_s, top_mm_s : ndarray
        Each item's length, tangential acceleration, feed and the machine's speed limit.
    end_limit_mm_s : ndarray
        The speed limit at its end.
    """

    length_mm: np.ndarray
    acc_mm_s2: np.ndarray
    feed_mm_s: np.ndarray
    top_mm_s: np.ndarray
    end_limit_mm_s: np.ndarray


def _interleave(lines: np.ndarray, arcs: np.ndarray) -> np.ndarray:
    """Items from M values of the lines and M - 1 of the arcs, shape (2M - 1,)."""
    out = np.empty(2 * len(lines) - 1)
    out[0::2] = lines
    out[1::2] = arcs
    return out


def _items(
    queue: Queue,
    j: Junctions,
    feed: np.ndarray,
    line_acc: np.ndarray,
    top: np.ndarray,
    period_s: float,
    *,
    arc_speed: bool,
) -> Items:
    """Stage 5: the queue's items; a line remainder the next arc passes in under
    :data:`GAP_CYCLES` periods becomes part of it (``blendCheckConsume``). With ``arc_speed``
    off (the ablation), a blend arc runs at the speed of its ends."""
    rem = j.remaining_mm(queue.moves.lengths_mm)
    arc = j.arc_mm
    v = j.speed_mm_s
    if arc_speed:
        # a blend arc runs at its own planned speed, its ends at the smaller of it and the lines'
        v = np.where(arc > 0, j.arc_speed_mm_s, v)
    with np.errstate(divide="ignore", invalid="ignore"):
        eat = (arc > 0) & (rem[:-1] < GAP_CYCLES * period_s * v) & ~queue.moves.is_arc[:-1]
    line_len = np.append(np.where(eat, 0.0, rem[:-1]), rem[-1])
    arc_acc = TANGENTIAL_ACC_RATIO * np.where(arc > 0, j.arc_acc_mm_s2, 0.0)
    return Items(
        length_mm=_interleave(line_len, arc + np.where(eat, rem[:-1], 0.0)),
        acc_mm_s2=_interleave(line_acc, arc_acc),
        feed_mm_s=_interleave(feed, v),
        top_mm_s=_interleave(top, v),
        end_limit_mm_s=np.append(np.repeat(v, 2), 0.0),
    )


def _item_times(
    queue: Queue,
    j: Junctions,
    items: Items,
    feed: np.ndarray,
    acc: np.ndarray,
    control: PlannerControl,
    stop_periods: str,
) -> np.ndarray:
    """Stage 6: the end speeds the look-ahead leaves and each item's time, shape (2M - 1,);
    LinuxCNC queues the non-empty items, an empty one's limit applies at the end of the kept
    item before it."""
    m, length, period_s = len(queue.moves), queue.moves.lengths_mm, control.period_s
    keep = np.flatnonzero(items.length_mm > 0)
    at = np.searchsorted(keep, np.arange(2 * m - 1), side="right") - 1
    limit = np.full(len(keep), np.inf)
    np.minimum.at(limit, at[at >= 0], items.end_limit_mm_s[at >= 0])
    q_len, q_acc = items.length_mm[keep], items.acc_mm_s2[keep]
    cap = q_len / (MIN_SEGMENT_CYCLES * period_s)
    q_feed = np.minimum(items.feed_mm_s[keep], cap)
    blended = limit > 0
    blended[-1] = False
    # move s is queued after the arc that joins it to move s - 1; the last is entered at its
    # measured entry, sqrt(a L / 2); the look-ahead plans with the machine's speed limits
    new_len = length[1:] - j.start_trim_mm
    if m > 1:
        new_len[-1] = length[-1]
    end = optimised_end_speeds(
        q_len,
        q_acc,
        np.minimum(items.top_mm_s[keep], cap),
        blended,
        np.searchsorted(keep, 2 * np.arange(1, m) - 1, side="right") - 1,
        new_len,
        TANGENTIAL_ACC_RATIO * acc[1:],
        np.minimum(feed[1:], length[1:] / (MIN_SEGMENT_CYCLES * period_s)),
    )
    limit = np.minimum(limit, np.where(blended, end, 0.0))
    limit = np.minimum(limit[:-1], np.minimum(q_feed[:-1], q_feed[1:]))
    t = np.zeros(2 * m - 1)
    t[keep] = segment_times(q_len, q_feed, q_acc, limit)
    if stop_periods == "whole":
        t[keep] = stops_on_periods(t[keep], limit, period_s)
    elif stop_periods == "mean":
        t[keep] += np.append(limit == 0, True) * (0.5 * period_s)
    return t


def blend_planner(
    toolpath: Toolpath,
    machine: Machine,
    control: PlannerControl,
    *,
    kinks: bool = True,
    sized_arcs: bool = True,
    arc_blends: bool = True,
    arc_rules: bool = True,
    arc_speed: bool = True,
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
    arc_speed : bool
        A blend arc runs at its own planned speed, up to the larger of its two moves' feeds
        (:func:`junction_blends`); on by default, off for the ablation: at the smaller.
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
    queue = _queue(toolpath, control)
    if queue is None:
        return Estimate("planner", machine.name, toolpath.dwell_s.copy(), toolpath)
    arc_ratio = "max_speed" if arc_rules else "feed"
    rules = Rules(kinks, sized_arcs, arc_blends, arc_ratio, stop_turn_rad, arc_speed)
    limits = MoveLimits.of(queue.moves, machine)
    kinds = _junction_kinds(queue, limits, machine, control, rules)
    j, feed, acc, line_acc = _junctions(queue, kinds, limits, machine, rules)
    top = limits.at(finalized=queue.finalized, arc_ratio=rules.arc_ratio, top=True)[0]
    items = _items(queue, j, feed, line_acc, top, control.period_s, arc_speed=rules.arc_speed)
    t = _item_times(queue, j, items, feed, acc, control, stop_periods)
    move_t = t[0::2] + np.concatenate([[0.0], t[1::2] / 2]) + np.concatenate([t[1::2] / 2, [0.0]])
    block_t = np.bincount(queue.block, weights=move_t, minlength=len(toolpath))
    rests = np.bincount(queue.rest_block, queue.rest_s, minlength=len(toolpath))
    block_t += toolpath.dwell_s + rests
    return Estimate("planner", machine.name, block_t, toolpath)
