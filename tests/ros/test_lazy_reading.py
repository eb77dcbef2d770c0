"""Reading a journal lazily gives what decoding every record gives.

The reader decodes a record on first use, reads revisions, kinds, summaries and stamps
from the bytes, leaves big payloads in the file (``DeferredMessage``), and the history
rebuilds a revision from the nearest snapshot. Each test compares those paths with the
full decode: every record decoded at once, and the mission replayed event by event from
the first snapshot (what the reader and the history did before), on journals written
as the server writes them (chunked and bare, closed and crash-left, damaged), on the
committed sample and on a journal of an older format. No ROS master.
"""

from __future__ import annotations

import random
import shutil
from pathlib import Path
from typing import Any

import pytest

wire = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.conversions import (  # noqa: E402
    event_from_msg,
    event_to_msg,
    mission_from_msg,
    mission_to_msg,
)
from rosmc_server.core import (  # noqa: E402
    EventKind,
    Mission,
    MissionContent,
    MissionState,
    RosmcError,
)
from rosmc_server.core.live.updates import apply_event  # noqa: E402
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC  # noqa: E402
from rosmc_server.recording import (  # noqa: E402
    JournalOptions,
    JournalWriter,
    latest_state,
    read_journal,
)
from rosmc_server.recording._mcap import scan as _scan  # noqa: E402
from rosmc_server.recording._mcap.codec import Decoder, serialize  # noqa: E402
from rosmc_server.recording._mcap.deferred import (  # noqa: E402
    HEAD_BYTES,
    DeferredMessage,
    payload_head,
)
from rosmc_server.recording.errors import JournalError  # noqa: E402
from rosmc_server.recording.history import MissionHistory  # noqa: E402
from rosmc_server.recording.lazy import Payload  # noqa: E402
from rosmc_server.recording.revisions import RevisionWalk  # noqa: E402
from tests.ros.recording_checks import SAMPLE  # noqa: E402
from tests.ros.test_reorder_journal import (  # noqa: E402
    LIBRARY,
    old_event_bytes,
    team_mission,
    write_old_journal,
)

T0 = 1_700_000_000_000_000_000


def plain_mission() -> Mission:
    """Six blueprint skills per robot."""
    counter = iter(range(10**6))
    mission = Mission(LIBRARY, clock=lambda: 5.0, new_id=lambda p: f"{p}-{next(counter)}")
    for agent in LIBRARY.dynamic_agents:
        for _ in range(6):
            mission.add_skill(agent, "navigate_to")
    return mission


def journaled(path: Path, chunked: bool, closed: bool = True) -> dict[int, MissionContent]:
    """Write a journal of about 150 changes (a replacement among them, a snapshot every
    20 events) as the server does; return the live mission at every revision."""
    mission = plain_mission()
    rng = random.Random(11)
    options = JournalOptions(chunked=chunked, fsync=False, snapshot_every=20)

    def snapshot() -> Any:
        return mission_to_msg(mission.state.content(), mission.revision, mission.revision / 10)

    writer = JournalWriter.create(path, snapshot(), T0, options)
    live = {mission.revision: mission.state.content()}
    for number in range(150):
        agents = [a for a in mission.state.agents if len(mission.state.task(a)) > 3]
        agent = rng.choice(agents or list(mission.library.dynamic_agents))
        if number == 70:
            event = mission.new_mission()
        elif not agents or rng.random() < 0.3:
            event = mission.add_skill(agent, "navigate_to", label=f"added {number}")
        elif rng.random() < 0.2:
            event = mission.delete_skills([mission.state.task(agent)[-1].id])
        else:
            skill = rng.choice(list(mission.state.task(agent)))
            event = mission.edit_skill(skill.id, label=f"edit {number}")
        log_time = T0 + (number + 1) * 10**8
        writer.append_event(event_to_msg(event, mission.state.agent_of), log_time)
        if event.kind is EventKind.MISSION_REPLACED or writer.snapshot_due:
            writer.append_snapshot(snapshot(), log_time)
        live[mission.revision] = mission.state.content()
    if closed:
        writer.close()
    else:
        writer.abandon()
        with path.open("ab") as file:
            file.write(b"\x06\x40\x00")  # a record cut short
    return live


