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
    "check_int",
    "check_range",
    "whole_periods",
]


def check_range(
    name: str,
    value,
    low: float,
    high: float = math.inf,
    *,
    low_open: bool = False,
    high_open: bool = False,
    allow_inf: bool = False,
    xyz: bool = False,
):
    """Raise ValueError naming ``name``, its value and the allowed interval, in one line, unless
    ``value`` is a real number (numpy's too; not a bool, not NaN) with ``low <= value <= high``
    (``low < value`` with ``low_open``, ``value < high`` with ``high_open``); ``allow_inf`` also
    admits ``inf``.

    With ``xyz``, ``value`` is three numbers (X, Y, Z), each checked (named ``name[X]`` ...).

    Returns
    -------
    float or tuple of float
        The value as a float; with ``xyz`` the three values as a tuple of floats.

    >>> check_range("feed_mm_s", 0.0, 0.0, 1000.0, low_open=True)
    Traceback (most recent call last):
    ...
    ValueError: feed_mm_s = 0.0 is out of range: allowed (0, 1000]
    """
    if xyz:
        try:
            v = tuple(value)
        except TypeError:
            v = ()
        if len(v) != 3:
            raise ValueError(f"{name} = {value!r} is out of range: allowed three numbers")
        return tuple(
            check_range(f"{name}[{axis}]", x, low, high, low_open=low_open, high_open=high_open,
                        allow_inf=allow_inf)
            for axis, x in zip("XYZ", v, strict=True)
        )  # fmt: skip
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)
    ok = ok and not math.isnan(value)
    if ok and not (allow_inf and value == math.inf):
        ok = (low < value if low_open else low <= value) and (
            value < high if high_open else value <= high
        )
    if not ok:
        interval = f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
        extra = " or inf" if allow_inf else ""
        raise ValueError(f"{name} = {value!r} is out of range: allowed {interval}{extra}")
    return float(value)


def check_int(name: str, value, low: int, high: float = math.inf) -> int:
    """Raise ValueError naming ``name``, its value and the allowed integers, in one line, unless
    ``value`` is an integer (numpy's too; not a bool) with ``low <= value <= high``.

    Returns
    -------
    int
        The value as a Python int.

    >>> check_int("n_jobs", 2.0, 1)
    Traceback (most recent call last):
    ...
    ValueError: n_jobs = 2.0 is out of range: allowed integers >= 1
    """
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)
    if not (ok and low <= value <= high):
        allowed = f">= {low}" if high == math.inf else f"in [{low}, {high:g}]"
        raise ValueError(f"{name} = {value!r} is out of range: allowed integers {allowed}")
    return int(value)


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
