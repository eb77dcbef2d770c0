"""Bringing the ground's view of a robot's skills in line with the robot's own snapshot.

After a link outage the robot's periodic snapshot may show progress whose
reports are still on their way (or were superseded). The robot is the truth
about execution, so the ground adopts its statuses in one event, except where
the ground already holds a final log entry (never rewritten; reported instead).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..model.changes import Change, EventKind, PlacedSkill, Proposal
from ..model.model import SkillStatus, Transfer
from ..model.state import MissionState


@dataclass(frozen=True)
class RobotSkill:
    """One skill as a robot's snapshot shows it."""

    id: str
    status: SkillStatus
    attempt: int = 1
    status_text: str = ""
    started: float = 0.0
    finished: float = 0.0


@dataclass(frozen=True)
class Reconciliation:
    """What reconciling found: the change to commit (if any) and disagreements left."""

    proposal: Proposal | None
    unknown_to_ground: tuple[str, ...]  # ids the robot holds that the ground does not
    conflicts: tuple[str, ...]  # one sentence per disagreement the ground cannot adopt


def plan_reconcile(
    state: MissionState, agent: str, robot_queue: Sequence[RobotSkill]
) -> Reconciliation:
    """Adopt the robot's statuses for skills the ground shows as synchronized."""
    puts: list[PlacedSkill] = []
    unknown: list[str] = []
    conflicts: list[str] = []
    for robot in robot_queue:
        if not state.has_skill(robot.id):
            unknown.append(robot.id)
            continue
        owner, index = state.locate(robot.id)
        ground = state.task(owner)[index]
        if owner != agent or ground.status is SkillStatus.IDLE:
            conflicts.append(f"{agent} holds '{robot.id}', which the ground has in its blueprint")
            continue
        if robot.status is SkillStatus.IDLE:
            conflicts.append(f"{agent} reports '{robot.id}' as IDLE, which it cannot be")
            continue
        same = (
            ground.status is robot.status
            and ground.attempt == robot.attempt
            and ground.status_text == robot.status_text
        )
        if same:
            continue
        if ground.status.is_final:
            conflicts.append(
                f"{agent} shows '{robot.id}' as {robot.status.name}, but the ground logged "
                f"it as {ground.status.name}"
            )
            continue
        adopted = replace(
            ground,
            status=robot.status,
            attempt=max(ground.attempt, robot.attempt),
            status_text=robot.status_text,
            started=robot.started,
            finished=robot.finished,
            transfer=Transfer.NONE if robot.status.has_started else ground.transfer,
        )
        puts.append(PlacedSkill(index, adopted))
    proposal = None
    if puts:
        proposal = Proposal(
            EventKind.STATUS_CHANGED,
            agent,
            f"{agent}'s snapshot updated {', '.join(p.skill.id for p in puts)}",
            Change(put_skills=tuple(puts)),
        )
    return Reconciliation(proposal, tuple(unknown), tuple(conflicts))
