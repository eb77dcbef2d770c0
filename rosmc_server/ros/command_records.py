"""Journal records of the commands the ground queues for its robots.

The journal keeps, per command, when it was asked and when the robot acknowledged it (or
that it was cancelled while it waited), so that a command delivered long after it was
asked is never a mystery in a recording. Built here from the link's outgoing items.
"""

from __future__ import annotations

import rosmc.msg as wire

from ..conversions import time_to_msg
from ..core.robots.link import Outgoing


def command_record(
    event: int,
    item: Outgoing[wire.RobotCommand],
    asked: float,
    delivered: float = 0.0,
    result: int = 0,
) -> wire.CommandRecord:
    """A ``rosmc/CommandRecord`` of ``item``; ``asked`` and ``delivered`` are wall times."""
    command = item.payload
    return wire.CommandRecord(
        event=event,
        agent=command.agent,
        type=command.type,
        seq=item.seq,
        asked=time_to_msg(asked),
        delivered=time_to_msg(delivered),
        held=item.held,
        result=result,
        skill_ids=[skill.id for skill in command.skills] + list(command.skill_ids),
        argument=command.argument,
    )
