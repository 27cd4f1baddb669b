"""Compiled control loop of the Fanuc-like kernel (numba): one pass over the interpolation
periods, from the blocks' planned feeds to the servo's measured positions
(:func:`nctwin.kernel.fanuc.simulate` prepares its inputs and reads its outputs)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..toolpath import MotionKind

__all__ = ["Blocks", "Outputs", "Settings", "control_loop"]

_RAPID, _DWELL = int(MotionKind.RAPID), int(MotionKind.DWELL)
_NEXT, _CUT, _DRAIN_CUT, _RAPIDS, _DRAIN_RAPID, _INPOS, _PAUSE, _DONE = range(8)


@njit(cache=True)
def _start_rapid(blk, start, end, linear, rem, dirs):  # pragma: no cover - compiled
    """Load rapid block ``blk`` into the rapid interpolator: one distance along the line
    (linear type) or one per axis (non-linear type). Returns whether it has anything to move."""
    rem[:] = 0.0
    dirs[:, :] = 0.0
    d0 = end[blk, 0] - start[blk, 0]
    d1 = end[blk, 1] - start[blk, 1]
    d2 = end[blk, 2] - start[blk, 2]
    if linear:
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if length > 0.0:
            rem[0] = length
            dirs[0, 0] = d0 / length
            dirs[0, 1] = d1 / length
            dirs[0, 2] = d2 / length
    else:
        for a in range(3):
            d = end[blk, a] - start[blk, a]
            rem[a] = abs(d)
            dirs[a, a] = 1.0 if d >= 0.0 else -1.0
    return rem[0] > 0.0 or rem[1] > 0.0 or rem[2] > 0.0


@njit(cache=True, inline="always")
def _box(total, buf, at, a, x, k):  # pragma: no cover - compiled
    """One period of a moving average of ``k`` periods on axis ``a``: ``x`` in, the mean out
    (``total`` the running sum, ``buf`` the last ``k`` inputs, ``at`` the oldest's row)."""
    total[a] += x - buf[at, a]
    buf[at, a] = x
    return total[a] / k


class Blocks(NamedTuple):
    """The N blocks as the loop reads them (:func:`nctwin.kernel.fanuc.simulate` makes them).

    Parameters
    ----------
    kind : ndarray of int64, shape (N,)
        :class:`~nctwin.toolpath.MotionKind` of each block.
    start, end : ndarray, shape (N, 3)
        Start and end points (C-contiguous).
    cut_steps : ndarray, shape (P, 3)
        The cutting blocks' interpolated position steps, period by period.
    cut_off : ndarray of int64, shape (N + 1,)
        Each block's first row of ``cut_steps``.
    drain_after, stop_after : ndarray of bool, shape (N,)
        Whether the filters empty after the block; whether the axes also settle in position.
    pause_n : ndarray of int64, shape (N,)
        Dwell of each block in periods.
    """

    kind: np.ndarray
    start: np.ndarray
    end: np.ndarray
    cut_steps: np.ndarray
    cut_off: np.ndarray
    drain_after: np.ndarray
    stop_after: np.ndarray
    pause_n: np.ndarray


class Settings(NamedTuple):
    """The control's settings in the loop's units (periods, mm, mm/s).

    Parameters
    ----------
    ti : float
        Interpolation period (s).
    rapid_feed : float
        Rapid feed (mm/s).
    k_rapid, k_bell : int
        Rapid acc/dec and its bell filter, in periods.
    linear_rapid : bool
        Linear-interpolation-type rapids (else each axis at its own rapid feed).
    overlap : bool
        Rapid overlap: the next rapid starts once the last has braked to ``overlap_feed``.
    overlap_feed : float
        Path speed (mm/s) at which a rapid may overlap the next.
    exp_cut : bool
        Exponential cutting acc/dec (else two moving averages).
    k1, k2 : int
        Lengths of the two cutting moving averages, in periods.
    exp_keep, exp_gain : float
        Exponential filter: share kept per period, and gain.
    unit : float
        Least increment (mm): the exponential filter is empty below it.
    ad : ndarray, shape (3, 2, 2)
        Each axis's discretised servo state matrix.
    bd : ndarray, shape (3, 2)
        Each axis's discretised servo input vector.
    width : ndarray, shape (3,)
        In-position widths (mm).
    """

    ti: float
    rapid_feed: float
    k_rapid: int
    k_bell: int
    linear_rapid: bool
    overlap: bool
    overlap_feed: float
    exp_cut: bool
    k1: int
    k2: int
    exp_keep: float
    exp_gain: float
    unit: float
    ad: np.ndarray
    bd: np.ndarray
    width: np.ndarray


class Outputs(NamedTuple):
    """Arrays the loop writes (capacity C samples, N blocks).

    Parameters
    ----------
    cmd, pos : ndarray, shape (C, 3)
        Commanded and measured positions.
    blk : ndarray of int64, shape (C,)
        Block of each sample.
    wait : ndarray, shape (N,)
        In-position wait after each block (s), zeros to start with.
    end : ndarray, shape (N,)
        Time at which each block's command ends (s), NaN to start with.
    """

    cmd: np.ndarray
    pos: np.ndarray
    blk: np.ndarray
    wait: np.ndarray
    end: np.ndarray


@njit(cache=True)
def control_loop(blocks, settings, out):  # pragma: no cover - compiled
    """Run the control period by period (:class:`Blocks`, :class:`Settings`, into
    :class:`Outputs`); see :func:`nctwin.kernel.fanuc.simulate`. Returns the number of samples
    written, or -1 if the output arrays (capacity ``len(out.blk)``) are too short."""
    kind, start, end, cut_steps, cut_off, drain_after, stop_after, pause_n = blocks
    (ti, rapid_feed, k_rapid, k_bell, linear_rapid, overlap, overlap_feed, exp_cut, k1, k2,
     exp_keep, exp_gain, unit, ad, bd, width) = settings  # fmt: skip
    cmd_out, pos_out, blk_out, wait_out, end_out = out
    n_blocks = len(kind)
    cap = len(blk_out)
    buf1 = np.zeros((k1, 3))  # cutting acc/dec: two moving averages
    buf2 = np.zeros((k2, 3))
    bufr = np.zeros((k_rapid, 3))  # rapid acc/dec: T_R, then the bell T_S
    bufb = np.zeros((k_bell, 3))
    sum1 = np.zeros(3)
    sum2 = np.zeros(3)
    sumr = np.zeros(3)
    sumb = np.zeros(3)
    i1 = i2 = ir = ib = 0
    resid = np.zeros(3)  # exponential filter: distance still inside it
    rem = np.zeros(3)  # rapid interpolator: distance left (along the line, or per axis)
    dirs = np.zeros((3, 3))
    rapid_speed = 0.0  # path speed out of the rapid filters in the last period (never rises
    # once a rapid is interpolated)
    err = np.zeros((3, 2))  # servo state per axis: following error, actual velocity
    cmd = np.zeros(3)
    if n_blocks:
        cmd[:] = start[0]
    xc = np.zeros(3)
    xr = np.zeros(3)
    i = 0
    cmd_out[0] = cmd
    pos_out[0] = cmd
    blk_out[0] = 0
    b = 0
    j = 0
    phase = _NEXT
    last_cut = -1
    last_rap = -1
    wait0 = 0
    final = False
    while phase != _DONE:
        flush = False
        xc[:] = 0.0
        xr[:] = 0.0
        if phase == _NEXT:
            if b == n_blocks:
                phase, final, wait0 = _INPOS, True, i
                continue
            j = 0
            if kind[b] == _DWELL:
                phase = _PAUSE
            elif kind[b] == _RAPID:
                _start_rapid(b, start, end, linear_rapid, rem, dirs)
                phase = _RAPIDS
            else:
                phase = _CUT
            continue
        elif phase == _CUT:
            if j == cut_off[b + 1] - cut_off[b]:
                if drain_after[b]:
                    phase = _DRAIN_CUT
                else:
                    b += 1
                    phase = _NEXT
                continue
            p = cut_off[b] + j
            for a in range(3):
                xc[a] = cut_steps[p, a]
            j += 1
            last_cut = i + 1
        elif phase == _DRAIN_CUT:
            if exp_cut:
                done = resid[0] == 0.0 and resid[1] == 0.0 and resid[2] == 0.0
            else:
                done = last_cut < 0 or i >= last_cut + k1 + k2 - 2
            if done:
                buf1[:, :] = 0.0
                buf2[:, :] = 0.0
                sum1[:] = 0.0
                sum2[:] = 0.0
                last_cut = -1
                end_out[b] = i * ti
                if stop_after[b]:
                    phase, wait0 = _INPOS, i
                else:
                    b += 1
                    phase = _NEXT
                continue
            flush = exp_cut
        elif phase == _RAPIDS:
            if rem[0] <= 0.0 and rem[1] <= 0.0 and rem[2] <= 0.0:
                # interpolated: with rapid overlap, the next rapid starts once the filters'
                # output has braked to overlap_feed; else the filters empty and the axes settle
                if overlap and b + 1 < n_blocks and kind[b + 1] == _RAPID:
                    if rapid_speed <= overlap_feed:
                        b += 1
                        _start_rapid(b, start, end, linear_rapid, rem, dirs)
                        continue
                else:
                    phase = _DRAIN_RAPID
                    continue
            else:
                for q in range(3):  # one period at F_r, the remainder in the last one
                    step = rapid_feed * ti
                    if rem[q] - step <= 1e-9:  # the rest, forgiving round-off
                        step = rem[q]
                    rem[q] -= step
                    for a in range(3):
                        xr[a] += step * dirs[q, a]
                last_rap = i + 1
        elif phase == _DRAIN_RAPID:
            if last_rap < 0 or i >= last_rap + k_rapid + k_bell - 2:
                bufr[:, :] = 0.0
                bufb[:, :] = 0.0
                sumr[:] = 0.0
                sumb[:] = 0.0
                last_rap = -1
                end_out[b] = i * ti
                phase, wait0 = _INPOS, i
                continue
        elif phase == _INPOS:
            if (
                abs(err[0, 0]) <= width[0]
                and abs(err[1, 0]) <= width[1]
                and abs(err[2, 0]) <= width[2]
            ):
                wb = n_blocks - 1 if final else b
                if wb >= 0:
                    wait_out[wb] += (i - wait0) * ti
                if final:
                    phase = _DONE
                else:
                    b += 1
                    phase = _NEXT
                continue
        elif phase == _PAUSE:
            if j == pause_n[b]:
                b += 1
                phase = _NEXT
                continue
            j += 1

        # ---- one interpolation period: acc/dec filters, command, servo
        if i + 1 >= cap:
            return -1
        i += 1
        small = True
        speed2 = 0.0
        for a in range(3):
            if exp_cut:
                r0 = resid[a]
                resid[a] = r0 * exp_keep + xc[a] * exp_gain
                oc = xc[a] + r0 - resid[a]
                small = small and abs(resid[a]) <= unit
            else:
                oc = _box(sum2, buf2, i2, a, _box(sum1, buf1, i1, a, xc[a], k1), k2)
            orap = _box(sumb, bufb, ib, a, _box(sumr, bufr, ir, a, xr[a], k_rapid), k_bell)
            speed2 += orap * orap
            d_cmd = oc + orap
            cmd[a] += d_cmd
            v_cmd = d_cmd / ti
            e, w = err[a, 0], err[a, 1]
            err[a, 0] = ad[a, 0, 0] * e + ad[a, 0, 1] * w + bd[a, 0] * v_cmd
            err[a, 1] = ad[a, 1, 0] * e + ad[a, 1, 1] * w + bd[a, 1] * v_cmd
        rapid_speed = math.sqrt(speed2) / ti
        if flush and small:  # the exponential tail: less than one increment left
            for a in range(3):
                cmd[a] += resid[a]
                err[a, 0] += resid[a]
                resid[a] = 0.0
        i1 = (i1 + 1) % k1
        i2 = (i2 + 1) % k2
        ir = (ir + 1) % k_rapid
        ib = (ib + 1) % k_bell
        for a in range(3):
            cmd_out[i, a] = cmd[a]
            pos_out[i, a] = cmd[a] - err[a, 0]
        blk_out[i] = min(b, n_blocks - 1) if n_blocks else 0
    return i + 1
