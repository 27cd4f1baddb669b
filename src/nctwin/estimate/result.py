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
    """

    method: str
    machine: str
    block_times_s: np.ndarray
    toolpath: Toolpath

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
        """Machine-readable summary (what ``nctwin estimate --json`` prints)."""
        return {
            "method": self.method,
            "machine": self.machine,
            "cycle_time_s": self.cycle_time_s,
            "length_mm": self.toolpath.length_mm,
            "blocks": len(self.toolpath),
            "by_kind": self.by_kind(),
        }
