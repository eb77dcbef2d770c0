"""Operator commands that wait for contact with a robot: the rules, free of ROS.

A command for a robot the ground cannot hear (never heard, or heard before and silent for
longer than the link timeout) is the operator's intent: it is accepted, held unsent and
unnumbered in the link's :class:`~rosmc_server.core.robots.link.Outbox`, and leaves, in order and
once, when the robot is heard. While it waits it can be cancelled or superseded, so what
waits stays small. Before a new command is queued, :func:`collapse` cancels it against the
unsent ones it supersedes:

* an UNSYNC of skills that are still in an unsent UPLOAD removes them from that upload
  (and the upload when it empties) and needs nothing sent for them: a take-back cancels a
  waiting send;
* BARRIERS and SET_OPTIONS replace the robot's whole barrier set / options: an unsent older
  one is withdrawn (a second policy change replaces the first: the latest wins);
* controls collapse with what waits, wherever it waits in the queue, so that at most one
  STOP, one START and one PAUSE or RESUME wait at a time: a control equal to one still
  waiting is a repeat (a START only if no upload waits after it: the robot is to start
  what was sent after too); RESUME cancels a waiting PAUSE (and the reverse) and needs
  nothing sent; STOP withdraws every waiting START, PAUSE and RESUME (the robot is to end
  up stopped either way).

Commands already transmitted are never touched: the robot may have them, and their sequence
numbers are given out. Only *work* is bounded (:func:`is_work`: uploads, take-backs,
retries, skips): at most :data:`MAX_WAITING` of it waits per robot, and :func:`refusal`
words the one-sentence answer beyond that. Commands that make a robot safer or let it go on
(stop, pause, resume, start, a lost-link policy) are never refused for lack of room: they
collapse as above, so they cannot pile up.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, Protocol, TypeVar

from ..errors import RuleViolation, Unavailable
from ..skills.library import Library
from ..views.vocabulary import counted
from .commands import CommandKind
from .link import Outbox, Outgoing

MAX_WAITING = 50  # unsent work per robot; more is refused before the mission changes

_REPLACING = (CommandKind.BARRIERS, CommandKind.SET_OPTIONS)
_CONTROLS = (CommandKind.START, CommandKind.PAUSE, CommandKind.RESUME, CommandKind.STOP)
_OPPOSITE = {CommandKind.PAUSE: CommandKind.RESUME, CommandKind.RESUME: CommandKind.PAUSE}
_STOPPED_BY_STOP = (CommandKind.START, CommandKind.PAUSE, CommandKind.RESUME)
_WORK = frozenset((CommandKind.UPLOAD, CommandKind.UNSYNC, CommandKind.RETRY, CommandKind.SKIP))


def is_work(kind: int) -> bool:
    """Whether a command of ``kind`` counts against :data:`MAX_WAITING` (see the module)."""
    return kind in _WORK


def waiting_work(outbox: Outbox[C]) -> int:
    """How much work waits unsent in ``outbox`` (what the bound counts)."""
    return sum(1 for item in outbox.unsent() if is_work(item.payload.type))


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


def _control(outbox: Outbox[C], command: C, kind: CommandKind, withdrawn: list[Any]) -> C | None:
    unsent = outbox.unsent()
    if kind is CommandKind.STOP:
        for item in unsent:
            if item.payload.type in _STOPPED_BY_STOP:
                _withdraw(outbox, item, withdrawn)
        return None if any(i.payload.type == kind for i in unsent) else command
    if kind is CommandKind.START:
        starts = [n for n, item in enumerate(unsent) if item.payload.type == kind]
        if starts and not any(
            item.payload.type == CommandKind.UPLOAD for item in unsent[starts[-1] :]
        ):
            return None  # the waiting START starts all that waits
        return command
    waiting = [item for item in unsent if item.payload.type in _OPPOSITE]
    last = waiting[-1] if waiting else None
    if last is not None and last.payload.type == kind:
        return None  # the same control is already waiting
    if last is not None:  # its opposite waits: neither needs to go
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


def room_refusal(
    agent: str, kind: CommandKind | None, waiting: int, limit: int = MAX_WAITING
) -> str:
    """The bound on waiting work, as the services apply it before the mission changes: the
    one-sentence refusal of a command of ``kind`` for ``agent``, which has ``waiting`` unsent
    work commands (:func:`waiting_work`); "" if it may wait. Only work is bounded: a control
    or a policy collapses with what waits, and ``kind`` None (a take-back that cancels an
    unanswered upload) withdraws work rather than adding some."""
    if kind is None or not is_work(kind):
        return ""
    return refusal(agent, waiting, limit)


def check_link_command(
    library: Library, agent: str, kind: CommandKind | None, waiting: Callable[[], int]
) -> None:
    """Refuse a command of ``kind`` for ``agent`` that its robot link cannot take: an unknown
    agent (NotFound), a static one, which has no link (RuleViolation), or one whose bound
    on waiting work is reached (Unavailable, :func:`room_refusal`; ``waiting`` counts its
    unsent work). Out of contact is no reason: the command waits."""
    if agent not in library.dynamic_agents:
        library.agent(agent)
        raise RuleViolation(f"'{agent}' is a static agent and has no robot link")
    sentence = room_refusal(agent, kind, waiting())
    if sentence:
        raise Unavailable(sentence)


def refusal(agent: str, waiting: int, limit: int = MAX_WAITING) -> str:
    """The one-sentence refusal of more work when ``agent`` has ``waiting`` unsent work
    commands (:func:`waiting_work`), "" below the bound."""
    if waiting < limit:
        return ""
    return (
        f"{agent} already has {limit} uploads and take-backs waiting for contact; take some "
        "back or wait until the robot is heard (stop, pause, resume and policies still go)"
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
