"""The column-wise reductions of nctwin._rows give numpy's axis=1 reductions bit for bit."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin._rows import row_min, row_norm

SPECIAL = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e-300, 1e300])


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 300), strided=st.booleans())
def test_row_reductions_equal_numpy_axis_1(seed, n, strided):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(2 * n, 3)) * 10.0 ** rng.integers(-8, 9, (2 * n, 3))
    special = rng.random((2 * n, 3)) < 0.1
    v[special] = rng.choice(SPECIAL, int(special.sum()))
    v = v[::2] if strided else v[:n]
    with np.errstate(over="ignore", invalid="ignore"):
        np.testing.assert_array_equal(row_norm(v), np.linalg.norm(v, axis=1))
        expected = np.min(v, axis=1)
    np.testing.assert_array_equal(row_min(v), expected)
    np.testing.assert_array_equal(np.signbit(row_min(v)), np.signbit(expected))
