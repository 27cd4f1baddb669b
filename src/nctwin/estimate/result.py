"""The result type every estimator returns."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..toolpath import MotionKind, Toolpath

__all__ = ["Estimate"]


@dataclass(frozen=True, eq=False)
class Estimate:
    """A cycle-time estimate.

    Parameters
    ----------
    method : str
        Name of the estimator.
    machine : str
        Name of the machine profile.
    block_times_s : ndarray, shape (N,)
        Time of each block of the tool path.
    toolpath : Toolpath
        The estimated tool path.
    floor_time_s : float, optional
        Physical floor of the program, for a method that can predict less than that (the
        learned ones): every move's length over its programmed feed within the machine's
        limits, plus the dwells; None for the others.
    clamped_moves : int
        Moves whose predicted time was below their floor and was raised to it.
    unclamped_time_s : float, optional
        Cycle time before the moves were raised to their floor (None without a floor).
    """

    method: str
    machine: str
    block_times_s: np.ndarray
    toolpath: Toolpath
    floor_time_s: float | None = None
    clamped_moves: int = 0
    unclamped_time_s: float | None = None

    @property
    def cycle_time_s(self) -> float:
        """Total time of the program."""
        return float(self.block_times_s.sum())

    def by_kind(self) -> dict[str, dict[str, float]]:
        """Blocks, length (mm) and time (s) per kind of block."""
        kinds = self.toolpath.kind
        lengths = self.toolpath.lengths_mm
        out = {}
        for k in MotionKind:
            m = kinds == k
            out[k.name.lower()] = {
                "blocks": int(m.sum()),
                "length_mm": float(lengths[m].sum()),
                "time_s": float(self.block_times_s[m].sum()),
            }
        return out

    def summary(self) -> dict:
        """Machine-readable summary (what ``nctwin estimate --json`` prints).

        With a floor, also ``clamped_to_floor`` (moves raised to their floor),
        ``unclamped_cycle_time_s`` and ``floor_time_s``.
        """
        out = {
            "method": self.method,
            "machine": self.machine,
            "cycle_time_s": self.cycle_time_s,
            "length_mm": self.toolpath.length_mm,
            "blocks": len(self.toolpath),
            "by_kind": self.by_kind(),
        }
        if self.floor_time_s is not None:
            out["clamped_to_floor"] = self.clamped_moves
            out["unclamped_cycle_time_s"] = self.unclamped_time_s
            out["floor_time_s"] = self.floor_time_s
        return out
