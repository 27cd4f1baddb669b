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

from .checks import check_int
from .motion import Motion
from .toolpath import MotionKind, Toolpath

__all__ = ["CHUNK_JUNCTIONS", "BlockTargets", "block_targets"]


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


#: Junctions searched at once by :func:`block_targets`: its memory is a few arrays of
#: ``CHUNK_JUNCTIONS x (2 search_samples + 1)`` numbers (4 MB each at the defaults) however long
#: the program (all junctions at once took 6 GB for 200,000 blocks).
CHUNK_JUNCTIONS = 1024


def _junction_chunk(
    pos_axes: np.ndarray,
    label: np.ndarray,
    points: np.ndarray,
    switch: np.ndarray,
    leaving_dwell: np.ndarray,
    offsets: np.ndarray,
) -> np.ndarray:
    """Sample index of the junction point of each of K junctions (eq. 1), shape (K,).

    ``pos_axes`` (3, n) are the sampled positions axis by axis, ``points`` (K, 3) the commanded
    points, ``switch`` (K,) the first sample labelled with the block after each, ``leaving_dwell``
    (K,) whether the block before is a dwell. Every row is computed alone, so any split of the
    junctions into chunks gives the same bits. The squared distance is summed X, then Y, then Z,
    the order of ``((p - q) ** 2).sum(axis=-1)`` over the three axes.
    """
    n_samples = len(label)
    before, after = label[switch - 1], label[switch]
    cand = np.clip(switch[:, None] + offsets[None, :], 0, n_samples - 1)
    d2 = (pos_axes[0][cand] - points[:, 0, None]) ** 2
    d2 += (pos_axes[1][cand] - points[:, 1, None]) ** 2
    d2 += (pos_axes[2][cand] - points[:, 2, None]) ** 2
    lab = label[cand]
    d2[(lab < before[:, None]) | (lab > after[:, None])] = np.inf
    # a stop ties many samples at the point: arriving counts for the block that stops (the
    # first tied sample), waiting for the dwell, so a dwell ends at the last tied sample
    pick = np.argmin(d2, axis=1)
    dwell = np.flatnonzero(leaving_dwell)
    if len(dwell):
        pick[dwell] = d2.shape[1] - 1 - np.argmin(d2[dwell, ::-1], axis=1)
    return cand[np.arange(len(switch)), pick]


def block_targets(
    motion: Motion,
    toolpath: Toolpath,
    *,
    search_samples: int = 250,
    chunk_junctions: int = CHUNK_JUNCTIONS,
) -> BlockTargets:
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
    chunk_junctions : int
        Junctions searched at once (memory only: the result does not depend on it).

    Returns
    -------
    BlockTargets
    """
    check_int("chunk_junctions", chunk_junctions, 1)
    n = len(toolpath)
    n_samples = len(motion)
    pos, label = motion.pos_mm, motion.block
    junction = np.zeros(n + 1, dtype=np.int64)
    junction[n] = n_samples - 1
    if n > 1:
        points = toolpath.end_mm[:-1]  # N_k, between block k and k + 1
        switch = np.clip(np.searchsorted(label, np.arange(1, n), side="left"), 1, n_samples - 1)
        leaving_dwell = toolpath.kind[:-1] == MotionKind.DWELL
        offsets = np.arange(-search_samples, search_samples + 1)
        pos_axes = np.ascontiguousarray(pos.T)
        # the candidates of all junctions at once would be (N - 1) x (2 w + 1) x 3 floats, GBs
        # for a long program: junctions go in chunks, each row computed as it would be alone
        for lo in range(0, n - 1, chunk_junctions):
            hi = min(lo + chunk_junctions, n - 1)
            junction[1 + lo : 1 + hi] = _junction_chunk(
                pos_axes, label, points[lo:hi], switch[lo:hi], leaving_dwell[lo:hi], offsets
            )
        np.maximum.accumulate(junction, out=junction)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    travelled = np.concatenate([[0.0], np.cumsum(step)])
    return BlockTargets(
        junction_sample=junction,
        length_mm=np.diff(travelled[junction]),
        time_s=np.diff(junction) * motion.period_s,
    )
