"""Per-block quantities measured on a sampled motion: the learning targets every chapter reads.

Chien, Sencer & Ward (2023), Sec. 3: the targets are read from a sampled motion at the *junction
points* :math:`R_k`, the interpolated samples nearest to the commanded points :math:`N_k`
(eq. 1). Between consecutive junction points the blended G-line has length :math:`\\tilde l_k`
(the integral of the feed) and time :math:`\\tilde t_k`; its average feed is

.. math:: \\bar f_k = \\tilde l_k / \\tilde t_k \\qquad (2)

and the cycle time is :math:`T = \\sum_k \\tilde l_k / \\bar f_k = \\sum_k \\tilde t_k` (eq. 3).
Every kernel's motion, a recording of LinuxCNC and the slow logger of Sun et al. (2022) are read
the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .motion import Motion
from .toolpath import MotionKind, Toolpath

__all__ = ["BlockTargets", "block_targets"]


@dataclass(frozen=True)
class BlockTargets:
    """Per-block quantities measured on a motion (Chien et al. 2023, eq. 1-3).

    Parameters
    ----------
    junction_sample : ndarray of int64, shape (N + 1,)
        Sample index of the junction point at the start of each block, and of the end.
    length_mm : ndarray, shape (N,)
        Blended length between consecutive junction points.
    time_s : ndarray, shape (N,)
        Time between consecutive junction points.
    """

    junction_sample: np.ndarray
    length_mm: np.ndarray
    time_s: np.ndarray

    @property
    def avg_feed_mm_s(self) -> np.ndarray:
        """Average feed per block (eq. 2), shape (N,); NaN where the time is zero."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.time_s > 0, self.length_mm / self.time_s, np.nan)

    @property
    def cycle_time_s(self) -> float:
        """Cycle time, eq. 3."""
        return float(self.time_s.sum())


def block_targets(motion: Motion, toolpath: Toolpath, *, search_samples: int = 250) -> BlockTargets:
    """Junction points, blended lengths, times and average feeds of every block.

    The junction point of a commanded point is the sample nearest to it (eq. 1). It is searched
    among the samples within ``search_samples`` of where the motion's block label passes the
    junction, and labelled with one of the two blocks that meet there, so the search is O(N)
    and never matches another pass of the tool over the same point.

    Parameters
    ----------
    motion : Motion
        From a kernel run of ``toolpath``.
    toolpath : Toolpath
    search_samples : int
        Half-width of the search window, in samples.

    Returns
    -------
    BlockTargets
    """
    n = len(toolpath)
    n_samples = len(motion)
    pos, label = motion.pos_mm, motion.block
    junction = np.zeros(n + 1, dtype=np.int64)
    junction[n] = n_samples - 1
    if n > 1:
        points = toolpath.end_mm[:-1]  # N_k, between block k and k + 1
        switch = np.clip(np.searchsorted(label, np.arange(1, n), side="left"), 1, n_samples - 1)
        before, after = label[switch - 1], label[switch]
        offsets = np.arange(-search_samples, search_samples + 1)
        cand = np.clip(switch[:, None] + offsets[None, :], 0, n_samples - 1)
        d2 = ((pos[cand] - points[:, None, :]) ** 2).sum(axis=2)
        lab = label[cand]
        d2[(lab < before[:, None]) | (lab > after[:, None])] = np.inf
        # a stop ties many samples at the point: arriving counts for the block that stops,
        # waiting for the dwell, so a dwell starts at the first tied sample and ends at the last
        first = np.argmin(d2, axis=1)
        last = d2.shape[1] - 1 - np.argmin(d2[:, ::-1], axis=1)
        leaving_dwell = toolpath.kind[:-1] == MotionKind.DWELL
        junction[1:n] = cand[np.arange(n - 1), np.where(leaving_dwell, last, first)]
        np.maximum.accumulate(junction, out=junction)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    travelled = np.concatenate([[0.0], np.cumsum(step)])
    return BlockTargets(
        junction_sample=junction,
        length_mm=np.diff(travelled[junction]),
        time_s=np.diff(junction) * motion.period_s,
    )
