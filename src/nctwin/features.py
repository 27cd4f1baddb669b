"""Features and learning targets, one extractor per paper.

Chien, Sencer & Ward (2023), Sec. 3: the targets of the BiLSTM are read from a sampled motion
at the *junction points* :math:`R_k`, the interpolated samples nearest to the commanded points
:math:`N_k` (eq. 1). Between consecutive junction points the blended G-line has length
:math:`\\tilde l_k` (the integral of the feed) and time :math:`\\tilde t_k`; its average feed is

.. math:: \\bar f_k = \\tilde l_k / \\tilde t_k \\qquad (2)

and the cycle time is :math:`T = \\sum_k \\tilde l_k / \\bar f_k = \\sum_k \\tilde t_k` (eq. 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .motion import Motion
from .toolpath import MotionKind, Toolpath

__all__ = [
    "CHIEN2023_FEATURES",
    "SUN2022_FEATURES",
    "BlockTargets",
    "block_targets",
    "chien2023_features",
    "sun2022_features",
]


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


#: Column names of :func:`chien2023_features`.
CHIEN2023_FEATURES = ("feed_mm_s", "length_mm", "theta_start_rad", "theta_end_rad", "tol_mm")


def chien2023_features(toolpath: Toolpath, machine_tol_mm: float) -> np.ndarray:
    r"""Input features of the BiLSTM, one row per G-line (Chien et al. 2023, Sec. 2.2, Fig. 4).

    Row ``k`` is :math:`(F, l_k, \theta_k, \theta_{k+1}, \varepsilon)`: commanded feed, nominal
    length, corner angle at the start and at the end of the G-line, and blending tolerance (the
    program's ``G64 P`` where it sets one, else ``machine_tol_mm``). The tool starts and ends the
    program at rest, which the kernel treats like a reversal, so the start angle of the first
    G-line and the end angle of the last are :math:`\pi`.

    Parameters
    ----------
    toolpath : Toolpath
        Linear feed moves (the programs of the paper).
    machine_tol_mm : float
        The machine's default blending tolerance.

    Returns
    -------
    ndarray, shape (N, 5)
        Columns :data:`CHIEN2023_FEATURES`.
    """
    n = len(toolpath)
    theta = np.append(toolpath.corner_angles_rad, np.pi)
    if n:
        theta[0] = np.pi
    return np.column_stack(
        [
            toolpath.feed_mm_s,
            toolpath.lengths_mm,
            theta[:n],
            theta[1:],
            toolpath.effective_tolerance_mm(machine_tol_mm),
        ]
    )


#: Column names of :func:`sun2022_features`, per axis ``a``.
SUN2022_FEATURES = (
    "cos_prev", "cos", "cos_next", "feed_prev_mm_s", "feed_mm_s", "feed_next_mm_s",
    "acc_prev_mm_s2", "acc_mm_s2", "acc_next_mm_s2",
)  # fmt: skip


def sun2022_features(toolpath: Toolpath, rapid_feed_mm_s: float) -> np.ndarray:
    r"""Input features of the per-axis networks, one row per cutter location (Sun et al. 2022,
    Table 1, eq. 5-8).

    Cutter location :math:`CL_n` is the end of block :math:`n`. With :math:`f_n` the commanded
    feed (the rapid feed for G0), the nominal time of the block is
    :math:`t_n = \lVert CL_n - CL_{n-1} \rVert / f_n` (eq. 5), the nominal axis feed
    :math:`f_{a,n} = (a_n - a_{n-1}) / t_n` (eq. 6), the nominal axis acceleration
    :math:`a_{a,n} = (f_{a,n} - f_{a,n-1}) / t_n` (eq. 7), and the angle feature is the cosine

    .. math:: \theta_n = \frac{(CL_{n+1} - CL_n)\cdot(CL_{n-1} - CL_n)}
                             {\lvert CL_{n+1} - CL_n\rvert\,\lvert CL_{n-1} - CL_n\rvert}
        \qquad (8)

    (-1 for a straight continuation, 1 for a reversal). Each axis gets these at
    :math:`n-1, n, n+1`; the first and last rows repeat their edge values, the program starts and
    ends at rest (zero feed), and :math:`\theta = -1` where a neighbour is missing.

    Parameters
    ----------
    toolpath : Toolpath
        Linear moves and rapids of non-zero length.
    rapid_feed_mm_s : float
        Commanded feed of G0.

    Returns
    -------
    ndarray, shape (N, 3, 9)
        ``[n, axis, feature]``, features in the order of :data:`SUN2022_FEATURES`.
    """
    d = toolpath.end_mm - toolpath.start_mm
    length = np.linalg.norm(d, axis=1)
    if (length <= 0).any():
        k = int(np.flatnonzero(length <= 0)[0])
        raise ValueError(f"block {k} (line {toolpath.line[k]}) has zero length: drop it first")
    f = np.where(toolpath.kind == MotionKind.RAPID, rapid_feed_mm_s, toolpath.feed_mm_s)
    t = length / f  # eq. 5
    feed = d / t[:, None]  # eq. 6, (N, 3)
    prev_feed = np.vstack([np.zeros((1, 3)), feed[:-1]])
    acc = (feed - prev_feed) / t[:, None]  # eq. 7
    u = d / length[:, None]
    cos = np.full(len(d), -1.0)
    cos[:-1] = -np.einsum("ij,ij->i", u[1:], u[:-1])  # eq. 8 at the end of each block
    out = np.empty((len(d), 3, 9))
    for j, per_line in enumerate((np.repeat(cos[:, None], 3, axis=1), feed, acc)):
        padded = np.concatenate([per_line[:1], per_line, per_line[-1:]])
        out[:, :, 3 * j : 3 * j + 3] = np.stack([padded[:-2], padded[1:-1], padded[2:]], axis=2)
    return out
