"""The undo link in journals: ``MissionEvent.undoes``, and old journals that lack it.

An undo names the edit it takes back in the event's typed ``undoes`` field; it travels
through the conversions and the journal, and a resumed server knows from it which edits
were undone (so the next undo walks back further, and undoing the undo is the redo). A
journal written before the field existed decodes with its recorded definition, which has
no ``undoes``: the decoding reads the link from the undo's summary there, and only there.
No ROS master.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.writer import Writer as McapWriter

wire = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.conversions import event_from_msg, event_to_msg, mission_to_msg  # noqa: E402
from rosmc_server.core import InvalidRequest, Mission, MissionEvent, load_library  # noqa: E402
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC  # noqa: E402
from rosmc_server.recording import JournalWriter, read_journal  # noqa: E402
from rosmc_server.recording._mcap.codec import serialize  # noqa: E402
from tests.ros.test_reorder_journal import SECTION, T0, resumed  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
LIBRARY = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")


def edited_and_undone() -> tuple[Mission, object, list[MissionEvent]]:
    """A mission with a skill added and edited, the edit undone: (mission, snapshot, events)."""
    counter = iter(range(10**6))
    mission = Mission(LIBRARY, clock=lambda: 5.0, new_id=lambda p: f"{p}-{next(counter)}")
    snapshot = mission_to_msg(mission.state.content(), mission.revision, 0.0)
    added = mission.add_skill("drone", "navigate_to")
    edited = mission.edit_skill(added.change.put_skills[0].skill.id, label="north")
    undo = mission.undo()
    return mission, snapshot, [added, edited, undo]


def test_an_undo_event_names_the_edit_it_takes_back_in_a_typed_field() -> None:
    mission, _, (added, edited, undo) = edited_and_undone()
    assert (added.undoes, edited.undoes, undo.undoes) == (0, 0, edited.revision)
    msg = event_to_msg(undo, mission.state.agent_of)
    assert msg.undoes == edited.revision
    assert event_from_msg(msg) == undo
    # The summary is words for people: a new event is never read from it.
    msg.undoes = 0
    assert undo.summary.startswith(f"undo of revision {edited.revision} (")
    assert event_from_msg(msg).undoes == 0


def test_a_resumed_mission_knows_which_edits_were_undone(tmp_path: Path) -> None:
    mission, snapshot, events = edited_and_undone()
    path = tmp_path / "journal.mcap"
    with JournalWriter.create(path, snapshot, T0) as writer:
        for event in events:
            writer.append_event(event_to_msg(event, mission.state.agent_of), T0 + event.revision)
    assert_resumes_with_the_link(path, mission, events)


def old_definition() -> bytes:
    """``rosmc/MissionEvent`` as journals recorded it before ``undoes``."""
    main, *sections = str(wire.MissionEvent._full_text).split(SECTION)
    main = "\n".join(line for line in main.split("\n") if not line.startswith("uint64 undoes"))
    return SECTION.join([main, *sections]).encode()


def test_an_old_journal_links_its_undos_through_their_summaries(tmp_path: Path) -> None:
    mission, snapshot, events = edited_and_undone()
    path = tmp_path / "old.mcap"
    with path.open("wb") as file:
        writer = McapWriter(file)
        writer.start(profile="ros1", library="rosmc before undoes")
        mission_schema = writer.register_schema(
            "rosmc/Mission", "ros1msg", str(wire.Mission._full_text).encode()
        )
        event_schema = writer.register_schema("rosmc/MissionEvent", "ros1msg", old_definition())
        snapshots = writer.register_channel(MISSION_TOPIC, "ros1", mission_schema)
        changes = writer.register_channel(EVENTS_TOPIC, "ros1", event_schema)
        writer.add_message(snapshots, log_time=T0, data=serialize(snapshot), publish_time=T0)
        for event in events:
            data = serialize(event_to_msg(event, mission.state.agent_of))
            at = T0 + event.revision
            # undoes, a uint64, is the last field: the old definition has no such bytes
            writer.add_message(changes, log_time=at, data=data[:-8], publish_time=at)
        writer.finish()

    result = read_journal(path)
    assert any("recorded definition of rosmc/MissionEvent" in w for w in result.warnings)
    read = [event_from_msg(record.message) for record in result.records[1:]]
    assert [e.undoes for e in read] == [0, 0, events[1].revision]
    assert_resumes_with_the_link(path, mission, events)


def assert_resumes_with_the_link(path: Path, mission: Mission, events: list[MissionEvent]) -> None:
    """The resumed mission equals ``mission``; its history knows the edit was undone."""
    _, edited, undo = events
    again = resumed(path)
    assert again.state.content() == mission.state.content()
    assert again.history.latest() == events[0].revision  # the add: the edit is undone
    redo = again.undo(undo.revision)  # undoing the undo brings the edit back
    assert redo.undoes == undo.revision
    assert again.state.skill(edited.change.put_skills[0].skill.id).label == "north"
    again.undo()  # the redo itself is the newest edit now
    with pytest.raises(InvalidRequest):
        again.undo(12345)
