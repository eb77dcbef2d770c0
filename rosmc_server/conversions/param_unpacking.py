"""The parameters of a skill record read from ROS 1 wire bytes into core values.

Part of :mod:`rosmc_server.conversions`, the hot inner loop of :mod:`.unpacking` (a
snapshot's skills carry one or a few parameters each). Tests check it with the rest of
the reader against genpy and ``mission_from_msg``.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from typing import Any

import genpy

from ..core import ParamType, Pose
from .values import json_param, param_type

_COUNT = struct.Struct("<I").unpack_from
_PARAM_NUMBERS = struct.Struct("<2Bqd").unpack_from  # type, bool_value, int_value, float_value
_POSE = struct.Struct("<6d").unpack_from
# The usual form in one read: a parameter with empty string_value and json_value (type
# ... float_value, both lengths, pose, marker's length). It is at most as long as the
# field run it starts, so valid bytes never end inside it.
_PARAM_FIXED = struct.Struct("<2BqdII6dI").unpack_from


def read_params(data: bytes, pos: int) -> tuple[dict[str, Any], dict[str, str], int]:
    """The ``rosmc/ParameterValue[]`` at ``pos``: values, marker bindings, where it ends."""
    count = _COUNT(data, pos)[0]
    pos += 4
    params: dict[str, Any] = {}
    bindings: dict[str, str] = {}
    for _ in range(count):
        size = _COUNT(data, pos)[0]
        pos += 4
        name = data[pos : pos + size].decode("utf-8", "rosmsg")
        pos += size
        # type, bool, int, float, len(string_value), len(json_value), pose, len(marker)
        fixed = _PARAM_FIXED(data, pos)
        type_number = fixed[0]
        if type_number in _FIXED_TYPES and not (fixed[4] or fixed[5]) and name:
            if type_number == _FLOAT:  # the usual forms, read at once
                params[name] = fixed[3]
            elif type_number == _POSE_TYPE:
                params[name] = _assemble_pose(*fixed[6:12])
            elif type_number == _INT:
                params[name] = fixed[2]
            else:
                params[name] = bool(fixed[1])
            pos += 78
            size = fixed[12]
        elif type_number == _STRING and name and not _COUNT(data, pos + 22 + fixed[4])[0]:
            # Text (its length where the fixed form has string_value's) and no JSON: the
            # text, then the unused JSON, pose and the marker's length.
            end = pos + 22 + fixed[4]
            params[name] = data[pos + 22 : end].decode("utf-8", "rosmsg")
            pos = end + 56
            size = _COUNT(data, pos - 4)[0]
        else:
            params[name], pos = _read_param_value(data, pos, name)
            size = _COUNT(data, pos)[0]
            pos += 4
        if size:  # a bound marker
            bindings[name] = data[pos : pos + size].decode("utf-8", "rosmsg")
            pos += size
    return params, bindings, pos


def _read_param_value(data: bytes, pos: int, name: str) -> tuple[Any, int]:
    """The value of the parameter whose fields start at ``pos``, and where its marker starts.

    Any form: text, JSON, or numbers beside non-empty text fields (which are ignored).
    """
    type_number, bool_value, int_value, float_value = _PARAM_NUMBERS(data, pos)
    pos += 18
    size = _COUNT(data, pos)[0]  # string_value
    text = data[pos + 4 : pos + 4 + size].decode("utf-8", "rosmsg") if size else ""
    pos += 4 + size
    size = _COUNT(data, pos)[0]  # json_value
    json_text = data[pos + 4 : pos + 4 + size].decode("utf-8", "rosmsg") if size else ""
    pos += 4 + size
    ptype = _PARAM_TYPES.get(type_number) if name else None
    value: Any
    if ptype is ParamType.FLOAT:
        value = float_value
    elif ptype is ParamType.POSE:
        value = _assemble_pose(*_POSE(data, pos))
    elif ptype is ParamType.INT:
        value = int_value
    elif ptype is ParamType.STRING:
        value = text
    elif ptype is ParamType.BOOL:
        value = bool(bool_value)
    else:  # LIST, DICT, or InvalidRequest for a nameless or unknown parameter
        if pos > len(data):  # the JSON text was cut short: malformed, not invalid
            raise genpy.DeserializationError("the bytes end inside a parameter")
        value = json_param(name, param_type(name, type_number), json_text)
    return value, pos + 48


_PARAM_TYPES: Mapping[int, ParamType] = {int(t): t for t in ParamType}
_FLOAT, _POSE_TYPE, _INT = int(ParamType.FLOAT), int(ParamType.POSE), int(ParamType.INT)
_STRING = int(ParamType.STRING)
_FIXED_TYPES = frozenset({_FLOAT, _POSE_TYPE, _INT, int(ParamType.BOOL)})  # no text, no JSON
_assemble_pose = Pose.assemble
