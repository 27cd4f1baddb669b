"""Cycle-time estimators: analytic ones, simulation on a virtual NC kernel, and networks trained
on a real control's recordings.

Each method is a function ``f(toolpath, machine) -> Estimate``; :data:`METHODS` maps the names
the CLI accepts to them. ``bilstm`` and ``axis_nn`` are the networks of the chapter "Predicting a
real controller" (:mod:`nctwin.estimate.learned`); they exist only for a machine with shipped
recordings (``linuxcnc_sim``), and train once on first use.
"""

from __future__ import annotations

from collections.abc import Callable

import pandas as pd

from ..machine import MachineProfile
from ..paths import results_dir
from ..recordings import MACHINE as RECORDED_MACHINE
from ..toolpath import Toolpath
from .blend_planner import blend_planner
from .block_overlap import block_overlap
from .cam import cam
from .kernel import kernel
from .result import Estimate

__all__ = [
    "METHODS",
    "Estimate",
    "best_method",
    "cam",
    "default_method",
    "estimate",
    "kernel",
]


def _bilstm(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    """:func:`nctwin.estimate.learned.bilstm`, imported on first use (torch takes seconds to
    import, and the other methods do not need it)."""
    from .learned import bilstm

    return bilstm(toolpath, machine)


def _axis_nn(toolpath: Toolpath, machine: MachineProfile) -> Estimate:
    """:func:`nctwin.estimate.learned.axis_nn`, imported on first use."""
    from .learned import axis_nn

    return axis_nn(toolpath, machine)


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


def best_method(summary: pd.DataFrame) -> str:
    """The method with the lowest median error on the public programs (on the test paths where
    no public program was run): the default of ``nctwin estimate`` for the recorded machine."""
    group = "public" if (summary.set == "public").any() else "test paths"
    rows = summary[summary.set == group].sort_values(
        ["median_abs_err_pct", "worst_abs_err_pct"], kind="stable"
    )
    return str(rows.method.iloc[0])


#: Where the methods were compared on a machine that only recordings know: profile name -> the
#: summary a chapter wrote (``results/<stem>/<table>.csv``, see :func:`best_method`).
COMPARED = {RECORDED_MACHINE: ("linuxcnc_real_kernel", "summary")}


def default_method(machine: MachineProfile) -> str:
    """The method ``nctwin estimate`` uses when none is named: for a machine of
    :data:`COMPARED`, the best one its chapter found (:func:`best_method` of the chapter's
    summary, where it has been written); ``cam`` for the others."""
    if machine.name not in COMPARED:
        return "cam"
    stem, table = COMPARED[machine.name]
    path = results_dir() / stem / f"{table}.csv"
    return best_method(pd.read_csv(path)) if path.is_file() else "cam"
