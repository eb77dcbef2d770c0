"""The MCAP mission journal: round trips, crash recovery, resume, interoperability.

Real files in tmp_path, real genpy messages, no ROS master.
"""

import os
import shutil
import signal
import subprocess
import sys
import threading
from datetime import datetime
from io import BytesIO
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.exceptions import EndOfFile
from mcap.reader import NonSeekingReader, SeekingReader
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from mcap_ros1.decoder import DecoderFactory
from mcap_ros1.writer import Writer as Ros1Writer

msg = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.interface import (  # noqa: E402
    AGENT_STATES_TOPIC,
    EVENTS_TOPIC,
    MISSION_TOPIC,
    ROBOT_REPORTS_TOPIC,
)
from rosmc_server.recording import (  # noqa: E402
    JOURNAL_TOPICS,
    JournalError,
    JournalOptions,
    JournalWriter,
    default_journal_path,
    latest_state,
    read_journal,
)
from rosmc_server.recording._mcap.files import part_path  # noqa: E402

LAYOUTS = [pytest.param(True, id="chunked"), pytest.param(False, id="bare")]
T0 = 1_700_000_000_000_000_000


def event(revision: int, agent: str = "drone", kind: int = 0) -> Any:
    """A small MissionEvent that adds one skill with a few parameters."""
    skill = msg.Skill(id=f"s{revision}", agent=agent, skill="move_to", label="move to RSS 1")
    skill.parameters = [
        msg.ParameterValue(name="speed", type=msg.ParameterValue.FLOAT, float_value=0.5),
        msg.ParameterValue(name="goal", type=msg.ParameterValue.POSE, marker="rss1"),
    ]
    return msg.MissionEvent(
        revision=revision,
        kind=kind,
        agent=agent,
        summary=f"added skill s{revision}",
        put_skills=[msg.PlacedSkill(index=revision, skill=skill)],
    )


def mission(revision: int, agents: int = 2, skills: int = 3) -> Any:
    """A Mission snapshot with ``agents`` x ``skills`` skills."""
    tasks = [
        msg.AgentTask(
            agent=f"a{a}",
            skills=[msg.Skill(id=f"a{a}s{s}", agent=f"a{a}", skill="scan") for s in range(skills)],
        )
        for a in range(agents)
    ]
    return msg.Mission(revision=revision, library="library: demo", tasks=tasks)


def write_sample(path: Path, chunked: bool, events: int = 8) -> tuple[JournalWriter, list[Any]]:
    """Write a snapshot, events, a second snapshot and telemetry; return the open writer
    and the expected (topic, log time, message, end offset) rows, in order."""
    options = JournalOptions(chunked=chunked)
    writer = JournalWriter.create(path, mission(0), T0, options)
    rows = [(MISSION_TOPIC, T0, mission(0), writer.offset)]
    for rev in range(1, events + 1):
        t = T0 + rev * 1000
        writer.append_event(event(rev), t)
        rows.append((EVENTS_TOPIC, t, event(rev), writer.offset))
        if rev == events // 2:
            writer.append_snapshot(mission(rev, skills=rev), t + 1)
            rows.append((MISSION_TOPIC, t + 1, mission(rev, skills=rev), writer.offset))
            report = msg.RobotReport(agent="drone", seq=rev, skill_id="s1", status_text="ok")
            writer.append_report(report, t + 2)
            rows.append((ROBOT_REPORTS_TOPIC, t + 2, report, writer.offset))
            states = msg.AgentStates(revision=rev, agents=[msg.AgentState(agent="drone")])
            writer.append_agent_states(states, t + 3)
            rows.append((AGENT_STATES_TOPIC, t + 3, states, writer.offset))
    return writer, rows


INDEX_LENGTH = 9 + 2 + 4 + 16  # the message index record that follows each one-message chunk


