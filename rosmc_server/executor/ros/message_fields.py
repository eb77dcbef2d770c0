"""Fields of ROS messages found by path and filled from skill parameters, at run time.

A binding names message types as text (``actionlib/Test``) and fields as paths
(``target_pose.pose``). The executor resolves both when it starts, so a typo or a field
that no parameter can fill stops it there with one sentence, not in the middle of a
mission. How each parameter type fills a field:

* bool, int, float, string: a field of that kind (an int fills a float field too; a float
  fills a ``duration`` in seconds).
* pose: ``geometry_msgs/Pose``, ``PoseStamped`` (frame ``map``, stamped now), ``Pose2D``
  (x, y, yaw) or ``Point`` (x, y, z).
* list: an array of numbers or strings; an area (a list of ``{x, y}`` corners) fills a
  ``geometry_msgs/Polygon``, a ``PolygonStamped`` or a ``Point[]``/``Point32[]`` field.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, cast

import genpy
import rospy
from geometry_msgs.msg import (
    Point,
    Point32,
    Polygon,
    PolygonStamped,
    Pose2D,
    PoseStamped,
    Quaternion,
)
from geometry_msgs.msg import Pose as PoseMsg
from roslib.message import get_message_class

from rosmc_server.conversions.values import value_type
from rosmc_server.core import ParamType, Pose, SkillSetupError, Value
from rosmc_server.core.skills.bindings import FieldSource, template_fields
from rosmc_server.interface import MAP_FRAME

Convert = Callable[[Any], Any]
_INTS = {"int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "byte", "char"}
_FLOATS = {"float32", "float64"}


def message_class(name: str, where: str) -> type[genpy.Message]:
    """The message class called ``name`` (``package/Type``); SkillSetupError if none."""
    try:
        cls = get_message_class(name)
    except (ValueError, ImportError):
        cls = None
    if cls is None:
        raise SkillSetupError(f"{where}: there is no message type {name} on this robot")
    return cast(type[genpy.Message], cls)


def field_type(cls: type[genpy.Message], path: str, where: str) -> str:
    """The type of field ``path`` of ``cls`` (e.g. "geometry_msgs/Pose"); SkillSetupError."""
    parts = path.split(".")
    for index, part in enumerate(parts):
        slots = dict(zip(cls.__slots__, cls._slot_types, strict=True))
        if part not in slots:
            known = ", ".join(cls.__slots__) or "none"
            raise SkillSetupError(f"{where}: {cls._type} has no field '{part}' (it has: {known})")
        kind = str(slots[part])
        if index == len(parts) - 1:
            return kind
        nested = None if "[" in kind or "/" not in kind else get_message_class(kind)
        if nested is None:
            raise SkillSetupError(f"{where}: field '{part}' is of type {kind}, which has no fields")
        cls = nested
    raise AssertionError("a path has at least one part")


def _quaternion(pose: Pose) -> Quaternion:
    cr, sr = math.cos(pose.roll / 2), math.sin(pose.roll / 2)
    cp, sp = math.cos(pose.pitch / 2), math.sin(pose.pitch / 2)
    cy, sy = math.cos(pose.yaw / 2), math.sin(pose.yaw / 2)
    return Quaternion(
        x=sr * cp * cy - cr * sp * sy,
        y=cr * sp * cy + sr * cp * sy,
        z=cr * cp * sy - sr * sp * cy,
        w=cr * cp * cy + sr * sp * sy,
    )


def _pose(pose: Pose) -> PoseMsg:
    return PoseMsg(position=Point(pose.x, pose.y, pose.z), orientation=_quaternion(pose))


def _stamped_pose(pose: Pose) -> PoseStamped:
    stamped = PoseStamped(pose=_pose(pose))
    stamped.header.frame_id, stamped.header.stamp = MAP_FRAME, rospy.Time.now()
    return stamped


def _polygon(corners: list[Mapping[str, float]]) -> Polygon:
    return Polygon(points=[Point32(c["x"], c["y"], c.get("z", 0.0)) for c in corners])


def _stamped_polygon(corners: list[Mapping[str, float]]) -> PolygonStamped:
    stamped = PolygonStamped(polygon=_polygon(corners))
    stamped.header.frame_id, stamped.header.stamp = MAP_FRAME, rospy.Time.now()
    return stamped


_POSE_FIELDS: Mapping[str, Convert] = {
    "geometry_msgs/Pose": _pose,
    "geometry_msgs/PoseStamped": _stamped_pose,
    "geometry_msgs/Pose2D": lambda p: Pose2D(p.x, p.y, p.yaw),
    "geometry_msgs/Point": lambda p: Point(p.x, p.y, p.z),
}
_AREA_FIELDS: Mapping[str, Convert] = {
    "geometry_msgs/Polygon": _polygon,
    "geometry_msgs/PolygonStamped": _stamped_polygon,
    "geometry_msgs/Point[]": lambda cs: [Point(c["x"], c["y"], c.get("z", 0.0)) for c in cs],
    "geometry_msgs/Point32[]": lambda cs: _polygon(cs).points,
}


def converter(ptype: ParamType, kind: str) -> Convert | None:
    """How a ``ptype`` value becomes a field of type ``kind`` (None: it cannot)."""
    element = kind[: kind.index("[")] if kind.endswith("]") else ""
    simple: Mapping[ParamType, Mapping[str, Convert]] = {
        ParamType.BOOL: {"bool": bool},
        ParamType.INT: {**dict.fromkeys(_INTS, int), **dict.fromkeys(_FLOATS, float)},
        ParamType.FLOAT: {**dict.fromkeys(_FLOATS, float), "duration": genpy.Duration.from_sec},
        ParamType.STRING: {"string": str},
        ParamType.POSE: _POSE_FIELDS,
        ParamType.LIST: _AREA_FIELDS,
    }
    found = simple.get(ptype, {}).get(kind)
    plain = _INTS | _FLOATS | {"string", "bool"}
    if found is None and ptype is ParamType.LIST and element in plain:
        return list
    return found


@dataclass(frozen=True)
class Filler:
    """One field of a message and where its value comes from."""

    path: str
    convert: Convert
    parameter: str = ""
    constant: Value | None = None

    def fill(self, msg: genpy.Message, params: Mapping[str, Value]) -> None:
        """Set the field in ``msg`` from ``params`` (or the constant)."""
        *parents, last = self.path.split(".")
        target = msg
        for name in parents:
            target = getattr(target, name)
        value = params[self.parameter] if self.parameter else self.constant
        setattr(target, last, self.convert(value))


@dataclass(frozen=True)
class MessageRecipe:
    """How to build a goal, request or message from a skill's parameters."""

    cls: type[genpy.Message]
    fillers: tuple[Filler, ...]

    @classmethod
    def make(
        cls,
        message: type[genpy.Message],
        sources: tuple[FieldSource, ...],
        parameters: Mapping[str, ParamType],
        where: str,
    ) -> MessageRecipe:
        """Check every field against its parameter; SkillSetupError with the first misfit."""
        fillers = []
        for source in sources:
            kind = field_type(message, source.field, where)
            if source.parameter:
                ptype, what = parameters[source.parameter], f"parameter '{source.parameter}'"
            else:
                assert source.constant is not None
                ptype, what = value_type(source.constant), f"the constant {source.constant!r}"
            convert = converter(ptype, kind)
            if convert is None:
                raise SkillSetupError(
                    f"{where}: field '{source.field}' of {message._type} is of type {kind}, "
                    f"which {what} ({ptype.name.lower()}) cannot fill"
                )
            fillers.append(Filler(source.field, convert, source.parameter, source.constant))
        return cls(message, tuple(fillers))

    def build(self, params: Mapping[str, Value]) -> genpy.Message:
        """A new message with every field filled."""
        msg = self.cls()
        for filler in self.fillers:
            filler.fill(msg, params)
        return msg