def eager_messages(path: Path) -> list[tuple[str, int, Any]]:
    """Every message of a one-file journal, each decoded at once (the full decode)."""
    scan = _scan.scan(path)
    decoder = Decoder()
    found = []
    for msg in scan.messages:
        channel = scan.channels[msg.channel_id]
        message = decoder.decode(scan.schemas[channel.schema_id], msg.data)
        found.append((channel.topic, msg.log_time, message))
    return found


def replayed(path: Path) -> dict[int, MissionContent]:
    """The mission at every revision, replayed event by event from the first snapshot
    with every record decoded (as the history did before it rebuilt on demand)."""
    states: dict[int, MissionContent] = {}
    mission: list[MissionState] = []

    def restart(msg: Any, _replacing: Any) -> None:
        content, revision = mission_from_msg(msg)
        mission[:] = [MissionState(content, revision)]
        states[revision] = mission[0].content()

    def apply(msg: Any) -> bool:
        try:
            apply_event(mission[0], event_from_msg(msg))
        except RosmcError:
            return False
        states[mission[0].revision] = mission[0].content()
        return True

    walk: RevisionWalk[Any, Any] = RevisionWalk(restart, apply)
    for topic, _time, msg in eager_messages(path):
        if topic == MISSION_TOPIC:
            walk.snapshot(int(msg.revision), msg)
        elif topic == EVENTS_TOPIC:
            walk.event(int(msg.revision), msg.kind == msg.MISSION_REPLACED, msg)
    walk.finish()
    return states


def assert_lazy_fields_hold(path: Path) -> None:
    """Each record's message and its leading fields, read without decoding, equal the
    full decode's."""
    records = read_journal(path).records
    eager = eager_messages(path)
    assert [(r.topic, r.log_time) for r in records] == [(t, lt) for t, lt, _ in eager]
    for record, (_topic, _time, msg) in zip(records, eager, strict=True):
        if record.topic in (MISSION_TOPIC, EVENTS_TOPIC):
            assert record.revision == int(msg.revision)
            assert record.field("stamp") == msg.stamp
        if record.topic == EVENTS_TOPIC:
            assert record.kind == msg.kind
            assert record.field("summary") == msg.summary
            assert record.field("agent") == msg.agent
        assert serialize(record.message) == serialize(msg)  # NaN fields compare unequal


def assert_history_is_the_replay(path: Path, live: dict[int, MissionContent] | None) -> None:
    """The history at every revision (in a random order, and again in order) equals the
    event-by-event replay, and the live mission where there is one."""
    reference = replayed(path)
    history = MissionHistory.from_journal(path)
    assert [info.revision for info in history.revisions] == sorted(reference)
    order = list(reference)
    random.Random(3).shuffle(order)
    for revision in [*order, *sorted(reference)]:
        content = history.at_revision(revision).content()
        assert content == reference[revision], f"revision {revision}"
        if live is not None:
            assert content == live[revision], f"revision {revision} (live)"