def expected_at(rows: list[Any], cut: int, chunked: bool, data_end: int) -> tuple[list[Any], int]:
    """The rows a file cut at ``cut`` still holds, and how many bytes past them it has.

    A chunk is a complete record before its message index is: it is recovered even when
    the index after it was cut off.
    """
    ends = [(row, row[-1] - (INDEX_LENGTH if chunked else 0), row[-1]) for row in rows]
    kept = [row for row, message_end, _ in ends if message_end <= cut]
    last_good = max(e for _, m, end in ends for e in (m, end) if e <= cut)
    return kept, cut - min(last_good, data_end)


def assert_prefix(result: Any, rows: list[Any]) -> None:
    """The result holds exactly ``rows`` (topic, log time, message), in order."""
    got = [(r.topic, r.log_time, r.message) for r in result.records]
    assert got == [row[:3] for row in rows]


def mcap_messages(path: Path) -> list[tuple[str, int, bytes]]:
    """Messages as the mcap package's indexed reader sees them (summary required)."""
    with path.open("rb") as file:
        reader = SeekingReader(file, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        found = [(c.topic, m.log_time, m.data) for _, c, m in reader.iter_messages()]
        assert summary.statistics.message_count == len(found)
    with path.open("rb") as file:  # and the sequential reader, checking every CRC
        assert list(StreamReader(file, validate_crcs=True).records)
    return found


def serialized(message: Any) -> bytes:
    buffer = BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


@pytest.mark.parametrize("chunked", LAYOUTS)
def test_round_trip(tmp_path: Path, chunked: bool) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked)
    writer.close()
    result = read_journal(path)
    assert result.clean and result.complete and result.dropped_bytes == 0
    assert_prefix(result, rows)
    assert result.messages(EVENTS_TOPIC) == [r[2] for r in rows if r[0] == EVENTS_TOPIC]
    assert type(result.records[1].message) is msg.MissionEvent  # the installed class


@pytest.mark.parametrize("chunked", LAYOUTS)
def test_closed_journal_is_standard_mcap(tmp_path: Path, chunked: bool) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked)
    writer.close()
    assert mcap_messages(path) == [(r[0], r[1], serialized(r[2])) for r in rows]
    with path.open("rb") as file:
        reader = SeekingReader(file, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None
        assert len(summary.chunk_indexes) == (len(rows) if chunked else 0)
        assert {s.name for s in summary.schemas.values()} >= {"rosmc/MissionEvent", "rosmc/Mission"}
        assert all(s.encoding == "ros1msg" for s in summary.schemas.values())
        assert reader.get_header().profile == "ros1"
        decoded = list(reader.iter_decoded_messages(topics=[EVENTS_TOPIC]))
    assert [d.decoded_message.revision for d in decoded] == list(range(1, 9))
    schema = decoded[0].schema
    assert schema is not None and schema.data == msg.MissionEvent._full_text.encode()


@pytest.mark.parametrize("chunked", LAYOUTS)
def test_cut_at_every_offset_recovers_the_complete_prefix(tmp_path: Path, chunked: bool) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked)
    data_end = writer.offset
    writer.close()
    data = path.read_bytes()
    cut_path = tmp_path / "cut.mcap"
    every_byte = range(rows[-4][3] - 40, data_end + 40)  # the last three records
    summary = range(data_end + 40, len(data) + 1, 37)  # the summary repeats the schemas: 13 kB
    for cut in [*every_byte, *summary, len(data) - 1, len(data)]:
        cut_path.write_bytes(data[:cut])
        result = read_journal(cut_path)
        kept, dropped = expected_at(rows, cut, chunked, data_end)
        assert_prefix(result, kept)
        if cut == len(data):
            assert result.clean
            continue
        assert not result.complete
        assert result.dropped_bytes == dropped
        assert any("not closed cleanly" in w for w in result.warnings)
        if dropped:
            assert any(f"dropped the last {dropped} bytes" in w for w in result.warnings)
        else:
            assert len(result.warnings) == 1


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    chunked=st.booleans(),
    kinds=st.lists(st.sampled_from(["event", "snapshot", "report"]), min_size=1, max_size=30),
    cut_fraction=st.floats(min_value=0.0, max_value=1.0),
)
def test_random_journal_cut_anywhere(
    tmp_path: Path, chunked: bool, kinds: list[str], cut_fraction: float
) -> None:
    path = tmp_path / f"h{os.getpid()}.mcap"
    path.unlink(missing_ok=True)
    writer = JournalWriter.create(path, mission(0), T0, JournalOptions(chunked=chunked))
    rows = [(mission(0), writer.offset)]
    for i, kind in enumerate(kinds, start=1):
        if kind == "event":
            writer.append_event(event(i), T0 + i)
            rows.append((event(i), writer.offset))
        elif kind == "snapshot":
            writer.append_snapshot(mission(i, skills=i % 7), T0 + i)
            rows.append((mission(i, skills=i % 7), writer.offset))
        else:
            writer.append_report(msg.RobotReport(agent="rover", seq=i), T0 + i)
            rows.append((msg.RobotReport(agent="rover", seq=i), writer.offset))
    writer.abandon()
    data = path.read_bytes()
    start = rows[0][1]  # at least the opening snapshot survives
    cut = start + int((len(data) - start) * cut_fraction)
    path.write_bytes(data[:cut])
    result = read_journal(path)
    kept, dropped = expected_at(rows, cut, chunked, len(data))
    assert [r.message for r in result.records] == [row[0] for row in kept]
    assert result.dropped_bytes == dropped


