"""Collapse superseded commands while they still wait to leave for a robot.

Commands to a robot the ground has not heard yet (or not since the server started) wait
unnumbered in the link's outbox. An operator who synchronizes and takes the skills back
again, or presses start twice, should not build up work the robot receives in one burst
when it appears. Before a new command is queued, :func:`collapse` cancels it against the
unsent ones it supersedes:

* an UNSYNC of skills that are still in an unsent UPLOAD removes them from that upload
  (and the upload when it empties) and needs nothing sent for them;
* BARRIERS and SET_OPTIONS replace the robot's whole barrier set / options: an unsent older
  one is withdrawn;
* a control equal to the last unsent command is a repeat; RESUME right after an unsent
  PAUSE (or the reverse) cancels both.

Commands already transmitted are never touched: the robot may have them, and their sequence
numbers are given out.
"""

from __future__ import annotations

import rosmc.msg as wire

from ..core.commands import CommandKind
from ..core.link import Outbox

MAX_UNSENT = 200  # per robot; more is refused before the mission changes (see operator services)

_REPLACING = (CommandKind.BARRIERS, CommandKind.SET_OPTIONS)
_CONTROLS = (CommandKind.START, CommandKind.PAUSE, CommandKind.RESUME, CommandKind.STOP)
_OPPOSITE = {CommandKind.PAUSE: CommandKind.RESUME, CommandKind.RESUME: CommandKind.PAUSE}


def collapse(
    outbox: Outbox[wire.RobotCommand], command: wire.RobotCommand
) -> wire.RobotCommand | None:
    """``command`` after cancelling it against unsent ones; None if nothing is left to send."""
    kind = CommandKind(command.type)
    if kind is CommandKind.UNSYNC:
        return _unsync(outbox, command)
    if kind in _REPLACING:
        for item in outbox.unsent():
            if item.payload.type == kind:
                outbox.withdraw(item)
        return command
    if kind in _CONTROLS:
        pending = outbox.pending()
        last = pending[-1] if pending and not (pending[-1].seq or pending[-1].attempts) else None
        if last is not None and last.payload.type == kind:
            return None  # the same control is already waiting
        if last is not None and _OPPOSITE.get(kind) == last.payload.type:
            outbox.withdraw(last)
            return None
    return command


def _unsync(
    outbox: Outbox[wire.RobotCommand], command: wire.RobotCommand
) -> wire.RobotCommand | None:
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
            outbox.withdraw(item)
    if not remaining:
        return None
    command.skill_ids = remaining
    return command
