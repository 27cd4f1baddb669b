"""Cycle-time estimators: analytic ones, and simulation on a virtual NC kernel.

Each method is a function ``f(toolpath, machine) -> Estimate``; :data:`METHODS` maps the names
the CLI accepts to them. Later chapters add their methods here.
"""

from __future__ import annotations

from collections.abc import Callable

from ..machine import MachineProfile
from ..toolpath import Toolpath
from .block_overlap import block_overlap
from .cam import cam
from .kernel import kernel
from .result import Estimate

__all__ = ["METHODS", "Estimate", "cam", "estimate", "kernel"]

#: Estimators by name.
METHODS: dict[str, Callable[[Toolpath, MachineProfile], Estimate]] = {
    "cam": cam,
    "kernel": kernel,
    "block_overlap": block_overlap,
}


def estimate(toolpath: Toolpath, machine: MachineProfile, method: str = "cam") -> Estimate:
    """Estimate the cycle time of ``toolpath`` on ``machine`` with the named method."""
    try:
        fn = METHODS[method]
    except KeyError:
        raise ValueError(f"method = {method!r} is unknown: allowed {', '.join(METHODS)}") from None
    return fn(toolpath, machine)
