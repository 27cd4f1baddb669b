r"""Chien, Sencer & Ward (2023): a BiLSTM predicts the average feed of every G-line, and from it
the cycle time.

The method in plain arrays: the features of each G-line (Sec. 2.2, Fig. 4), the network
(:data:`BILSTM_CONFIG`: 10 hidden units per direction, tanh, a fully connected output) and the
prediction step, eq. 3 per G-line. The targets are :func:`nctwin.targets.block_targets` of a
kernel's motion (eq. 1-2).

Eq. 3, :math:`T = \sum_k \tilde l_k / \bar f_k`, needs the blended lengths :math:`\tilde l_k`,
which are not known before the program runs and which the paper does not say how it obtains;
using the nominal :math:`l_k` instead overestimates :math:`T` by 4-8 % on the test contours. And a
network trained with a squared loss predicts the conditional *mean* of each output, so a cycle
time formed from a ratio of two predictions is biased where the targets are noisy. The network
therefore predicts the time ratio :math:`s_k = F \tilde t_k / l_k` as a second output, and the
predicted cycle time is eq. 3 per G-line, linear in the prediction:

.. math:: \hat T = \sum_k \hat s_k\, l_k / F .
"""

from __future__ import annotations

import numpy as np

from ..learn.models import ModelConfig
from ..toolpath import Toolpath

__all__ = [
    "BILSTM_CONFIG",
    "FEATURES",
    "MIN_FEED_MM_S",
    "eq3_time_s",
    "features",
    "predict",
]

#: Column names of :func:`features`.
FEATURES = ("feed_mm_s", "length_mm", "theta_start_rad", "theta_end_rad", "tol_mm")
#: The paper's network: a BiLSTM of 10 hidden units per direction (tanh), a fully connected
#: output of the average feed and the time ratio.
BILSTM_CONFIG = ModelConfig("bilstm", n_inputs=len(FEATURES), n_outputs=2, hidden=10)
#: Floor of a predicted average feed (mm/s), so that a prediction near 0 stays a finite time.
MIN_FEED_MM_S = 1.0


def features(toolpath: Toolpath, machine_tol_mm: float) -> np.ndarray:
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
        Columns :data:`FEATURES`.
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


def block_times_s(
    time_ratio: np.ndarray, feed_mm_s: np.ndarray, length_mm: np.ndarray
) -> np.ndarray:
    r"""Predicted time of each G-line, eq. 3 per G-line: :math:`\hat t_k = \hat s_k l_k / F`
    (a negative predicted ratio counts as 0).

    Parameters
    ----------
    time_ratio, feed_mm_s, length_mm : ndarray, shape (N,)
        :math:`\hat s_k`, the commanded feed and the nominal length of each G-line.

    Returns
    -------
    ndarray, shape (N,)
    """
    return np.maximum(time_ratio, 0.0) * length_mm / feed_mm_s


def predict(output: np.ndarray, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""The network's output as average feeds and G-line times.

    Parameters
    ----------
    output : ndarray, shape (N, 2)
        Predicted average feed :math:`\hat{\bar f}_k` and time ratio :math:`\hat s_k`.
    features : ndarray, shape (N, 5)
        :func:`features` of the same G-lines.

    Returns
    -------
    avg_feed_mm_s : ndarray, shape (N,)
        :math:`\hat{\bar f}_k`, at least :data:`MIN_FEED_MM_S` (what Figs. 7 and 9 show).
    block_time_s : ndarray, shape (N,)
        :func:`block_times_s`; the cycle time is their sum (eq. 3).
    """
    feed = np.maximum(output[:, 0], MIN_FEED_MM_S)
    return feed, block_times_s(output[:, 1], features[:, 0], features[:, 1])


def eq3_time_s(avg_feed_mm_s: np.ndarray, length_mm: np.ndarray) -> float:
    r"""The paper's eq. 3 from the predicted average feeds, :math:`T = \sum_k l_k / \hat{\bar
    f}_k`, with the nominal lengths :math:`l_k` (the blended :math:`\tilde l_k` are not known
    before the program runs).

    Parameters
    ----------
    avg_feed_mm_s, length_mm : ndarray, shape (N,)
        :math:`\hat{\bar f}_k` (:func:`predict`, floored at :data:`MIN_FEED_MM_S`) and
        :math:`l_k`.

    Returns
    -------
    float
        Cycle time (s).
    """
    return float(np.sum(length_mm / avg_feed_mm_s))