@pytest.mark.parametrize("chunked", LAYOUTS)
def test_resume_after_a_cut_then_append_and_close(tmp_path: Path, chunked: bool) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked)
    writer.abandon()
    data = path.read_bytes()
    work = tmp_path / "work.mcap"
    for cut in range(rows[-3][3] - 5, len(data) + 1, 3):
        for leftover in tmp_path.glob("work.mcap*"):
            leftover.unlink()
        work.write_bytes(data[:cut])
        kept, dropped = expected_at(rows, cut, chunked, len(data))
        resumed = JournalWriter.resume(work, JournalOptions(chunked=not chunked))
        assert resumed.chunked == chunked  # a resumed journal keeps its layout
        assert resumed.recovered is not None
        assert_prefix(resumed.recovered, kept)
        saved = list(tmp_path.glob("work.mcap.dropped-*"))
        assert [p.read_bytes() for p in saved] == ([data[cut - dropped : cut]] if dropped else [])
        resumed.append_event(event(100), T0 + 10**6)
        resumed.close()
        result = read_journal(work)
        assert result.clean, result.warnings
        assert_prefix(result, [*kept, (EVENTS_TOPIC, T0 + 10**6, event(100))])
        expected = [(r[0], r[1], serialized(r[2])) for r in kept]
        assert mcap_messages(work) == [
            *expected,
            (EVENTS_TOPIC, T0 + 10**6, serialized(event(100))),
        ]


def test_resume_restores_message_indexes_cut_off_after_a_chunk(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked=True)
    writer.abandon()
    path.write_bytes(path.read_bytes()[: rows[-1][3] - INDEX_LENGTH])
    resumed = JournalWriter.resume(path)
    assert resumed.recovered is not None and len(resumed.recovered.records) == len(rows)
    resumed.close()
    with path.open("rb") as file:
        summary = SeekingReader(file).get_summary()
    assert summary is not None
    assert all(len(c.message_index_offsets) == 1 for c in summary.chunk_indexes)
    assert len(mcap_messages(path)) == len(rows)


