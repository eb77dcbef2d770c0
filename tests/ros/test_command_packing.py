"""Packed robot commands are byte for byte what genpy writes for the same command.

:class:`~rosmc_server.conversions.command_packing.PackedCommand` keeps an upload's skills
as the core's skill instances and writes them when the command is sent. A robot must not
be able to tell: random commands of every kind (many skills, ids, barriers, tricky text,
numbered and stamped as a transmission numbers them) serialize exactly as the genpy
message of the same command does, also after an unsynchronize shortened the skills.
"""

from __future__ import annotations

import random

import genpy
import rosmc.msg as wire

from rosmc_server.conversions import barrier_to_msg, skill_to_msg
from rosmc_server.conversions.command_packing import (
    PACKED_COMMAND_MD5,
    PackedCommand,
    command_msg,
)
from rosmc_server.conversions.packing import serialized
from rosmc_server.core import Barrier
from rosmc_server.core.robots.commands import CommandKind, CommandSpec
from rosmc_server.core.robots.link import Outbox
from rosmc_server.core.robots.waiting import collapse
from rosmc_server.core.skills.library import library_from_dict
from tests.ros.test_event_packing import ALPHABET
from tests.unit.conftest import TEST_LIBRARY
from tests.unit.random_missions import random_content, text


def test_the_packed_writer_is_in_use() -> None:
    # A changed rosmc/RobotCommand definition falls back to genpy; this asks for an update.
    assert wire.RobotCommand._md5sum == PACKED_COMMAND_MD5


def agent_of(skill_id: str) -> str:
    return skill_id[:3]


def genpy_command(spec: CommandSpec) -> wire.RobotCommand:
    """The command as a plain genpy message (what the link queued before packing)."""
    return wire.RobotCommand(
        agent=spec.agent,
        type=int(spec.kind),
        skills=[skill_to_msg(s) for s in spec.skills],
        skill_ids=list(spec.skill_ids),
        barriers=[barrier_to_msg(b, agent_of) for b in spec.barriers],
        argument=spec.argument,
    )


def random_specs(count: int, seed: int) -> list[CommandSpec]:
    library = library_from_dict(TEST_LIBRARY)
    rng = random.Random(seed)
    skills = [s for task in random_content(library, 600, seed=seed).tasks.values() for s in task]
    ids = [skill.id for skill in skills]
    specs = []
    for _ in range(count):
        members = tuple(rng.sample(ids, rng.randrange(0, 4)))
        specs.append(
            CommandSpec(
                text(rng, ALPHABET),
                rng.choice(list(CommandKind)),
                tuple(rng.sample(skills, rng.choice((0, 1, 3, 40, 300)))),
                tuple(rng.sample(ids, rng.randrange(0, 4))),
                (Barrier(text(rng, ALPHABET), members),) if members else (),
                text(rng, ALPHABET, most=30),
            )
        )
    return specs


def test_every_command_packs_as_genpy_serializes_it() -> None:
    rng = random.Random(3)
    for number, spec in enumerate(random_specs(150, seed=17)):
        packed, expected = command_msg(spec, agent_of), genpy_command(spec)
        assert isinstance(packed, PackedCommand)
        for _ in range(2):  # a retransmission is numbered and stamped anew
            seq, stamp = rng.randrange(2**64), genpy.Time(rng.randrange(2**31), 7)
            packed.seq, packed.stamp = expected.seq, expected.stamp = seq, stamp
            assert serialized(packed) == serialized(expected), number
        read = wire.RobotCommand().deserialize(serialized(packed))
        assert read == expected
        assert [s.id for s in packed.skills] == list(s.id for s in spec.skills)


def test_an_upload_shortened_by_an_unsynchronize_sends_the_skills_it_kept() -> None:
    skills = random_content(library_from_dict(TEST_LIBRARY), 60, seed=4).tasks["alpha"]
    upload = CommandSpec("alpha", CommandKind.UPLOAD, tuple(skills))
    outbox: Outbox[wire.RobotCommand] = Outbox()
    queued = command_msg(upload, agent_of)
    before = serialized(queued)  # sent once, then withheld again: its bytes are kept
    outbox.enqueue(queued)
    unsync = command_msg(
        CommandSpec("alpha", CommandKind.UNSYNC, skill_ids=tuple(s.id for s in skills[5:])),
        agent_of,
    )
    collapse(outbox, unsync)
    kept = CommandSpec("alpha", CommandKind.UPLOAD, tuple(skills[:5]))
    assert serialized(queued) == serialized(genpy_command(kept)) != before
    assert "packed" in str(queued)
