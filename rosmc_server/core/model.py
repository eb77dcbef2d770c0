"""The mission's building blocks: skill instances, barriers and task markers.

All are frozen value objects; the mission state replaces them as a whole when
they change, which keeps every change explicit and easy to journal.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field

from .params import MarkerType, Pose, Value

_new_object = object.__new__  # an instance without running its constructor


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


@dataclass(frozen=True)
class SkillInstance:
    """One parameterized skill in an agent's task.

    ``bindings`` maps parameter names to the task marker that fills them.
    """

    id: str
    agent: str
    skill: str
    label: str
    params: Mapping[str, Value]
    bindings: Mapping[str, str] = field(default_factory=dict)
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
        ``object.__setattr__``; filling the instance's dict directly (in field order, so
        it stays a compact key-sharing dict) is three times as fast, which counts where
        thousands of skills are read at once (mission files, snapshots). The price: the
        dict then exists as an object of its own, about 64 bytes more per skill than the
        constructor's inline fields. A test checks that both build equal skills with
        every field.
        """
        made = _new_object(cls)
        fields = made.__dict__
        fields["id"] = id
        fields["agent"] = agent
        fields["skill"] = skill
        fields["label"] = label
        fields["params"] = params
        fields["bindings"] = bindings
        fields["status"] = status
        fields["transfer"] = transfer
        fields["resolution"] = resolution
        fields["attempt"] = attempt
        fields["timeout"] = timeout
        fields["max_retries"] = max_retries
        fields["status_text"] = status_text
        fields["started"] = started
        fields["finished"] = finished
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
