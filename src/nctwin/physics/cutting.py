r"""Mechanistic milling forces of an end mill (the process force of Denkena et al. 2020).

Conventions
-----------
Frames
    :func:`tool_forces` works in the *feed frame* of Altintas (Manufacturing Automation, 2012,
    ch. 2): feed along :math:`+x'`, the spindle turning clockwise seen from above, the immersion
    angle :math:`\phi` of a tooth measured clockwise from :math:`+y'`. Up milling engages
    :math:`\phi \in [0, \arccos(1 - a_e/R)]`, down milling :math:`[\pi - \arccos(1 - a_e/R),
    \pi]`, a slot :math:`[0, \pi]`. :func:`workpiece_forces` rotates the result by the feed
    direction into machine X, Y and flips its sign: the dynamometer under the workpiece measures
    the force *on the workpiece*, which is also the load the feed drives carry.
Cutting law
    Per tooth :math:`j` and axial disc :math:`k` of height :math:`dz`, with chip thickness
    :math:`h = f_z \sin\phi + \Delta r_j + \Delta x' \sin\phi + \Delta y' \cos\phi`
    (runout :math:`\Delta r_j`; regenerative dynamic chip of a tool vibrating against the
    workpiece by :math:`(x', y')(t)`, :math:`\Delta x' = x'(t) - x'(t - T)` and likewise
    :math:`\Delta y'`, :math:`T` the tooth period; Altintas 2012, ch. 3; a tooth that leaves
    the cut, :math:`h \le 0`, cuts nothing, which bounds a chatter vibration),

    .. math:: dF_t = (K_{tc} h + K_{te})\,dz, \quad dF_r = (K_{rc} h + K_{re})\,dz, \quad
              dF_a = (K_{ac} h + K_{ae})\,dz,

    .. math:: dF_{x'} = -dF_t\cos\phi - dF_r\sin\phi, \quad
              dF_{y'} = dF_t\sin\phi - dF_r\cos\phi, \quad dF_{z'} = dF_a,

    summed over the engaged teeth and discs (Altintas eq. 2.24). A helix lags disc :math:`k` at
    height :math:`z_k` by :math:`z_k \tan\beta / R`.
Units
    mm, s, N, N·mm (torque), rad; time series are vectorised over samples, teeth and discs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_range

__all__ = [
    "C45",
    "CuttingCoefficients",
    "EndMill",
    "immersion",
    "plunge_forces",
    "tool_forces",
    "workpiece_forces",
]


@dataclass(frozen=True)
class EndMill:
    """A flat end mill.

    Parameters
    ----------
    diameter_mm : float
        Paper: 10 mm.
    teeth : int
        Paper: 4.
    helix_deg : float
        Helix angle (paper: variable, 38°/35°; the mean is used); 0 gives straight flutes.
    runout_mm : float
        Radial runout of the tool axis (a tooth's radius varies by this amplitude).
    runout_angle_rad : float
        Angular position of the runout relative to tooth 0.
    disc_mm : float
        Height of the axial discs the flutes are cut into.
    """

    diameter_mm: float = 10.0
    teeth: int = 4
    helix_deg: float = 36.5
    runout_mm: float = 0.004
    runout_angle_rad: float = 0.3
    disc_mm: float = 0.25

    def __post_init__(self) -> None:
        check_range("diameter_mm", self.diameter_mm, 0.0, low_open=True)
        check_range("teeth", self.teeth, 1)
        check_range("helix_deg", self.helix_deg, 0.0, 60.0)
        check_range("runout_mm", self.runout_mm, 0.0, 0.1)
        check_range("disc_mm", self.disc_mm, 0.0, 5.0, low_open=True)

    @property
    def radius_mm(self) -> float:
        return 0.5 * self.diameter_mm


@dataclass(frozen=True)
class CuttingCoefficients:
    """Linear-edge cutting coefficients (Altintas eq. 2.24).

    Parameters
    ----------
    ktc_n_mm2, krc_n_mm2, kac_n_mm2 : float
        Tangential, radial and axial shearing coefficients (N/mm²).
    kte_n_mm, kre_n_mm, kae_n_mm : float
        Edge (ploughing) coefficients (N/mm).
    """

    ktc_n_mm2: float
    krc_n_mm2: float
    kac_n_mm2: float
    kte_n_mm: float
    kre_n_mm: float
    kae_n_mm: float

    def __post_init__(self) -> None:
        for name in ("ktc_n_mm2", "krc_n_mm2", "kac_n_mm2", "kte_n_mm", "kre_n_mm", "kae_n_mm"):
            check_range(name, getattr(self, name), 0.0, 1e5)


#: C45 (AISI 1045) carbon steel with a coated carbide end mill: values of the order Altintas
#: (2012, Table 2.1) reports for AISI 1045; not identified on the paper's machine.
C45 = CuttingCoefficients(
    ktc_n_mm2=2100.0, krc_n_mm2=800.0, kac_n_mm2=400.0, kte_n_mm=22.0, kre_n_mm=28.0, kae_n_mm=4.0
)


def immersion(ae_mm: float, radius_mm: float, mode: str) -> tuple[float, float]:
    """Start and exit immersion angles (rad) of radial depth ``ae_mm``.

    Parameters
    ----------
    ae_mm : float
        Radial depth of cut, in (0, 2 R]; ``2 R`` is a slot whatever ``mode``.
    radius_mm : float
    mode : {"up", "down"}

    Returns
    -------
    (phi_start_rad, phi_exit_rad)
    """
    check_range("ae_mm", ae_mm, 0.0, 2.0 * radius_mm, low_open=True)
    if mode not in ("up", "down"):
        raise ValueError(f"mode = {mode!r} is unknown: allowed up, down")
    if ae_mm >= 2.0 * radius_mm:
        return 0.0, float(np.pi)
    if ae_mm > radius_mm:
        width = float(np.pi - np.arccos(ae_mm / radius_mm - 1.0))
    else:
        width = float(np.arccos(1.0 - ae_mm / radius_mm))
    return (0.0, width) if mode == "up" else (float(np.pi) - width, float(np.pi))


def tool_forces(
    t_s: np.ndarray,
    *,
    spindle_rpm: float,
    feed_per_tooth_mm: np.ndarray | float,
    ap_mm: np.ndarray | float,
    phi_start_rad: float,
    phi_exit_rad: float,
    tool: EndMill,
    coefficients: CuttingCoefficients = C45,
    regeneration_mm: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Forces on the tool in the feed frame, and the cutting torque.

    Parameters
    ----------
    t_s : ndarray, shape (T,)
        Sample times; the spindle angle is :math:`2\\pi n t / 60`.
    spindle_rpm : float
        Spindle speed n (1/min), > 0.
    feed_per_tooth_mm : float or ndarray, shape (T,)
        :math:`f_z = v_f / (N n)`; 0 where the tool does not feed.
    ap_mm : float or ndarray, shape (T,)
        Axial depth of cut; 0 where the tool is out of the material.
    phi_start_rad, phi_exit_rad : float
        Engagement (:func:`immersion`).
    tool : EndMill
    coefficients : CuttingCoefficients
    regeneration_mm : ndarray, shape (T, 2), optional
        :math:`(\\Delta x', \\Delta y')`: the tool's vibration against the workpiece now minus
        one tooth period ago, in the feed frame (the regenerative chip); None: no vibration.

    Returns
    -------
    force_n : ndarray, shape (T, 3)
        :math:`F_{x'}, F_{y'}, F_{z'}` on the tool.
    torque_nmm : ndarray, shape (T,)
        Cutting torque about the spindle axis, :math:`R \\sum dF_t`.
    """
    check_range("spindle_rpm", spindle_rpm, 0.0, 1e5, low_open=True)
    if not 0.0 <= phi_start_rad < phi_exit_rad <= np.pi:
        raise ValueError(
            f"phi_start_rad, phi_exit_rad = {phi_start_rad!r}, {phi_exit_rad!r} are out of "
            "range: allowed 0 <= start < exit <= pi"
        )
    t = np.asarray(t_s, dtype=float)
    n_t = t.shape[0]
    fz = np.broadcast_to(np.asarray(feed_per_tooth_mm, dtype=float), (n_t,))
    ap = np.broadcast_to(np.asarray(ap_mm, dtype=float), (n_t,))
    regen = np.zeros((n_t, 2)) if regeneration_mm is None else np.asarray(regeneration_mm)
    if regen.shape != (n_t, 2):
        raise ValueError(f"regeneration_mm shape = {regen.shape!r}: allowed ({n_t}, 2)")
    r = tool.radius_mm
    n_teeth = tool.teeth
    pitch = 2.0 * np.pi / n_teeth
    n_disc = max(int(np.ceil(float(ap.max(initial=0.0)) / tool.disc_mm)), 1)
    z = (np.arange(n_disc) + 0.5) * tool.disc_mm  # disc centres (K,)
    lag = z * np.tan(np.radians(tool.helix_deg)) / r  # (K,)
    j = np.arange(n_teeth)
    # runout: radius of tooth j minus that of the tooth before it adds to its chip
    radii = tool.runout_mm * np.cos(tool.runout_angle_rad - j * pitch)
    d_r = radii - np.roll(radii, 1)  # (N,)
    spin = 2.0 * np.pi * spindle_rpm / 60.0 * t  # (T,)
    phi = np.mod(spin[:, None, None] + j[None, :, None] * pitch - lag[None, None, :], 2 * np.pi)
    engaged = (
        (phi >= phi_start_rad) & (phi <= phi_exit_rad) & (z[None, None, :] < ap[:, None, None])
    )
    sin_p, cos_p = np.sin(phi), np.cos(phi)
    h = (
        (fz[:, None, None] + regen[:, 0, None, None]) * sin_p
        + regen[:, 1, None, None] * cos_p
        + d_r[None, :, None]
    )
    cut = engaged & (h > 0.0) & (fz[:, None, None] > 0.0)
    h = np.where(cut, h, 0.0)
    # the last disc is partial where ap is not a multiple of disc_mm
    dz = np.clip(ap[:, None, None] - (z[None, None, :] - 0.5 * tool.disc_mm), 0.0, tool.disc_mm)
    w = cut * dz
    c = coefficients
    d_ft = (c.ktc_n_mm2 * h + c.kte_n_mm) * w
    d_fr = (c.krc_n_mm2 * h + c.kre_n_mm) * w
    d_fa = (c.kac_n_mm2 * h + c.kae_n_mm) * w
    fx = (-d_ft * cos_p - d_fr * sin_p).sum(axis=(1, 2))
    fy = (d_ft * sin_p - d_fr * cos_p).sum(axis=(1, 2))
    fa = d_fa.sum(axis=(1, 2))
    return np.stack([fx, fy, fa], axis=1), r * d_ft.sum(axis=(1, 2))


def plunge_forces(
    axial_feed_per_tooth_mm: np.ndarray, *, tool: EndMill, coefficients: CuttingCoefficients = C45
) -> tuple[np.ndarray, np.ndarray]:
    """Axial force and torque of plunging (the end cutting edges drill, as at the start of the
    paper's circular pockets).

    Each of the N end edges, of length R, cuts a chip of the axial feed per tooth; its radial
    coefficient acts along the axis and its tangential force at R/2 gives the torque. The lateral
    forces of the symmetric edges cancel.

    Parameters
    ----------
    axial_feed_per_tooth_mm : ndarray, shape (T,)
        Downward feed per tooth (>= 0; 0 where not plunging).
    tool : EndMill
    coefficients : CuttingCoefficients

    Returns
    -------
    axial_force_n : ndarray, shape (T,)
        Force on the tool along +z (the workpiece pushes the tool up).
    torque_nmm : ndarray, shape (T,)
    """
    f = np.asarray(axial_feed_per_tooth_mm, dtype=float)
    if np.any(f < 0):
        raise ValueError(f"axial_feed_per_tooth_mm min = {f.min()!r} is out of range: allowed >= 0")
    r, c, n = tool.radius_mm, coefficients, tool.teeth
    active = f > 0
    axial = n * (c.krc_n_mm2 * f + c.kre_n_mm) * r * active
    torque = n * (c.ktc_n_mm2 * f + c.kte_n_mm) * r * (0.5 * r) * active
    return axial, torque


def workpiece_forces(force_tool_feed_frame_n: np.ndarray, feed_angle_rad: np.ndarray) -> np.ndarray:
    """Rotate feed-frame tool forces into machine X, Y, Z and flip them onto the workpiece.

    Parameters
    ----------
    force_tool_feed_frame_n : ndarray, shape (T, 3)
        From :func:`tool_forces` (plus any axial plunge force).
    feed_angle_rad : ndarray, shape (T,)
        Direction of the feed in the machine's XY plane, atan2(v_y, v_x).

    Returns
    -------
    ndarray, shape (T, 3)
        Force on the workpiece (what the dynamometer measures), machine frame.
    """
    f = np.asarray(force_tool_feed_frame_n, dtype=float)
    c, s = np.cos(feed_angle_rad), np.sin(feed_angle_rad)
    fx = c * f[:, 0] - s * f[:, 1]
    fy = s * f[:, 0] + c * f[:, 1]
    return -np.stack([fx, fy, f[:, 2]], axis=1)
