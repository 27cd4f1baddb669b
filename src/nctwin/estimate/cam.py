"""The CAD/CAM baseline: path length over programmed feed.

.. math::

    T_\\mathrm{CAM} = \\sum_{k \\in \\mathrm{feed}} \\frac{l_k}{\\min(F_k, F_\\max)}
        + \\sum_{k \\in \\mathrm{rapid}} \\frac{l_k}{F_\\mathrm{rapid}}
        + \\sum_{k \\in \\mathrm{dwell}} t_k

This is what CAM systems print and what every paper compares against (Chien et al. 2023, Table 1
"CAM"; Sun et al. 2022, "CAD/CAM time"): it assumes the tool moves at the programmed feed from the
first to the last sample of every block, so it ignores acceleration, corners and blending and
underestimates the real cycle time. A feed above the machine's maximum is clamped, as every control
clamps it.
"""

from __future__ import annotations

import numpy as np

from ..machine import Machine
from ..toolpath import MotionKind, Toolpath
from .result import Estimate

__all__ = ["cam"]


def cam(toolpath: Toolpath, machine: Machine) -> Estimate:
    """CAD/CAM cycle time: each block at its programmed feed (or the rapid feed), no dynamics.

    Parameters
    ----------
    toolpath : Toolpath
    machine : Machine
        Supplies the rapid feed and the maximum feed.

    Returns
    -------
    Estimate
        With ``block_times_s`` of shape (N,).
    """
    kind = toolpath.kind
    feed = np.minimum(toolpath.feed_mm_s, machine.max_feed_mm_s)
    feed = np.where(kind == MotionKind.RAPID, machine.rapid_feed_mm_s, feed)
    lengths = toolpath.lengths_mm
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(lengths > 0, lengths / feed, 0.0)
    t = np.where(kind == MotionKind.DWELL, toolpath.dwell_s, t)
    return Estimate("cam", machine.name, t, toolpath)
