"""Typed parameter values: the types a skill parameter can have and their checks.

Values are plain Python data so they serialize to YAML and JSON unchanged:
``bool``, ``int``, ``float``, ``str``, JSON-compatible ``list`` and ``dict``,
and :class:`Pose` for 6D poses.
"""

from __future__ import annotations

import enum
import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from ..errors import InvalidRequest
from ..validation import MAX_TEXT, check_text, excerpt, finite_float

_new_object = object.__new__  # an instance without running its constructor


class ParamType(enum.IntEnum):
    """The type of a skill parameter (numbers match ``rosmc/ParameterValue``)."""

    BOOL = 0
    INT = 1
    FLOAT = 2
    STRING = 3
    LIST = 4
    DICT = 5
    POSE = 6


class MarkerType(enum.IntEnum):
    """The kind of a task marker (numbers match ``rosmc/TaskMarker``)."""

    POSITION = 0
    POSE = 1
    AREA = 2


@dataclass(frozen=True)
class Pose:
    """A pose as operators edit it: metres and roll/pitch/yaw in radians."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0

    FIELDS = ("x", "y", "z", "roll", "pitch", "yaw")

    @classmethod
    def assemble(cls, x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> Pose:
        """The pose of these six already checked floats, built without the constructor.

        A frozen dataclass's constructor sets each field through ``object.__setattr__``;
        filling the instance's dict directly is about twice as fast, which counts where
        thousands of poses are read at once (mission files, snapshots), for about 64 bytes
        more per pose (the dict becomes an object of its own). A test checks that both
        build equal poses with every field.
        """
        made = _new_object(cls)
        fields = made.__dict__
        fields["x"] = x
        fields["y"] = y
        fields["z"] = z
        fields["roll"] = roll
        fields["pitch"] = pitch
        fields["yaw"] = yaw
        return made

    def to_dict(self) -> dict[str, float]:
        """The pose as a mapping of its six fields."""
        return {name: getattr(self, name) for name in self.FIELDS}

    @classmethod
    def from_any(cls, raw: object, what: str) -> Pose:
        """Build a pose from a Pose or a mapping with a subset of the six fields."""
        if isinstance(raw, Pose):
            values = raw.to_dict()
        elif isinstance(raw, Mapping):
            unknown = [str(key) for key in raw if key not in cls.FIELDS]
            if unknown:
                raise InvalidRequest(f"{what} has unknown pose fields {', '.join(sorted(unknown))}")
            values = {name: raw.get(name, 0.0) for name in cls.FIELDS}
        else:
            raise InvalidRequest(f"{what} must be a pose (x, y, z, roll, pitch, yaw)")
        return cls(**{name: _finite(value, f"{name} of {what}") for name, value in values.items()})


Value = bool | int | float | str | list[Any] | dict[str, Any] | Pose
QuickCheck = Callable[[object], Value | None]  # see quick_checker

# Which marker types may fill a parameter that declares a given marker type:
# a point and a pose are interchangeable (a point has heading 0).
COMPATIBLE_MARKERS: Mapping[MarkerType, frozenset[MarkerType]] = {
    MarkerType.POSITION: frozenset({MarkerType.POSITION, MarkerType.POSE}),
    MarkerType.POSE: frozenset({MarkerType.POSITION, MarkerType.POSE}),
    MarkerType.AREA: frozenset({MarkerType.AREA}),
}

# The parameter type a marker of each kind fills.
MARKER_PARAM_TYPE: Mapping[MarkerType, ParamType] = {
    MarkerType.POSITION: ParamType.POSE,
    MarkerType.POSE: ParamType.POSE,
    MarkerType.AREA: ParamType.LIST,
}


def _finite(raw: object, what: str) -> float:
    if isinstance(raw, bool) or not isinstance(raw, (int, float)):
        raise InvalidRequest(f"{what} must be a number, got {excerpt(raw)}")
    number = finite_float(raw)
    if number is None:
        raise InvalidRequest(f"{what} must be a finite number, got {excerpt(raw)}")
    return number


INT_MIN, INT_MAX = -(2**63), 2**63 - 1  # an int parameter travels as int64
MAX_DEPTH = 32  # nesting of list/dict parameter values; deeper data is refused


def check_json_data(raw: object, what: str, depth: int = 0) -> Any:
    """Return a deep copy of JSON-compatible data, or raise InvalidRequest.

    Allowed: None, bool, int, finite float, str, lists and string-keyed dicts of these,
    nested at most MAX_DEPTH levels.
    """
    if raw is None or isinstance(raw, (bool, int, str)):
        return raw
    if isinstance(raw, float):
        return _finite(raw, what)
    if depth >= MAX_DEPTH and isinstance(raw, (list, tuple, Mapping)):
        raise InvalidRequest(f"{what} is nested more than {MAX_DEPTH} levels deep")
    if isinstance(raw, (list, tuple)):
        return [check_json_data(item, f"{what}[{i}]", depth + 1) for i, item in enumerate(raw)]
    if isinstance(raw, Mapping):
        out: dict[str, Any] = {}
        for key, item in raw.items():
            if not isinstance(key, str):
                raise InvalidRequest(f"{what} has a non-text key {key!r}")
            out[key] = check_json_data(item, f"{what}.{key}", depth + 1)
        return out
    raise InvalidRequest(f"{what} holds a {type(raw).__name__}, which is not list/dict data")


def check_value(
    ptype: ParamType,
    raw: object,
    what: str,
    minimum: float | None = None,
    maximum: float | None = None,
    choices: tuple[Value, ...] = (),
) -> Value:
    """Check ``raw`` against a parameter's type, bounds and choices; return it normalized."""
    value: Value
    if ptype is ParamType.BOOL:
        if not isinstance(raw, bool):
            raise InvalidRequest(f"{what} must be true or false, got {excerpt(raw)}")
        value = raw
    elif ptype is ParamType.INT:
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise InvalidRequest(f"{what} must be a whole number, got {excerpt(raw)}")
        if not INT_MIN <= raw <= INT_MAX:  # robots receive an int64
            raise InvalidRequest(f"{what} must fit in 64 bits, got {excerpt(raw)}")
        value = raw
    elif ptype is ParamType.FLOAT:
        value = _finite(raw, what)
    elif ptype is ParamType.STRING:
        if not isinstance(raw, str):
            raise InvalidRequest(f"{what} must be text, got {excerpt(raw)}")
        value = check_text(raw, what)
    elif ptype is ParamType.LIST:
        if not isinstance(raw, (list, tuple)):
            raise InvalidRequest(f"{what} must be a list, got {excerpt(raw)}")
        value = check_json_data(raw, what)
    elif ptype is ParamType.DICT:
        if not isinstance(raw, Mapping):
            raise InvalidRequest(f"{what} must be a mapping, got {excerpt(raw)}")
        value = check_json_data(raw, what)
    else:
        value = Pose.from_any(raw, what)
    _check_range(value, what, minimum, maximum)
    if choices and value not in choices:
        allowed = ", ".join(repr(choice) for choice in choices)
        raise InvalidRequest(f"{what} must be one of {allowed}, got {value!r}")
    return value


