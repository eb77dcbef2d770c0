"""Superseded commands collapse while they wait, unsent, for a robot (ros/command_queue.py)."""

from __future__ import annotations

import rosmc.msg as wire

from rosmc_server.core.commands import CommandKind
from rosmc_server.core.link import Outbox
from rosmc_server.ros.command_queue import collapse


def command(kind: CommandKind, skills: tuple[str, ...] = (), ids: tuple[str, ...] = ()):
    return wire.RobotCommand(
        type=int(kind), skills=[wire.Skill(id=s) for s in skills], skill_ids=list(ids)
    )


def queue(outbox: Outbox[wire.RobotCommand], msg: wire.RobotCommand) -> None:
    kept = collapse(outbox, msg)
    if kept is not None:
        outbox.enqueue(kept)


def kinds(outbox: Outbox[wire.RobotCommand]) -> list[tuple[CommandKind, list[str]]]:
    return [
        (CommandKind(i.payload.type), [s.id for s in i.payload.skills] + i.payload.skill_ids)
        for i in outbox.pending()
    ]


def test_an_unsync_cancels_what_an_unsent_upload_would_have_brought() -> None:
    outbox: Outbox[wire.RobotCommand] = Outbox()
    queue(outbox, command(CommandKind.UPLOAD, ("a", "b", "c")))
    queue(outbox, command(CommandKind.UNSYNC, ids=("b", "c", "x")))
    assert kinds(outbox) == [(CommandKind.UPLOAD, ["a"]), (CommandKind.UNSYNC, ["x"])]
    queue(outbox, command(CommandKind.UNSYNC, ids=("a",)))
    assert kinds(outbox) == [(CommandKind.UNSYNC, ["x"])]


def test_replacing_commands_and_repeated_controls_keep_only_what_matters() -> None:
    outbox: Outbox[wire.RobotCommand] = Outbox()
    queue(outbox, command(CommandKind.BARRIERS))
    queue(outbox, command(CommandKind.START))
    queue(outbox, command(CommandKind.START))
    queue(outbox, command(CommandKind.BARRIERS))
    assert kinds(outbox) == [(CommandKind.START, []), (CommandKind.BARRIERS, [])]
    queue(outbox, command(CommandKind.PAUSE))
    queue(outbox, command(CommandKind.RESUME))
    assert kinds(outbox) == [(CommandKind.START, []), (CommandKind.BARRIERS, [])]


def test_commands_already_transmitted_are_never_touched() -> None:
    outbox: Outbox[wire.RobotCommand] = Outbox()
    outbox.robot_numbering(0, now=0.0)  # the robot has been heard: commands go out
    queue(outbox, command(CommandKind.UPLOAD, ("a",)))
    queue(outbox, command(CommandKind.START))
    assert len(outbox.due(0.0)) == 2
    queue(outbox, command(CommandKind.UNSYNC, ids=("a",)))
    queue(outbox, command(CommandKind.START))
    assert kinds(outbox) == [
        (CommandKind.UPLOAD, ["a"]),
        (CommandKind.START, []),
        (CommandKind.UNSYNC, ["a"]),
        (CommandKind.START, []),
    ]
