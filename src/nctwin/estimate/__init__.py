"""Cycle-time estimators: analytic ones, simulation on a virtual NC kernel, and networks trained
on a real control's recordings.

Each method runs a tool path on a machine profile's :class:`~nctwin.machine.Machine` and one of
its controls (:data:`nctwin.machine.METHOD_CONTROLS` says which): ``cam`` on the machine alone,
``kernel`` on ``[control.fir]``, ``block_overlap`` on ``[control.accdec]``, ``planner`` on
``[control.planner]``. ``bilstm`` and ``axis_nn`` are the networks of the chapter "Predicting a
real controller" (:mod:`nctwin.estimate.learned`); they exist only for a profile that names
shipped recordings (``linuxcnc_sim``), and train once on first use. :func:`estimate` picks the
control from the profile; a profile that lacks it is refused in one line.

:func:`cycle_time` adds what the shop floor sees (:mod:`nctwin.estimate.cycle`): the times that
are no motion from the profile's ``[control.sequence]``, the motion time between spindle starts
and stops, and the feed and rapid overrides.
"""

from __future__ import annotations

from collections.abc import Callable

import pandas as pd

from ..machine import Profile
from ..toolpath import Toolpath
from .blend_planner import blend_planner
from .block_overlap import block_overlap
from .cam import cam
from .cycle import CycleTime, apply_overrides
from .kernel import kernel
from .result import Estimate

__all__ = [
    "METHODS",
    "CycleTime",
    "Estimate",
    "best_method",
    "cam",
    "cycle_time",
    "estimate",
    "kernel",
]


def _cam(toolpath: Toolpath, profile: Profile) -> Estimate:
    return cam(toolpath, profile.machine)


def _kernel(toolpath: Toolpath, profile: Profile) -> Estimate:
    return kernel(toolpath, profile.machine, profile.control_for("kernel"))


def _block_overlap(toolpath: Toolpath, profile: Profile) -> Estimate:
    return block_overlap(toolpath, profile.machine, profile.control_for("block_overlap"))


def _planner(toolpath: Toolpath, profile: Profile) -> Estimate:
    return blend_planner(toolpath, profile.machine, profile.control_for("planner"))


def _bilstm(toolpath: Toolpath, profile: Profile) -> Estimate:
    """:func:`nctwin.estimate.learned.bilstm`, imported on first use (torch takes seconds to
    import, and the other methods do not need it)."""
    from .learned import bilstm

    return bilstm(toolpath, profile)


def _axis_nn(toolpath: Toolpath, profile: Profile) -> Estimate:
    """:func:`nctwin.estimate.learned.axis_nn`, imported on first use."""
    from .learned import axis_nn

    return axis_nn(toolpath, profile)


#: Estimators by name, each run on a profile (its machine and the control the method needs).
METHODS: dict[str, Callable[[Toolpath, Profile], Estimate]] = {
    "cam": _cam,
    "kernel": _kernel,
    "block_overlap": _block_overlap,
    "planner": _planner,
    "bilstm": _bilstm,
    "axis_nn": _axis_nn,
}


def estimate(toolpath: Toolpath, profile: Profile, method: str | None = None) -> Estimate:
    """Estimate the cycle time of ``toolpath`` on ``profile`` with the named method (default
    the profile's ``default_method``).

    Raises
    ------
    ValueError
        For an unknown method, or a profile without the control the method needs.
    """
    method = profile.default_method if method is None else method
    try:
        fn = METHODS[method]
    except KeyError:
        raise ValueError(f"method = {method!r} is unknown: allowed {', '.join(METHODS)}") from None
    profile.control_for(method)  # refuses a profile without the method's control first
    return fn(toolpath, profile)


def cycle_time(
    toolpath: Toolpath,
    profile: Profile,
    method: str | None = None,
    *,
    rapid_override_pct: float = 100.0,
    feed_override_pct: float = 100.0,
) -> CycleTime:
    """The cycle time of ``toolpath`` on ``profile``: :func:`estimate` under the overrides
    (:func:`~nctwin.estimate.cycle.apply_overrides`, 100 % leaves the inputs as they are), plus
    the non-motion times of the profile's ``[control.sequence]`` (none without it).

    Raises
    ------
    ValueError
        As :func:`estimate`, and for an override out of (0, 200] %.
    """
    toolpath, profile = apply_overrides(
        toolpath,
        profile,
        rapid_override_pct=rapid_override_pct,
        feed_override_pct=feed_override_pct,
    )
    return CycleTime.of(estimate(toolpath, profile, method), profile.sequence)


def best_method(summary: pd.DataFrame) -> str:
    """The method of :data:`METHODS` with the lowest median error on the public programs (on the
    test paths where no public program was run): what a chapter that compares methods on a
    machine's recordings recommends as its profile's ``default_method``. A row of another name
    (a method with fitted constants, such as ``planner_fitted``) is not a method a profile can
    name, and is passed over."""
    group = "public" if (summary.set == "public").any() else "test paths"
    rows = summary[(summary.set == group) & summary.method.isin(list(METHODS))].sort_values(
        ["median_abs_err_pct", "worst_abs_err_pct"], kind="stable"
    )
    return str(rows.method.iloc[0])