def quick_value(
    ptype: ParamType,
    raw: object,
    minimum: float | None = None,
    maximum: float | None = None,
    choices: tuple[Value, ...] = (),
) -> Value | None:
    """What :func:`check_value` returns for a value in its usual form, or None if unsure.

    A mission of thousands of skills is mostly floats, ints, text and poses of six floats
    that pass every check; this accepts exactly those, without building the sentence a
    failed check would need. Anything else (an int for a float, a missing pose field, a
    value out of bounds) is None: :func:`check_value` then converts it or says what is
    wrong. A test checks that both agree wherever this answers.
    """
    if type(raw) is dict:
        return _quick_pose(raw) if ptype is ParamType.POSE and not choices else None
    if not isinstance(raw, (bool, int, float, str)) or _QUICK_TYPES.get(type(raw)) is not ptype:
        return None
    if isinstance(raw, float) and not _isfinite(raw):
        return None
    if type(raw) is int and not INT_MIN <= raw <= INT_MAX:
        return None
    if type(raw) is str and len(raw) > MAX_TEXT:  # (a surrogate is found in the document)
        return None
    if not isinstance(raw, str) and (
        (minimum is not None and raw < minimum) or (maximum is not None and raw > maximum)
    ):
        return None
    return raw if not choices or raw in choices else None


