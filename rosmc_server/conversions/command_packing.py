"""Robot commands whose skills stay the core's skill instances until they are sent.

Part of :mod:`rosmc_server.conversions`. An upload of 3,000 skills as a genpy
``rosmc/RobotCommand`` costs 3,000 ``rosmc/Skill`` messages built when the command is
queued, and genpy serializes them again on every transmission. A :class:`PackedCommand`
holds the core's (frozen) skills in ``skills``, which is all the link reads of them
(their ids: what the robot acknowledged, what an unsynchronize cancels), and writes their
bytes through :func:`~.packing.skill_bytes` when first sent; a retransmission reuses them.

Used only while ``rosmc/RobotCommand`` is the definition it was written for (its md5sum);
otherwise :func:`command_msg` gives the plain genpy message. A test checks the bytes
against genpy's for random commands.
"""

from __future__ import annotations

import io
import operator
from collections.abc import Callable, Sequence
from typing import Any

import rosmc.msg as wire

from ..core import SkillInstance
from ..core.robots.commands import CommandSpec
from .mission import barrier_to_msg, skill_to_msg
from .packing import skill_bytes, string_bytes

# The rosmc/RobotCommand definition PackedCommand writes (with its nested types).
PACKED_COMMAND_MD5 = "4bcb7f42f5857169c3e02119190ba777"

_SKILLS_AFTER_AGENT = 8 + 8 + 1  # seq, stamp and type come between the agent and the skills


class PackedCommand(wire.RobotCommand):  # type: ignore[misc]
    """A ``rosmc/RobotCommand`` whose ``skills`` are core skill instances.

    Every other field is an ordinary genpy field (``seq`` and ``stamp`` change on each
    transmission). ``skills`` may be replaced by a shorter list of the same instances (an
    unsynchronize cancels part of an upload not sent yet); the bytes follow it.
    """

    skills: list[SkillInstance]  # the genpy slot, holding core skills

    def __init__(self, **fields: Any) -> None:
        super().__init__(**fields)
        self._skill_bytes: tuple[list[SkillInstance], bytes] | None = None

    def serialize(self, buff: Any) -> None:
        """Write the message's wire bytes to ``buff``."""
        skills = self.skills
        self.skills = []
        try:
            head = io.BytesIO()
            super().serialize(head)
        finally:
            self.skills = skills
        data = head.getvalue()
        at = len(string_bytes(self.agent)) + _SKILLS_AFTER_AGENT
        buff.write(data[:at])
        buff.write(self.skills_bytes())
        buff.write(data[at + 4 :])  # after the empty array's count

    def skills_bytes(self) -> bytes:
        """The wire bytes of the ``rosmc/Skill[]`` of ``skills`` (made once per list)."""
        skills = self.skills
        cached = self._skill_bytes
        if cached is not None and _same(cached[0], skills):
            return cached[1]
        names: dict[str, bytes] = {}
        out = io.BytesIO()  # each skill's bytes written as made: not all of them, then joined
        out.write(len(skills).to_bytes(4, "little"))
        for skill in skills:
            out.write(skill_bytes(skill, names))
        data = out.getvalue()
        self._skill_bytes = (list(skills), data)
        return data

    def __str__(self) -> str:
        return (
            f"rosmc/RobotCommand {self.type} to {self.agent} seq {self.seq} "
            f"({len(self.skills)} skills, packed)"
        )

    __repr__ = __str__


def command_msg(spec: CommandSpec, agent_of: Callable[[str], str]) -> wire.RobotCommand:
    """``spec`` as the message the link queues: a :class:`PackedCommand` while the
    definition is the one it writes, else a genpy ``rosmc/RobotCommand``."""
    fields = {
        "agent": spec.agent,
        "type": int(spec.kind),
        "skill_ids": list(spec.skill_ids),
        "barriers": [barrier_to_msg(b, agent_of) for b in spec.barriers],
        "argument": spec.argument,
    }
    if wire.RobotCommand._md5sum != PACKED_COMMAND_MD5:
        return wire.RobotCommand(skills=[skill_to_msg(s) for s in spec.skills], **fields)
    return PackedCommand(skills=list(spec.skills), **fields)


def _same(old: Sequence[SkillInstance], new: Sequence[SkillInstance]) -> bool:
    return len(old) == len(new) and all(map(operator.is_, old, new))