@pytest.mark.parametrize("chunked", LAYOUTS)
def test_resume_a_closed_journal_continues_it(tmp_path: Path, chunked: bool) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked)
    writer.close()
    with JournalWriter.resume(path) as resumed:
        assert resumed.recovered is not None and resumed.recovered.clean
        resumed.append_event(event(9), T0 + 10**6)
    assert not list(tmp_path.glob("*.dropped-*"))  # a summary is not data
    result = read_journal(path)
    assert result.clean
    assert latest_state(result).revision == 9
    assert len(mcap_messages(path)) == len(rows) + 1


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (b"", "is empty"),
        (b"hello, this is not a journal at all", "not an MCAP file"),
        (b"\x89MCAP0\r\n\x01\x20\x00\x00", "cut short before its MCAP header"),
        (b"\x89MC", "cut short before its MCAP header"),
        (b"\x89MCAP0\r\n\x05\x00\x00\x00\x00\x00\x00\x00\x00", "first record is not a header"),
    ],
)
def test_not_a_journal_is_a_clear_error(tmp_path: Path, content: bytes, needle: str) -> None:
    path = tmp_path / "bad.mcap"
    path.write_bytes(content)
    with pytest.raises(JournalError, match=needle):
        read_journal(path)
    with pytest.raises(JournalError, match=needle):
        JournalWriter.resume(path)
    assert path.read_bytes() == content  # a failed resume changes nothing


def test_missing_file_is_a_journal_error(tmp_path: Path) -> None:
    with pytest.raises(JournalError, match=r"nope\.mcap"):
        read_journal(tmp_path / "nope.mcap")
    with pytest.raises(JournalError, match=r"nope\.mcap"):
        JournalWriter.resume(tmp_path / "nope.mcap")


def test_damaged_record_in_the_middle_costs_that_record_only(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked=True)
    writer.abandon()
    data = bytearray(path.read_bytes())
    data[rows[2][3] + 60] ^= 0xFF  # inside the payload of the fourth record's chunk: bad CRC
    path.write_bytes(bytes(data))
    result = read_journal(path)
    assert_prefix(result, rows[:3] + rows[4:])
    assert result.dropped_bytes == 0 and not result.clean
    [damage] = result.damage
    assert (damage.start, damage.end) == (rows[2][3], rows[3][3])  # the chunk and its index
    assert "CRC" in damage.what and not damage.kept


def test_zero_filled_tail_is_damage_not_records(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked=False)
    writer.abandon()
    with path.open("ab") as file:
        file.write(bytes(4096))  # what a file system can leave after a power loss
    result = read_journal(path)
    assert_prefix(result, rows)
    assert result.dropped_bytes == 4096


