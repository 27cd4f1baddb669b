"""Cycle time by the analytic block-overlap method of Lee et al. (2022), as an estimate
(the method itself: :mod:`nctwin.methods.lee2022`)."""

from __future__ import annotations

import numpy as np

from ..controls import AccDecControl
from ..machine import Machine
from ..methods import lee2022
from ..toolpath import Toolpath
from .result import Estimate

__all__ = ["block_overlap"]


def block_overlap(
    toolpath: Toolpath,
    machine: Machine,
    control: AccDecControl,
    *,
    overlap: bool = True,
    inposition: bool = True,
    inposition_s: tuple[float, float, float] | np.ndarray | None = None,
) -> Estimate:
    """``method="block_overlap"``: :func:`nctwin.methods.lee2022.overlapped_block_times` of
    ``toolpath`` on ``machine`` with the acc/dec ``control`` (the keywords are its ablations),
    per-block times of shape (N,), named after ``machine``."""
    times = lee2022.overlapped_block_times(
        toolpath,
        machine,
        control,
        overlap=overlap,
        inposition=inposition,
        inposition_s=inposition_s,
    )
    return Estimate("block_overlap", machine.name, times, toolpath)
