"""Small shared helpers: parameter range checks and wall-clock timing."""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Callable

import numpy as np

__all__ = [
    "best_time_s",
    "check_choice",
    "check_number",
    "check_range",
    "check_xyz",
    "whole_periods",
]


def check_range(
    name: str, value: float, low: float, high: float = np.inf, *, low_open: bool = False
) -> None:
    """Raise ValueError naming ``name``, its value and the allowed interval unless
    ``low <= value <= high`` (``low < value`` with ``low_open``): :func:`check_number` with a
    closed upper end."""
    check_number(name, value, low, high, lo_closed=not low_open, hi_closed=True)


def check_number(
    name: str,
    value,
    lo: float,
    hi: float,
    *,
    lo_closed: bool = False,
    hi_closed: bool = False,
    allow_inf: bool = False,
) -> None:
    """Raise ValueError naming ``name``, its value and the allowed interval unless ``value`` is
    a real number (numpy's too; not a bool, not NaN) in it; ``allow_inf`` also admits ``inf``.

    >>> check_number("feed_mm_s", 0.0, 0.0, 1000.0)
    Traceback (most recent call last):
    ...
    ValueError: feed_mm_s = 0.0 is out of range: allowed (0, 1000)
    """
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)
    ok = ok and not math.isnan(value)
    if ok and not (allow_inf and value == math.inf):
        ok = (lo <= value if lo_closed else lo < value) and (
            value <= hi if hi_closed else value < hi
        )
    if not ok:
        interval = f"{'[' if lo_closed else '('}{lo:g}, {hi:g}{']' if hi_closed else ')'}"
        extra = " or inf" if allow_inf else ""
        raise ValueError(f"{name} = {value!r} is out of range: allowed {interval}{extra}")


def check_xyz(
    name: str,
    value,
    lo: float,
    hi: float,
    *,
    lo_closed: bool = False,
    hi_closed: bool = False,
    allow_inf: bool = False,
) -> tuple[float, float, float]:
    """Three numbers (X, Y, Z), each checked by :func:`check_number` (named ``name[X]`` ...),
    as a tuple of floats."""
    try:
        v = tuple(value)
    except TypeError:
        raise ValueError(f"{name} = {value!r} is out of range: allowed three numbers") from None
    if len(v) != 3:
        raise ValueError(f"{name} = {value!r} is out of range: allowed three numbers")
    for axis, x in zip("XYZ", v, strict=True):
        check_number(f"{name}[{axis}]", x, lo, hi, lo_closed=lo_closed, hi_closed=hi_closed,
                     allow_inf=allow_inf)  # fmt: skip
    return tuple(float(x) for x in v)


def check_choice(name: str, value, allowed: tuple) -> None:
    """Raise ValueError naming ``name``, its value and the allowed values unless it is one."""
    if value not in allowed:
        raise ValueError(
            f"{name} = {value!r} is out of range: allowed {', '.join(map(repr, allowed))}"
        )


def whole_periods(name: str, value_s: float, period_s: float) -> int:
    """A time setting as a whole number of periods.

    Raises
    ------
    ValueError
        Naming the setting, its value and the allowed values, if it is not a whole multiple.
    """
    k = round(value_s / period_s)
    if not math.isclose(k * period_s, value_s, rel_tol=1e-9, abs_tol=1e-12):
        raise ValueError(
            f"{name} = {value_s!r} is out of range: allowed whole multiples of "
            f"period_s = {period_s!r}"
        )
    return k


def best_time_s(fn: Callable[[], object], *, repeat: int = 5, warmup: int = 1) -> float:
    """Shortest wall time of ``fn()`` over ``repeat`` runs, after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)
