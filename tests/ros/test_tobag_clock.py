"""``rosmc tobag`` writes one clock: the bag's time is the clock the ``/tf`` stamps use.

``rosbag play --clock`` publishes the bag's time on ``/clock``; with ``/use_sim_time`` a tf2
listener then looks transforms up at that time. The bag of the committed sample is read
back with ``rosbag`` in time order, as ``rosbag play`` plays it, and a real tf2 buffer is fed
its ``/tf``: a lookup at the clock of the moment works (no "extrapolation into the future").
No ROS master.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import rosbag
import rospy
import tf2_py
from tf2_msgs.msg import TFMessage

from rosmc_server.interface import EVENTS_TOPIC, TF_TOPIC
from rosmc_server.recording import read_journal
from rosmc_server.recording.bag_clock import LOG_TIME, MissionClock
from rosmc_server.recording.to_rosbag import journal_to_rosbag
from tests.ros.recording_checks import SAMPLE


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    summary = journal_to_rosbag(SAMPLE, tmp_path_factory.mktemp("tobag") / "demo.bag")
    assert summary.clock == TF_TOPIC
    return summary.path


def played(bag: Path) -> list[tuple[rospy.Time, str, object]]:
    """The bag's messages in the order ``rosbag play`` publishes them, with the clock then.

    ``/tf`` as tf2_msgs/TFMessage (what a subscriber gets), the rest as raw tuples.
    """
    with rosbag.Bag(str(bag)) as reader:
        return [
            (t, topic, TFMessage().deserialize(raw[1]) if topic == TF_TOPIC else raw)
            for topic, raw, t in reader.read_messages(raw=True)
        ]


def robot_frames(tf: object) -> list[str]:
    return [str(t.child_frame_id) for t in tf.transforms]  # type: ignore[attr-defined]


def test_a_tf2_lookup_at_the_played_clock_finds_the_transforms(bag: Path) -> None:
    buffer = tf2_py.BufferCore(rospy.Duration(3600))
    looked_up = 0
    for clock, topic, msg in played(bag):
        if topic != TF_TOPIC:
            continue
        for transform in msg.transforms:  # type: ignore[attr-defined]
            buffer.set_transform(transform, "rosbag_play")
        # What a node with /use_sim_time asks for: the transform now, on /clock.
        for frame in robot_frames(msg):
            found = buffer.lookup_transform_core("map", frame, clock)
            assert found.header.stamp == clock
            looked_up += 1
    assert looked_up > 500


def test_every_message_plays_within_the_clock_of_the_transforms(bag: Path) -> None:
    # Between two TF messages a lookup at the clock interpolates once the next one is in.
    messages = played(bag)
    buffer = tf2_py.BufferCore(rospy.Duration(3600))
    for _, topic, msg in messages:
        if topic == TF_TOPIC:
            for transform in msg.transforms:  # type: ignore[attr-defined]
                buffer.set_transform(transform, "rosbag_play")
    tf_times = [clock for clock, topic, _ in messages if topic == TF_TOPIC]
    inside = [(c, t) for c, t, _ in messages if tf_times[0] <= c <= tf_times[-1]]
    assert len(inside) > 0.9 * len(messages)
    for clock, topic in inside:
        found = buffer.lookup_transform_core("map", "drone/base_link", clock)
        assert found.header.stamp == clock, topic


def test_events_play_at_their_own_stamps_in_a_simulation(bag: Path) -> None:
    # The server stamps its events on the same sim clock as the simulator's TF.
    with rosbag.Bag(str(bag)) as reader:
        events = [(t, msg) for _, msg, t in reader.read_messages(topics=[EVENTS_TOPIC])]
    close = [abs((clock - msg.stamp).to_sec()) < 2.0 for clock, msg in events]
    assert len(events) > 50 and sum(close) > 0.9 * len(events)


def test_the_clock_maps_log_times_through_the_stamps() -> None:
    records = read_journal(SAMPLE).records
    clock = MissionClock.of(records)
    assert clock.source == TF_TOPIC and clock.rate > 1.0  # recorded at real-time factor 20
    times = [clock.at(record.log_time) for record in sorted(records, key=lambda r: r.log_time)]
    assert times == sorted(times) and times[0] >= 1
    assert MissionClock.of(()).source == LOG_TIME
    assert MissionClock.of(()).at(123) == 123
