"""A journal that grows past ``part_bytes`` goes on in part files; readers and resume
follow the chain, and the writer's memory stops growing with the number of changes.

Real files in tmp_path, the real writer and readers, the mcap package's readers. No ROS
master.
"""

from __future__ import annotations

import gc
import tracemalloc
from pathlib import Path

import pytest
from mcap.reader import SeekingReader
from mcap.stream_reader import StreamReader

msg = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC  # noqa: E402
from rosmc_server.recording import (  # noqa: E402
    JournalError,
    JournalOptions,
    JournalWriter,
    latest_state,
    read_journal,
)
from tests.ros.test_journal import event, mission  # noqa: E402

T0 = 1_700_000_000_000_000_000
PART = 40_000  # bytes: 20 kB of schemas and channels, then about 45 events


def mcap_count(path: Path) -> int:
    """Messages the mcap package reads from ``path`` (indexed, then sequentially)."""
    with path.open("rb") as file:
        reader = SeekingReader(file, validate_crcs=True)
        count = len(list(reader.iter_messages()))
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert summary.statistics.message_count == count
    with path.open("rb") as file:
        assert list(StreamReader(file, validate_crcs=True).records)
    return count


def grow(writer: JournalWriter, first: int, last: int) -> None:
    """Append events ``first`` to ``last``, with a snapshot whenever one is due."""
    for rev in range(first, last + 1):
        writer.append_event(event(rev), T0 + rev)
        if writer.snapshot_due:
            writer.append_snapshot(mission(rev), T0 + rev)


def event_revisions(result: object) -> list[int]:
    return [int(r.message.revision) for r in result.records if r.topic == EVENTS_TOPIC]  # type: ignore[attr-defined]


def test_a_full_file_goes_on_in_the_next_part_at_a_snapshot(tmp_path: Path) -> None:
    path = tmp_path / "m.mcap"
    options = JournalOptions(part_bytes=PART, snapshot_every=10**6)
    writer = JournalWriter.create(path, mission(0), T0, options)
    grow(writer, 1, 100)
    assert writer.path == path and writer.part_path.name.startswith("m.part0")
    writer.close()
    parts = sorted(tmp_path.glob("m.part*.mcap"))
    assert [p.name for p in parts] == [f"m.part{n:03d}.mcap" for n in range(2, len(parts) + 2)]
    assert len(parts) >= 2
    files = [path, *parts]
    assert all(f.stat().st_size < 2 * PART for f in files)
    counts = [mcap_count(f) for f in files]  # every part is a complete MCAP file
    result = read_journal(path)
    assert result.clean and result.files == tuple(files)
    assert event_revisions(result) == list(range(1, 101))
    assert sum(counts) == len(result.records)
    for part in parts:  # each part opens with the snapshot that started it
        first = read_journal(part).records  # any part names the whole journal...
        assert first == result.records
    with parts[0].open("rb") as file:
        opening = next(iter(SeekingReader(file).iter_messages()))
    assert opening[1].topic == MISSION_TOPIC
    assert latest_state(result).revision == 100


def test_telemetry_alone_fills_a_part_and_resume_reads_back_to_a_snapshot(
    tmp_path: Path,
) -> None:
    path = tmp_path / "m.mcap"
    options = JournalOptions(part_bytes=PART)
    writer = JournalWriter.create(path, mission(0), T0, options)
    grow(writer, 1, 5)
    report = msg.RobotReport(agent="drone", status_text="x" * 300)
    while writer.part_path == path:  # no change, no snapshot: rotated at twice the size
        writer.append_report(report, T0 + 10)
    assert path.stat().st_size >= 2 * PART
    writer.abandon()
    resumed = JournalWriter.resume(path, options)
    assert resumed.recovered is not None
    assert resumed.recovered.files == (path, tmp_path / "m.part002.mcap")
    assert resumed.needs_snapshot and not resumed.damaged
    state = latest_state(resumed.recovered)
    assert state.revision == 5 and state.gaps == ()
    resumed.close()


