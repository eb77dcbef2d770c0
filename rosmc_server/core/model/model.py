"""The mission's building blocks: skill instances, barriers and task markers.

All are frozen value objects; the mission state replaces them as a whole when
they change, which keeps every change explicit and easy to journal.
"""

from __future__ import annotations

import enum
import operator
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from itertools import repeat
from types import MappingProxyType
from typing import Any

from ..skills.params import MarkerType, Pose, Value

_new_object = object.__new__  # an instance without running its constructor
# The bindings of every skill bound to no marker (most): one shared, read-only mapping.
NO_BINDINGS: Mapping[str, str] = MappingProxyType({})


class SkillStatus(enum.IntEnum):
    """Execution status of a skill instance (numbers match ``rosmc/SkillStatus``)."""

    IDLE = 0
    IDLE_SYNCHRONIZED = 1
    SYNCWAITING = 2
    RUNNING = 3
    PAUSED = 4
    SUCCESS = 5
    FAILURE = 6

    @property
    def is_active(self) -> bool:
        """Reached by the robot and not finished: waiting, running or paused."""
        return self in (
            SkillStatus.SYNCWAITING,
            SkillStatus.RUNNING,
            SkillStatus.PAUSED,
        )

    @property
    def is_final(self) -> bool:
        """SUCCESS or FAILURE: an immutable execution log."""
        return self in (SkillStatus.SUCCESS, SkillStatus.FAILURE)

    @property
    def has_started(self) -> bool:
        """The robot has reached this skill (it is active or final)."""
        return self.is_active or self.is_final


class Transfer(enum.IntEnum):
    """A ground-to-robot transfer awaiting the robot's answer."""

    NONE = 0
    UPLOADING = 1
    REMOVING = 2


class Resolution(enum.IntEnum):
    """What the operator decided about a FAILURE."""

    NONE = 0
    RETRIED = 1
    SKIPPED = 2


@dataclass(frozen=True, slots=True)
class SkillInstance:
    """One parameterized skill in an agent's task.

    ``bindings`` maps parameter names to the task marker that fills them. Slots, not a
    dict per instance: a mission holds tens of thousands of skills.
    """

    id: str
    agent: str
    skill: str
    label: str
    params: Mapping[str, Value]
    bindings: Mapping[str, str] = field(default_factory=lambda: NO_BINDINGS)
    status: SkillStatus = SkillStatus.IDLE
    transfer: Transfer = Transfer.NONE
    resolution: Resolution = Resolution.NONE
    attempt: int = 1
    timeout: float = 0.0
    max_retries: int = 0
    status_text: str = ""
    started: float = 0.0
    finished: float = 0.0

    @classmethod
    def assemble(
        cls,
        id: str,
        agent: str,
        skill: str,
        label: str,
        params: Mapping[str, Value],
        bindings: Mapping[str, str],
        status: SkillStatus,
        transfer: Transfer,
        resolution: Resolution,
        attempt: int,
        timeout: float,
        max_retries: int,
        status_text: str,
        started: float,
        finished: float,
    ) -> SkillInstance:
        """The skill of these already checked fields, built without the constructor.

        A frozen dataclass's constructor sets each of the fifteen fields through
        ``object.__setattr__``; setting the slots through their descriptors is about
        twice as fast, which counts where thousands of skills are read at once (mission
        files, snapshots). A test checks that both build equal skills with every field.
        """
        made = _new_object(cls)
        _set_id(made, id)
        _set_agent(made, agent)
        _set_skill(made, skill)
        _set_label(made, label)
        _set_params(made, params)
        _set_bindings(made, bindings or NO_BINDINGS)
        _set_status(made, status)
        _set_transfer(made, transfer)
        _set_resolution(made, resolution)
        _set_attempt(made, attempt)
        _set_timeout(made, timeout)
        _set_max_retries(made, max_retries)
        _set_status_text(made, status_text)
        _set_started(made, started)
        _set_finished(made, finished)
        return made

    @classmethod
    def assemble_columns(cls, count: int, columns: Iterable[Iterable[Any]]) -> list[SkillInstance]:
        """``count`` skills whose fields come a column at a time, in field order: the
        first skill takes the first value of every column, and so on.

        The fields must be as :meth:`assemble` takes them, with ``bindings`` already
        :data:`NO_BINDINGS` where there are none. Each column fills its field of every
        skill in one pass that runs in C (no Python call per skill and field): about half
        the time of :meth:`assemble` per skill, for readers of thousands at once (a
        snapshot). Columns must hold ``count`` values or more (a constant field can be an
        ``itertools.repeat``). A test checks the skills equal the constructor's.
        """
        made = list(map(_new_object, repeat(cls, count)))
        for set_field, column in zip(_SETTERS, columns, strict=True):
            any(map(set_field, made, column))  # each set gives None: any() runs them all
        return made

    @property
    def is_editable(self) -> bool:
        """In the blueprint and not being uploaded."""
        return self.status is SkillStatus.IDLE and self.transfer is Transfer.NONE

    @property
    def is_settled(self) -> bool:
        """Finished for good: SUCCESS, or a FAILURE the operator retried or skipped."""
        if self.status is SkillStatus.SUCCESS:
            return True
        return self.status is SkillStatus.FAILURE and self.resolution is not Resolution.NONE


(
    _set_id,
    _set_agent,
    _set_skill,
    _set_label,
    _set_params,
    _set_bindings,
    _set_status,
    _set_transfer,
    _set_resolution,
    _set_attempt,
    _set_timeout,
    _set_max_retries,
    _set_status_text,
    _set_started,
    _set_finished,
) = _SETTERS = tuple(getattr(SkillInstance, name).__set__ for name in SkillInstance.__slots__)
skill_id_of = operator.attrgetter("id")  # a skill's id, in C (for map over thousands)
_fields_of = operator.attrgetter(*SkillInstance.__slots__)
_FIELD_PLACE = MappingProxyType({name: at for at, name in enumerate(SkillInstance.__slots__)})


def skill_with(skill: SkillInstance, /, **changes: Any) -> SkillInstance:
    """A copy of ``skill`` with ``changes``: ``dataclasses.replace`` for skills, faster.

    A synchronize of thousands of skills copies each with a new transfer state;
    ``replace`` spends about 3 µs a copy walking the dataclass fields, this about 1.3.
    A field name the skill does not have raises TypeError, as ``replace`` does.
    """
    values = list(_fields_of(skill))
    for name, value in changes.items():
        place = _FIELD_PLACE.get(name)
        if place is None:
            raise TypeError(f"a skill instance has no field {name!r}")
        values[place] = value
    made = SkillInstance.assemble(*values)
    _set_bindings(made, values[_FIELD_PLACE["bindings"]])  # as given, even an empty dict
    return made


@dataclass(frozen=True)
class Barrier:
    """Skills on distinct agents that start together."""

    id: str
    skill_ids: tuple[str, ...]


@dataclass(frozen=True)
class TaskMarker:
    """A point or region of interest that skill parameters can be bound to.

    For an AREA, ``pose`` is the centroid of ``vertices``.
    """

    name: str
    type: MarkerType
    pose: Pose
    vertices: tuple[Pose, ...] = ()

    def value_for(self, param_type_is_list: bool) -> Value:
        """The parameter value this marker gives a bound parameter."""
        if param_type_is_list:
            return [{"x": v.x, "y": v.y} for v in self.vertices]
        if self.type is MarkerType.POSITION:
            return Pose(self.pose.x, self.pose.y, self.pose.z)
        return self.pose
