"""``rosmc export``: the committed sample recording as one MCAP file for Foxglove.

The export is read back with the ``mcap`` package's readers (the indexed one Foxglove's
seeking matches, and the streaming one, both checking CRCs) and decoded with
``mcap_ros1``. No ROS master.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import NonSeekingReader, SeekingReader
from mcap_ros1.decoder import DecoderFactory

from rosmc_server.cli import main as rosmc
from rosmc_server.interface import EVENTS_TOPIC, TF_TOPIC, WORLD_TOPIC
from rosmc_server.recording import JournalResult, read_journal
from rosmc_server.recording.export import (
    CHANGES_TOPIC,
    CHUNK_BYTES,
    ROBOTS_TOPIC,
    TASKS_TOPIC,
)
from rosmc_server.recording.history import MissionHistory
from rosmc_server.text import format_tasks
from tests.ros.recording_checks import SAMPLE

Decoded = list[tuple[str, int, int, Any]]  # topic, log time, publish time, message


@pytest.fixture(scope="module")
def journal() -> JournalResult:
    return read_journal(SAMPLE)


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("export") / "demo.mcap"
    assert rosmc(["export", str(SAMPLE), str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def decoded(exported: Path) -> Decoded:
    with exported.open("rb") as stream:
        reader = SeekingReader(stream, validate_crcs=True, decoder_factories=[DecoderFactory()])
        return [
            (channel.topic, message.log_time, message.publish_time, msg)
            for _, channel, message, msg in reader.iter_decoded_messages(log_time_order=True)
        ]


def test_chunks_of_a_reasonable_size_with_indexes_and_a_summary(
    exported: Path, journal: JournalResult
) -> None:
    with exported.open("rb") as stream:
        summary = SeekingReader(stream, validate_crcs=True).get_summary()
    with exported.open("rb") as stream:
        streamed = list(NonSeekingReader(stream, validate_crcs=True).iter_messages())
    assert summary is not None and summary.statistics is not None
    stats = summary.statistics
    assert stats.message_count == len(streamed) > len(journal.records)
    chunks = summary.chunk_indexes
    # The journal has a chunk per message; the export a few, each about CHUNK_BYTES.
    assert 2 <= len(chunks) <= len(streamed) // 100
    assert all(index.uncompressed_size < 2 * CHUNK_BYTES for index in chunks)
    assert all(index.compression == "zstd" for index in chunks)
    assert all(index.message_index_offsets for index in chunks)
    assert stats.chunk_count == len(chunks)


def test_the_figures_of_docs_export_md_are_the_samples(
    exported: Path, journal: JournalResult
) -> None:
    doc = (Path(__file__).resolve().parents[2] / "docs" / "export.md").read_text()
    found = re.search(
        r"sample recording's ([\d,]+) messages\s+\(([\d,]+) exported\)\s+go into (\d+) chunks", doc
    )
    assert found, "docs/export.md names the sample's figures"
    with exported.open("rb") as stream:
        summary = SeekingReader(stream, validate_crcs=True).get_summary()
    assert summary is not None and summary.statistics is not None
    figures = [int(group.replace(",", "")) for group in found.groups()]
    actual = [len(journal.records), summary.statistics.message_count, len(summary.chunk_indexes)]
    assert figures == actual, "update the figures in docs/export.md"


def test_every_recorded_message_on_one_clock(decoded: Decoded, journal: JournalResult) -> None:
    recorded = [(r.topic, r.log_time) for r in journal.records]
    kept = [(topic, log) for topic, log, _, _ in decoded if not topic.startswith("/rosmc/export")]
    assert sorted(kept) == sorted(recorded)
    assert all(publish == log for _, log, publish, _ in decoded)
    tf = [(log, msg) for topic, log, _, msg in decoded if topic == TF_TOPIC]
    world = [(log, msg) for topic, log, _, msg in decoded if topic == WORLD_TOPIC]
    assert tf and world
    # The simulator stamped these with sim time (seconds since its start); now log time.
    for log, msg in tf:
        assert {t.header.stamp.to_nsec() for t in msg.transforms} == {log}
    for log, msg in world:
        assert {m.header.stamp.to_nsec() for m in msg.markers} <= {log}


def test_robots_are_drawn_as_markers_in_their_frames(decoded: Decoded) -> None:
    tf = {log: msg for topic, log, _, msg in decoded if topic == TF_TOPIC}
    robots = {log: msg for topic, log, _, msg in decoded if topic == ROBOTS_TOPIC}
    assert robots.keys() == tf.keys()
    for log, array in robots.items():
        frames = {t.child_frame_id for t in tf[log].transforms}
        assert {m.header.frame_id for m in array.markers} == frames
        for frame in frames:
            agent = frame.split("/")[0]
            body = [m for m in array.markers if m.header.frame_id == frame]
            assert {m.ns for m in body} == {f"robots/{agent}"}
            assert all(m.frame_locked and m.header.stamp.to_nsec() == log for m in body)
            assert [m.text for m in body if m.type == m.TEXT_VIEW_FACING] == [agent]
            assert len(body) >= 3, f"{agent} is a label, not a body"
    assert {"drone", "science_rover", "manipulator_rover"} <= {
        m.ns.split("/")[1] for array in robots.values() for m in array.markers
    }


def test_the_mission_as_readable_text(decoded: Decoded, journal: JournalResult) -> None:
    history = MissionHistory(journal)
    changes = [msg.data for topic, _, _, msg in decoded if topic == CHANGES_TOPIC]
    events = [msg for topic, _, _, msg in decoded if topic == EVENTS_TOPIC]
    assert len(changes) == len(events)
    assert [line.split()[0] for line in changes] == [f"r{e.revision}" for e in events]
    texts = [(log, msg.data) for topic, log, _, msg in decoded if topic == TASKS_TOPIC]
    last_log, last = texts[-1]
    final = history.at_revision(history.revisions[-1].revision)
    title = f"{SAMPLE.name} at {history.seconds(last_log):.1f} s"
    assert last == format_tasks(final, title)
    assert all(skill.id in last for skill in final.skills())


def test_an_existing_file_is_kept_unless_forced(
    exported: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "taken.mcap"
    out.write_bytes(b"mine")
    assert rosmc(["export", str(SAMPLE), str(out)]) == 1
    assert "exists; give --force" in capsys.readouterr().err
    assert out.read_bytes() == b"mine"
    assert rosmc(["--json", "export", str(SAMPLE), str(out), "--force"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["path"] == str(out) and data["counts"][ROBOTS_TOPIC] > 0
    assert out.read_bytes() == exported.read_bytes()