def test_resume_reads_only_the_last_part_unless_it_needs_the_one_before(tmp_path: Path) -> None:
    path = tmp_path / "m.mcap"
    options = JournalOptions(part_bytes=PART, snapshot_every=10**6)
    writer = JournalWriter.create(path, mission(0), T0, options)
    grow(writer, 1, 60)
    writer.abandon()
    with JournalWriter.resume(path, options) as resumed:
        assert resumed.recovered is not None
        assert resumed.recovered.files == (resumed.part_path,)  # bounded, however long
        assert latest_state(resumed.recovered).revision == 60
        # A late snapshot (of revision 58, journaled after 59 and 60) never starts a part: a
        # resume that read that part alone would miss r59 and r60. A current one does.
        while not resumed.snapshot_due:
            resumed.append_report(msg.RobotReport(agent="drone"), T0 + 61)
        previous = resumed.part_path
        resumed.append_snapshot(mission(58), T0 + 62)
        assert resumed.part_path == previous
        resumed.append_snapshot(mission(60), T0 + 63)
        assert resumed.part_path != previous
        resumed.append_event(event(61), T0 + 64)
        resumed.abandon()
    with JournalWriter.resume(path, options) as again:
        assert again.recovered is not None
        assert again.recovered.files == (again.part_path,)  # it starts the mission alone
        state = latest_state(again.recovered)
        assert state.revision == 61 and state.gaps == ()


def test_create_refuses_beside_the_parts_of_an_older_journal(tmp_path: Path) -> None:
    path = tmp_path / "m.mcap"
    (tmp_path / "m.part002.mcap").write_bytes(b"older")
    with pytest.raises(JournalError, match=r"part files of an older journal .*m\.part002"):
        JournalWriter.create(path, mission(0), T0)
    assert not path.exists()


def test_a_part_created_just_before_a_crash_is_replaced(tmp_path: Path) -> None:
    path = tmp_path / "m.mcap"
    options = JournalOptions(part_bytes=2 * PART, snapshot_every=10**6)
    writer = JournalWriter.create(path, mission(0), T0, options)
    grow(writer, 1, 20)
    writer.abandon()
    assert not (tmp_path / "m.part002.mcap").exists(), "the 20 events fill one part"
    (tmp_path / "m.part002.mcap").write_bytes(b"")  # created, nothing written yet
    with JournalWriter.resume(path, options) as resumed:
        assert resumed.part_path == path
        resumed.append_event(event(21), T0 + 21)
    assert not (tmp_path / "m.part002.mcap").exists()
    assert event_revisions(read_journal(path)) == list(range(1, 22))


def test_the_writers_memory_stops_growing_with_the_number_of_changes(tmp_path: Path) -> None:
    """What the summary needs is all a writer keeps, and only for the file it writes."""
    options = JournalOptions(part_bytes=64_000, snapshot_every=100)
    writer = JournalWriter.create(tmp_path / "m.mcap", mission(0), T0, options)
    tracemalloc.start()
    try:
        grow(writer, 1, 1000)
        gc.collect()
        after_1000 = tracemalloc.get_traced_memory()[0]
        grow(writer, 1001, 3000)
        gc.collect()
        after_3000 = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
        writer.close()
    # 2000 more changes: about a megabyte if every change kept its index entry.
    assert after_3000 - after_1000 < 64_000


def test_every_part_records_the_library_after_its_first_snapshot(tmp_path: Path) -> None:
    from rosmc_server.conversions import library_from_msg, library_to_msg
    from rosmc_server.core import load_library
    from rosmc_server.interface import LIBRARY_TOPIC
    from rosmc_server.ros.replay_library import SHIPPED_LIBRARY

    library = library_to_msg(load_library(SHIPPED_LIBRARY))
    path = tmp_path / "m.mcap"
    options = JournalOptions(part_bytes=PART, snapshot_every=10**6)
    writer = JournalWriter.create(path, mission(0), T0, options, library)
    grow(writer, 1, 100)
    writer.close()
    files = [path, *sorted(tmp_path.glob("m.part*.mcap"))]
    assert len(files) >= 2
    for file in files:  # each part on its own says which library the mission ran with
        with file.open("rb") as stream:
            topics = [c.topic for _, c, _ in SeekingReader(stream).iter_messages()]
        assert topics[:2] == [MISSION_TOPIC, LIBRARY_TOPIC] and topics.count(LIBRARY_TOPIC) == 1
    record = next(r for r in read_journal(path).records if r.topic == LIBRARY_TOPIC)
    assert library_from_msg(record.message) == load_library(SHIPPED_LIBRARY)
