"""Cycle time by simulation on the FIR kernel: the per-block times are the times between the
junction points of the simulated motion (Chien et al. 2023, eq. 1-3), read as the motion is
made, so memory does not grow with the program's duration
(:func:`nctwin.kernel.fir_stream.stream_block_targets`)."""

from __future__ import annotations

from ..controls import FirControl
from ..kernel.fir_stream import stream_block_targets
from ..machine import Machine
from ..toolpath import Toolpath
from .result import Estimate

__all__ = ["kernel"]


def kernel(toolpath: Toolpath, machine: Machine, control: FirControl) -> Estimate:
    """Simulate ``toolpath`` on the FIR kernel (:func:`nctwin.kernel.fir.run`) with the FIR
    control ``control``; block times between junctions, the same bits as
    ``block_targets(fir.run(...))``."""
    targets = stream_block_targets(toolpath, machine, control)
    return Estimate("kernel", machine.name, targets.time_s, toolpath)
