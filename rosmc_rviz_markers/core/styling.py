"""What a task marker's colour says: the status of the skills that use it.

The status is computed from the mission every time (never decoded back from a colour), the
highest-priority use wins across all agents, and a marker is *locked* (not draggable, not
renamable) only while an unfinished synchronized skill uses it: once those skills are
finished (success or failure, an immutable log) it is editable again.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable

from rosmc_server.core.model.model import SkillInstance, SkillStatus, Transfer
from rosmc_server.core.rules.edit_rules import MarkerAction, marker_refusal
from rosmc_server.core.views.geometry import Color


class MarkerUse(enum.IntEnum):
    """How a task marker is used, lowest priority first (the highest use wins)."""

    UNUSED = 0
    SUCCESS = 1
    BLUEPRINT = 2
    SYNCHRONIZED = 3
    UPLOADING = 4
    FAILURE = 5
    PAUSED = 6
    WAITING = 7
    RUNNING = 8

    @property
    def label(self) -> str:
        """Lower-case words for the marker's description."""
        return {MarkerUse.WAITING: "waiting at barrier"}.get(self, self.name.lower())


USE_COLORS = {
    MarkerUse.UNUSED: Color(0.55, 0.55, 0.58, 0.55),
    MarkerUse.BLUEPRINT: Color(0.35, 0.65, 1.00, 0.6),
    MarkerUse.UPLOADING: Color(0.60, 0.45, 1.00, 0.6),
    MarkerUse.SYNCHRONIZED: Color(0.95, 0.95, 0.95, 0.6),
    MarkerUse.RUNNING: Color(0.25, 1.00, 0.40, 0.6),
    MarkerUse.WAITING: Color(1.00, 0.85, 0.10, 0.6),
    MarkerUse.PAUSED: Color(0.75, 0.55, 0.35, 0.6),
    MarkerUse.SUCCESS: Color(0.10, 0.75, 0.80, 0.6),
    MarkerUse.FAILURE: Color(1.00, 0.20, 0.10, 0.6),
}
HIGHLIGHT = Color(1.0, 0.95, 0.2, 1.0)
LOCK_COLOR = Color(1.0, 1.0, 1.0, 0.9)


def skill_use(skill: SkillInstance) -> MarkerUse:
    """The use a single skill makes of the markers it is bound to."""
    if skill.status is SkillStatus.IDLE:
        return MarkerUse.UPLOADING if skill.transfer is Transfer.UPLOADING else MarkerUse.BLUEPRINT
    return {
        SkillStatus.IDLE_SYNCHRONIZED: MarkerUse.SYNCHRONIZED,
        SkillStatus.SYNCWAITING: MarkerUse.WAITING,
        SkillStatus.RUNNING: MarkerUse.RUNNING,
        SkillStatus.PAUSED: MarkerUse.PAUSED,
        SkillStatus.SUCCESS: MarkerUse.SUCCESS,
        SkillStatus.FAILURE: MarkerUse.FAILURE,
    }[skill.status]


def marker_use(skills: Iterable[SkillInstance]) -> MarkerUse:
    """The highest-priority use among the skills bound to a marker (UNUSED if none)."""
    return max((skill_use(s) for s in skills), default=MarkerUse.UNUSED)


def is_locked(skills: Iterable[SkillInstance]) -> bool:
    """A marker is locked (cannot move or be renamed) while a robot holds a skill that uses
    it: the server's rule (:func:`~rosmc_server.core.rules.edit_rules.marker_refusal`)."""
    return marker_refusal("", tuple(skills), MarkerAction.MOVE) is not None
