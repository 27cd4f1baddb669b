"""Figures. Computing happens elsewhere; these functions only draw what they are given."""

from __future__ import annotations

import numpy as np

from ..machine import MachineProfile
from ..motion import Motion
from ..toolpath import MotionKind, Toolpath

__all__ = ["commanded_feed_mm_s", "feed_profile"]


def commanded_feed_mm_s(motion: Motion, toolpath: Toolpath, machine: MachineProfile) -> np.ndarray:
    """Programmed feed of the block each sample executes (rapid feed for rapids, 0 in dwells),
    capped at the machine's maximum feed, shape (n,)."""
    kind = toolpath.kind[motion.block]
    f = np.minimum(toolpath.feed_mm_s[motion.block], machine.max_feed_mm_s)
    f = np.where(kind == MotionKind.RAPID, machine.rapid_feed_mm_s, f)
    return np.where(kind == MotionKind.DWELL, 0.0, f)


def feed_profile(
    motion: Motion, toolpath: Toolpath, machine: MachineProfile, ax=None, title: str | None = None
):
    """Commanded and actual feed over time, the plot a process engineer looks at first.

    Returns the matplotlib Axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(9, 3.5), constrained_layout=True)
    ax.plot(
        motion.t_s,
        commanded_feed_mm_s(motion, toolpath, machine),
        lw=1.0,
        color="0.55",
        label="commanded",
    )
    ax.plot(motion.t_s, motion.speed_mm_s, lw=1.0, color="C0", label="actual (interpolated)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("feed (mm/s)")
    ax.set_xlim(0, max(motion.cycle_time_s, motion.period_s))
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper right", frameon=False)
    if title:
        ax.set_title(title)
    return ax
