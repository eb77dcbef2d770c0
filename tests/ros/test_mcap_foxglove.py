"""A recording as Foxglove and the ``mcap`` tools read it: ROS 1 conventions, index, frames.

Foxglove opens a ROS 1 MCAP file when its profile is ``ros1``, every schema is a
``ros1msg`` definition of a ``package/Type`` with its dependencies, and every channel
carries ``ros1`` messages; it seeks through the summary (statistics, chunk indexes and
message indexes). Its 3D panel shows the robots from ``tf2_msgs/TFMessage`` on ``/tf``
and the site from ``visualization_msgs/MarkerArray``, placed by frame ids that must form
one tree rooted at the fixed frame. Checked on the committed sample with the ``mcap``
package's own readers and its ROS 1 decoder, not the journal reader.
"""

from __future__ import annotations

import io
from collections.abc import Iterator
from typing import Any

import pytest
from mcap.reader import NonSeekingReader, SeekingReader
from mcap_ros1.decoder import DecoderFactory

from rosmc_server.core import load_library
from rosmc_server.demo import LIBRARY
from rosmc_server.interface import MAP_FRAME, TF_TOPIC, WORLD_TOPIC, base_link
from rosmc_server.recording import JOURNAL_TOPICS
from tests.ros.recording_checks import SAMPLE


@pytest.fixture(scope="module")
def indexed() -> Iterator[SeekingReader]:
    with SAMPLE.open("rb") as stream:
        yield SeekingReader(stream, validate_crcs=True, decoder_factories=[DecoderFactory()])


@pytest.fixture(scope="module")
def decoded(indexed: SeekingReader) -> dict[str, list[tuple[int, Any]]]:
    """Every message decoded by mcap_ros1 from the schema embedded in the file."""
    found: dict[str, list[tuple[int, Any]]] = {}
    for _, channel, message, ros in indexed.iter_decoded_messages():
        found.setdefault(channel.topic, []).append((message.log_time, ros))
    return found


def test_profile_schemas_and_channels_follow_the_ros1_conventions(indexed: SeekingReader) -> None:
    assert indexed.get_header().profile == "ros1"
    summary = indexed.get_summary()
    assert summary is not None, "no summary: Foxglove would read the whole file to seek"
    schemas = {schema.id: schema for schema in summary.schemas.values()}
    for schema in schemas.values():
        assert schema.encoding == "ros1msg"
        package, _, name = schema.name.partition("/")
        assert package and name and "/" not in name, schema.name
        for dependency in schema.data.decode().split("\nMSG: ")[1:]:
            assert "/" in dependency.splitlines()[0], "dependencies named package/Type"
    channels = {c.topic: c for c in summary.channels.values()}
    assert {topic: schemas[c.schema_id].name for topic, c in channels.items()} == dict(
        JOURNAL_TOPICS
    )
    assert {c.message_encoding for c in channels.values()} == {"ros1"}


def test_the_summary_indexes_every_message(indexed: SeekingReader) -> None:
    summary = indexed.get_summary()
    assert summary is not None and summary.statistics is not None
    with SAMPLE.open("rb") as stream:
        streamed = list(NonSeekingReader(stream, validate_crcs=True).iter_messages())
    stats = summary.statistics
    assert stats.message_count == len(streamed) > 0
    assert stats.channel_count == len(summary.channels)
    assert stats.schema_count == len(summary.schemas)
    counts: dict[int, int] = {}
    for _, channel, _ in streamed:
        counts[channel.id] = counts.get(channel.id, 0) + 1
    assert stats.channel_message_counts == counts
    times = [message.log_time for _, _, message in streamed]
    assert (stats.message_start_time, stats.message_end_time) == (min(times), max(times))
    assert summary.chunk_indexes and all(c.message_index_offsets for c in summary.chunk_indexes)
    # Read through the indexes (as Foxglove seeks): the same messages as read front to back.
    through_index = sorted((m.log_time, c.id, bytes(m.data)) for _, c, m in indexed.iter_messages())
    assert through_index == sorted((m.log_time, c.id, bytes(m.data)) for _, c, m in streamed)
    assert all(m.publish_time == m.log_time for _, _, m in streamed)


def test_seeking_by_time_reads_only_that_window(indexed: SeekingReader) -> None:
    every = [m.log_time for _, _, m in indexed.iter_messages()]
    start, end = every[len(every) // 3], every[2 * len(every) // 3]
    window = [m.log_time for _, _, m in indexed.iter_messages(starting_at=start, ending_before=end)]
    assert window == [t for t in every if start <= t < end]


def test_every_message_decodes_from_its_embedded_schema(
    decoded: dict[str, list[tuple[int, Any]]], indexed: SeekingReader
) -> None:
    raw = {(c.topic, m.log_time, bytes(m.data)) for _, c, m in indexed.iter_messages()}
    again = set()
    for topic, messages in decoded.items():
        for log_time, ros in messages:
            buffer = io.BytesIO()
            ros.serialize(buffer)
            again.add((topic, log_time, buffer.getvalue()))
    assert again == raw


def test_tf_places_every_robot_below_the_fixed_frame(
    decoded: dict[str, list[tuple[int, Any]]],
) -> None:
    robots = set(load_library(LIBRARY).dynamic_agents)
    children: set[str] = set()
    for _, message in decoded[TF_TOPIC]:
        for transform in message.transforms:
            assert transform.header.frame_id == MAP_FRAME
            assert transform.header.stamp.to_nsec() > 0
            rotation = transform.transform.rotation
            norm = rotation.x**2 + rotation.y**2 + rotation.z**2 + rotation.w**2
            assert norm == pytest.approx(1.0, abs=1e-6), "a valid quaternion"
            children.add(transform.child_frame_id)
    assert children == {base_link(robot) for robot in robots}
    assert not any(frame.startswith("/") for frame in children | {MAP_FRAME})


def test_the_site_markers_hang_in_frames_tf_knows(
    decoded: dict[str, list[tuple[int, Any]]],
) -> None:
    robots = set(load_library(LIBRARY).dynamic_agents)
    frames = {MAP_FRAME} | {base_link(robot) for robot in robots}
    markers = [marker for _, message in decoded[WORLD_TOPIC] for marker in message.markers]
    assert markers
    for marker in markers:
        assert marker.header.frame_id in frames, marker.header.frame_id
        if marker.action == marker.ADD:
            pose = marker.pose.orientation
            assert pose.x**2 + pose.y**2 + pose.z**2 + pose.w**2 == pytest.approx(1.0, abs=1e-6)
            assert marker.color.a > 0, f"an invisible marker {marker.ns}/{marker.id}"
