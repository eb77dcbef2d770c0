"""Skills bound to existing ROS interfaces by configuration, as a library declares them.

A library skill may carry a ``binding``: instead of a Python implementation, the robot's
executor runs the skill by sending an actionlib goal, calling a service or publishing on a
topic, filling fields of the goal/request/message from the skill's parameters::

    binding:
      action: /fibonacci                 # or service: NAME, or topic: NAME (exactly one)
      type: actionlib/Test               # the action, service or message type
      fields: {goal: steps}              # field path <- parameter; {value: X} is a constant
      status: 'at {feedback}'            # action feedback -> the skill's status text
      outcome: 'reached {result}'        # result or response -> the outcome's text
      success: success                   # a bool field of the result or response

This module reads and checks that text (pure Python). Whether the type exists and each field
fits its parameter is checked by the executor at start, where the message classes are.
"""

from __future__ import annotations

import enum
import re
import string
from collections.abc import Mapping
from dataclasses import dataclass

from ..documents.documents import DocumentReader
from ..errors import InvalidRequest
from .params import Value, check_json_data

_PATH = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$")
_TYPE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*/[A-Za-z_][A-Za-z0-9_]*$")


class BindingKind(enum.Enum):
    """What a bound skill talks to."""

    ACTION = "action"
    SERVICE = "service"
    TOPIC = "topic"


@dataclass(frozen=True)
class FieldSource:
    """One field of the goal, request or message: from a parameter, or a constant."""

    field: str
    parameter: str = ""
    constant: Value | None = None


@dataclass(frozen=True)
class BindingSpec:
    """A skill run through an action, a service or a topic (see the module docstring)."""

    kind: BindingKind
    name: str
    type: str
    fields: tuple[FieldSource, ...] = ()
    status: str = ""
    outcome: str = ""
    success: str = ""

    def describe(self) -> str:
        """E.g. "action /fibonacci (actionlib/Test)", for messages."""
        return f"{self.kind.value} {self.name} ({self.type})"


def template_fields(template: str) -> list[str]:
    """The field paths a status or outcome template reads ("{a.b:.1f}" reads "a.b").

    ValueError if the template is no valid format string or reads something else.
    """
    paths = []
    for _, name, _, _ in string.Formatter().parse(template):
        if name is None:
            continue
        if not _PATH.match(name):
            raise ValueError(f"'{{{name}}}' names no message field")
        paths.append(name)
    return paths


def read_binding(
    reader: DocumentReader, raw: object, key: str, parameters: Mapping[str, object]
) -> BindingSpec:
    """Check a skill's ``binding`` entry against the skill's ``parameters``."""
    kinds = {kind.value for kind in BindingKind}
    body = reader.mapping(
        raw, key, required={"type"}, optional=kinds | {"fields", "status", "outcome", "success"}
    )
    given = sorted(kinds & set(body))
    if len(given) != 1:
        reader.fail(key, "give exactly one of action, service or topic")
    kind = BindingKind(given[0])
    name = reader.text(body[kind.value], f"{key}.{kind.value}")
    type_name = reader.text(body["type"], f"{key}.type")
    if not _TYPE.match(type_name):
        reader.fail(f"{key}.type", f"must be package/Name, got {type_name!r}")
    texts = {k: reader.text(body.get(k, ""), f"{key}.{k}", empty=True) for k in _TEXTS}
    for what in ("status", "outcome"):
        try:
            template_fields(texts[what])
        except ValueError as error:
            reader.fail(f"{key}.{what}", str(error))
    if texts["success"] and not _PATH.match(texts["success"]):
        reader.fail(f"{key}.success", f"must be a field path, got {texts['success']!r}")
    _no_misplaced(reader, kind, texts, key)
    fields = _read_fields(reader, body.get("fields", {}), f"{key}.fields", parameters)
    return BindingSpec(kind, name, type_name, fields, **texts)


_TEXTS = ("status", "outcome", "success")


def _no_misplaced(
    reader: DocumentReader, kind: BindingKind, texts: Mapping[str, str], key: str
) -> None:
    if kind is not BindingKind.ACTION and texts["status"]:
        reader.fail(f"{key}.status", "only an action has feedback to show as status text")
    if kind is BindingKind.TOPIC:
        for what in ("outcome", "success"):
            if texts[what]:
                reader.fail(f"{key}.{what}", "a topic has no result: the skill succeeds once sent")


def _read_fields(
    reader: DocumentReader, raw: object, key: str, parameters: Mapping[str, object]
) -> tuple[FieldSource, ...]:
    sources = []
    for field, source in reader.mapping(raw, key).items():
        where = f"{key}.{field}"
        if not isinstance(field, str) or not _PATH.match(field):
            reader.fail(key, f"{field!r} is no field path (names joined by dots)")
        if isinstance(source, Mapping):
            body = reader.mapping(source, where, required={"value"}, optional=set())
            try:
                constant = check_json_data(body["value"], where)
            except InvalidRequest as error:
                reader.fail(where, str(error))
            sources.append(FieldSource(field, constant=constant))
            continue
        parameter = reader.text(source, where)
        if parameter not in parameters:
            known = ", ".join(parameters) or "none"
            reader.fail(where, f"names no parameter of the skill ({parameter!r}; it has: {known})")
        sources.append(FieldSource(field, parameter=parameter))
    return tuple(sources)
