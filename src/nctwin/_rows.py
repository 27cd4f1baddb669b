"""Reductions over the three columns of (N, 3) arrays, bit for bit numpy's over ``axis=1``.

numpy reduces a short axis one row at a time (an inner loop of three per row), which costs about
ten times the column arithmetic below; the columns are combined in the order numpy's reduction
takes them (``tests/test_rows.py``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["row_min", "row_norm"]


def row_norm(v: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(v, axis=1)`` of ``v`` (N, 3), shape (N,): ``sqrt((x² + y²) + z²)``."""
    sq = v * v
    return np.sqrt((sq[:, 0] + sq[:, 1]) + sq[:, 2])


def row_min(v: np.ndarray) -> np.ndarray:
    """``np.min(v, axis=1)`` of ``v`` (N, 3), shape (N,), NaN propagated alike."""
    return np.minimum(np.minimum(v[:, 0], v[:, 1]), v[:, 2])
