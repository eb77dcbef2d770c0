"""Which skills may be edited and which task markers changed: the rules as sentences.

The server's operations (:mod:`.editing`, :mod:`.markers`) raise these sentences; a GUI
offers an edit, a marker's move, rename or delete exactly when the same function finds
nothing to refuse (:func:`legal_marker_actions`). Like :mod:`.legality`, each rule is
written once.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence

from ..model.model import SkillInstance, SkillStatus
from ..model.state import MissionState


class MarkerAction(enum.Enum):
    """What can be done to a task marker."""

    MOVE = "move"
    RENAME = "be renamed"
    DELETE = "be deleted"


def edit_refusal(skill: SkillInstance, verb: str) -> str | None:
    """Why ``skill`` cannot be ``verb`` (edited, deleted, moved), if it cannot: only the
    editable blueprint can."""
    if skill.is_editable:
        return None
    state = "being uploaded" if skill.status is SkillStatus.IDLE else skill.status.name
    return f"skill '{skill.id}' is {state}; only blueprint skills can be {verb}"


def marker_refusal(name: str, bound: Sequence[SkillInstance], action: MarkerAction) -> str | None:
    """Why marker ``name``, which the skills ``bound`` use, cannot take ``action``, if not.

    A marker in use cannot be deleted; one a robot holds a skill of (synchronized and not
    finished) cannot move or be renamed: the robot has its values already.
    """
    if action is MarkerAction.DELETE:
        if bound:
            users = ", ".join(skill.id for skill in bound)
            return f"marker '{name}' is in use by {users}; unbind them first"
        return None
    for skill in bound:
        if not skill.is_editable and not skill.status.is_final:
            return (
                f"marker '{name}' is bound to '{skill.id}', which has been synchronized, "
                f"so it cannot {action.value}"
            )
    return None


def legal_marker_actions(state: MissionState, name: str) -> set[MarkerAction]:
    """The actions the server would accept for marker ``name`` now."""
    bound = state.bound_to(name)
    return {action for action in MarkerAction if marker_refusal(name, bound, action) is None}
