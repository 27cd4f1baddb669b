r"""Analytic cycle time of a block-overlap CNC (Lee et al. 2022, JKSPE 39(7), 537-543).

A calculator, not a simulator: every block's time comes from a closed form in its length, feed
and the control's time constants, block overlap is a cumulative sum over chains of cutting
blocks, and in-position time is a per-axis table. The cost is O(blocks), vectorised.

Notation: :math:`T_I` interpolation period (``period_s``), :math:`A_T` cutting acc/dec time
constant, :math:`A_{TR}` rapid time constant, :math:`A_s` rapid bell (S-curve) time constant,
:math:`F` feed, :math:`F_r` rapid feed, :math:`l` block length,
:math:`\lceil t \rceil_{T_I} = \lceil t / T_I \rceil T_I`.

Per-block times (Sec. 2.1)
    Cutting, normal block (:math:`\lceil l/F \rceil_{T_I} \ge A_T`), eq. 1-3:

    .. math:: T_b = \lceil l / F \rceil_{T_I}, \qquad T_a = A_T, \qquad T = T_b + T_a.

    Cutting, short block (:math:`\lceil l/F \rceil_{T_I} < A_T`; it never reaches F), eq. 4-5:
    :math:`T_b = A_T`, :math:`T_a = \lceil l / F \rceil_{T_I}`, :math:`T = T_b + T_a`.

    Rapid, linear type, eq. 6, 13: :math:`T = \lceil l / F_r \rceil_{T_I} + A_{TR} + A_s`;
    non-linear type (each axis at :math:`F_r` on its own), eq. 7-8, 14: :math:`l` is replaced by
    :math:`\max(|\Delta x|, |\Delta y|, |\Delta z|)`.

    Short rapid (:math:`\lceil l/F_r \rceil_{T_I} < A_{TR}`): a triangle at the acceleration
    :math:`a = F_r / A_{TR}` (eq. 9), :math:`T_a = \lceil \sqrt{l / a} \rceil_{T_I}` (eq. 10-12),
    :math:`T = 2 T_a + A_s` (eq. 15-16).

    Dwell (G4): :math:`\lceil t_\mathrm{dwell} \rceil_{T_I}`.
Block overlap (Sec. 2.2, Fig. 6-8)
    Only between consecutive *cutting* blocks. The next block starts where the current block's
    deceleration begins (normal block: after :math:`T_b`) or where its constant-velocity part
    begins (short block: after :math:`T_a`); in both cases after
    :math:`\lceil l/F \rceil_{T_I}`. With :math:`s_k` the start of block :math:`k` in its chain,
    the chain ends at :math:`\max_k (s_k + T_k)`, so profiles may overlap beyond the next block
    (Fig. 7). Rapids and dwells are not overlapped: the next block starts when they end.
In-position (Sec. 2.3)
    After each rapid, the measured in-position time of the slowest of the moving axes is added
    (the paper's, means of repeated single-axis rapids: ``data/papers/lee2022_inposition.csv``).

Per-block times (:func:`overlapped_block_times`, which
:func:`nctwin.estimate.block_overlap.block_overlap` reports as an estimate): a cutting block gets
the time until the next block of its chain starts; the chain's last block also gets the chain's
remaining tail; a rapid gets :math:`T` plus its in-position time. They sum to the cycle time.
"""

from __future__ import annotations

import math

import numpy as np

from ..controls import AccDecControl
from ..machine import Machine
from ..toolpath import MotionKind, PathMode, Toolpath

__all__ = ["block_times", "check_program", "overlapped_block_times"]

_CUT = (MotionKind.LINEAR, MotionKind.ARC_CW, MotionKind.ARC_CCW)


def _ceil_ti(t_s: np.ndarray, period_s: float) -> np.ndarray:
    """:math:`\\lceil t \\rceil_{T_I}` (eq. 2), forgiving 1e-9 period of round-off."""
    return np.ceil(np.asarray(t_s, dtype=float) / period_s - 1e-9) * period_s


def check_program(toolpath: Toolpath, source: str = "<program>") -> None:
    """Refuse a program with a construct the method cannot model.

    The paper's parser reads G00, G01, G02/G03 and G04 (Sec. 2.4), and its cycle-time
    calculator knows two ways a block may end: overlapped into the next cutting block, or
    stopped before a rapid or a dwell (Sec. 2.2). An exact-stop mode (``G61``, ``G61.1``) stops
    cutting blocks the method would overlap, and a blending tolerance (``G64 P``) is a
    path-blending rule of another kind of control; both would be priced wrongly, so they are
    refused.

    Parameters
    ----------
    toolpath : Toolpath
        N blocks, with their source lines.
    source : str
        The program's file name, for the message.

    Raises
    ------
    ValueError
        ``"<source>:<line>: <reason>"`` for the first such block.
    """
    exact = toolpath.path_mode >= PathMode.EXACT_PATH
    tol = (toolpath.path_mode == PathMode.BLEND) & np.isfinite(toolpath.blend_tol_mm)
    for bad, reason in (
        (exact, "exact-stop mode (G61/G61.1): the block-overlap method has no exact stop"),
        (tol, "G64 P blending tolerance: the block-overlap method has no path tolerance"),
    ):
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{source}:{toolpath.line[k]}: {reason}")


