"""Cycle-time estimators: analytic ones, simulation on a virtual NC kernel, and networks trained
on a real control's recordings.

Each method is a function ``f(toolpath, machine) -> Estimate``; :data:`METHODS` maps the names
the CLI accepts to them. ``bilstm`` and ``axis_nn`` are the networks of the chapter "Predicting a
real controller" (:mod:`nctwin.realkernel`); they exist only for a machine with shipped
recordings (``linuxcnc_sim``), and train once on first use.
"""

from __future__ import annotations

from collections.abc import Callable

from ..machine import MachineProfile
from ..toolpath import Toolpath
from .blend_planner import blend_planner
from .block_overlap import block_overlap
from .cam import cam
from .kernel import kernel
from .result import Estimate

__all__ = ["METHODS", "Estimate", "cam", "estimate", "kernel"]


def _bilstm(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    from ..realkernel import bilstm_estimate  # the networks need the recordings and torch

    return bilstm_estimate(toolpath, machine)


def _axis_nn(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    from ..realkernel import axis_nn_estimate

    return axis_nn_estimate(toolpath, machine)


#: Estimators by name.
METHODS: dict[str, Callable[[Toolpath, MachineProfile], Estimate]] = {
    "cam": cam,
    "kernel": kernel,
    "block_overlap": block_overlap,
    "planner": blend_planner,
    "bilstm": _bilstm,
    "axis_nn": _axis_nn,
}


def estimate(toolpath: Toolpath, machine: MachineProfile, method: str = "cam") -> Estimate:
    """Estimate the cycle time of ``toolpath`` on ``machine`` with the named method."""
    try:
        fn = METHODS[method]
    except KeyError:
        raise ValueError(f"method = {method!r} is unknown: allowed {', '.join(METHODS)}") from None
    return fn(toolpath, machine)
