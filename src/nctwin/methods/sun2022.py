r"""Sun, Dominguez-Caballero, Ward, Ayvar-Soberanis & Curtis (2022): one feed-forward network per
axis predicts the axis feeds at every cutter location, and from them the machining time.

The method in plain arrays: the input features of Table 1 (eq. 5-8), the network
(:data:`MODEL_CONFIG`: 2 hidden layers of 5 and 10 tansig neurons, a linear output, MSE) and the
machining time from the predicted axis feeds (eq. 9-10).
"""

from __future__ import annotations

import numpy as np

from ..learn.models import ModelConfig
from ..toolpath import MotionKind, Toolpath

__all__ = [
    "FEATURES",
    "MIN_FEED_SHARE",
    "MODEL_CONFIG",
    "block_times_s",
    "features",
    "resultant_feed_mm_s",
]

#: The paper's network: 9 features, hidden layers of 5 and 10 tanh neurons, one linear output.
MODEL_CONFIG = ModelConfig(kind="mlp", n_inputs=9, n_outputs=1, mlp_widths=(5, 10))

#: Lowest resultant feed eq. 10 divides by, as a share of the commanded feed: a network that
#: predicts a standstill on a cutting move would otherwise give an infinite time.
MIN_FEED_SHARE = 0.01


#: Column names of :func:`features`, per axis ``a``.
FEATURES = (
    "cos_prev", "cos", "cos_next", "feed_prev_mm_s", "feed_mm_s", "feed_next_mm_s",
    "acc_prev_mm_s2", "acc_mm_s2", "acc_next_mm_s2",
)  # fmt: skip


def features(toolpath: Toolpath, rapid_feed_mm_s: float) -> np.ndarray:
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
        ``[n, axis, feature]``, features in the order of :data:`FEATURES`.
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


def resultant_feed_mm_s(axis_feed_mm_s: np.ndarray, commanded_mm_s: np.ndarray) -> np.ndarray:
    r"""Resultant feed at each cutter location from the axis feeds (eq. 9),
    :math:`\lVert f_n \rVert = \sqrt{f_{x,n}^2 + f_{y,n}^2 + f_{z,n}^2}`, kept above
    :data:`MIN_FEED_SHARE` of the commanded feed.

    Parameters
    ----------
    axis_feed_mm_s : ndarray, shape (N, 3)
        Predicted (or measured) axis feeds.
    commanded_mm_s : ndarray, shape (N,)
        Commanded feed of each block (the rapid feed for G0).

    Returns
    -------
    ndarray, shape (N,)
    """
    return np.maximum(np.linalg.norm(axis_feed_mm_s, axis=1), MIN_FEED_SHARE * commanded_mm_s)


def block_times_s(
    axis_feed_mm_s: np.ndarray, length_mm: np.ndarray, commanded_mm_s: np.ndarray
) -> np.ndarray:
    r"""Time of each block, :math:`t_n = l_n / \lVert f_n \rVert` (eq. 10; the machining time is
    their sum, over every block, rapids included, as the paper's sum runs over every cutter
    location), with the resultant feed of :func:`resultant_feed_mm_s`.

    Parameters
    ----------
    axis_feed_mm_s : ndarray, shape (N, 3)
    length_mm : ndarray, shape (N,)
        Length of each block, :math:`\lVert CL_n - CL_{n-1} \rVert`.
    commanded_mm_s : ndarray, shape (N,)

    Returns
    -------
    ndarray, shape (N,)
    """
    return length_mm / resultant_feed_mm_s(axis_feed_mm_s, commanded_mm_s)
