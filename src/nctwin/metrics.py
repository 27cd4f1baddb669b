r"""The package's one relative error and accuracy, in percent, as in all five papers:

.. math:: e = \frac{|\hat T - T|}{T} \times 100\,\%,

with :math:`\hat T` predicted and :math:`T` measured; accuracy is :math:`100\,\% - e`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["accuracy_pct", "error_pct"]


def error_pct(predicted: Any, measured: Any, *, signed: bool = False) -> Any:
    r"""Relative error in percent, :math:`|\hat T - T| / T \times 100`, or with ``signed``
    :math:`100 (\hat T - T) / T` (negative: an underestimate). The package's one percent error.

    Parameters
    ----------
    predicted
        Predicted value(s) :math:`\hat T`; scalar or array-like.
    measured
        Measured value(s) :math:`T`, all > 0; broadcast against ``predicted``.
    signed
        Keep the sign.

    Returns
    -------
    float or numpy.ndarray
        A float for scalar inputs, else an array of the broadcast shape.

    Raises
    ------
    ValueError
        If any ``measured`` is <= 0 (the error relative to it is undefined).

    Examples
    --------
    >>> round(error_pct(45.3, 44.5), 2)  # Chien et al. 2023, Table 1, I, 75 mm/s, 0.4 mm
    1.8
    """
    p = np.asarray(predicted, dtype=float)
    m = np.asarray(measured, dtype=float)
    if np.any(m <= 0):
        raise ValueError(f"measured must be > 0, got {m[m <= 0].ravel()[:5].tolist()}")
    out = 100.0 * (p - m) / m if signed else np.abs(p - m) / m * 100.0
    return float(out) if out.ndim == 0 else out


def accuracy_pct(predicted: Any, measured: Any) -> Any:
    """Accuracy in percent, ``100 - error_pct(predicted, measured)``.

    Examples
    --------
    >>> round(accuracy_pct(2172.4, 2169.1), 1)  # Lee et al. 2022, set 1: printed 99.8 %
    99.8
    """
    return 100.0 - error_pct(predicted, measured)
