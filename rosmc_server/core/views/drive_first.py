"""Drive there first: the move a skill at a place needs when its robot is not going there.

A skill that works at a point (identify stones, pick a stone) does not move the robot
there by itself. When the robot would be elsewhere when the skill starts (the previous
location in its task, or its current position, is farther than :data:`ARRIVED`), the
operator is offered the robot's move skill just before it, bound to the same marker (or
given the same point).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..model.model import SkillInstance
from ..skills.library import Library, ParameterSpec, SkillSpec
from ..skills.params import MarkerType, Pose, Value
from .places import last_location, location_xy

MOVE_SKILLS = ("navigate_to", "move_to", "go_to", "drive_to", "fly_to")
"""Names of the skills that move a robot to a place, in order of preference."""
ARRIVED = 1.0  # metres: a robot this close to a skill's place is already there


@dataclass(frozen=True)
class DriveFirst:
    """The move to add at ``index`` of ``agent``'s task, before the skill at that place."""

    agent: str
    skill: str
    index: int
    params: dict[str, Value]
    bindings: dict[str, str]
    words: str


def move_skill(library: Library, agent: str) -> tuple[str, str] | None:
    """``agent``'s move skill and its target parameter (None: it has none)."""
    skills = library.skills_of(agent)
    for name in MOVE_SKILLS:
        spec = skills.get(name)
        target = _point_parameter(spec) if spec is not None else None
        if target is not None:
            return name, target.name
    return None


def drive_first(
    library: Library,
    task: Sequence[tuple[SkillInstance, SkillSpec]],
    index: int,
    robot: Pose | None,
) -> DriveFirst | None:
    """The move to offer before ``task[index]`` (None: nothing to offer).

    Offered for a skill with a point or pose parameter that is not itself a move, when
    its robot has a move skill and would not already be at the skill's place.
    """
    skill, spec = task[index]
    move = move_skill(library, skill.agent)
    target = _point_parameter(spec)
    if move is None or target is None or skill.skill == move[0]:
        return None
    xy = location_xy(skill.params.get(target.name))
    if xy is None:
        return None
    before = last_location(task[:index])
    if before is not None:
        earlier = location_xy(before[0].params.get(before[1]))
    else:
        earlier = (robot.x, robot.y) if robot is not None else None
    if earlier is not None and math.dist(earlier, xy) <= ARRIVED:
        return None
    marker = skill.bindings.get(target.name, "")
    where = f"marker '{marker}'" if marker else f"({xy[0]:.1f}, {xy[1]:.1f})"
    params: dict[str, Value] = {} if marker else {move[1]: Pose(*xy)}
    bindings = {move[1]: marker} if marker else {}
    words = f"{move[0]} to {where} before {skill.label or skill.skill}"
    return DriveFirst(skill.agent, move[0], index, params, bindings, words)


def _point_parameter(spec: SkillSpec) -> ParameterSpec | None:
    return next(
        (p for p in spec.parameters if p.marker_type in (MarkerType.POSITION, MarkerType.POSE)),
        None,
    )
