r"""What LinuxCNC makes of a junction with a programmed arc that is not tangent
(:mod:`nctwin.estimate.blend_planner`): a blend arc, a tangent pass at the kink speed, or a
parabolic blend.

LinuxCNC 2.9 (``src/emc/tp/tp.c``, ``blendmath.c``, ``tc.c``; the Debian package
``2.9.0~pre1+git20230208.f1270d6ed7`` that :mod:`nctwin.kernel.linuxcnc` runs) handles a
junction that ``tpSetupTangent`` does not pass as tangent in ``tpHandleBlendArc``. Its rules,
stated here as facts:

1. **Kink speed** (``tpSetupTangent``, ``tcSetKinkProperties``): the rejected kink keeps the
   speed :math:`v_k = v_{\max}\, r_k / k` and an acceleration reduction :math:`r_k` on both
   moves, with :math:`r_k` = :data:`KINK_RATIO` and :math:`k`
   the kink's acceleration share (doubled next to an arc, ``acc_scale_max /=
   BLEND_ACC_RATIO_TANGENTIAL``): at a 1° kink after an arc at 66 mm/s, about 3 mm/s.
2. **Blend geometry** (``blendInit3FromArcLine``, ``blendInit3FromLineArc``,
   ``blendInit3FromArcArc``): with the half supplement of the turn :math:`\theta_t`, an arc is
   *convex* at the junction where the other move turns towards its centre. Each arc may lose at
   most :math:`\phi_{\max}` of its sweep, :math:`\min(2/3\,\phi_1, \theta_t)` at its end and
   :math:`\min(\phi_2/3, \theta_t)` at its start where convex (:math:`\pi/2` for
   :math:`\theta_t` where not); a convex arc lowers the blend's angle to
   :math:`\theta = \theta_t - \phi_{\max}/4` and offers the length :math:`r \sin(\phi_{\max}/4)`
   (:math:`r \phi_{\max}` where not convex), a line half its length. Two arcs fail below
   :math:`\theta = \pi/12`, and every blend fails where the other move is not in the arc's
   plane (``pmUnitCartsColinear`` of the binormal and the arc's normal).
3. **Blend size and speed** (``blendParamKinematics``, ``blendComputeParameters``): as between
   two lines (:func:`~nctwin.estimate.blend_limits.junction_blends`), with the lengths of 2,
   the goal speed :math:`\max(v_1, v_2)` within the plane's velocity limit, and
   :math:`R` the planned radius and :math:`v_p` the planned speed.
4. **The blend arc as it is made** (``blendArcLinePostProcess``, ``blendLineArcPostProcess``,
   ``blendArcArcPostProcess``): a circle of radius :math:`R` tangent to the line (at the
   distance :math:`d_L` from the junction, the smaller root of a quadratic) and to the arc's
   circle (its centre at :math:`r \mp R` from the arc's, inside where convex), or to both
   circles. The blend fails where no such circle exists, where it lies further than the
   tolerance from the junction (``T_final``), where it takes more than :math:`\phi_{\max}` of
   an arc, or all of a line or arc (``pmCartLineStretch``, ``pmCircleStretch``). Near a small
   kink this circle touches the moves close to the junction: its length
   :math:`R\,\beta` (:math:`\beta` its turn) is far below the planned :math:`R(\pi - 2\theta)`.
5. **Speed limit of the blend arc** (``tpInitBlendArcFromPrev``, ``tcFinalizeLength``,
   ``tcClampVelocityByLength``): :math:`\min(v_p, \ell / T_s)` for its length :math:`\ell`
   and the servo period :math:`T_s` (and :math:`\ell / (1.02\,T_s)` in the look-ahead, as for
   every item).
6. **The best of three** (``tpChooseBestBlend``): the blend arc is kept only if its speed
   limit beats both the kink speed :math:`v_k` and half the parabolic blend's net speed
   (``estimateParabolicBlendPerformance``, :func:`parabolic_performance`, its angle between
   the directions of :func:`parabolic_directions`, not the tangents); where the arc
   fails, the better of the other two is taken. A tangent pass runs both moves at
   :math:`1 - r_k` of their acceleration; a parabolic blend at half
   (``tcGetOverallMaxAccel``).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..toolpath import Toolpath

__all__ = [
    "ARC_BLEND",
    "KINK_RATIO",
    "PARABOLIC_BLEND",
    "TANGENT_BLEND",
    "arc_junction_blends",
    "arc_junctions",
    "blend_plane_acc",
    "choose_blends",
    "parabolic_directions",
    "parabolic_performance",
]

#: ``tpChooseBestBlend``'s answers, in the order of its performance array (a tie goes to the
#: first).
PARABOLIC_BLEND, TANGENT_BLEND, ARC_BLEND = 0, 1, 2
#: Pairs of unit vectors closer than this (squared distance) are parallel
#: (``TP_ANGLE_EPSILON_SQ``).
_ANGLE_EPSILON_SQ = 1e-12
#: A blend arc shorter than this fails (``TP_MIN_ARC_LENGTH``, mm).
_MIN_ARC_LENGTH = 1e-6
#: Two arcs need a blend angle of at least this (``blendInit3FromArcArc``).
_ARC_ARC_THETA_MIN = math.pi / 12.0
#: A junction whose kink needs less than this share of an axis's acceleration is passed as
#: tangent, without a blend arc or a stop (``ARC_BLEND_TANGENT_KINK_RATIO``, default 0.1).
KINK_RATIO = 0.1
#: A line's remainder the blend arc passes in under this many servo periods becomes part of
#: it (``ARC_BLEND_GAP_CYCLES``, default 4).
GAP_CYCLES = 4


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / n[:, None]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def _colinear(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``pmUnitCartsColinear``: unit vectors parallel or anti-parallel."""
    d = np.minimum(np.sum((a - b) ** 2, axis=1), np.sum((a + b) ** 2, axis=1))
    return d < _ANGLE_EPSILON_SQ


