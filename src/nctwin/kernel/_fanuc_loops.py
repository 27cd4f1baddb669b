"""Compiled control loop of the Fanuc-like kernel (numba): one pass over the interpolation
periods, from the blocks' planned feeds to the servo's measured positions
(:func:`nctwin.kernel.fanuc.simulate` prepares its inputs and reads its outputs)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..toolpath import MotionKind

__all__ = ["control_loop"]

_RAPID, _DWELL = int(MotionKind.RAPID), int(MotionKind.DWELL)
_NEXT, _CUT, _DRAIN_CUT, _RAPIDS, _DRAIN_RAPID, _INPOS, _PAUSE, _DONE = range(8)


@njit(cache=True)
def _start_rapid(slot, blk, start, end, linear, rem, vel, dirs):  # pragma: no cover - compiled
    """Load rapid block ``blk`` into planner slot ``slot``: one planner along the line (linear
    type) or one per axis (non-linear type). Returns whether it has anything to move."""
    rem[slot, :] = 0.0
    vel[slot, :] = 0.0
    dirs[slot, :, :] = 0.0
    d0 = end[blk, 0] - start[blk, 0]
    d1 = end[blk, 1] - start[blk, 1]
    d2 = end[blk, 2] - start[blk, 2]
    if linear:
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if length > 0.0:
            rem[slot, 0] = length
            dirs[slot, 0, 0] = d0 / length
            dirs[slot, 0, 1] = d1 / length
            dirs[slot, 0, 2] = d2 / length
    else:
        for a in range(3):
            d = end[blk, a] - start[blk, a]
            rem[slot, a] = abs(d)
            dirs[slot, a, a] = 1.0 if d >= 0.0 else -1.0
    return rem[slot, 0] > 0.0 or rem[slot, 1] > 0.0 or rem[slot, 2] > 0.0


# fmt: off
@njit(cache=True)
def control_loop(
    kind, start, end, cut_pts, cut_off, drain_after, stop_after, pause_n,
    ti, rapid_feed, rapid_acc, k_bell, linear_rapid, overlap, overlap_feed,
    exp_cut, k1, k2, exp_keep, exp_gain, unit,
    ad, bd, width,
    cmd_out, pos_out, blk_out, wait_out, end_out,
):  # pragma: no cover - compiled
    """Run the control period by period; see :func:`simulate`. Returns the number of samples
    written, or -1 if the output arrays (capacity ``len(blk_out)``) are too short."""
    # fmt: on
    n_blocks = len(kind)
    cap = len(blk_out)
    buf1 = np.zeros((k1, 3))
    buf2 = np.zeros((k2, 3))
    bufb = np.zeros((k_bell, 3))
    sum1 = np.zeros(3)
    sum2 = np.zeros(3)
    sumb = np.zeros(3)
    i1 = i2 = ib = 0
    resid = np.zeros(3)  # exponential filter: distance still inside it
    rem = np.zeros((2, 3))  # rapid planners: two slots (current, previous) of up to 3
    vel = np.zeros((2, 3))
    dirs = np.zeros((2, 3, 3))
    act = np.zeros(2, np.bool_)
    cur = 0
    decel = False
    feed_prev = 0.0
    feed_cur = 0.0
    err = np.zeros((3, 2))  # servo state per axis: following error, actual velocity
    cmd = np.zeros(3)
    if n_blocks:
        cmd[:] = start[0]
    interp = cmd.copy()
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
                cur = 0
                act[0] = _start_rapid(0, b, start, end, linear_rapid, rem, vel, dirs)
                act[1] = False
                decel, feed_prev, feed_cur = False, 0.0, 0.0
                phase = _RAPIDS
            else:
                interp[:] = start[b]
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
                xc[a] = cut_pts[p, a] - interp[a]
                interp[a] = cut_pts[p, a]
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
            other = 1 - cur
            if (
                overlap
                and b + 1 < n_blocks
                and kind[b + 1] == _RAPID
                and not act[other]
                and (not act[cur] or (decel and feed_cur <= overlap_feed))
            ):
                cur = other
                b += 1
                act[cur] = _start_rapid(cur, b, start, end, linear_rapid, rem, vel, dirs)
                decel, feed_prev, feed_cur = False, 0.0, 0.0
                continue
            if not act[0] and not act[1]:
                phase = _DRAIN_RAPID
                continue
            for s in range(2):
                if not act[s]:
                    continue
                fmax = 0.0
                left = False
                for q in range(3):
                    r = rem[s, q]
                    if r <= 0.0:
                        continue
                    # fastest speed from which braking at rapid_acc still stops on the end
                    # point, braking by rapid_acc * ti every period
                    v_brake = rapid_acc * (math.sqrt(0.25 * ti * ti + 2.0 * r / rapid_acc)
                                           - 0.5 * ti)  # fmt: skip
                    v = min(vel[s, q] + rapid_acc * ti, rapid_feed, v_brake)
                    step = v * ti
                    if step >= r:
                        step = r
                        rem[s, q] = 0.0
                        vel[s, q] = 0.0
                    else:
                        rem[s, q] = r - step
                        vel[s, q] = v
                        left = True
                        fmax = max(fmax, v)
                    for a in range(3):
                        xr[a] += step * dirs[s, q, a]
                act[s] = left
                if s == cur:
                    decel = fmax < feed_prev
                    feed_cur = fmax
                    feed_prev = fmax
            last_rap = i + 1
        elif phase == _DRAIN_RAPID:
            if last_rap < 0 or i >= last_rap + k_bell - 1:
                bufb[:, :] = 0.0
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
        for a in range(3):
            if exp_cut:
                r0 = resid[a]
                resid[a] = r0 * exp_keep + xc[a] * exp_gain
                oc = xc[a] + r0 - resid[a]
                small = small and abs(resid[a]) <= unit
            else:
                sum1[a] += xc[a] - buf1[i1, a]
                buf1[i1, a] = xc[a]
                y = sum1[a] / k1
                sum2[a] += y - buf2[i2, a]
                buf2[i2, a] = y
                oc = sum2[a] / k2
            sumb[a] += xr[a] - bufb[ib, a]
            bufb[ib, a] = xr[a]
            d_cmd = oc + sumb[a] / k_bell
            cmd[a] += d_cmd
            v_cmd = d_cmd / ti
            e, w = err[a, 0], err[a, 1]
            err[a, 0] = ad[a, 0, 0] * e + ad[a, 0, 1] * w + bd[a, 0] * v_cmd
            err[a, 1] = ad[a, 1, 0] * e + ad[a, 1, 1] * w + bd[a, 1] * v_cmd
        if flush and small:  # the exponential tail: less than one increment left
            for a in range(3):
                cmd[a] += resid[a]
                err[a, 0] += resid[a]
                resid[a] = 0.0
        i1 = (i1 + 1) % k1
        i2 = (i2 + 1) % k2
        ib = (ib + 1) % k_bell
        for a in range(3):
            cmd_out[i, a] = cmd[a]
            pos_out[i, a] = cmd[a] - err[a, 0]
        blk_out[i] = min(b, n_blocks - 1) if n_blocks else 0
    return i + 1
