"""Typed values from users: text and parsed-file values coerced and range-checked in one place."""

from __future__ import annotations

import enum

import pytest
from hypothesis import given
from hypothesis import strategies as st

from uavtool.checks import DN, NON_NEGATIVE, POSITIVE, Range, coerce
from uavtool.errors import InputError, ParamError


class Mode(enum.Enum):
    FAST = "fast"
    SLOW = "slow"


@pytest.mark.parametrize(
    ("value", "hint", "bounds", "expected"),
    [
        ("2.5", float, POSITIVE, 2.5),
        (3, float, POSITIVE, 3.0),
        ("7", int, Range(1, 10), 7),
        ("yes", bool, Range(), True),
        (False, bool, Range(), False),
        ("[[1, 2, 3]]", tuple[tuple[int, int, int], ...], DN, ((1, 2, 3),)),
        ([[1, 2, 3]], tuple[tuple[int, int, int], ...], DN, ((1, 2, 3),)),
        ("[]", tuple[float, ...], Range(), ()),
        ("slow", Mode, Range(), Mode.SLOW),
        ("FAST", Mode, Range(), Mode.FAST),
    ],
)
def test_good_values_are_converted(
    value: object, hint: object, bounds: Range, expected: object
) -> None:
    assert coerce(value, hint, name="k", bounds=bounds) == expected


@pytest.mark.parametrize(
    ("value", "hint", "bounds", "expected"),
    [
        ("nan", float, Range(), "k=nan: expected a finite number"),
        ("inf", float, Range(), "k=inf: expected a finite number"),
        (10**400, float, Range(), "expected a finite number"),
        ("-1", float, NON_NEGATIVE, "k=-1: expected a finite number ≥ 0"),
        ("0", float, POSITIVE, "k=0: expected a finite number > 0"),
        ("2.5", int, Range(1, 10), "k=2.5: expected an integer in [1, 10]"),
        (True, int, Range(), "k=True: expected an integer"),
        ("9" * 5000, int, Range(), "expected an integer"),
        ("maybe", bool, Range(), "k=maybe: expected true or false"),
        (
            "5",
            tuple[tuple[int, int, int], ...],
            DN,
            "k=5: expected a list of lists of 3 integers in [0, 255]",
        ),
        ("null", tuple[tuple[int, int, int], ...], DN, "k=null: expected a list of lists"),
        (
            "[[1, 2]]",
            tuple[tuple[int, int, int], ...],
            DN,
            "expected a list of lists of 3 integers",
        ),
        (
            "[[1, 2, 256]]",
            tuple[tuple[int, int, int], ...],
            DN,
            "expected a list of lists of 3 integers",
        ),
        (
            "[[true, 2, 3]]",
            tuple[tuple[int, int, int], ...],
            DN,
            "expected a list of lists of 3 integers",
        ),
        ("[1, NaN]", tuple[float, ...], Range(), "expected a list of finite numbers"),
        ("[" * 100_000, tuple[float, ...], Range(), "expected a list of finite numbers"),
        ("medium", Mode, Range(), "k=medium: expected one of fast, slow"),
    ],
)
def test_bad_values_say_what_was_expected(
    value: object, hint: object, bounds: Range, expected: str
) -> None:
    with pytest.raises(InputError) as info:
        coerce(value, hint, name="k", bounds=bounds)
    assert expected in str(info.value)
    assert "\n" not in str(info.value)


def test_the_caller_picks_the_error_type() -> None:
    with pytest.raises(ParamError):
        coerce("x", float, name="k", error=ParamError)


@given(st.floats(allow_nan=True, allow_infinity=True) | st.integers() | st.text() | st.none())
def test_a_float_is_finite_and_in_range_or_refused(value: object) -> None:
    bounds = Range(-1.0, 1.0, lo_open=True)
    try:
        out = coerce(value, float, name="k", bounds=bounds)
    except InputError:
        return
    assert isinstance(out, float) and -1.0 < out <= 1.0
