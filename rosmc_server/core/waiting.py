"""Operator commands that wait for contact with a robot: the rules, free of ROS.

A command for a robot the ground cannot hear (never heard, or heard before and silent for
longer than the link timeout) is the operator's intent: it is accepted, held unsent and
unnumbered in the link's :class:`~rosmc_server.core.link.Outbox`, and leaves, in order and
once, when the robot is heard. While it waits it can be cancelled or superseded, so what
waits stays small. Before a new command is queued, :func:`collapse` cancels it against the
unsent ones it supersedes:

* an UNSYNC of skills that are still in an unsent UPLOAD removes them from that upload
  (and the upload when it empties) and needs nothing sent for them: a take-back cancels a
  waiting send;
* BARRIERS and SET_OPTIONS replace the robot's whole barrier set / options: an unsent older
  one is withdrawn (a second policy change replaces the first);
* a control equal to the last unsent command is a repeat; RESUME right after an unsent
  PAUSE (or the reverse) cancels both; STOP withdraws the START, PAUSE and RESUME waiting
  right before it (the robot is to end up stopped either way).

Commands already transmitted are never touched: the robot may have them, and their sequence
numbers are given out. At most :data:`MAX_WAITING` commands wait per robot;
:func:`refusal` words the one-sentence answer beyond that.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, Protocol, TypeVar

from .commands import CommandKind
from .link import Outbox, Outgoing
from .vocabulary import counted

MAX_WAITING = 50  # unsent commands per robot; more is refused before the mission changes

_REPLACING = (CommandKind.BARRIERS, CommandKind.SET_OPTIONS)
_CONTROLS = (CommandKind.START, CommandKind.PAUSE, CommandKind.RESUME, CommandKind.STOP)
_OPPOSITE = {CommandKind.PAUSE: CommandKind.RESUME, CommandKind.RESUME: CommandKind.PAUSE}
_STOPPED_BY_STOP = (CommandKind.START, CommandKind.PAUSE, CommandKind.RESUME)


class Command(Protocol):
    """What the rules read and change of a command (``rosmc/RobotCommand`` has it all)."""

    type: int
    skills: list[Any]  # each with an ``id``
    skill_ids: list[str]


C = TypeVar("C", bound=Command)


@dataclass
class Collapsed:
    """What :func:`collapse` made of a new command.

    ``kept`` is the command to queue (None: nothing is left to send); ``withdrawn`` are the
    unsent commands it cancelled, in queue order.
    """

    kept: Any
    withdrawn: list[Any] = field(default_factory=list)


def collapse(outbox: Outbox[C], command: C) -> Collapsed:
    """``command`` after cancelling it against the unsent ones it supersedes."""
    kind = CommandKind(command.type)
    result = Collapsed(command)
    if kind is CommandKind.UNSYNC:
        result.kept = _unsync(outbox, command, result.withdrawn)
    elif kind in _REPLACING:
        for item in outbox.unsent():
            if item.payload.type == kind:
                _withdraw(outbox, item, result.withdrawn)
    elif kind in _CONTROLS:
        result.kept = _control(outbox, command, kind, result.withdrawn)
    return result


def _withdraw(outbox: Outbox[C], item: Outgoing[C], withdrawn: list[Any]) -> None:
    outbox.withdraw(item)
    withdrawn.append(item)


def _last_unsent(outbox: Outbox[C]) -> Outgoing[C] | None:
    pending = outbox.pending()
    last = pending[-1] if pending else None
    return last if last is not None and not (last.seq or last.attempts) else None


def _control(outbox: Outbox[C], command: C, kind: CommandKind, withdrawn: list[Any]) -> C | None:
    if kind is CommandKind.STOP:
        while (last := _last_unsent(outbox)) is not None and last.payload.type in _STOPPED_BY_STOP:
            _withdraw(outbox, last, withdrawn)
    last = _last_unsent(outbox)
    if last is not None and last.payload.type == kind:
        return None  # the same control is already waiting
    if last is not None and _OPPOSITE.get(kind) == last.payload.type:
        _withdraw(outbox, last, withdrawn)
        return None
    return command


def _unsync(outbox: Outbox[C], command: C, withdrawn: list[Any]) -> C | None:
    remaining = list(command.skill_ids)
    for item in outbox.unsent():
        upload = item.payload
        if upload.type != CommandKind.UPLOAD:
            continue
        cancelled = {skill.id for skill in upload.skills} & set(remaining)
        if not cancelled:
            continue
        upload.skills = [skill for skill in upload.skills if skill.id not in cancelled]
        remaining = [skill_id for skill_id in remaining if skill_id not in cancelled]
        if not upload.skills:
            _withdraw(outbox, item, withdrawn)
    if not remaining:
        return None
    command.skill_ids = remaining
    return command


def refusal(agent: str, waiting: int, limit: int = MAX_WAITING) -> str:
    """The one-sentence refusal when ``agent`` has ``waiting`` unsent commands, "" below it."""
    if waiting < limit:
        return ""
    return (
        f"{agent} already has {limit} commands waiting for contact; "
        "take some back or wait until the robot is heard"
    )


def duration_text(seconds: float) -> str:
    """A wait in the largest unit that reads well: ``40 s``, ``2 min``, ``3 h``."""
    if seconds < 60:
        return f"{max(0, int(seconds))} s"
    if seconds < 3600:
        return f"{int(seconds // 60)} min"
    return f"{int(seconds // 3600)} h"


def waiting_text(count: int, seconds: float) -> str:
    """``2 commands waiting for contact 3 min`` (the oldest's age); "" if none waits."""
    if count <= 0:
        return ""
    age = f" {duration_text(seconds)}" if seconds >= 0 else ""
    return f"{counted(count, 'command')} waiting for contact{age}"


def queued_notes(waiting: Iterable[tuple[str, bool, float]]) -> list[str]:
    """Notes for a command that waits for several robots: ``(agent, never heard, last heard)``.

    Robots never heard share one note; each robot out of contact has its own (its age).
    """
    waiting = list(waiting)
    unheard = [agent for agent, never_heard, _ in waiting if never_heard]
    notes = [queued_note(", ".join(unheard), True, -1.0)] if unheard else []
    return notes + [queued_note(a, False, last) for a, never, last in waiting if not never]


def queued_note(agent: str, never_heard: bool, last_heard: float) -> str:
    """What an operator's answer says about a command that waits for ``agent``."""
    if never_heard:
        return (
            f"queued for {agent}: not heard since the server started; "
            "it goes out when the robot first reports"
        )
    return (
        f"queued for {agent}: out of contact (last heard {duration_text(last_heard)} ago); "
        "it goes out when the robot is heard again"
    )