@pytest.fixture(params=[65536, 1], ids=["big-deferred", "all-deferred"])
def defer_bytes(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> int:
    """Leave payloads from this size on in the file (1: every one)."""
    monkeypatch.setattr(_scan, "DEFER_BYTES", request.param)
    return int(request.param)


@pytest.mark.parametrize("chunked", [True, False], ids=["chunked", "bare"])
@pytest.mark.parametrize("closed", [True, False], ids=["closed", "crash-left"])
def test_every_revision_and_the_resumed_state_equal_the_full_decode(
    tmp_path: Path, defer_bytes: int, chunked: bool, closed: bool
) -> None:
    path = tmp_path / "m.mcap"
    live = journaled(path, chunked, closed)
    assert_lazy_fields_hold(path)
    assert_history_is_the_replay(path, live)
    latest = latest_state(read_journal(path))
    content, revision = mission_from_msg(latest.snapshot)
    state = MissionState(content, revision)
    for event in latest.events:
        apply_event(state, event_from_msg(event))
    assert state.revision == max(live) and state.content() == live[max(live)]


def test_latest_state_decodes_only_its_snapshot_and_the_events_after_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "m.mcap"
    journaled(path, chunked=True)
    result = read_journal(path)
    decoded: list[Payload] = []
    original = Payload.decode

    def counting(payload: Payload) -> Any:
        decoded.append(payload)
        return original(payload)

    monkeypatch.setattr(Payload, "decode", counting)
    latest = latest_state(result)
    assert len(decoded) <= 1 + len(latest.events) and len(latest.events) < 20
    assert int(latest.snapshot.revision) > 140


def test_a_damaged_event_costs_the_revisions_to_the_next_snapshot_as_before(
    tmp_path: Path, defer_bytes: int
) -> None:
    path = tmp_path / "m.mcap"
    live = journaled(path, chunked=True)
    scan = _scan.scan(path)
    events = next(c.id for c in scan.channels.values() if c.topic == EVENTS_TOPIC)
    spans = [
        span
        for msg, span in zip(scan.messages, scan.spans, strict=True)
        if msg.channel_id == events and int.from_bytes(payload_head(msg)[:8], "little") == 30
    ]
    data = bytearray(path.read_bytes())
    data[(spans[0][0] + spans[0][1]) // 2] ^= 0x20
    path.write_bytes(bytes(data))

    history = MissionHistory.from_journal(path)
    assert history.problems and history.gaps
    shown = [info.revision for info in history.revisions]
    assert 30 not in shown and max(shown) == max(live)
    assert_history_is_the_replay(path, live)


def test_a_deferred_message_reads_as_the_kept_one(tmp_path: Path) -> None:
    path = tmp_path / "m.mcap"
    journaled(path, chunked=True)
    kept = _scan.scan(path)
    original = _scan.DEFER_BYTES
    try:
        _scan.DEFER_BYTES = 1
        deferred = _scan.scan(path)
    finally:
        _scan.DEFER_BYTES = original
    assert all(isinstance(m, DeferredMessage) for m in deferred.messages)
    fields = [(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data) for m in kept.messages]
    assert [
        (m.channel_id, m.sequence, m.log_time, m.publish_time, m.data) for m in deferred.messages
    ] == fields
    assert deferred.spans == kept.spans
    assert [payload_head(m) for m in deferred.messages] == [
        m.data[:HEAD_BYTES] for m in kept.messages
    ]
    assert deferred.chunk_indexes == kept.chunk_indexes and deferred.data_end == kept.data_end


def test_the_committed_sample_reads_lazily_as_in_full(defer_bytes: int) -> None:
    assert_lazy_fields_hold(SAMPLE)
    assert_history_is_the_replay(SAMPLE, None)


def test_a_journal_of_an_older_format_reads_lazily_as_in_full(tmp_path: Path) -> None:
    mission = team_mission()
    snapshot = mission_to_msg(mission.state.content(), mission.revision, 0.0)
    events = []
    for number in range(6):
        skill = mission.state.task("drone")[3 + number]
        events.append(old_event_bytes(mission.edit_skill(skill.id, label=f"old {number}"), mission))
    path = tmp_path / "old.mcap"
    write_old_journal(path, snapshot, events)
    assert_lazy_fields_hold(path)
    assert_history_is_the_replay(path, None)


def test_a_recording_copied_away_after_reading_says_so_when_a_payload_is_asked_for(
    tmp_path: Path,
) -> None:
    path = tmp_path / "m.mcap"
    journaled(path, chunked=True)
    original = _scan.DEFER_BYTES
    try:
        _scan.DEFER_BYTES = 1
        records = read_journal(path).records
    finally:
        _scan.DEFER_BYTES = original
    shutil.move(path, tmp_path / "moved.mcap")
    assert records[-1].revision > 0  # read from the bytes kept
    with pytest.raises(JournalError, match="changed since it was read"):
        _ = records[-1].message