def block_times(
    toolpath: Toolpath, machine: Machine, control: AccDecControl
) -> dict[str, np.ndarray]:
    """Per-block times without overlap (Sec. 2.1, eq. 1-16).

    Parameters
    ----------
    toolpath : Toolpath
        N blocks.
    machine : Machine
        Fr (``rapid_feed_mm_s``) and the maximum feed; nothing else of it (the paper's
        method knows no axis limits).
    control : AccDecControl
        TI, AT, ATR, As and the rapid type.

    Returns
    -------
    dict of ndarray, each shape (N,)
        ``"T"`` the block's time :math:`T = T_b + T_a (+ A_s)`; ``"advance"`` the time after
        which the next block of a chain may start (:math:`\\lceil l/F \\rceil_{T_I}`, cutting
        blocks only, else ``T``); ``"short"`` whether the block is short (cutting or rapid).
    """
    ti = control.period_s
    at, atr, bell = (
        control.cut_time_constant_s,
        control.rapid_time_constant_s,
        control.rapid_bell_s,
    )
    for name in ("cut_time_constant_s", "rapid_time_constant_s", "rapid_bell_s"):
        control.periods(name)  # ValueError unless a whole number of periods
    kind = toolpath.kind
    lengths = toolpath.lengths_mm
    cut = np.isin(kind, _CUT)
    rapid = kind == MotionKind.RAPID
    feed = np.minimum(toolpath.feed_mm_s, machine.max_feed_mm_s)
    bad = cut & ~(feed > 0) & (lengths > 0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"feed_mm_s = {float(toolpath.feed_mm_s[j])!r} of block {j} "
            f"(line {toolpath.line[j]}) is out of range: a cutting block needs a feed F > 0"
        )

    with np.errstate(invalid="ignore", divide="ignore"):
        tb_cut = np.where(cut & (lengths > 0), _ceil_ti(lengths / feed, ti), 0.0)  # eq. 2
    short_cut = cut & (tb_cut > 0) & (tb_cut < at - 1e-12)
    # normal: Tb = ceil(l/F), Ta = AT (eq. 3); short: Tb = AT, Ta = ceil(l/F) (eq. 4-5)
    t_cut = np.where(tb_cut > 0, tb_cut + at, 0.0)

    d = np.abs(toolpath.end_mm - toolpath.start_mm)
    travel = lengths if control.rapid_type == "linear" else d.max(axis=1)  # eq. 6 / eq. 7
    fr = machine.rapid_feed_mm_s
    tb_r = np.where(rapid & (travel > 0), _ceil_ti(travel / fr, ti), 0.0)
    short_r = rapid & (tb_r > 0) & (tb_r < atr - 1e-12)
    a = fr / atr if atr > 0 else math.inf  # eq. 9
    ta_short = _ceil_ti(np.sqrt(travel / a), ti)  # eq. 10-12
    t_rapid = np.where(short_r, 2.0 * ta_short, tb_r + atr) + bell  # eq. 6-8, 13-16
    t_rapid = np.where(tb_r > 0, t_rapid, 0.0)

    t_dwell = _ceil_ti(toolpath.dwell_s, ti)
    t = np.where(cut, t_cut, np.where(rapid, t_rapid, t_dwell))
    advance = np.where(cut, tb_cut, t)
    return {"T": t, "advance": advance, "short": short_cut | short_r}


def overlapped_block_times(
    toolpath: Toolpath,
    machine: Machine,
    control: AccDecControl,
    *,
    overlap: bool = True,
    inposition: bool = True,
    inposition_s: tuple[float, float, float] | np.ndarray | None = None,
) -> np.ndarray:
    """Per-block times by the block-overlap method of Lee et al. 2022 (their sum is the cycle
    time).

    Parameters
    ----------
    toolpath : Toolpath
        N blocks.
    machine : Machine
    control : AccDecControl
        As for :func:`block_times`; ``control.inposition_time_s`` is the default in-position
        table.
    overlap : bool
        Apply block overlap between consecutive cutting blocks (Sec. 2.2). False gives the
        ablation "no block overlap": every block's full :math:`T` is added.
    inposition : bool
        Add the in-position time after rapids (Sec. 2.3). False gives the ablation.
    inposition_s : array-like, shape (3,), optional
        Measured in-position times of X, Y, Z (s); default ``control.inposition_time_s``.

    Returns
    -------
    ndarray, shape (N,)

    Raises
    ------
    ValueError
        If a time constant is not a whole multiple of ``period_s``, a cutting block has no
        feed, or ``inposition_s`` is not three non-negative numbers.
    """
    n = len(toolpath)
    bt = block_times(toolpath, machine, control)
    t, advance = bt["T"], bt["advance"]
    cut = np.isin(toolpath.kind, _CUT)
    out = t.copy()
    if overlap and n:
        # chains of consecutive cutting blocks (Fig. 8): start times by cumulative sums
        first = np.ones(n, bool)
        first[1:] = ~(cut[1:] & cut[:-1])
        starts_idx = np.flatnonzero(first)
        chain = np.cumsum(first) - 1
        csum = np.cumsum(advance)
        before = csum - advance  # sum of advances before each block
        start = before - before[starts_idx][chain]  # s_k within its chain
        end = np.maximum.reduceat(start + t, starts_idx)  # chain end
        last_idx = np.append(starts_idx[1:], n) - 1
        adv_total = np.add.reduceat(advance, starts_idx)
        out = np.where(cut, advance, t)
        tail = np.where(cut[last_idx], end - adv_total, 0.0)
        out[last_idx] += tail
    if inposition:
        tab = control.inposition_time_s if inposition_s is None else inposition_s
        tab = np.asarray(tab, dtype=float)
        if tab.shape != (3,) or not np.all(np.isfinite(tab)) or np.any(tab < 0):
            raise ValueError(
                f"inposition_s = {inposition_s!r} is out of range: allowed three numbers >= 0 s"
            )
        moved = np.abs(toolpath.end_mm - toolpath.start_mm) > 1e-9
        comp = np.max(np.where(moved, tab[None, :], 0.0), axis=1, initial=0.0)
        out = out + np.where(toolpath.kind == MotionKind.RAPID, comp, 0.0)
    return out
