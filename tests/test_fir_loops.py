"""The compiled sample loops of the FIR kernel compute the same bits as the numpy they replace."""

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from nctwin import parse
from nctwin.geometry import PathGeometry
from nctwin.kernel import _fir_loops

PERIOD_S = 0.001


def _numpy_filter(x: np.ndarray, taps: list[int]) -> np.ndarray:
    """The box cascade with numpy's running sums: ``x`` (m, 3) held at its last value."""
    cur = x - x[0]
    for n in taps:
        held = np.concatenate([cur, np.repeat(cur[-1:], n - 1, axis=0)])
        c = np.cumsum(held, axis=0)
        out = c.copy()
        out[n:] = c[n:] - c[:-n]
        cur = out / n
    return cur + x[0]


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    m=st.integers(2, 400),
    taps=st.lists(st.integers(2, 60), min_size=1, max_size=2),
)
def test_box_cascade_equals_numpy_running_sums(seed, m, taps):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(size=(m, 3)), axis=0) + rng.uniform(-500, 500, 3)
    out = np.empty((m + sum(taps) - len(taps), 3))
    _fir_loops.box_cascade(x, np.array(taps, dtype=np.int64), out)
    np.testing.assert_array_equal(out, _numpy_filter(x, taps))
    # an axis-major input seen through its transpose gives the same bits
    out_t = np.empty_like(out)
    _fir_loops.box_cascade(np.ascontiguousarray(x.T).T, np.array(taps, dtype=np.int64), out_t)
    np.testing.assert_array_equal(out_t, out)
    # and so does the input streamed in chunks, the tail flushed at the end
    t = np.array(taps, dtype=np.int64)
    total, ring = np.zeros((len(t), 3)), np.empty((len(t), t.max(), 3))
    count, last = np.zeros(len(t), dtype=np.int64), np.empty((len(t), 3))
    streamed = np.empty_like(out)
    cuts = np.unique(np.r_[0, np.sort(rng.integers(0, m, 3)), m])
    for lo, hi in itertools.pairwise(cuts):
        _fir_loops.box_stream(x[lo:hi], x[0], t, total, ring, count, last, streamed[lo:hi])
    _fir_loops.box_flush(x[-1], x[0], t, total, ring, count, last, streamed[m:])
    np.testing.assert_array_equal(streamed + x[0], out)
    # and so does the input in the first rows of the output, filtered in place
    out_in_place = np.empty_like(out)
    out_in_place[:m] = x
    _fir_loops.box_cascade(out_in_place[:m], np.array(taps, dtype=np.int64), out_in_place)
    np.testing.assert_array_equal(out_in_place, out)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    k=st.integers(2, 60),
    pauses=st.booleans(),
    infinite=st.booleans(),
)
def test_sample_command_equals_np_interp(seed, k, pauses, infinite):
    # knot times as the kernel makes them: arrival and departure, equal where no pause
    rng = np.random.default_rng(seed)
    dur = rng.exponential(0.01, k)
    hold = np.where(rng.random(k) < 0.3, rng.exponential(0.005, k), 0.0) if pauses else 0.0
    steps = np.column_stack([np.broadcast_to(hold, (k,)), dur]).ravel()[:-1]  # pause, move, ...
    t_knots = np.concatenate([[0.0], np.cumsum(steps)])
    x_knots = np.repeat(np.cumsum(rng.normal(size=(k, 3)), axis=0), 2, axis=0)
    x_knots[1::2] += rng.normal(0, 1e-3, (k, 3)) * (rng.random((k, 1)) < 0.5)
    if infinite:  # np.interp's fallbacks where the straight formula gives NaN
        odd = rng.random(x_knots.shape) < 0.1
        x_knots[odd] = rng.choice([np.inf, -np.inf, np.nan], int(odd.sum()))
    n_cmd = int(np.ceil(t_knots[-1] / PERIOD_S)) + 1
    out = np.empty((n_cmd, 3))
    t = np.arange(n_cmd) * PERIOD_S
    with np.errstate(invalid="ignore"):
        _fir_loops.sample_command(n_cmd, PERIOD_S, t_knots, x_knots, 0, out)
        expected = np.column_stack([np.interp(t, t_knots, x_knots[:, a]) for a in range(3)])
        # from any first sample on, the same bits
        i0 = int(rng.integers(0, n_cmd))
        part = np.empty((n_cmd - i0, 3))
        _fir_loops.sample_command(n_cmd - i0, PERIOD_S, t_knots, x_knots, i0, part)
    np.testing.assert_array_equal(out, expected)
    np.testing.assert_array_equal(part, expected[i0:])


