"""Plain values <-> messages: times, poses and named parameter values.

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from typing import Any

import genpy
import rosmc.msg as wire

from ..core import InvalidRequest, ParamType, Pose, Value

# Deeper LIST/DICT values are refused: the core checks them and the YAML mission files
# write them recursively, which fails a few hundred levels down.
MAX_JSON_NESTING = 32


def time_to_msg(seconds: float) -> genpy.Time:
    """Seconds since the epoch as a ROS time (0 stays 0)."""
    return genpy.Time.from_sec(max(0.0, seconds))


def pose_to_msg(pose: Pose) -> wire.Pose6D:
    """A core pose as ``rosmc/Pose6D``."""
    return wire.Pose6D(pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw)


def pose_from_msg(msg: wire.Pose6D) -> Pose:
    """``rosmc/Pose6D`` as a core pose."""
    return Pose(msg.x, msg.y, msg.z, msg.roll, msg.pitch, msg.yaw)


def value_type(value: Value) -> ParamType:
    """The wire type of a core value (core values are normalized, so this is exact)."""
    if isinstance(value, bool):
        return ParamType.BOOL
    if isinstance(value, int):
        return ParamType.INT
    if isinstance(value, float):
        return ParamType.FLOAT
    if isinstance(value, str):
        return ParamType.STRING
    if isinstance(value, list):
        return ParamType.LIST
    if isinstance(value, dict):
        return ParamType.DICT
    return ParamType.POSE


def param_to_msg(name: str, value: Value, marker: str = "") -> wire.ParameterValue:
    """One named value as ``rosmc/ParameterValue``."""
    msg = wire.ParameterValue(name=name, marker=marker)
    ptype = value_type(value)
    msg.type = int(ptype)
    if ptype is ParamType.BOOL:
        msg.bool_value = value
    elif ptype is ParamType.INT:
        msg.int_value = value
    elif ptype is ParamType.FLOAT:
        msg.float_value = value
    elif ptype is ParamType.STRING:
        msg.string_value = value
    elif ptype in (ParamType.LIST, ParamType.DICT):
        msg.json_value = json.dumps(value, separators=(",", ":"))
    else:
        assert isinstance(value, Pose)
        msg.pose_value = pose_to_msg(value)
    return msg


def param_from_msg(msg: wire.ParameterValue) -> tuple[str, object]:
    """The name and raw value of a ``rosmc/ParameterValue`` (checked later by the core)."""
    name = msg.name
    ptype = param_type(name, msg.type)
    if ptype is ParamType.BOOL:
        return name, bool(msg.bool_value)
    if ptype is ParamType.INT:
        return name, int(msg.int_value)
    if ptype is ParamType.FLOAT:
        return name, float(msg.float_value)
    if ptype is ParamType.STRING:
        return name, msg.string_value
    if ptype is ParamType.POSE:
        return name, pose_from_msg(msg.pose_value)
    return name, json_param(name, ptype, msg.json_value)


def param_type(name: str, number: int) -> ParamType:
    """The type of parameter ``name`` from its wire number; InvalidRequest for a bad
    name or number."""
    if not name:
        raise InvalidRequest("a parameter has an empty name")
    try:
        return ParamType(number)
    except ValueError:
        raise InvalidRequest(f"parameter '{name}' has unknown type number {number}") from None


def json_param(name: str, ptype: ParamType, text: str) -> object:
    """The list or dict a LIST or DICT parameter's ``json_value`` holds (InvalidRequest if
    it holds anything else, or nests too deeply)."""
    try:
        data = json.loads(text)
    except (ValueError, RecursionError):
        raise InvalidRequest(f"parameter '{name}' does not hold valid JSON") from None
    expected = list if ptype is ParamType.LIST else dict
    if not isinstance(data, expected):
        raise InvalidRequest(f"parameter '{name}' must hold a JSON {expected.__name__}")
    if _nesting(data) > MAX_JSON_NESTING:
        raise InvalidRequest(
            f"parameter '{name}' nests its JSON deeper than {MAX_JSON_NESTING} levels"
        )
    return data


def _nesting(data: object) -> int:
    """How deep lists and dicts nest in ``data`` (without recursion: the data may be deep)."""
    deepest = 0
    stack = [(data, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            item = list(item.values())
        if isinstance(item, list):
            deepest = max(deepest, depth)
            stack.extend((child, depth + 1) for child in item)
    return deepest


def params_from_msgs(
    msgs: Iterable[wire.ParameterValue],
) -> tuple[dict[str, object], dict[str, str]]:
    """Split parameter messages into values and marker bindings; names must be unique.

    A bound parameter takes its value from its marker, so only its name and marker
    are read: the value fields of a binding may be left empty.
    """
    values: dict[str, object] = {}
    bindings: dict[str, str] = {}
    for msg in msgs:
        if msg.marker:
            name = msg.name
            if not name:
                raise InvalidRequest("a parameter has an empty name")
        else:
            name, value = param_from_msg(msg)
        if name in values or name in bindings:
            raise InvalidRequest(f"parameter '{name}' is given twice")
        if msg.marker:
            bindings[name] = msg.marker
        else:
            values[name] = value
    return values, bindings


def enum_from_number(kind: Any, number: int, what: str) -> Any:
    """``kind(number)``, or InvalidRequest naming ``what`` for a number it does not know."""
    try:
        return kind(number)
    except ValueError:
        raise InvalidRequest(f"unknown {what} number {number}") from None
