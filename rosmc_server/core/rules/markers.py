"""Task markers: points and regions of interest that skill parameters follow.

A marker bound to an unfinished skill that has left the editable blueprint is
locked: it can neither move nor be renamed, because the robot already holds the
values. Once those skills are finished (SUCCESS or FAILURE) the marker is free to
move again; the finished skills keep the values they ran with (an immutable log).
A marker in use cannot be deleted.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from ..errors import InvalidRequest, RuleViolation
from ..model.changes import Change, EventKind, PlacedSkill, Proposal
from ..model.model import TaskMarker
from ..model.state import MissionState
from ..skills.library import Library
from ..skills.params import MarkerType, Pose
from ..validation import MAX_NAME, check_corners, check_one_line
from ..views.vocabulary import counted
from .edit_rules import MarkerAction, marker_refusal
from .editing import bound_values

_NAME_NUMBER = re.compile(r"(\d+)$")


def check_marker(marker: TaskMarker) -> TaskMarker:
    """Check a marker's shape; return it with an AREA's pose set to its centroid."""
    name = check_one_line(marker.name, "a marker name", MAX_NAME)
    check_corners(len(marker.vertices), name)
    pose = Pose.from_any(marker.pose, f"the pose of marker '{name}'")
    vertices = tuple(
        Pose.from_any(v, f"vertex {i} of marker '{name}'") for i, v in enumerate(marker.vertices)
    )
    if marker.type is MarkerType.AREA:
        if len(vertices) < 3:
            raise InvalidRequest(f"area marker '{name}' needs at least 3 vertices")
        pose = Pose(
            sum(v.x for v in vertices) / len(vertices),
            sum(v.y for v in vertices) / len(vertices),
            sum(v.z for v in vertices) / len(vertices),
        )
    elif vertices:
        raise InvalidRequest(f"{marker.type.name.lower()} marker '{name}' takes no vertices")
    return TaskMarker(name, MarkerType(marker.type), pose, vertices)


def generated_name(state: MissionState, marker_type: MarkerType) -> str:
    """The next free name like ``Pose 3`` for a marker of ``marker_type``."""
    prefix = marker_type.name.capitalize()
    used = {
        int(match.group(1))
        for m in state.markers
        if m.name.startswith(prefix + " ") and (match := _NAME_NUMBER.search(m.name))
    }
    number = 1
    while number in used:
        number += 1
    return f"{prefix} {number}"


def plan_add_marker(state: MissionState, marker: TaskMarker) -> Proposal:
    """Add a marker; an empty name is replaced by a generated one."""
    if not marker.name.strip():
        marker = replace(marker, name=generated_name(state, marker.type))
    marker = check_marker(marker)
    if state.has_marker(marker.name):
        raise RuleViolation(f"a task marker called '{marker.name}' already exists")
    return Proposal(
        EventKind.MARKER_ADDED,
        "",
        f"{marker.type.name.lower()} marker '{marker.name}' added",
        Change(put_markers=(marker,)),
    )


def plan_move_marker(
    state: MissionState,
    library: Library,
    name: str,
    pose: Pose,
    vertices: Sequence[Pose],
) -> Proposal:
    """Move a marker; every skill bound to it takes the new values."""
    old = state.marker(name)
    moved = check_marker(TaskMarker(name, old.type, pose, tuple(vertices)))
    bound = state.bound_to(name)
    _refuse(marker_refusal(name, bound, MarkerAction.MOVE))

    def find_marker(marker_name: str) -> TaskMarker:
        return moved if marker_name == name else state.marker(marker_name)

    puts = []
    for skill in bound:
        if skill.status.is_final:
            continue  # a finished skill's parameters are the log of what it did
        spec = library.skill(skill.agent, skill.skill)
        names = {param: marker for param, marker in skill.bindings.items() if marker == name}
        values = dict(skill.params)
        values.update(bound_values(find_marker, spec, names))
        puts.append(PlacedSkill(state.locate(skill.id)[1], replace(skill, params=values)))
    follow = f"; {counted(len(puts), 'bound skill')} follow" if puts else ""
    return Proposal(
        EventKind.MARKER_MOVED,
        "",
        f"marker '{name}' moved{follow}",
        Change(put_skills=tuple(puts), put_markers=(moved,)),
    )


def plan_rename_marker(state: MissionState, name: str, new_name: str) -> Proposal:
    """Rename a marker; every binding to it follows."""
    old = state.marker(name)
    renamed = check_marker(replace(old, name=new_name))
    if renamed.name == name:
        raise InvalidRequest(f"marker '{name}' already has that name")
    if state.has_marker(renamed.name):
        raise RuleViolation(f"a task marker called '{renamed.name}' already exists")
    bound = state.bound_to(name)
    _refuse(marker_refusal(name, bound, MarkerAction.RENAME))
    puts = tuple(
        PlacedSkill(
            state.locate(skill.id)[1],
            replace(
                skill,
                bindings={
                    param: renamed.name if marker == name else marker
                    for param, marker in skill.bindings.items()
                },
            ),
        )
        for skill in bound
    )
    return Proposal(
        EventKind.MARKER_RENAMED,
        "",
        f"marker '{name}' renamed to '{renamed.name}'",
        Change(put_skills=puts, removed_marker_names=(name,), put_markers=(renamed,)),
    )


def plan_delete_marker(state: MissionState, name: str) -> Proposal:
    """Delete a marker that no skill is bound to."""
    state.marker(name)
    _refuse(marker_refusal(name, state.bound_to(name), MarkerAction.DELETE))
    return Proposal(
        EventKind.MARKER_DELETED,
        "",
        f"marker '{name}' deleted",
        Change(removed_marker_names=(name,)),
    )


def _refuse(refusal: str | None) -> None:
    if refusal is not None:
        raise RuleViolation(refusal)
