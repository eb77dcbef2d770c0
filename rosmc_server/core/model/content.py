"""A mission's content without indexes (what files and snapshots hold), and task sections.

Kept apart from :mod:`.state` so that changes, which may carry a whole content, do not
import the state that applies them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..skills.library import Library
from .model import Barrier, SkillInstance, TaskMarker


@dataclass
class MissionContent:
    """The content of a mission, without indexes: what files and snapshots hold."""

    library: str
    tasks: dict[str, list[SkillInstance]]
    barriers: dict[str, Barrier] = field(default_factory=dict)
    markers: dict[str, TaskMarker] = field(default_factory=dict)

    @classmethod
    def empty(cls, library: Library) -> MissionContent:
        """A mission with an empty task for every dynamic agent of ``library``."""
        return cls(library.name, {agent: [] for agent in library.dynamic_agents})

    def copy(self) -> MissionContent:
        """A copy whose tasks and mappings can change without touching this one."""
        return MissionContent(
            self.library,
            {agent: list(task) for agent, task in self.tasks.items()},
            dict(self.barriers),
            dict(self.markers),
        )


@dataclass(frozen=True)
class Sections:
    """Where an agent's task splits.

    ``task[:synced_end]`` is the synchronized section, ``task[synced_end:editable_start]``
    the blueprint skills being uploaded, ``task[editable_start:]`` the editable blueprint.
    """

    synced_end: int
    editable_start: int
