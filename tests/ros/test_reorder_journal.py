"""Reorders in journals: the moves new events carry, and the whole orders of old journals.

A real core mission is journaled the way the server journals it; the recording's
history and a resume (latest snapshot, then every event through ``Mission.replay``)
must give the order the mission had at every revision. A journal written before
``MissionEvent`` had ``moves`` (its recorded definition lacks the field, and its
reorders list the agent's whole blueprint), and one written before the packed
``move_ids`` / ``move_indexes`` (its moves are ``SkillMove`` messages), must still
read, replay and resume.
No ROS master.
"""

from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest
from mcap.writer import Writer as McapWriter

wire = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.conversions import (  # noqa: E402
    event_from_msg,
    event_to_msg,
    mission_from_msg,
    mission_to_msg,
    moves_to_msgs,
)
from rosmc_server.core import (  # noqa: E402
    Change,
    EventKind,
    Mission,
    MissionContent,
    MissionEvent,
    RuleViolation,
    load_library,
)
from rosmc_server.core.model.changes import SkillMove  # noqa: E402
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC  # noqa: E402
from rosmc_server.recording import JournalWriter, latest_state, read_journal  # noqa: E402
from rosmc_server.recording._mcap.codec import serialize  # noqa: E402
from rosmc_server.recording.history import MissionHistory  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
LIBRARY = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
T0 = 1_700_000_000_000_000_000
SECTION = "\n" + "=" * 80 + "\n"


def team_mission() -> Mission:
    """Ten skills per robot, two barriers across them, the drone's first two uploading."""
    counter = iter(range(10**6))
    mission = Mission(LIBRARY, clock=lambda: 5.0, new_id=lambda p: f"{p}-{next(counter)}")
    for agent in LIBRARY.dynamic_agents:
        for _ in range(10):
            mission.add_skill(agent, "navigate_to")
    mission.synchronize("drone", mission.state.task("drone")[1].id)
    ids = {a: [s.id for s in mission.state.task(a)] for a in LIBRARY.dynamic_agents}
    mission.add_barrier([ids["drone"][4], ids["science_rover"][3]])
    mission.add_barrier([ids["science_rover"][7], ids["manipulator_rover"][6]])
    return mission


def orders(content: MissionContent) -> dict[str, list[str]]:
    return {agent: [s.id for s in task] for agent, task in content.tasks.items()}


def resumed(path: Path) -> Mission:
    """What the server does with ``~resume``: the newest snapshot, then every later event."""
    latest = latest_state(read_journal(path))
    content, revision = mission_from_msg(latest.snapshot)
    mission = Mission(LIBRARY, content, revision)
    for event_msg in latest.events:
        mission.replay(event_from_msg(event_msg))
    return mission


def test_reorders_journaled_as_moves_replay_to_the_order_of_every_revision(
    tmp_path: Path,
) -> None:
    mission = team_mission()
    path = tmp_path / "moves.mcap"
    snapshot = mission_to_msg(mission.state.content(), mission.revision, 0.0)
    live = {mission.revision: mission.state.content()}
    rng = random.Random(3)
    with JournalWriter.create(path, snapshot, T0) as writer:
        for step in range(40):
            agent = rng.choice(LIBRARY.dynamic_agents)
            start = mission.state.sections(agent).editable_start
            ids = [s.id for s in mission.state.task(agent)[start:]]
            try:
                if step % 2:
                    skill_id = rng.choice(ids)
                    index = rng.randrange(start, start + len(ids))
                    event = mission.move_skills(agent, [SkillMove(skill_id, index)])
                else:
                    event = mission.reorder(agent, rng.sample(ids, len(ids)))
            except RuleViolation:
                continue  # a deadlock, refused
            msg = event_to_msg(event, mission.state.agent_of)
            assert not msg.blueprint_order and not msg.moves
            assert len(msg.move_indexes) == len(event.change.moves)
            writer.append_event(msg, T0 + event.revision)
            live[event.revision] = mission.state.content()
    assert len(live) > 15
    history = MissionHistory.from_journal(path)
    assert not history.problems
    for revision, content in live.items():
        assert orders(history.at_revision(revision).content()) == orders(content)
    assert resumed(path).state.content() == mission.state.content()


PACKED_MOVES = ("string move_ids", "uint32[] move_indexes", "uint64 undoes")


def old_mission_event_definition(moves_as_messages: bool = False) -> bytes:
    """``rosmc/MissionEvent`` as journals recorded it before the packed move fields (and
    ``undoes``, which came later), and (unless ``moves_as_messages``) before reorders
    carried moves at all."""
    dropped = PACKED_MOVES if moves_as_messages else ("SkillMove[]", *PACKED_MOVES)
    main, *sections = str(wire.MissionEvent._full_text).split(SECTION)
    main = "\n".join(line for line in main.split("\n") if not line.startswith(dropped))
    kept = [s for s in sections if moves_as_messages or not s.startswith("MSG: rosmc/SkillMove")]
    return SECTION.join([main, *kept]).encode()


