"""The mission <-> messages: skills, barriers, task markers, snapshots and events.

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core. ``x_to_msg`` builds a message from a core object;
``x_from_msg`` builds the core object back (raising InvalidRequest for malformed
input, so service handlers can answer with an error). Round trips are exact.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from typing import Any

import rosmc.msg as wire

from ..core import (
    Barrier,
    Change,
    EventKind,
    MarkerType,
    MissionContent,
    MissionEvent,
    PlacedSkill,
    Resolution,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
)
from ..core.model.changes import SkillMove
from .move_fields import moves_from_fields, moves_to_fields
from .values import (
    enum_from_number,
    param_from_msg,
    param_to_msg,
    pose_from_msg,
    pose_to_msg,
    time_to_msg,
)


def skill_to_msg(skill: SkillInstance) -> wire.Skill:
    """A skill instance as ``rosmc/Skill``."""
    return wire.Skill(
        id=skill.id,
        agent=skill.agent,
        skill=skill.skill,
        label=skill.label,
        parameters=[
            param_to_msg(name, value, skill.bindings.get(name, ""))
            for name, value in skill.params.items()
        ],
        status=wire.SkillStatus(int(skill.status)),
        transfer=int(skill.transfer),
        resolution=int(skill.resolution),
        attempt=skill.attempt,
        timeout=skill.timeout,
        max_retries=skill.max_retries,
        status_text=skill.status_text,
        started=skill.started,
        finished=skill.finished,
    )


def skill_from_msg(msg: wire.Skill) -> SkillInstance:
    """``rosmc/Skill`` as a skill instance (values as sent; the core checks them on use)."""
    params: dict[str, Any] = {}
    bindings: dict[str, str] = {}
    for param in msg.parameters:
        name, value = param_from_msg(param)
        params[name] = value
        if param.marker:
            bindings[name] = param.marker
    return SkillInstance(
        id=msg.id,
        agent=msg.agent,
        skill=msg.skill,
        label=msg.label,
        params=params,
        bindings=bindings,
        status=enum_from_number(SkillStatus, msg.status.value, "status"),
        transfer=enum_from_number(Transfer, msg.transfer, "transfer"),
        resolution=enum_from_number(Resolution, msg.resolution, "resolution"),
        attempt=msg.attempt,
        timeout=msg.timeout,
        max_retries=msg.max_retries,
        status_text=msg.status_text,
        started=msg.started,
        finished=msg.finished,
    )


def barrier_to_msg(barrier: Barrier, agent_of: Callable[[str], str]) -> wire.Barrier:
    """A barrier as ``rosmc/Barrier`` (with each member's agent)."""
    return wire.Barrier(
        id=barrier.id,
        skill_ids=list(barrier.skill_ids),
        agents=[agent_of(skill_id) for skill_id in barrier.skill_ids],
    )


def barrier_from_msg(msg: wire.Barrier) -> Barrier:
    """``rosmc/Barrier`` as a core barrier."""
    return Barrier(msg.id, tuple(msg.skill_ids))


def marker_to_msg(marker: TaskMarker) -> wire.TaskMarker:
    """A task marker as ``rosmc/TaskMarker``."""
    return wire.TaskMarker(
        name=marker.name,
        type=int(marker.type),
        pose=pose_to_msg(marker.pose),
        vertices=[pose_to_msg(v) for v in marker.vertices],
    )


def marker_from_msg(msg: wire.TaskMarker) -> TaskMarker:
    """``rosmc/TaskMarker`` as a core marker (shape checked by the core)."""
    return TaskMarker(
        msg.name,
        enum_from_number(MarkerType, msg.type, "marker type"),
        pose_from_msg(msg.pose),
        tuple(pose_from_msg(v) for v in msg.vertices),
    )


def mission_to_msg(
    content: MissionContent,
    revision: int,
    stamp: float,
    skill_msg: Callable[[SkillInstance], wire.Skill] = skill_to_msg,
) -> wire.Mission:
    """A full snapshot as ``rosmc/Mission`` (``skill_msg`` converts each skill)."""
    agent_of = {skill.id: agent for agent, task in content.tasks.items() for skill in task}
    return wire.Mission(
        revision=revision,
        stamp=time_to_msg(stamp),
        library=content.library,
        tasks=[
            wire.AgentTask(agent=agent, skills=[skill_msg(s) for s in task])
            for agent, task in content.tasks.items()
        ],
        barriers=[barrier_to_msg(b, agent_of.__getitem__) for b in content.barriers.values()],
        markers=[marker_to_msg(m) for m in content.markers.values()],
    )


def mission_from_msg(msg: wire.Mission) -> tuple[MissionContent, int]:
    """``rosmc/Mission`` as core content and revision."""
    tasks = {task.agent: [skill_from_msg(s) for s in task.skills] for task in msg.tasks}
    barriers = {b.id: barrier_from_msg(b) for b in msg.barriers}
    markers = {m.name: marker_from_msg(m) for m in msg.markers}
    return MissionContent(msg.library, tasks, barriers, markers), msg.revision


def event_to_msg(event: MissionEvent, agent_of: Callable[[str], str]) -> wire.MissionEvent:
    """An event as ``rosmc/MissionEvent`` (a replacement travels without content)."""
    change = event.change
    msg = wire.MissionEvent(
        revision=event.revision,
        stamp=time_to_msg(event.stamp),
        kind=int(event.kind),
        agent=event.agent,
        summary=event.summary,
        put_skills=[
            wire.PlacedSkill(index=p.index, skill=skill_to_msg(p.skill)) for p in change.put_skills
        ],
        removed_skill_ids=list(change.removed_skill_ids),
        order_agent=change.order_agent,
        blueprint_order=list(change.blueprint_order),
        put_barriers=[barrier_to_msg(b, agent_of) for b in change.put_barriers],
        removed_barrier_ids=list(change.removed_barrier_ids),
        put_markers=[marker_to_msg(m) for m in change.put_markers],
        removed_marker_names=list(change.removed_marker_names),
        undoes=event.undoes,
    )
    fields = moves_to_fields(change.moves)
    if fields is None:
        msg.moves, msg.move_indexes = moves_to_msgs(change.moves), ()
    else:
        msg.move_ids, msg.move_indexes = fields
    return msg


def moves_to_msgs(moves: Sequence[SkillMove]) -> list[wire.SkillMove]:
    """Core moves as ``rosmc/SkillMove`` messages."""
    return [wire.SkillMove(skill_id=m.skill_id, index=m.index) for m in moves]


def moves_from_msgs(msgs: Sequence[wire.SkillMove]) -> tuple[SkillMove, ...]:
    """``rosmc/SkillMove`` messages as core moves."""
    return tuple(SkillMove(m.skill_id, m.index) for m in msgs)


def event_from_msg(msg: wire.MissionEvent) -> MissionEvent:
    """``rosmc/MissionEvent`` as a core event (a replacement has no content).

    An event recorded before reorders carried moves has no ``moves`` field and
    gives the whole new order in ``blueprint_order``; the core applies either. One
    recorded before the packed move fields carries its moves in ``moves``. One
    recorded before events carried ``undoes`` names the edit it took back in its summary
    only (see :func:`undoes_of`).
    """
    change = Change(
        put_skills=tuple(PlacedSkill(p.index, skill_from_msg(p.skill)) for p in msg.put_skills),
        removed_skill_ids=tuple(msg.removed_skill_ids),
        order_agent=msg.order_agent,
        blueprint_order=tuple(msg.blueprint_order),
        put_barriers=tuple(barrier_from_msg(b) for b in msg.put_barriers),
        removed_barrier_ids=tuple(msg.removed_barrier_ids),
        put_markers=tuple(marker_from_msg(m) for m in msg.put_markers),
        removed_marker_names=tuple(msg.removed_marker_names),
        moves=moves_from_fields(msg) or moves_from_msgs(getattr(msg, "moves", ())),
    )
    return MissionEvent(
        msg.revision,
        enum_from_number(EventKind, msg.kind, "event kind"),
        msg.agent,
        msg.summary,
        msg.stamp.to_sec(),
        change,
        undoes_of(msg),
    )


# How an undo's summary began before events carried ``undoes`` ("undo of revision 7 (...)").
_OLD_UNDO_SUMMARY = re.compile(r"undo of revision (\d+) ")


def undoes_of(msg: wire.MissionEvent) -> int:
    """The revision of the edit ``msg`` takes back (0: none).

    Events carry it in ``undoes``. A journal written before that field existed decodes
    with its own recorded definition, which has no ``undoes``; there an undo's summary
    was the only link ("undo of revision 7 (...)", the words the server has always
    written), so it is read from the summary, here and nowhere else. The link matters
    when such a journal is resumed: the server's undo history then knows that the edit
    was undone, and that the undo itself can be undone (the redo).
    """
    undoes = getattr(msg, "undoes", None)
    if undoes is not None:
        return int(undoes)
    match = _OLD_UNDO_SUMMARY.match(msg.summary)
    return int(match.group(1)) if match else 0
