"""Cycle time by simulation on the FIR kernel: the per-block times are the times between the
junction points of the simulated motion (Chien et al. 2023, eq. 1-3)."""

from __future__ import annotations

from ..features import block_targets
from ..kernel import fir
from ..machine import MachineProfile
from ..toolpath import Toolpath
from .result import Estimate

__all__ = ["kernel"]


def kernel(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    """Simulate ``toolpath`` on :func:`nctwin.kernel.fir.run`; block times between junctions."""
    targets = block_targets(fir.run(toolpath, machine), toolpath)
    return Estimate("kernel", machine.name, targets.time_s, toolpath)