def old_event_bytes(event: MissionEvent, mission: Mission) -> bytes:
    """The event serialized without ``moves``, the packed move fields and ``undoes``: with
    an empty epoch, its last 24 bytes are five empty fields (moves, epoch, move ids, move
    indexes, undoes), of which the old definition has one."""
    msg = event_to_msg(event, mission.state.agent_of)
    assert not msg.moves and not msg.move_indexes and not msg.epoch and not msg.undoes
    data = serialize(msg)
    assert data.endswith(b"\0" * 24)
    return data[:-20]


def moves_as_messages_bytes(event: MissionEvent, mission: Mission) -> bytes:
    """The event serialized as journals did before the packed move fields: its moves as
    ``SkillMove`` messages, and without the two packed fields and ``undoes`` (empty: the
    last 16 bytes)."""
    msg = event_to_msg(event, mission.state.agent_of)
    msg.moves = moves_to_msgs(event.change.moves)
    msg.move_ids, msg.move_indexes = "", ()
    data = serialize(msg)
    assert data.endswith(b"\0" * 16)
    return data[:-16]


def write_old_journal(
    path: Path, snapshot: Any, events: list[bytes], moves_as_messages: bool = False
) -> None:
    with path.open("wb") as file:
        writer = McapWriter(file)
        writer.start(profile="ros1", library="rosmc before moves")
        mission_schema = writer.register_schema(
            "rosmc/Mission", "ros1msg", str(wire.Mission._full_text).encode()
        )
        event_schema = writer.register_schema(
            "rosmc/MissionEvent", "ros1msg", old_mission_event_definition(moves_as_messages)
        )
        snapshots = writer.register_channel(MISSION_TOPIC, "ros1", mission_schema)
        changes = writer.register_channel(EVENTS_TOPIC, "ros1", event_schema)
        writer.add_message(snapshots, log_time=T0, data=serialize(snapshot), publish_time=T0)
        for number, data in enumerate(events, start=1):
            writer.add_message(changes, log_time=T0 + number, data=data, publish_time=T0 + number)
        writer.finish()


def test_an_old_journal_whose_reorders_list_the_whole_order_still_replays(
    tmp_path: Path,
) -> None:
    mission = team_mission()
    snapshot = mission_to_msg(mission.state.content(), mission.revision, 0.0)
    blueprint = [s.id for s in mission.state.task("drone")[2:]]  # after the two uploading
    new_order = blueprint[5:] + blueprint[:5]  # the drone's one barrier member: no deadlock
    old_reorder = MissionEvent(
        mission.revision + 1,
        EventKind.SKILLS_REORDERED,
        "drone",
        "drone's blueprint reordered",
        6.0,
        Change(order_agent="drone", blueprint_order=tuple(new_order)),
    )
    mission.replay(old_reorder)
    after = mission.add_skill("drone", "land", index=3)  # a later event lands where it should
    path = tmp_path / "old.mcap"
    write_old_journal(
        path, snapshot, [old_event_bytes(old_reorder, mission), old_event_bytes(after, mission)]
    )

    result = read_journal(path)
    assert any("recorded definition of rosmc/MissionEvent" in w for w in result.warnings)
    first = event_from_msg(result.records[1].message)
    assert first.change.blueprint_order == tuple(new_order) and first.change.moves == ()
    history = MissionHistory.from_journal(path)
    assert not history.problems
    final = history.at_revision(after.revision).content()
    assert orders(final) == orders(mission.state.content())
    drone = orders(history.at_revision(old_reorder.revision).content())["drone"]
    assert drone[2:] == new_order
    assert resumed(path).state.content() == mission.state.content()


def test_a_journal_whose_moves_are_messages_still_replays(tmp_path: Path) -> None:
    mission = team_mission()
    snapshot = mission_to_msg(mission.state.content(), mission.revision, 0.0)
    blueprint = [s.id for s in mission.state.task("drone")[2:]]
    reorder = mission.reorder("drone", blueprint[5:] + blueprint[:5])
    moved = mission.move_skills("drone", [SkillMove(blueprint[0], 2)])
    after = mission.add_skill("drone", "land", index=3)
    path = tmp_path / "messages.mcap"
    events = [moves_as_messages_bytes(event, mission) for event in (reorder, moved, after)]
    write_old_journal(path, snapshot, events, moves_as_messages=True)

    result = read_journal(path)
    assert any("recorded definition of rosmc/MissionEvent" in w for w in result.warnings)
    read = [event_from_msg(record.message) for record in result.records[1:]]
    assert [list(e.change.moves) for e in read] == [
        list(e.change.moves) for e in (reorder, moved, after)
    ]
    assert read[0].change.moves and read[1].change.moves == (SkillMove(blueprint[0], 2),)
    history = MissionHistory.from_journal(path)
    assert not history.problems
    assert orders(history.at_revision(reorder.revision).content())["drone"][2:] == (
        blueprint[5:] + blueprint[:5]
    )
    assert resumed(path).state.content() == mission.state.content()
