"""Cycle time by simulation on the FIR kernel: the per-block times are the times between the
junction points of the simulated motion (Chien et al. 2023, eq. 1-3)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..features import block_targets
from ..kernel import fir
from ..machine import MachineProfile
from ..toolpath import MotionKind, PathMode, Toolpath
from .result import Estimate

__all__ = ["fir_setup", "kernel"]


def fir_setup(toolpath: Toolpath, machine: MachineProfile) -> tuple[Toolpath, MachineProfile]:
    """The tool path and profile the FIR kernel runs, with the machine's stand-in settings.

    ``fir_acc_scale`` scales the axis accelerations; ``fir_blend_ratio`` lowers the tolerance
    of each junction to that share of the shorter of its two moves (written as the ``G64 P``
    of the block that starts there, which the kernel reads); ``fir_block_periods`` caps the
    feed of each cutting move at its length over that many periods. With the defaults
    (1, inf, 0) both come back unchanged.
    """
    if machine.fir_acc_scale != 1.0:
        acc = tuple(machine.fir_acc_scale * a for a in machine.axis_max_acceleration_mm_s2)
        machine = dataclasses.replace(machine, axis_max_acceleration_mm_s2=acc, fir_acc_scale=1.0)
    if machine.fir_blend_ratio == np.inf and machine.fir_block_periods == 0:
        return toolpath, machine
    length = toolpath.lengths_mm
    moving = length > 0
    tol = toolpath.effective_tolerance_mm(machine.blend_tol_mm)
    prev = np.full(len(toolpath), np.inf)
    idx = np.flatnonzero(moving)
    prev[idx[1:]] = length[idx[:-1]]
    limit = np.where(moving, machine.fir_blend_ratio * np.minimum(length, prev), np.inf)
    new_tol = np.where(tol > 0, np.minimum(tol, limit), tol)
    blend = np.isfinite(new_tol) & (new_tol > 0) & (new_tol != tol)
    feed = toolpath.feed_mm_s
    if machine.fir_block_periods:
        cap = length / (machine.fir_block_periods * machine.period_s)
        feed = np.where((toolpath.kind != MotionKind.RAPID) & moving, np.minimum(feed, cap), feed)
    toolpath = dataclasses.replace(
        toolpath,
        feed_mm_s=feed,
        path_mode=np.where(blend, PathMode.BLEND, toolpath.path_mode).astype(np.int8),
        blend_tol_mm=np.where(blend, new_tol, toolpath.blend_tol_mm),
    )
    machine = dataclasses.replace(machine, fir_blend_ratio=np.inf, fir_block_periods=0)
    return toolpath, machine


def kernel(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    """Simulate ``toolpath`` on :func:`nctwin.kernel.fir.run` (with the machine's stand-in
    settings, :func:`fir_setup`); block times between junctions."""
    tp, m = fir_setup(toolpath, machine)
    targets = block_targets(fir.run(tp, m), tp)
    return Estimate("kernel", machine.name, targets.time_s, toolpath)