def _numpy_derivatives(pos: np.ndarray) -> list[np.ndarray]:
    """Velocity from sample 1 on, acceleration from 2, jerk from 3: numpy's differences."""
    derivs = [(pos[1:] - pos[:-1]) / PERIOD_S]
    for _ in range(2):
        derivs.append(np.diff(derivs[-1], axis=0) / PERIOD_S)
    return derivs


#: Sample counts across several chunks of the derivative loops, and their edges.
SAMPLES = st.one_of(
    st.integers(1, 40), st.integers(1, 4 * _fir_loops.CHUNK + 5), st.sampled_from([513, 514, 515])
)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=SAMPLES)
def test_derivative_peaks_equal_numpy_differences(seed, n):
    rng = np.random.default_rng(seed)
    pos = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    peak = _fir_loops.derivative_peaks(pos, PERIOD_S)
    for order, d in enumerate(_numpy_derivatives(pos)):
        np.testing.assert_array_equal(peak[order], np.abs(d).max(axis=0, initial=0.0))


def _numpy_limit_ratios(pos, limits, over):
    """The ratios with numpy's differences, as the kernel computed them before the loop."""
    derivs = _numpy_derivatives(pos)
    ratio = np.zeros(len(pos))
    for order, a in np.argwhere(over):
        r = np.abs(derivs[order][:, a]) / limits[order, a]
        np.maximum(ratio[order + 1 :], r, out=ratio[order + 1 :])
    return ratio


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=SAMPLES, mask=st.integers(0, 511))
def test_limit_ratios_equal_numpy_differences(seed, n, mask):
    rng = np.random.default_rng(seed)
    pos = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    limits = rng.uniform(0.5, 2.0, (3, 3)) * np.array([[1e3], [1e6], [1e9]])
    over = (mask >> np.arange(9)).reshape(3, 3) % 2 == 1
    ratio = np.empty(n)
    _fir_loops.limit_ratios(pos, PERIOD_S, limits, over, ratio)
    np.testing.assert_array_equal(ratio, _numpy_limit_ratios(pos, limits, over))


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 80), ranges=st.integers(0, 30))
def test_range_min_equals_brute_force(seed, n, ranges):
    rng = np.random.default_rng(seed)
    lo = rng.integers(0, n, ranges)
    hi = np.clip(lo + rng.integers(-2, n + 1, ranges), 0, n)  # some empty, hi <= lo
    value = rng.choice(rng.uniform(0, 1, 5), ranges)  # ties among the values
    expected = np.full(n, np.inf)
    for a, b, v in zip(lo, hi, value, strict=True):
        expected[a:b] = np.minimum(expected[a:b], v)
    np.testing.assert_array_equal(_fir_loops.range_min(n, lo, hi, value), expected)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    k=st.integers(0, 3 * _fir_loops.BATCH),
    nodes=st.integers(1, 24),
)
def test_filtered_points_equal_einsum_of_points(seed, k, nodes):
    rng = np.random.default_rng(seed)
    geo = PathGeometry(parse("G1 X10 F600\nG3 X20 Y10 Z2 I0 J10\nG1 Y20\nG2 X30 Y30 I10\nG1 X0 Y0"))
    s = rng.uniform(-1, geo.total_mm + 1, k)
    speed = rng.uniform(0, 200, k)
    offsets = rng.normal(0, 0.05, nodes)
    weights = rng.random(nodes)
    out = np.empty((k, 3))
    _fir_loops.filtered_points(s, speed, offsets, weights, geo.loop_arrays, out)
    pts = geo.points((s[:, None] + speed[:, None] * offsets[None, :]).ravel())
    expected = np.einsum("l,klc->kc", weights, pts.reshape(k, nodes, 3))
    np.testing.assert_array_equal(out, expected)
