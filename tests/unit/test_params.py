"""Parameter values: the quick path agrees with the full check; numbers too large are refused.

:func:`~rosmc_server.core.skills.params.quick_value` accepts a value in its usual form without
building an error sentence (a mission of 10,000 skills is read through it). Wherever it
answers, :func:`~rosmc_server.core.skills.params.check_value` must give the same value of the
same type; where it does not, the full check decides. Integers YAML reads from a long
string of digits are too large for a float or an int64: every check says so in a
sentence instead of raising OverflowError.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rosmc_server.core import InvalidRequest, ParamType, Pose
from rosmc_server.core.rules.editing import check_timeout
from rosmc_server.core.skills.params import (
    INT_MAX,
    INT_MIN,
    check_value,
    quick_checker,
    quick_value,
)
from rosmc_server.core.skills.policy import LostLinkKind, LostLinkPolicy
from rosmc_server.core.validation import check_time, finite_float

HUGE = 10**400  # what YAML reads from "1" and 400 zeros

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([HUGE, -HUGE, INT_MAX, INT_MIN, INT_MAX + 1, INT_MIN - 1, 0, -0.0]),
)
pose_keys = st.sampled_from([*Pose.FIELDS, "w", "X"])
raw_values = st.one_of(
    numbers,
    st.booleans(),
    st.text(max_size=5),
    st.none(),
    st.lists(numbers, max_size=3),
    st.dictionaries(pose_keys, st.one_of(numbers, st.booleans(), st.text(max_size=2)), max_size=7),
    st.builds(Pose, st.floats(), st.floats()),
)
bounds = st.one_of(st.none(), st.floats(-100, 100), st.integers(-100, 100))


@st.composite
def choices_for(draw: Any, ptype: ParamType) -> tuple[Any, ...]:
    pool = {
        ParamType.BOOL: st.booleans(),
        ParamType.INT: st.integers(-5, 5),
        ParamType.FLOAT: st.floats(-5, 5),
        ParamType.STRING: st.text(max_size=2),
    }.get(ptype)
    if pool is None or not draw(st.booleans()):
        return ()
    return tuple(draw(st.lists(pool, min_size=1, max_size=3)))


@given(st.sampled_from(list(ParamType)), raw_values, bounds, bounds, st.data())
def test_the_quick_path_answers_as_the_full_check(
    ptype: ParamType, raw: Any, minimum: Any, maximum: Any, data: Any
) -> None:
    if ptype not in (ParamType.INT, ParamType.FLOAT):
        minimum = maximum = None  # the library allows bounds on numbers only
    choices = data.draw(choices_for(ptype))
    quick = quick_value(ptype, raw, minimum, maximum, choices)
    if quick is None:
        return  # the full check decides, as it always did
    full = check_value(ptype, raw, "p", minimum, maximum, choices)
    assert quick == full
    assert type(quick) is type(full)


@given(st.sampled_from(list(ParamType)), raw_values, bounds, bounds, st.data())
def test_a_specialized_quick_check_answers_as_the_quick_path(
    ptype: ParamType, raw: Any, minimum: Any, maximum: Any, data: Any
) -> None:
    if ptype not in (ParamType.INT, ParamType.FLOAT):
        minimum = maximum = None
    choices = data.draw(choices_for(ptype))
    specialized = quick_checker(ptype, minimum, maximum, choices)(raw)
    general = quick_value(ptype, raw, minimum, maximum, choices)
    assert specialized == general
    assert type(specialized) is type(general)


def test_the_quick_path_takes_the_usual_forms() -> None:
    assert quick_value(ParamType.FLOAT, 0.5, 0.0, 1.0) == 0.5
    assert quick_value(ParamType.INT, 3, 1, 5) == 3
    assert quick_value(ParamType.STRING, "quick", choices=("quick", "slow")) == "quick"
    assert quick_value(ParamType.BOOL, False) is False
    assert quick_value(ParamType.POSE, {"x": 1.0, "y": 2.0}) == Pose(1.0, 2.0)
    # ... and leaves the rest to the full check
    assert quick_value(ParamType.FLOAT, 1) is None  # converted there
    assert quick_value(ParamType.INT, True) is None  # refused there
    assert quick_value(ParamType.FLOAT, math.inf) is None
    assert quick_value(ParamType.POSE, {"x": 1}) is None
    assert quick_value(ParamType.LIST, [1]) is None


@pytest.mark.parametrize("raw", [HUGE, -HUGE], ids=["huge", "-huge"])
def test_a_float_parameter_refuses_a_number_too_large_in_a_sentence(raw: int) -> None:
    with pytest.raises(InvalidRequest, match=r"must be a finite number, got -?1000+…$"):
        check_value(ParamType.FLOAT, raw, "parameter 'speed'")
    with pytest.raises(InvalidRequest, match="x of a pose must be a finite number"):
        check_value(ParamType.POSE, {"x": raw}, "a pose")


@pytest.mark.parametrize("raw", [INT_MAX + 1, INT_MIN - 1, HUGE], ids=["max+1", "min-1", "huge"])
def test_an_int_parameter_must_fit_in_64_bits(raw: int) -> None:
    assert check_value(ParamType.INT, INT_MAX, "p") == INT_MAX
    with pytest.raises(InvalidRequest, match="parameter 'n' must fit in 64 bits, got"):
        check_value(ParamType.INT, raw, "parameter 'n'", 0)


def test_times_timeouts_and_policies_refuse_numbers_too_large_in_a_sentence() -> None:
    assert finite_float(HUGE) is None and finite_float(True) is None
    assert finite_float(2**64) == 2.0**64
    with pytest.raises(InvalidRequest, match="a start time must be a finite number"):
        check_time(HUGE, "a start time")
    with pytest.raises(InvalidRequest, match="a timeout must be a finite, non-negative"):
        check_timeout(HUGE)
    with pytest.raises(InvalidRequest, match="'after' must be a positive number"):
        LostLinkPolicy(LostLinkKind.HOLD, after=HUGE)
