"""Packed events are byte for byte what genpy writes for the same event.

:class:`~rosmc_server.conversions.event_packing.PackedEvent` writes a mission event's
moves straight from the core's moves, once, for the journal and the topic. A receiver must
not be able to tell: random events of every kind of content (skills put, ids removed,
barriers, markers, many moves, tricky text and epochs) serialize exactly as
``event_to_msg`` with the epoch set does, and read back to the same core event.
"""

from __future__ import annotations

import random

import pytest
import rosmc.msg as wire

from rosmc_server.conversions import event_from_msg, event_to_msg
from rosmc_server.conversions.event_packing import (
    PACKED_EVENT_MD5,
    PackedEvent,
    packed_event,
)
from rosmc_server.conversions.move_fields import order_from_field, order_to_field
from rosmc_server.conversions.packing import serialized
from rosmc_server.core import Barrier, EventKind, Library, MissionEvent
from rosmc_server.core.model.changes import Change, PlacedSkill, SkillMove
from rosmc_server.core.skills.library import library_from_dict
from tests.unit.conftest import TEST_LIBRARY
from tests.unit.random_missions import random_content, text

ALPHABET = ["a", "Z", "0", "-", "_", " ", "é", "ß", "→", "火", "\u2028", '"']


@pytest.fixture(scope="module")
def library() -> Library:
    return library_from_dict(TEST_LIBRARY)


def test_the_packed_writer_is_in_use() -> None:
    # A changed rosmc/MissionEvent definition falls back to genpy; this asks for an update.
    assert wire.MissionEvent._md5sum == PACKED_EVENT_MD5


def random_events(library: Library, count: int, seed: int) -> list[MissionEvent]:
    """Events of random content over the skills of a random mission."""
    rng = random.Random(seed)
    content = random_content(library, 600, seed=seed)
    skills = [skill for task in content.tasks.values() for skill in task]
    ids = [skill.id for skill in skills]
    events = []
    for number in range(count):
        moves = tuple(
            SkillMove(rng.choice(ids), rng.randrange(0, 2**32))
            for _ in range(rng.choice((0, 1, 3, 40, 600)))
        )
        members = tuple(rng.sample(ids, rng.randrange(0, 4)))
        change = Change(
            put_skills=tuple(
                PlacedSkill(rng.randrange(0, 1000), skill)
                for skill in rng.sample(skills, rng.randrange(0, 4))
            ),
            removed_skill_ids=tuple(rng.sample(ids, rng.randrange(0, 4))),
            order_agent=text(rng, ALPHABET),
            put_barriers=(Barrier(text(rng, ALPHABET), members),) if members else (),
            removed_barrier_ids=tuple(text(rng, ALPHABET) for _ in range(rng.randrange(3))),
            put_markers=tuple(rng.sample(list(content.markers.values()), 1)),
            removed_marker_names=tuple(text(rng, ALPHABET) for _ in range(rng.randrange(3))),
            moves=moves,
        )
        kind = rng.choice(list(EventKind))
        stamp = rng.randrange(0, 2**31) + rng.randrange(0, 10**9) / 1e9
        undoes = rng.choice((0, 0, rng.randrange(1, 2**40)))
        agent, summary = text(rng, ALPHABET), text(rng, ALPHABET)
        events.append(MissionEvent(number, kind, agent, summary, stamp, change, undoes))
    return events


def test_every_event_packs_as_genpy_serializes_it(library: Library) -> None:
    rng = random.Random(5)
    for event in random_events(library, 200, seed=31):
        epoch = text(rng, ALPHABET, most=40)

        def located(skill_id: str) -> str:
            return skill_id[:3]  # a barrier member's agent, as the server's state gives it

        expected = event_to_msg(event, located)
        expected.epoch = epoch
        packed = packed_event(event, located, epoch)
        assert isinstance(packed, PackedEvent)
        assert serialized(packed) == serialized(expected), event.revision
        read = wire.MissionEvent().deserialize(serialized(packed))
        assert read == expected
        assert event_from_msg(read) == event_from_msg(expected)
        assert packed.revision == event.revision and packed.epoch == epoch
        assert event_from_msg(read).undoes == event.undoes


def test_a_whole_reorder_event_carries_every_move_in_order(library: Library) -> None:
    moves = tuple(SkillMove(f"robot-s{n:05d}", 10_000 - n) for n in range(10_000))
    change = Change(order_agent="robot", moves=moves)
    event = MissionEvent(9, EventKind.SKILLS_REORDERED, "robot", "reordered", 3.5, change)
    packed = packed_event(event, str, "epoch-1")
    read = wire.MissionEvent().deserialize(serialized(packed))
    assert not read.moves and read.move_ids.count("\n") == len(moves) - 1
    assert list(event_from_msg(read).change.moves) == list(moves)
    assert read.order_agent == "robot" and read.epoch == "epoch-1"
    assert "packed" in str(packed)


def test_moves_whose_ids_hold_a_line_break_travel_as_messages() -> None:
    # Only an id that never passed the id check can hold one; it must not split in two.
    moves = (SkillMove("a\nb", 3), SkillMove("c", 4))
    event = MissionEvent(
        2, EventKind.SKILLS_REORDERED, "r", "s", 1.0, Change(order_agent="r", moves=moves)
    )
    read = wire.MissionEvent().deserialize(serialized(packed_event(event, str, "e")))
    assert [(m.skill_id, m.index) for m in read.moves] == [("a\nb", 3), ("c", 4)]
    assert not read.move_indexes and event_from_msg(read).change.moves == moves


def test_a_whole_order_travels_as_lines_and_reads_back() -> None:
    order = [f"robot-s{n:05d}" for n in range(1000)]
    assert order_to_field(order) == ["\n".join(order)]
    assert order_from_field(order_to_field(order)) == order
    for plain in ([], ["one"], ["a\nb", "c"]):  # too short to join, or an id with a break
        assert order_to_field(plain) == plain and order_from_field(plain) == plain