@dataclass(frozen=True)
class Template:
    """A status or outcome text made from a message's fields ("" gives "")."""

    text: str

    @classmethod
    def make(cls, text: str, message: type[genpy.Message], where: str) -> Template:
        """Check that every field the text reads exists and formats; SkillSetupError."""
        for path in template_fields(text):
            field_type(message, path, where)
        template = cls(text)
        try:
            template.render(message())
        except (ValueError, TypeError, KeyError, AttributeError, IndexError) as error:
            raise SkillSetupError(f"{where}: the text {text!r} does not format: {error}") from error
        return template

    def render(self, msg: genpy.Message | None) -> str:
        """The text with ``msg``'s fields in it."""
        if not self.text or msg is None:
            return ""
        return self.text.format(**{slot: getattr(msg, slot) for slot in msg.__slots__})


def bool_field(message: type[genpy.Message], path: str, where: str) -> str:
    """``path`` if it names a bool field of ``message`` ("" stays ""); SkillSetupError."""
    if path and field_type(message, path, where) != "bool":
        raise SkillSetupError(f"{where}: success field '{path}' is no bool")
    return path


def read_field(msg: Any, path: str) -> Any:
    """The value of field ``path`` of ``msg``."""
    for name in path.split("."):
        msg = getattr(msg, name)
    return msg