def _angle(p: np.ndarray, q: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Angle at ``c`` between the rays to ``p`` and to ``q`` (``findTrimAngle``)."""
    return np.arccos(np.clip(_dot(_unit(p - c), _unit(q - c)), -1.0, 1.0))


def _line_circle_centre(
    p: np.ndarray,
    u: np.ndarray,
    b: np.ndarray,
    c: np.ndarray,
    dist: np.ndarray,
    r: np.ndarray,
    sign: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Centre of the circle of radius ``r`` tangent to the line through ``p`` along ``u`` (on
    the side of ``b x u``) whose centre lies ``dist`` from ``c``, at ``d_L`` along
    ``sign * u``: ``blendArcLinePostProcess`` (sign +1) and ``blendLineArcPostProcess`` (-1).
    Returns the centre and ``d_L`` (NaN where there is none)."""
    n = _unit(np.cross(b, u))
    rel = c - p
    cu, cn = _dot(rel, u), _dot(rel, n)
    half_b = cu  # the quadratic d^2 + 2 cu d + (cu^2 - dist^2 + (r - cn)^2)
    disc = half_b**2 - (cu**2 - dist**2 + (r - cn) ** 2)
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
    d_l = np.minimum(np.abs(-half_b + root), np.abs(-half_b - root))
    centre = p + sign * u * d_l[:, None] + n * r[:, None]
    return centre, d_l


def _circle_circle_centre(
    p: np.ndarray,
    c1: np.ndarray,
    c2: np.ndarray,
    d1: np.ndarray,
    d2: np.ndarray,
    b: np.ndarray,
    normal: np.ndarray,
) -> np.ndarray:
    """``blendArcArcPostProcess``: the point ``d1`` from ``c1`` and ``d2`` from ``c2`` on the
    side of ``normal``, the one nearer ``p`` (NaN where none)."""
    span = c2 - c1
    x = np.linalg.norm(span, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cx = (d1**2 - d2**2 + x**2) / (2.0 * x)
        cy = np.sqrt(d1**2 - cx**2)
    uc = _unit(span)
    nc = np.cross(b, uc)
    nc = _unit(np.where((_dot(normal, nc) < 0)[:, None], -nc, nc))
    base = c1 + uc * cx[:, None]
    plus, minus = base + nc * cy[:, None], base - nc * cy[:, None]
    nearer = np.linalg.norm(minus - p, axis=1) < np.linalg.norm(plus - p, axis=1)
    return np.where(nearer[:, None], minus, plus)


def blend_plane_acc(u1: np.ndarray, u2: np.ndarray, axis_acc_mm_s2: np.ndarray) -> np.ndarray:
    r"""Acceleration of blend arcs in the plane of two directions (LinuxCNC's
    ``calculateInscribedDiameter``): :math:`\min_i a_{i,\max} / \sqrt{1 - n_i^2}` with
    :math:`n = u_1 \times u_2 / |u_1 \times u_2|` the plane's normal; ``inf`` where the
    directions are parallel (no plane).

    Parameters
    ----------
    u1, u2 : ndarray, shape (K, 3)
        Unit directions of the moves before and after each junction.
    axis_acc_mm_s2 : ndarray, shape (3,)

    Returns
    -------
    ndarray, shape (K,)
    """
    n = np.cross(u1, u2)
    norm = np.linalg.norm(n, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        n = n / norm[:, None]
        in_plane = np.sqrt(np.maximum(1.0 - n**2, 0.0))  # share of each axis in the plane
        acc = np.min(np.asarray(axis_acc_mm_s2) / in_plane, axis=1)
    return np.where(norm > 0, acc, np.inf)


def arc_junction_blends(
    *,
    point: np.ndarray,
    u1: np.ndarray,
    u2: np.ndarray,
    arc1: np.ndarray,
    arc2: np.ndarray,
    centre1: np.ndarray,
    centre2: np.ndarray,
    normal1: np.ndarray,
    normal2: np.ndarray,
    sweep1: np.ndarray,
    sweep2: np.ndarray,
    length1: np.ndarray,
    length2: np.ndarray,
    speed1: np.ndarray,
    speed2: np.ndarray,
    tol_mm: np.ndarray,
    plane_acc: np.ndarray,
    plane_vel: np.ndarray,
) -> dict[str, np.ndarray]:
    r"""The blend arcs LinuxCNC makes at K junctions with a programmed arc (rules 2-5 of the
    module docstring), shapes (K,).

    Parameters
    ----------
    point : ndarray, shape (K, 3)
        The junction.
    u1, u2 : ndarray, shape (K, 3)
        Unit tangents at the end of the move before and the start of the move after.
    arc1, arc2 : ndarray of bool, shape (K,)
        The move before (after) is an arc; at least one is.
    centre1, centre2, normal1, normal2 : ndarray, shape (K, 3)
        Centre of each arc in the plane of the junction and the unit normal of its plane
        (ignored for a line).
    sweep1, sweep2 : ndarray, shape (K,)
        Unsigned sweep of each arc as LinuxCNC holds it (an arc shortened at its start by the
        blend before keeps the rest).
    length1, length2 : ndarray, shape (K,)
        Length of each move as programmed (``nominal_length``).
    speed1, speed2 : ndarray, shape (K,)
        Speed limit of each move (``tcGetMaxTargetVel``: the feed within the move's limits and
        its length per servo period).
    tol_mm : ndarray, shape (K,)
        The blend tolerance (``tcFindBlendTolerance``).
    plane_acc, plane_vel : ndarray, shape (K,)
        Acceleration and velocity limit of the plane of the turn (``calculateInscribedDiameter``).

    Returns
    -------
    dict of ndarray, shape (K,)
        ``made`` (bool: the blend arc is made), ``v_plan`` (its planned speed), ``radius``,
        ``length`` (of the arc as made, 0 where none), ``trim1`` and ``trim2`` (the length it
        takes off the end of the move before and the start of the move after).
    """
    cos_turn = np.clip(_dot(u1, u2), -1.0, 1.0)
    theta_t = np.arccos(-cos_turn) / 2.0
    made = (np.pi / 2.0 - theta_t >= 1e-6) & (theta_t >= 1e-6)
    b = _unit(np.cross(u1, u2))
    made &= (~arc1 | _colinear(b, normal1)) & (~arc2 | _colinear(b, normal2))
    s1 = _Side.before(point, u2, arc1, centre1, sweep1, length1, theta_t)
    s2 = _Side.after(point, u1, arc2, centre2, sweep2, length2, theta_t)
    theta = np.where(s1.convex, theta_t - s1.phi_max_rad / 4.0, theta_t)
    theta = np.minimum(theta, np.where(s2.convex, theta_t - s2.phi_max_rad / 4.0, theta_t))
    made &= ~(arc1 & arc2) | (theta >= _ARC_ARC_THETA_MIN)
    v_plan, radius = _blend_size(theta, s1, s2, speed1, speed2, tol_mm, plane_acc, plane_vel)
    made &= (radius >= 1e-12) & (radius * (np.pi - 2.0 * theta) >= _MIN_ARC_LENGTH)
    centre, trim1, trim2 = _blend_centre(point, u1, u2, b, s1, s2, radius)
    fits, trim1, trim2, beta = _blend_contacts(point, u1, u2, centre, s1, s2, trim1, trim2)
    with np.errstate(invalid="ignore"):
        made &= np.linalg.norm(centre - point, axis=1) - radius <= tol_mm  # T_final
    made &= fits
    length = np.where(made, radius * beta, 0.0)
    return {
        "made": made,
        "v_plan": np.where(made, v_plan, 0.0),
        "radius": np.where(made, radius, 0.0),
        "length": length,
        "trim1": np.where(made, trim1, 0.0),
        "trim2": np.where(made, trim2, 0.0),
    }


@dataclasses.dataclass(frozen=True)
class _Side:
    """One move at K junctions, the one before or the one after, as a blend sees it, shapes
    (K,) (``centre_mm`` (K, 3)): whether it is an arc, its centre in the junction's plane and
    radius, whether it is convex there, the most of its sweep the blend may take, its sweep as
    LinuxCNC holds it, its programmed length and the length it offers the blend."""

    arc: np.ndarray
    centre_mm: np.ndarray
    radius_mm: np.ndarray
    convex: np.ndarray
    phi_max_rad: np.ndarray
    sweep_rad: np.ndarray
    length_mm: np.ndarray
    offered_mm: np.ndarray

    @classmethod
    def _of(cls, arc, point, centre, sweep, length, theta_t, convex, most) -> _Side:
        r = np.linalg.norm(point - centre, axis=1)
        phi_max = np.minimum(most, np.where(convex, theta_t, np.pi / 2.0))
        with np.errstate(invalid="ignore"):
            offered = np.where(convex, np.sin(phi_max / 4.0) * r, phi_max * r)
        offered = np.where(arc, offered, length / 2.0)
        return cls(arc, centre, r, convex, phi_max, sweep, length, offered)

    @classmethod
    def before(cls, point, u_next, arc, centre, sweep, length, theta_t) -> _Side:
        """The move before: convex where the next move turns towards its centre; the blend
        may take two thirds of its sweep."""
        convex = arc & (_dot(point - centre, u_next) < 0)
        return cls._of(arc, point, centre, sweep, length, theta_t, convex, sweep * 2.0 / 3.0)

    @classmethod
    def after(cls, point, u_before, arc, centre, sweep, length, theta_t) -> _Side:
        """The move after: convex where the move before turns towards its centre; the blend
        may take a third of its sweep."""
        convex = arc & ~(_dot(point - centre, u_before) < 0)
        return cls._of(arc, point, centre, sweep, length, theta_t, convex, sweep / 3.0)


def _blend_size(theta, s1, s2, speed1, speed2, tol_mm, plane_acc, plane_vel):
    """``blendComputeParameters`` as between two lines: the planned speed and radius, (K,)."""
    sin_t, tan_t = np.sin(theta), np.tan(theta)
    with np.errstate(invalid="ignore", divide="ignore"):
        d_tol = np.cos(theta) * tol_mm / (1.0 - sin_t)
        d_geom = np.minimum(np.minimum(s1.offered_mm, s2.offered_mm), d_tol)
        r_geom = tan_t * d_geom
        a_n = np.sqrt(0.75) * plane_acc
        v_goal = np.minimum(np.maximum(speed1, speed2), plane_vel)
        v_plan = np.minimum(np.sqrt(a_n * r_geom), v_goal)
        a_para = 0.5 * plane_acc
        t_blend = np.minimum(np.sqrt(2.0 * a_para * d_geom), v_plan) / a_para
        r_blend = np.minimum(t_blend * v_plan / (np.pi - 2.0 * theta), r_geom)
        radius = np.maximum(v_plan**2 / a_n, r_blend)
    return v_plan, radius


def _blend_centre(point, u1, u2, b, s1, s2, radius):
    """The blend circle as made (``blend*PostProcess``): tangent to the line(s) and to the
    arc(s)' circle(s); its centre (K, 3) and a line's trim (K,) (NaN where none or an arc)."""
    d1 = np.where(s1.convex, -radius, radius) + s1.radius_mm
    d2 = np.where(s2.convex, -radius, radius) + s2.radius_mm
    centre = np.full_like(point, np.nan)
    trim1, trim2 = np.full(len(point), np.nan), np.full(len(point), np.nan)
    c1, c2 = s1.centre_mm, s2.centre_mm
    normal = _unit(u2 - u1)
    both = s1.arc & s2.arc
    if both.any():
        centre[both] = _circle_circle_centre(
            point[both], c1[both], c2[both], d1[both], d2[both], b[both], normal[both]
        )
    first = s1.arc & ~s2.arc
    if first.any():
        centre[first], trim2[first] = _line_circle_centre(
            point[first], u2[first], b[first], c1[first], d1[first], radius[first], 1.0
        )
    second = s2.arc & ~s1.arc
    if second.any():
        centre[second], trim1[second] = _line_circle_centre(
            point[second], u1[second], b[second], c2[second], d2[second], radius[second], -1.0
        )
    return centre, trim1, trim2


def _blend_contacts(point, u1, u2, centre, s1, s2, trim1, trim2):
    r"""Where the blend circle touches the moves: whether it takes no more than it may of each
    (bool), the exact trims, and the blend's turn :math:`\beta` between its two points of
    contact, shapes (K,)."""
    c1, c2, r1, r2 = s1.centre_mm, s2.centre_mm, s1.radius_mm, s2.radius_mm
    ang1 = _angle(point, centre, c1)
    ang2 = _angle(point, centre, c2)
    with np.errstate(invalid="ignore"):
        fits = (~s1.arc | (ang1 <= s1.phi_max_rad)) & (~s2.arc | (ang2 <= s2.phi_max_rad))
        trim1 = np.where(s1.arc, ang1 * r1, trim1)
        trim2 = np.where(s2.arc, ang2 * r2, trim2)
        fits &= (np.where(s1.arc, s1.sweep_rad - ang1, s1.length_mm - trim1) > 0) & (
            np.where(s2.arc, s2.sweep_rad - ang2, s2.length_mm - trim2) > 0
        )
        start = np.where(s1.arc[:, None], c1 + _unit(centre - c1) * r1[:, None],
                         point - u1 * trim1[:, None])  # fmt: skip
        end = np.where(s2.arc[:, None], c2 + _unit(centre - c2) * r2[:, None],
                       point + u2 * trim2[:, None])  # fmt: skip
        beta = _angle(start, end, centre)
        fits &= beta >= 1e-6
    fits &= np.isfinite(trim1) & np.isfinite(trim2) & np.isfinite(beta)
    return fits, trim1, trim2, beta


def parabolic_directions(
    moves: Toolpath,
    overall_acc_mm_s2: np.ndarray,
    req_speed_mm_s: np.ndarray,
    arc_rules: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Directions at the end and at the start of M moves whose angle sets a parabolic blend's
    speed (``tpComputeBlendVelocity``: ``tcGetEndAccelUnitVector``,
    ``tcGetStartAccelUnitVector``), shapes (M, 3).

    A line's is its direction. An arc's is not its tangent: at its end the tangent of its
    plane, :math:`n \times (p_{end} - c)` (``tcCircleEndAccelUnitVector``: a helix's rise
    left out); at its start the tangent of its plane scaled by the arc's overall acceleration
    :math:`a` (``tcGetOverallMaxAccel``) plus the unit vector to the centre scaled by
    :math:`(F/2)^2 / r` with the requested feed :math:`F` (``tcCircleStartAccelUnitVector``),
    normalised. A line into a helix that rises along it, or a helix that ends running along
    the next line within its plane, is so blended nearly straight on.

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length.
    overall_acc_mm_s2, req_speed_mm_s : ndarray, shape (M,)
        Each move's overall acceleration and requested feed (used on arcs only).
    arc_rules : bool
        False: the tangents, arcs' too (the planner's ablation).
    """
    end, start = moves.end_tangents.copy(), moves.start_tangents.copy()
    arc = np.flatnonzero(moves.is_arc)
    if not (len(arc) and arc_rules):
        return end, start
    rows = np.arange(len(arc))
    normal_axis = moves._plane_axes[arc, 2]
    planar_end, planar_start = end[arc], start[arc]
    planar_end[rows, normal_axis] = 0.0
    planar_start[rows, normal_axis] = 0.0
    inward = moves.center_mm[arc] - moves.start_mm[arc]
    inward[rows, normal_axis] = 0.0
    normal_acc = (0.5 * req_speed_mm_s[arc]) ** 2 / moves.radius_mm[arc]
    start_acc = _unit(planar_start) * overall_acc_mm_s2[arc, None]
    end[arc] = _unit(planar_end)
    start[arc] = _unit(start_acc + _unit(inward) * normal_acc[:, None])
    return end, start


def parabolic_performance(
    length1: np.ndarray,
    length2: np.ndarray,
    speed1: np.ndarray,
    speed2: np.ndarray,
    acc1: np.ndarray,
    acc2: np.ndarray,
    cos_turn: np.ndarray,
    tol_mm: np.ndarray,
) -> np.ndarray:
    r"""``tpChooseBestBlend``'s measure of a parabolic blend: half its net speed
    (``estimateParabolicBlendPerformance``, ``tpComputeBlendVelocity``), shape (K,).

    Each move's reachable speed is its triangle speed over half its length (neither is
    finalized yet), :math:`v_{r,i} = \min(\sqrt{a_i L_i / 2}, v_i)`; the blend time
    :math:`t_b = \min(L_1/v_{r,1}, L_2/v_{r,2}, \max(v_{r,1}/a_1, v_{r,2}/a_2))`, the speeds
    :math:`v_i' = \min(v_{r,i}, a_i t_b, 2\sqrt{a_1 T/\cos\theta})` and the measure
    :math:`\sin\theta\,(v_1' + v_2')/4`.

    Parameters
    ----------
    length1, length2, speed1, speed2 : ndarray, shape (K,)
        Length and speed limit of the moves before and after.
    acc1, acc2 : ndarray, shape (K,)
        Their tangential accelerations as LinuxCNC holds them then: halved for the parabolic
        end, reduced by the kink, and halved again on an arc (``acc_ratio_tan`` of 1/2 before
        the arc is finalized).
    cos_turn : ndarray, shape (K,)
        Cosine of the turn, :math:`u_1 \cdot u_2`.
    tol_mm : ndarray, shape (K,)
        The ``G64 P`` of the move before (0: none).
    """
    vr1 = np.minimum(np.sqrt(acc1 * length1 / 2.0), speed1)
    vr2 = np.minimum(np.sqrt(acc2 * length2 / 2.0), speed2)
    t_blend = np.minimum(
        np.minimum(length1 / vr1, length2 / vr2), np.maximum(vr1 / acc1, vr2 / acc2)
    )
    theta = np.arccos(-np.clip(cos_turn, -1.0, 1.0)) / 2.0
    cos_t = np.cos(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_tol = np.where((tol_mm > 0) & (cos_t > math.cos(math.pi / 2.0 - 1e-3)),
                         2.0 * np.sqrt(acc1 * tol_mm / cos_t), np.inf)  # fmt: skip
    v1 = np.minimum(np.minimum(vr1, t_blend * acc1), v_tol)
    v2 = np.minimum(np.minimum(vr2, t_blend * acc2), v_tol)
    return np.sin(theta) * (v1 + v2) / 4.0


def choose_blends(
    arc_speed: np.ndarray, kink_speed: np.ndarray, parabolic: np.ndarray
) -> np.ndarray:
    """``tpChooseBestBlend``: the fastest of a parabolic blend, a tangent pass at the kink speed
    and the blend arc (0 where it fails), the first of equals; :data:`PARABOLIC_BLEND`,
    :data:`TANGENT_BLEND` or :data:`ARC_BLEND` per junction."""
    return np.argmax(np.column_stack([parabolic, kink_speed, arc_speed]), axis=1)


def arc_junctions(
    moves: Toolpath,
    candidates: np.ndarray,
    *,
    speed_mm_s: np.ndarray,
    req_speed_mm_s: np.ndarray,
    path_acc_mm_s2: np.ndarray,
    tol_mm: np.ndarray,
    kink_share: np.ndarray,
    start_trim_mm: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
    axis_vel_mm_s: np.ndarray,
    period_s: float,
    arc_rules: bool = True,
) -> dict[str, np.ndarray]:
    r"""What LinuxCNC makes of the junctions of M moves marked ``candidates`` (rules 1-6 of the
    module docstring), shapes (M - 1,).

    Parameters
    ----------
    moves : Toolpath
        M moves of non-zero length.
    candidates : ndarray of bool, shape (M - 1,)
        Junctions with an arc on either side that are neither passed as tangent nor stops, with
        a tolerance.
    speed_mm_s : ndarray, shape (M,)
        Speed limit of each move as queued (``tcGetMaxTargetVel``: its feed within its limits
        and its length per servo period).
    req_speed_mm_s : ndarray, shape (M,)
        Requested feed of each move (``reqvel``: the feed within canon's limits).
    path_acc_mm_s2 : ndarray, shape (M,)
        The acceleration the axes allow along each move (``maxaccel``).
    tol_mm : ndarray, shape (M - 1,)
        Blend tolerance of each junction.
    kink_share : ndarray, shape (M - 1,)
        :math:`k` of each junction (``tpSetupTangent``).
    start_trim_mm : ndarray, shape (M,)
        Length the blend before each move takes off its start (a line's ``target`` is the
        rest).
    axis_acc_mm_s2, axis_vel_mm_s : ndarray, shape (3,)
    period_s : float
    arc_rules : bool
        The parabolic blend's directions (:func:`parabolic_directions`).

    Returns
    -------
    dict of ndarray, shape (M - 1,)
        ``choice`` (:data:`PARABOLIC_BLEND`, :data:`TANGENT_BLEND`, :data:`ARC_BLEND`; -1 where
        not a candidate), ``kink_speed`` (:math:`v_k`), ``v_plan``, ``length`` (of the blend
        arc), ``trim1``, ``trim2`` (taken off the move before and after).
    """
    m = len(moves)
    out = {
        "choice": np.full(m - 1, -1),
        "kink_speed": np.zeros(m - 1),
        "v_plan": np.zeros(m - 1),
        "length": np.zeros(m - 1),
        "trim1": np.zeros(m - 1),
        "trim2": np.zeros(m - 1),
    }
    j = np.flatnonzero(candidates)
    if not len(j):
        return out
    arc = moves.is_arc
    blend = _candidate_blends(moves, j, speed_mm_s, tol_mm, axis_acc_mm_s2, axis_vel_mm_s)
    # a line's remainder passed in under GAP_CYCLES periods at the planned speed joins the
    # blend arc before the choice (blendCheckConsume, arcFromBlendPoints3's line_length)
    length = moves.lengths_mm
    rest1 = length[j] - start_trim_mm[j] - blend["trim1"]
    with np.errstate(divide="ignore", invalid="ignore"):
        consumed = ~arc[j] & blend["made"] & (rest1 < GAP_CYCLES * period_s * blend["v_plan"])
    blend_len = blend["length"] + np.where(consumed, rest1, 0.0)
    arc_speed = np.minimum(blend["v_plan"], blend_len / period_s)
    kink_speed = np.minimum(speed_mm_s[j], speed_mm_s[j + 1]) * KINK_RATIO / kink_share[j]
    parabolic = _parabolic_measure(moves, j, speed_mm_s, req_speed_mm_s, path_acc_mm_s2,
                                   tol_mm, arc_rules)  # fmt: skip
    out["choice"][j] = choose_blends(np.where(blend["made"], arc_speed, 0.0), kink_speed, parabolic)
    out["kink_speed"][j] = kink_speed
    for key in ("v_plan", "length", "trim1", "trim2"):
        out[key][j] = blend[key]
    return out


def _candidate_blends(
    moves: Toolpath,
    j: np.ndarray,
    speed_mm_s: np.ndarray,
    tol_mm: np.ndarray,
    axis_acc_mm_s2: np.ndarray,
    axis_vel_mm_s: np.ndarray,
) -> dict[str, np.ndarray]:
    """:func:`arc_junction_blends` at the K junctions ``j`` (after moves ``j``), shapes (K,);
    an arc shortened at its start by the blend before it keeps the rest of its sweep."""
    m = len(moves)
    arc = moves.is_arc
    point = moves.end_mm[j]
    u1, u2 = moves.end_tangents[j], moves.start_tangents[j + 1]
    normal_axis = moves._plane_axes[:, 2]
    centre = moves.center_mm.copy()
    normal = np.zeros((m, 3))
    normal[np.arange(m), normal_axis] = 1.0
    rows = np.arange(len(j))
    centre1, centre2 = centre[j], centre[j + 1]
    centre1[rows, normal_axis[j]] = point[rows, normal_axis[j]]
    centre2[rows, normal_axis[j + 1]] = point[rows, normal_axis[j + 1]]
    sweep = np.abs(moves.sweep_rad)
    length = moves.lengths_mm
    same = {
        "point": point, "u1": u1, "u2": u2, "arc1": arc[j], "arc2": arc[j + 1],
        "centre1": centre1, "centre2": centre2, "normal1": normal[j], "normal2": normal[j + 1],
        "length1": length[j], "length2": length[j + 1],
        "speed1": speed_mm_s[j], "speed2": speed_mm_s[j + 1], "tol_mm": tol_mm[j],
        "plane_acc": blend_plane_acc(u1, u2, axis_acc_mm_s2),
        "plane_vel": blend_plane_acc(u1, u2, axis_vel_mm_s),
    }  # fmt: skip
    blend = arc_junction_blends(**same, sweep1=sweep[j], sweep2=sweep[j + 1])
    start_trim = np.zeros(m)
    start_trim[j + 1] = np.where(arc[j + 1], blend["trim2"] / moves.radius_mm[j + 1], 0.0)
    again = np.flatnonzero(start_trim[j] > 0)
    if len(again):
        sub = arc_junction_blends(
            **{key: value[again] for key, value in same.items()},
            sweep1=(sweep[j] - start_trim[j])[again],
            sweep2=sweep[j + 1][again],
        )
        for key, value in sub.items():
            blend[key][again] = value
    return blend


def _parabolic_measure(
    moves: Toolpath,
    j: np.ndarray,
    speed_mm_s: np.ndarray,
    req_speed_mm_s: np.ndarray,
    path_acc_mm_s2: np.ndarray,
    tol_mm: np.ndarray,
    arc_rules: bool,
) -> np.ndarray:
    """:func:`parabolic_performance` at the K junctions ``j``, shape (K,): the angle of the
    parabolic blend from its own directions, the moves at their overall acceleration then
    (their parabolic end, 1/2, the kink, :math:`1 - r_k`, and 1/2 on an arc not yet
    finalized)."""
    arc, length = moves.is_arc, moves.lengths_mm
    scale = 0.5 * (1.0 - KINK_RATIO)
    acc1 = path_acc_mm_s2[j] * scale * np.where(arc[j], 0.5, 1.0)
    acc2 = path_acc_mm_s2[j + 1] * scale * np.where(arc[j + 1], 0.5, 1.0)
    d_end, d_start = parabolic_directions(moves, path_acc_mm_s2 * scale, req_speed_mm_s, arc_rules)
    return parabolic_performance(
        length[j], length[j + 1], speed_mm_s[j], speed_mm_s[j + 1], acc1, acc2,
        np.einsum("ij,ij->i", d_end[j], d_start[j + 1]), tol_mm[j],
    )  # fmt: skip
