"""The shared range checks: one line naming the parameter, its value and what is allowed."""

import math

import numpy as np
import pytest

from nctwin.checks import check_int, check_range


@pytest.mark.parametrize("value", [1, 7, np.int64(3), np.uint8(100)])
def test_check_int_accepts_integers_in_range(value):
    assert check_int("n", value, 1, 100) == int(value)
    assert type(check_int("n", value, 1, 100)) is int


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (0, "n = 0 is out of range: allowed integers in [1, 100]"),
        (101, "n = 101 is out of range: allowed integers in [1, 100]"),
        (2.0, "n = 2.0 is out of range: allowed integers in [1, 100]"),
        (True, "n = True is out of range: allowed integers in [1, 100]"),
        ("3", "n = '3' is out of range: allowed integers in [1, 100]"),
    ],
)
def test_check_int_refuses_in_one_line(value, message):
    with pytest.raises(ValueError) as err:
        check_int("n", value, 1, 100)
    assert str(err.value) == message


def test_check_int_without_upper_bound_says_so():
    with pytest.raises(ValueError, match=r"^k = -1 is out of range: allowed integers >= 0$"):
        check_int("k", -1, 0)
    assert check_int("k", 10**12, 0) == 10**12


@pytest.mark.parametrize("value", [math.nan, math.inf, np.bool_(True), None])
def test_check_range_refuses_nan_inf_bool_none(value):
    with pytest.raises(ValueError, match=r"^x = .* is out of range: allowed \(0, inf\)$"):
        check_range("x", value, 0.0, math.inf, low_open=True, high_open=True)
