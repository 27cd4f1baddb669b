"""Cycle time by simulation on the FIR kernel: the per-block times are the times between the
junction points of the simulated motion (Chien et al. 2023, eq. 1-3)."""

from __future__ import annotations

from ..controls import FirControl
from ..kernel import fir
from ..machine import Machine
from ..targets import block_targets
from ..toolpath import Toolpath
from .result import Estimate

__all__ = ["kernel"]


def kernel(toolpath: Toolpath, machine: Machine, control: FirControl) -> Estimate:
    """Simulate ``toolpath`` on :func:`nctwin.kernel.fir.run` with the FIR control ``control``;
    block times between junctions."""
    targets = block_targets(fir.run(toolpath, machine, control), toolpath)
    return Estimate("kernel", machine.name, targets.time_s, toolpath)