def quick_checker(
    ptype: ParamType,
    minimum: float | None = None,
    maximum: float | None = None,
    choices: tuple[Value, ...] = (),
) -> QuickCheck:
    """:func:`quick_value` for one parameter, specialized once: ``checker(raw)`` answers as
    ``quick_value(ptype, raw, minimum, maximum, choices)`` does (a test checks it).

    A mission file checks thousands of values of a few parameters; the specialized check
    of a float, int, text or pose skips the dispatch on the type and on missing bounds.
    """
    low = -math.inf if minimum is None else minimum
    high = math.inf if maximum is None else maximum
    if ptype is ParamType.FLOAT and not choices:

        def check_float(raw: object) -> Value | None:
            if type(raw) is float and low <= raw <= high and _isfinite(raw):
                return raw
            return None

        return check_float
    if ptype is ParamType.INT and not choices:

        def check_int(raw: object) -> Value | None:
            if type(raw) is int and INT_MIN <= raw <= INT_MAX and low <= raw <= high:
                return raw
            return None

        return check_int
    if ptype is ParamType.STRING:

        def check_text(raw: object) -> Value | None:
            if type(raw) is str and (not choices or raw in choices):
                return raw
            return None

        return check_text
    if ptype is ParamType.POSE and not choices:
        return lambda raw: _quick_pose(raw) if type(raw) is dict else None
    return lambda raw: quick_value(ptype, raw, minimum, maximum, choices)


def _quick_pose(raw: dict[Any, Any]) -> Pose | None:
    """A pose of finite floats from a mapping of its fields (missing ones 0.0), or None."""
    if not raw.keys() <= _POSE_FIELDS:
        return None
    values = [raw.get(name, 0.0) for name in Pose.FIELDS]
    for value in values:
        if type(value) is not float or not _isfinite(value):
            return None
    return Pose.assemble(*values)


_POSE_FIELDS = frozenset(Pose.FIELDS)
# The Python type of the values quick_value takes for each parameter type (exactly that type:
# a bool is no int here, and an int for a float takes the full check, which converts it).
_QUICK_TYPES: Mapping[type, ParamType] = {
    bool: ParamType.BOOL,
    int: ParamType.INT,
    float: ParamType.FLOAT,
    str: ParamType.STRING,
}
_isfinite = math.isfinite


def _check_range(value: Value, what: str, minimum: float | None, maximum: float | None) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return
    if minimum is not None and value < minimum:
        raise InvalidRequest(f"{what} must be at least {minimum:g}, got {value:g}")
    if maximum is not None and value > maximum:
        raise InvalidRequest(f"{what} must be at most {maximum:g}, got {value:g}")


_TRUE = {"true", "yes", "on", "1"}
_FALSE = {"false", "no", "off", "0"}


def parse_text(ptype: ParamType, text: str, what: str) -> object:
    """Parse a value typed by a person (CLI ``key=value``, a GUI cell) for ``ptype``.

    The result still goes through :func:`check_value`; this only turns text into data.
    Poses accept ``x,y[,z[,roll,pitch,yaw]]`` or a YAML/JSON mapping.
    """
    stripped = text.strip()
    try:
        if ptype is ParamType.BOOL:
            lowered = stripped.lower()
            if lowered in _TRUE or lowered in _FALSE:
                return lowered in _TRUE
            raise InvalidRequest(f"{what} must be true or false, got {text!r}")
        if ptype is ParamType.INT:
            return int(stripped)
        if ptype is ParamType.FLOAT:
            return float(stripped)
        if ptype is ParamType.STRING:
            return text
        if ptype is ParamType.POSE and not stripped.startswith("{"):
            numbers = [float(part) for part in stripped.split(",")]
            if not 2 <= len(numbers) <= 6:
                raise InvalidRequest(f"{what} needs 2 to 6 numbers: x,y[,z,roll,pitch,yaw]")
            return dict(zip(Pose.FIELDS, numbers, strict=False))
        return yaml.safe_load(stripped)
    except ValueError as error:
        raise InvalidRequest(f"{what}: cannot read {text!r} as {ptype.name.lower()}") from error
    except yaml.YAMLError as error:
        raise InvalidRequest(f"{what}: {text!r} is not valid YAML or JSON") from error


def value_to_data(value: Value) -> object:
    """A value as plain YAML/JSON data (poses become mappings)."""
    return value.to_dict() if isinstance(value, Pose) else value


def value_to_json(value: Value) -> str:
    """A list or dict value as compact JSON text (the wire form of LIST and DICT)."""
    return json.dumps(value_to_data(value), separators=(",", ":"), sort_keys=False)
