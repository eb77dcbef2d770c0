"""Orientation math (core/world/frames.py) and the TF frame names (interface.py)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rosmc_server import interface
from rosmc_server.core import InvalidRequest
from rosmc_server.core.world.frames import (
    IDENTITY,
    quaternion_from_rpy,
    rpy_from_quaternion,
    yaw_of,
)

ANGLE = st.floats(-math.pi + 1e-6, math.pi - 1e-6)
PITCH = st.floats(-math.pi / 2 + 1e-3, math.pi / 2 - 1e-3)  # away from gimbal lock


def test_frame_names() -> None:
    assert interface.MAP_FRAME == "map"
    assert interface.base_link("drone") == "drone/base_link"


def test_known_rotations() -> None:
    assert quaternion_from_rpy() == IDENTITY
    x, y, z, w = quaternion_from_rpy(yaw=math.pi / 2)
    assert (x, y) == (0.0, 0.0)
    assert z == pytest.approx(math.sqrt(0.5)) and w == pytest.approx(math.sqrt(0.5))
    x, y, z, w = quaternion_from_rpy(roll=math.pi)
    assert (x, y, z, w) == pytest.approx((1.0, 0.0, 0.0, 0.0), abs=1e-12)


@given(ANGLE, PITCH, ANGLE)
def test_rpy_round_trips(roll: float, pitch: float, yaw: float) -> None:
    q = quaternion_from_rpy(roll, pitch, yaw)
    assert math.fsum(c * c for c in q) == pytest.approx(1.0)
    assert rpy_from_quaternion(q) == pytest.approx((roll, pitch, yaw), abs=1e-9)
    assert yaw_of(q) == pytest.approx(yaw, abs=1e-9)


@given(ANGLE, st.floats(0.1, 10.0))
def test_yaw_of_an_unnormalised_quaternion(yaw: float, scale: float) -> None:
    q = tuple(c * scale for c in quaternion_from_rpy(yaw=yaw))
    assert yaw_of(q) == pytest.approx(yaw, abs=1e-9)  # type: ignore[arg-type]


def test_gimbal_lock_keeps_pitch_in_range() -> None:
    q = quaternion_from_rpy(pitch=math.pi / 2)
    assert rpy_from_quaternion(q)[1] == pytest.approx(math.pi / 2)


@pytest.mark.parametrize("q", [(0.0, 0.0, 0.0, 0.0), (math.nan, 0.0, 0.0, 1.0)])
def test_a_quaternion_that_is_no_rotation_is_refused(q: tuple[float, ...]) -> None:
    with pytest.raises(InvalidRequest, match="not a rotation"):
        yaw_of(q)  # type: ignore[arg-type]