def test_kill_9_loses_no_acknowledged_change(tmp_path: Path) -> None:
    child = (
        "import sys\n"
        "import rosmc.msg as m\n"
        "from rosmc_server.recording import JournalOptions, JournalWriter\n"
        "chunked = sys.argv[2] == '1'\n"
        "options = JournalOptions(chunked=chunked, snapshot_every=20)\n"
        "w = JournalWriter.create(sys.argv[1], m.Mission(revision=0), 1, options)\n"
        "rev = 0\n"
        "while True:\n"
        "    rev += 1\n"
        "    w.append_event(m.MissionEvent(revision=rev, summary='x' * (rev % 400)), rev)\n"
        "    print(rev, flush=True)\n"
        "    if w.snapshot_due:\n"
        "        w.append_snapshot(m.Mission(revision=rev, library='y' * 20000), rev)\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    for run, (chunked, kill_after) in enumerate([(True, 150), (False, 230), (True, 377)]):
        path = tmp_path / f"kill{run}.mcap"
        args = [sys.executable, "-c", child, str(path), "1" if chunked else "0"]
        proc = subprocess.Popen(args, stdout=subprocess.PIPE, text=True, env=env)
        assert proc.stdout is not None
        acked = [int(proc.stdout.readline()) for _ in range(kill_after)]
        os.kill(proc.pid, signal.SIGKILL)
        acked += [int(line) for line in proc.stdout.read().split()]
        proc.wait(timeout=30)
        assert proc.returncode == -signal.SIGKILL
        result = read_journal(path)
        state = latest_state(result)
        assert state.problems == ()
        assert state.revision >= acked[-1]
        revisions = [e.revision for e in result.messages(EVENTS_TOPIC)]
        assert set(acked) <= set(revisions)
        assert revisions == list(range(1, len(revisions) + 1))
        with JournalWriter.resume(path) as resumed:
            resumed.append_event(msg.MissionEvent(revision=state.revision + 1), 10**9)
        assert read_journal(path).clean


def test_latest_state_picks_the_last_snapshot_and_stops_at_a_gap(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    with JournalWriter.create(path, mission(0), T0) as writer:
        for rev in (1, 2, 3):
            writer.append_event(event(rev), T0 + rev)
        writer.append_snapshot(mission(3), T0 + 4)
        for rev in (2, 4, 5, 7):  # 2 is older than the snapshot; 6 is missing
            writer.append_event(event(rev), T0 + 10 + rev)
        replaced = event(8, kind=msg.MissionEvent.MISSION_REPLACED)
        writer.append_event(replaced, T0 + 20)  # its snapshot is missing...
        writer.append_event(event(9), T0 + 21)  # ...and the journal goes on
    state = latest_state(read_journal(path))
    assert state.snapshot == mission(3) and state.snapshot_time == T0 + 4
    assert [e.revision for e in state.events] == [4, 5]  # nothing is applied over a gap
    assert state.revision == 5 and state.highest == 9 and state.next_revision == 10
    assert state.lost is not None and str(state.lost.revisions) == "r6..r9"
    assert state.problems == (f"journal {path}: 4 revisions r6..r9 cannot be rebuilt",)
    assert state.notes == ()


def test_latest_state_leaves_out_a_replacement_cut_off_before_its_snapshot(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    with JournalWriter.create(path, mission(0), T0) as writer:
        writer.append_event(event(1), T0 + 1)
        writer.append_event(event(2, kind=msg.MissionEvent.MISSION_REPLACED), T0 + 2)
        # killed here, before the server appended the new mission and replied
    state = latest_state(read_journal(path))
    assert [e.revision for e in state.events] == [1]
    assert state.revision == 1 and state.problems == ()
    assert len(state.notes) == 1 and "revision 2 replaced the mission" in state.notes[0]


def test_latest_state_without_events_and_without_snapshot(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    with JournalWriter.create(path, mission(5), T0):
        pass
    state = latest_state(read_journal(path))
    assert state.events == () and state.problems == () and state.revision == 5
    with pytest.raises(JournalError, match="no mission snapshot"):
        latest_state(read_journal(path, topics=[EVENTS_TOPIC]))


def test_snapshot_due_counts_events_also_across_resume(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer = JournalWriter.create(path, mission(0), T0, JournalOptions(snapshot_every=3))
    for rev in (1, 2):
        writer.append_event(event(rev), T0 + rev)
    assert not writer.snapshot_due
    writer.abandon()
    writer = JournalWriter.resume(path, JournalOptions(snapshot_every=3))
    writer.append_event(event(3), T0 + 3)
    assert writer.snapshot_due
    writer.append_snapshot(mission(3), T0 + 4)
    assert not writer.snapshot_due
    writer.close()


def test_writer_refuses_misuse(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer = JournalWriter.create(path, mission(0), T0)
    with pytest.raises(JournalError, match="already exists"):
        JournalWriter.create(path, mission(0), T0)
    with pytest.raises(JournalError, match="another writer"):
        JournalWriter.resume(path)
    size = writer.offset
    with pytest.raises(JournalError, match="records rosmc/MissionEvent"):
        writer.append_event(mission(1), T0)
    with pytest.raises(JournalError, match="cannot serialise"):
        writer.append_event(msg.MissionEvent(revision=-1), T0)
    assert writer.offset == size == path.stat().st_size
    writer.close()
    writer.close()  # closing twice is harmless
    with pytest.raises(JournalError, match="is closed"):
        writer.append_event(event(1), T0)
    assert read_journal(path).clean


def test_failed_write_leaves_a_valid_journal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "j.mcap"
    writer = JournalWriter.create(path, mission(0), T0)

    def half_then_full(fd: int, parts: Any) -> int:
        first = bytes(parts[0])
        os.write(fd, first[: len(first) // 2])
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "writev", half_then_full)
    with pytest.raises(JournalError, match="No space left"):
        writer.append_event(event(1), T0 + 1)
    monkeypatch.undo()
    assert path.stat().st_size == writer.offset
    writer.append_event(event(2), T0 + 2)
    writer.close()
    result = read_journal(path)
    assert result.clean and [r.message for r in result.records] == [mission(0), event(2)]
    assert len(mcap_messages(path)) == 2  # the failed chunk is not in the summary either


def test_appends_from_several_threads_stay_whole(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer = JournalWriter.create(path, mission(0), T0)

    def report(agent: str) -> None:
        for seq in range(200):
            writer.append_report(msg.RobotReport(agent=agent, seq=seq), T0 + seq)

    threads = [threading.Thread(target=report, args=(f"r{i}",)) for i in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    writer.close()
    reports = read_journal(path).messages(ROBOT_REPORTS_TOPIC)
    assert sorted((r.agent, r.seq) for r in reports) == [
        (f"r{i}", seq) for i in range(4) for seq in range(200)
    ]
    assert len(mcap_messages(path)) == 801


def test_big_snapshots_are_compressed_and_read_back(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    big = mission(1, agents=4, skills=200)
    with JournalWriter.create(path, big, T0, JournalOptions(compress_from=1024)) as writer:
        writer.append_event(event(2), T0 + 1)
    with path.open("rb") as file:
        summary = SeekingReader(file).get_summary()
    assert summary is not None
    assert [c.compression for c in summary.chunk_indexes] == ["zstd", ""]
    assert summary.chunk_indexes[0].compressed_size < len(serialized(big)) / 4
    assert read_journal(path).records[0].message == big


def test_foreign_mcap_with_unknown_schema_decodes_with_the_recorded_definition(
    tmp_path: Path,
) -> None:
    path = tmp_path / "foreign.mcap"
    with path.open("wb") as file:  # the mcap package's writer: zstd chunks, schemas inside
        writer = McapWriter(file)
        writer.start(profile="ros1", library="test")
        schema = writer.register_schema("rosmc_test/Extra", "ros1msg", b"uint32 x\nstring note\n")
        channel = writer.register_channel("/extra", "ros1", schema)
        for x in range(3):
            data = x.to_bytes(4, "little") + (2).to_bytes(4, "little") + b"hi"
            writer.add_message(channel, log_time=x, data=data, publish_time=x)
        writer.finish()
    result = read_journal(path)
    assert result.complete and result.dropped_bytes == 0
    assert [(r.message.x, r.message.note) for r in result.records] == [
        (0, "hi"),
        (1, "hi"),
        (2, "hi"),
    ]
    assert any("recorded definition of rosmc_test/Extra" in w for w in result.warnings)


@pytest.mark.parametrize("compression", [CompressionType.ZSTD, CompressionType.LZ4])
def test_mcap_ros1_recording_reads_and_resumes(tmp_path: Path, compression: Any) -> None:
    """A file of mcap_ros1's writer (several messages per chunk, schemas inside chunks)."""
    path = tmp_path / "ros1.mcap"
    with path.open("wb") as file:
        writer = Ros1Writer(file, chunk_size=2000, compression=compression)
        writer.write_message(MISSION_TOPIC, mission(0), log_time=T0)
        for rev in range(1, 20):
            writer.write_message(EVENTS_TOPIC, event(rev), log_time=T0 + rev)
        writer.finish()
    result = read_journal(path)
    assert result.clean, result.warnings
    assert [r.message for r in result.records] == [mission(0)] + [event(r) for r in range(1, 20)]
    with JournalWriter.resume(path) as resumed:
        assert resumed.chunked
        resumed.append_event(event(20), T0 + 20)
        resumed.append_report(msg.RobotReport(agent="drone"), T0 + 21)
    assert latest_state(read_journal(path)).revision == 20
    # Its head has no room for the revision mark: the journal goes on in a part that has.
    assert len(mcap_messages(path)) == 20
    assert len(mcap_messages(part_path(path, 2))) == 2


def test_resume_refuses_an_mcap_file_of_another_profile(tmp_path: Path) -> None:
    path = tmp_path / "ros2.mcap"
    with path.open("wb") as file:
        writer = McapWriter(file)
        writer.start(profile="ros2", library="test")
        writer.finish()
    before = path.read_bytes()
    with pytest.raises(JournalError, match="profile 'ros2', not a journal"):
        JournalWriter.resume(path)
    assert path.read_bytes() == before


def test_rosbags_decodes_the_journal_with_its_embedded_definitions(tmp_path: Path) -> None:
    typesys = pytest.importorskip("rosbags.typesys")
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked=True)
    writer.close()
    store = typesys.get_typestore(typesys.Stores.EMPTY)
    decoded = []
    with path.open("rb") as file:
        for schema, _channel, message in SeekingReader(file).iter_messages():
            assert schema is not None
            name = schema.name.replace("/", "/msg/")
            if name not in store.fielddefs:
                store.register(typesys.get_types_from_msg(schema.data.decode(), name))
            decoded.append(store.deserialize_ros1(message.data, name))
    events = [d for d, row in zip(decoded, rows, strict=True) if row[0] == EVENTS_TOPIC]
    assert [(e.revision, e.put_skills[0].skill.id) for e in events] == [
        (r, f"s{r}") for r in range(1, 9)
    ]


def test_rosbags_0_11_cannot_open_ros1_mcap(tmp_path: Path) -> None:
    """rosbags reads MCAP only as rosbag2 storage (profile ros2, CDR); documented here so a
    rosbags upgrade that lifts the limit is noticed."""
    highlevel = pytest.importorskip("rosbags.highlevel")
    path = tmp_path / "j.mcap"
    JournalWriter.create(path, mission(0), T0).close()
    with pytest.raises(highlevel.AnyReaderError, match="ros2"), highlevel.AnyReader([path]):
        pass


def test_mcap_stream_reader_yields_a_crashed_journal_then_fails(tmp_path: Path) -> None:
    """Why read_journal exists: the mcap package reads an unclosed file only up to an error."""
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked=False)
    writer.abandon()
    found = []
    with path.open("rb") as file, pytest.raises(EndOfFile):
        for _, _, message in NonSeekingReader(file).iter_messages(log_time_order=False):
            found.append(message.log_time)
    assert found == [r[1] for r in rows]


def test_default_journal_path(tmp_path: Path) -> None:
    def clock() -> datetime:
        return datetime(2024, 5, 17, 9, 3, 7)

    first = default_journal_path(tmp_path / "bags" / "new", now=clock)
    assert first == tmp_path / "bags" / "new" / "mission_20240517_090307.mcap"
    assert first.parent.is_dir()
    JournalWriter.create(first, mission(0), T0).close()
    second = default_journal_path(tmp_path / "bags" / "new", now=clock)
    assert second.name == "mission_20240517_090307_2.mcap"


def test_copy_of_an_open_journal_reads_as_unclosed(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    writer, rows = write_sample(path, chunked=True)
    shutil.copy(path, tmp_path / "copy.mcap")  # what a crash at this moment leaves
    writer.close()
    result = read_journal(tmp_path / "copy.mcap")
    assert_prefix(result, rows)
    assert not result.complete and result.dropped_bytes == 0


def test_journal_channels_are_the_graph_names() -> None:
    assert list(JOURNAL_TOPICS) == [
        EVENTS_TOPIC,
        MISSION_TOPIC,
        ROBOT_REPORTS_TOPIC,
        AGENT_STATES_TOPIC,
        "/tf",
        "/rosmc/sim/science",
        "/rosmc/sim/world",
        "/rosmc/robot_commands",  # added later: older journals keep their channel ids
        "/rosmc/site_in_force",  # added later, likewise
        "/rosmc/library",  # added last, likewise
    ]
    assert EVENTS_TOPIC == "/rosmc/mission_events" and MISSION_TOPIC == "/rosmc/mission"


def test_commands_are_journaled_with_when_asked_and_when_delivered(tmp_path: Path) -> None:
    asked = msg.CommandRecord(
        event=msg.CommandRecord.ASKED, agent="rover", type=0, held=True, skill_ids=["a"]
    )
    asked.asked.secs = 100
    delivered = msg.CommandRecord(event=msg.CommandRecord.DELIVERED, agent="rover", seq=4)
    delivered.asked.secs, delivered.delivered.secs = 100, 160
    with JournalWriter.create(tmp_path / "c.mcap", mission(0), T0) as writer:
        writer.append_command(asked, T0 + 1)
        writer.append_command(delivered, T0 + 2)
    records = read_journal(tmp_path / "c.mcap").messages("/rosmc/robot_commands")
    assert [(r.event, r.seq, r.asked.secs, r.delivered.secs) for r in records] == [
        (msg.CommandRecord.ASKED, 0, 100, 0),
        (msg.CommandRecord.DELIVERED, 4, 100, 160),
    ]
    assert records[0].held and records[0].skill_ids == ["a"]


def test_telemetry_channels_take_their_own_types_only(tmp_path: Path) -> None:
    from tf2_msgs.msg import TFMessage

    with JournalWriter.create(tmp_path / "t.mcap", mission(0), T0) as writer:
        writer.append_telemetry("/tf", TFMessage(), T0 + 2)
        with pytest.raises(JournalError, match="not a telemetry channel"):
            writer.append_telemetry(EVENTS_TOPIC, TFMessage(), 3)
        with pytest.raises(JournalError, match="records tf2_msgs/TFMessage"):
            writer.append_telemetry("/tf", msg.ScienceState(), 3)
    assert [r.topic for r in read_journal(tmp_path / "t.mcap").records][-1] == "/tf"
    # What Foxglove and the mcap tools do: decode it from the schema embedded in the file.
    with (tmp_path / "t.mcap").open("rb") as file:
        reader = SeekingReader(file, decoder_factories=[DecoderFactory()])
        decoded = list(reader.iter_decoded_messages(topics=["/tf"]))
    assert decoded[0].schema.name == "tf2_msgs/TFMessage"
    assert decoded[0].decoded_message.transforms == []


def test_latest_state_takes_a_late_snapshot_with_the_events_written_before_it(
    tmp_path: Path,
) -> None:
    """A periodic snapshot of revision 3, written after events 4 and 5, still recovers 5."""
    path = tmp_path / "late.mcap"
    with JournalWriter.create(path, mission(0), 1) as writer:
        for revision in range(1, 6):
            writer.append_event(event(revision), 10 + revision)
        writer.append_snapshot(mission(3), 20)
    state = latest_state(read_journal(path))
    assert state.snapshot.revision == 3
    assert [e.revision for e in state.events] == [4, 5]
    assert not state.problems


def test_latest_state_prefers_the_newest_snapshot_over_a_late_older_one(tmp_path: Path) -> None:
    """A replacement's snapshot (revision 2) wins over a periodic one of revision 1 after it."""
    path = tmp_path / "replaced.mcap"
    with JournalWriter.create(path, mission(0), 1) as writer:
        writer.append_event(event(1), 2)
        writer.append_event(event(2, kind=msg.MissionEvent.MISSION_REPLACED), 3)
        writer.append_snapshot(mission(2, agents=3), 4)
        writer.append_snapshot(mission(1), 5)
        writer.append_event(event(3), 6)
    state = latest_state(read_journal(path))
    assert state.snapshot.revision == 2 and len(state.snapshot.tasks) == 3
    assert [e.revision for e in state.events] == [3]
    assert not state.problems
