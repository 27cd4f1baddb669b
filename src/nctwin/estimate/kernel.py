"""Cycle time by simulation on the FIR kernel: the per-block times are the times between the
junction points of the simulated motion (Chien et al. 2023, eq. 1-3)."""

from __future__ import annotations

import pandas as pd

from ..kernel import fir
from ..machine import MachineProfile
from ..paths import results_dir
from ..recordings import MACHINE as RECORDED_MACHINE
from ..targets import block_targets
from ..toolpath import Toolpath
from .result import Estimate

__all__ = ["FITTED_FIR", "fir_settings", "kernel"]

#: Where the FIR settings of a machine that only recordings know are fitted: profile name ->
#: the fit a chapter wrote (``results/<stem>/<table>.csv``, ``fir_*`` columns, best row first).
FITTED_FIR = {RECORDED_MACHINE: ("linuxcnc_real_kernel", "fir_fit")}


def fir_settings(machine: MachineProfile) -> fir.FirSettings:
    """The FIR kernel's settings for ``machine``: the ``[fir]`` table of its profile, or for a
    machine of :data:`FITTED_FIR`, the best row of the chapter's fit.

    Raises
    ------
    ValueError
        If the fit of such a machine has not been written (run its chapter first).
    """
    if machine.name not in FITTED_FIR:
        return fir.FirSettings.load(machine.name)
    stem, table = FITTED_FIR[machine.name]
    path = results_dir() / stem / f"{table}.csv"
    if not path.is_file():
        raise ValueError(f"{path} is absent: the FIR settings of {machine.name} are fitted there")
    best = pd.read_csv(path).iloc[0]
    return fir.FirSettings(
        t1_s=float(best.fir_t1_s),
        t2_s=float(best.fir_t2_s),
        acc_scale=float(best.fir_acc_scale),
        blend_ratio=float(best.fir_blend_ratio),
        block_periods=int(best.fir_block_periods),
    )


def kernel(
    toolpath: Toolpath, machine: MachineProfile, settings: fir.FirSettings | None = None
) -> Estimate:
    """Simulate ``toolpath`` on :func:`nctwin.kernel.fir.run` with ``settings`` (default
    :func:`fir_settings`); block times between junctions."""
    settings = fir_settings(machine) if settings is None else settings
    targets = block_targets(fir.run(toolpath, machine, settings), toolpath)
    return Estimate("kernel", machine.name, targets.time_s, toolpath)
