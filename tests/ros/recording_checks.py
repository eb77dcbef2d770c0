"""Checks shared by the tests of the committed sample and of fresh recordings.

Each check reads the recording with a reader of its own (the ``mcap`` package, ``rosbag``,
``rosbags``), not with the journal reader under test, and fails with what differs.
"""

from __future__ import annotations

import copy
import io
from collections import defaultdict
from pathlib import Path
from typing import Any

import genpy
import rosbag
from mcap.reader import make_reader
from rosbags.rosbag1 import Reader as RosbagsReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from rosmc_server.conversions import mission_from_msg, mission_to_msg
from rosmc_server.recording.channels import LATCHED_TOPICS
from rosmc_server.recording.history import MissionHistory

Messages = dict[str, list[tuple[int, bytes]]]
"""Per topic: (log time in ns, ROS 1 bytes) of every message, in file order."""


def mcap_messages(path: Path) -> tuple[Messages, dict[str, tuple[str, bytes]]]:
    """Every message of an MCAP file by topic, and each topic's (schema name, definition)."""
    messages: Messages = defaultdict(list)
    schemas: dict[str, tuple[str, bytes]] = {}
    with path.open("rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            assert schema is not None, f"{channel.topic} has no schema"
            messages[channel.topic].append((message.log_time, bytes(message.data)))
            schemas[channel.topic] = (schema.name, bytes(schema.data))
    return dict(messages), schemas


def assert_bag_holds_the_journal(journal: Path, bag_path: Path) -> None:
    """``rosbag`` reads every journal message from the bag: topic, type, bytes, latching."""
    expected, schemas = mcap_messages(journal)
    found: Messages = defaultdict(list)
    with rosbag.Bag(str(bag_path)) as bag:
        topics = bag.get_type_and_topic_info().topics
        assert {t: topics[t].message_count for t in topics} == {
            t: len(m) for t, m in expected.items()
        }
        for topic, (name, _definition) in schemas.items():
            assert topics[topic].msg_type == name
        for topic, raw, stamp in bag.read_messages(raw=True):
            found[topic].append((stamp.to_nsec(), bytes(raw[1])))
        for connection in bag._connections.values():
            name, definition = schemas[connection.topic]
            header = connection.header
            assert header["type"].decode() == name
            assert header["message_definition"] == definition, connection.topic
            latched = connection.topic in LATCHED_TOPICS
            assert header.get("latching") == (b"1" if latched else b"0"), connection.topic
    for topic, messages in expected.items():
        # The bag's time is the mission clock (tests/ros/test_tobag_clock.py), not the log
        # time: the same messages, each in the bag once.
        assert sorted(raw for _, raw in found[topic]) == sorted(raw for _, raw in messages), (
            f"{topic} differs in the bag"
        )
    assert set(found) == set(expected)


def assert_rosbags_reads_the_bag(bag_path: Path, journal: Path) -> None:
    """``rosbags`` reads every message with only the definitions the bag carries."""
    expected, _ = mcap_messages(journal)
    typestore = get_typestore(Stores.EMPTY)  # nothing but what the bag embeds
    found: Messages = defaultdict(list)
    with RosbagsReader(bag_path) as reader:
        for connection in reader.connections:
            typestore.register(get_types_from_msg(connection.msgdef.data, connection.msgtype))
        for connection in reader.connections:
            _, digest = typestore.generate_msgdef(connection.msgtype, ros_version=1)
            assert digest == connection.digest, f"md5 of {connection.msgtype}"
        for connection, stamp, raw in reader.messages():
            message = typestore.deserialize_ros1(raw, connection.msgtype)
            again = typestore.serialize_ros1(message, connection.msgtype)
            assert bytes(again) == bytes(raw), f"{connection.topic} at {stamp} does not round-trip"
            found[connection.topic].append((stamp, bytes(raw)))

    def contents(messages: Messages) -> dict[str, list[bytes]]:
        return {topic: sorted(raw for _, raw in rows) for topic, rows in messages.items()}

    assert contents(found) == contents(expected)  # times: the mission clock, not log times


def unstamped(mission: Any) -> bytes:
    """A ``rosmc/Mission``'s ROS 1 bytes without its stamp: equal bytes, equal missions."""
    copied = copy.deepcopy(mission)
    copied.stamp = genpy.Time()
    buffer = io.BytesIO()
    copied.serialize(buffer)
    return buffer.getvalue()


def assert_history_is(history: MissionHistory, truth: dict[int, Any]) -> None:
    """At each revision of ``truth`` (revision -> the server's ``rosmc/Mission``), the history
    holds that mission: field by field as core content, and byte for byte as a message."""
    for revision, server in sorted(truth.items()):
        state = history.at_revision(revision)
        content, said = mission_from_msg(server)
        assert said == revision == state.revision
        assert state.content() == content, f"revision {revision} differs from the server's"
        rebuilt = mission_to_msg(state.content(), revision, 0.0)
        assert unstamped(rebuilt) == unstamped(server), f"revision {revision} (wire bytes)"


REPO = Path(__file__).resolve().parents[2]
SAMPLE = REPO / "bags" / "samples" / "demo.mcap"
"""The committed sample: the demo mission, recorded by tools/record_sample.py."""
REGENERATE = (
    "record it anew with `make sample` (tools/record_sample.py, about 20 s) and commit "
    "bags/samples/demo.mcap"
)
