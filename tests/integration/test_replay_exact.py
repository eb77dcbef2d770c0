"""A fresh recording of the real mission server replays exactly what the server held.

A real ``mission_server`` journals a mission while this test plays the operator (through
:class:`MissionClient`), the drone's robot link (upload acks, skill reports) and the
simulator (TF, the drone's telemetry, the site and the score). After every change the
test keeps the server's own answer to ``get_mission``: the truth at each revision, taken
from the server, not from the journal. Then:

* the history rebuilt from the journal equals that answer at every revision, field by
  field and byte for byte;
* ``rosmc replay`` publishes every recorded agent state, TF message, site and score as
  recorded, in order;
* ``rosmc tobag`` writes a bag that ``rosbag`` and ``rosbags`` read message for message.
"""

from __future__ import annotations

import io
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rospy
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from rosmc_server import interface
from rosmc_server.core import EventKind, MarkerType, Pose, TaskMarker
from rosmc_server.recording import read_journal
from rosmc_server.recording.history import MissionHistory
from rosmc_server.ros.client import MissionClient
from tests.conftest import wait_until
from tests.integration.server_fixtures import Client, FakeRobot, _launcher, _stop_all
from tests.ros.recording_checks import (
    assert_bag_holds_the_journal,
    assert_history_is,
    assert_rosbags_reads_the_bag,
)

pytest_plugins = ["tests.integration.server_fixtures"]

REPO = Path(__file__).resolve().parents[2]
ROSMC = REPO / "scripts" / "rosmc"
PREFIX = "/exact"
TELEMETRY_PERIOD = 0.05
TELEMETRY_TOPICS = (
    interface.AGENT_STATES_TOPIC,
    interface.TF_TOPIC,
    interface.SCIENCE_TOPIC,
    interface.WORLD_TOPIC,
)
TYPES = {
    interface.AGENT_STATES_TOPIC: wire.AgentStates,
    interface.TF_TOPIC: TFMessage,
    interface.SCIENCE_TOPIC: wire.ScienceState,
    interface.WORLD_TOPIC: MarkerArray,
}


@dataclass
class Fresh:
    """The journal of the session and the server's own mission at every revision."""

    path: Path
    truth: dict[int, wire.Mission] = field(default_factory=dict)


class Site:
    """Plays the simulator: TF and the drone's telemetry moving at 20 Hz, site and score."""

    def __init__(self) -> None:
        self._tf = rospy.Publisher(interface.TF_TOPIC, TFMessage, queue_size=10)
        self._telemetry = rospy.Publisher(
            interface.TELEMETRY_TOPIC.format(agent="drone"), wire.Telemetry, queue_size=10
        )
        self._science = rospy.Publisher(
            interface.SCIENCE_TOPIC, wire.ScienceState, queue_size=2, latch=True
        )
        self._world = rospy.Publisher(interface.WORLD_TOPIC, MarkerArray, queue_size=2, latch=True)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self) -> None:
        self._thread.start()

    def score(self, score: float, regions: int) -> None:
        self._science.publish(wire.ScienceState(stamp=rospy.Time.now(), score=score))
        markers = [Marker(action=Marker.DELETEALL)]
        for index in range(regions):
            marker = Marker(ns="regions", id=index, type=Marker.CYLINDER, action=Marker.ADD)
            marker.header.frame_id = interface.MAP_FRAME
            marker.pose.position.x = float(index)
            marker.pose.orientation.w = 1.0
            marker.scale.x = marker.scale.y = marker.scale.z = 1.0
            marker.color.a = 1.0
            markers.append(marker)
        self._world.publish(MarkerArray(markers=markers))

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5.0)
        for publisher in (self._tf, self._telemetry, self._science, self._world):
            publisher.unregister()

    def _run(self) -> None:
        began = time.monotonic()
        while not self._stop.wait(TELEMETRY_PERIOD):
            x = 2.0 * (time.monotonic() - began)  # 2 m/s: a new pose worth a record
            stamp = rospy.Time.now()
            transforms = []
            for agent, y in (("drone", 0.0), ("science_rover", 5.0)):
                transform = TransformStamped()
                transform.header.stamp = stamp
                transform.header.frame_id = interface.MAP_FRAME
                transform.child_frame_id = interface.base_link(agent)
                transform.transform.translation.x, transform.transform.translation.y = x, y
                transform.transform.rotation.w = 1.0
                transforms.append(transform)
            self._tf.publish(TFMessage(transforms=transforms))
            telemetry = wire.Telemetry(agent="drone", stamp=stamp, frame_id="map", battery=0.9)
            telemetry.pose.x, telemetry.in_coverage = x, True
            self._telemetry.publish(telemetry)


@pytest.fixture(scope="module")
def fresh(client_node: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Fresh]:
    """Record a session on a real server; keep the server's mission at every revision."""
    base = tmp_path_factory.mktemp("exact")
    start, started = _launcher(dict(client_node.env), base)
    # The test's robot announces itself once; a long link timeout keeps its link up.
    server = start("exact", link_timeout=600.0, agent_state_rate=10.0)
    site = Site()
    raw, client = Client(), MissionClient(10.0)
    try:
        robot = FakeRobot("drone")
        recording = Fresh(path=Path())
        first = raw.mission()  # the fresh mission, at revision 1
        recording.truth[first.revision] = first
        site.start()
        _session(recording, raw, client, robot, site)
        robot.close()
    finally:
        site.close()
        client.close()
        raw.close()
        _stop_all(started)  # closes the journal
    journals = list(Path(str(server.params["journal_dir"])).glob("*.mcap"))
    assert len(journals) == 1, journals
    recording.path = journals[0]
    yield recording


def _session(
    recording: Fresh, raw: Client, client: MissionClient, robot: FakeRobot, site: Site
) -> None:
    """Plan, synchronize, execute, edit and replace; every change is one revision."""

    def step(action: Callable[[], object]) -> None:
        before = raw.revision()
        action()
        wait_until(lambda: raw.revision() > before, 30.0, f"a change after revision {before}")
        mission = raw.mission()
        assert mission.revision == before + 1, "one change per step"
        recording.truth[before + 1] = mission

    def added(agent: str, skill: str, **kwargs: Any) -> str:
        ids: list[str] = []
        step(
            lambda: ids.append(
                client.add_skill(agent, skill, retry_on_conflict=True, **kwargs).skill_id
            )
        )
        return ids[0]

    site.score(0.0, 1)
    step(lambda: client.add_task_marker(TaskMarker("RSS A", MarkerType.POSITION, Pose(3.0, 4.0))))
    take_off = added("drone", "take_off", params={"altitude": 8.0})
    land = added("drone", "land")
    identify = added("science_rover", "identify_stones", bindings={"position": "RSS A"})
    explore = added("science_rover", "explore")
    step(lambda: client.add_barrier([land, identify]))
    step(lambda: client.edit_skill(take_off, {"altitude": 12.0}, label="higher"))
    step(lambda: client.move_task_marker("RSS A", Pose(6.0, 2.0)))
    time.sleep(0.6)  # the robots move on: TF and agent states are journaled meanwhile
    robot.announce()
    # A robot answers its commands in order: the library's policy first (no revision).
    robot.ack(robot.wait_command(wire.RobotCommand.SET_OPTIONS))
    step(lambda: client.synchronize("drone", take_off))
    upload = robot.wait_command(wire.RobotCommand.UPLOAD)
    step(lambda: robot.ack(upload))
    step(lambda: robot.report(1, take_off, wire.SkillStatus.RUNNING))
    site.score(0.5, 2)
    time.sleep(0.6)
    step(lambda: robot.report(2, take_off, wire.SkillStatus.SUCCESS))
    step(lambda: client.reorder_skills("science_rover", [explore, identify]))
    step(lambda: client.rename_task_marker("RSS A", "RSS B"))
    step(lambda: client.delete_skills([explore]))
    site.score(1.0, 3)
    time.sleep(0.6)
    step(lambda: client.new_mission(keep_markers=True))
    added("drone", "take_off", params={"altitude": 5.0})


@pytest.fixture(scope="module")
def history(fresh: Fresh) -> MissionHistory:
    return MissionHistory.from_journal(fresh.path)


def test_every_revision_replays_as_the_server_answered_it(
    fresh: Fresh, history: MissionHistory
) -> None:
    assert history.problems == ()
    assert [r.revision for r in history.revisions] == sorted(fresh.truth)
    kinds = {r.kind for r in history.revisions}
    for kind in ("SYNC_CONFIRMED", "STATUS_CHANGED", "MISSION_REPLACED", "MARKER_RENAMED"):
        assert EventKind[kind] in kinds
    assert_history_is(history, fresh.truth)


def test_the_replay_publishes_agent_states_tf_site_and_score_as_recorded(
    fresh: Fresh, client_node: Any
) -> None:
    recorded = {
        topic: [_bytes(m) for m in read_journal(fresh.path).messages(topic)]
        for topic in TELEMETRY_TOPICS
    }
    assert all(len(messages) >= 2 for messages in recorded.values()), {
        topic: len(messages) for topic, messages in recorded.items()
    }
    heard: dict[str, list[bytes]] = {topic: [] for topic in TELEMETRY_TOPICS}
    subscribers = [
        rospy.Subscriber(
            interface.prefixed(topic, PREFIX),
            TYPES[topic],
            lambda msg, topic=topic: heard[topic].append(_bytes(msg)),
            queue_size=1000,
        )
        for topic in TELEMETRY_TOPICS
    ]
    try:
        done = subprocess.run(
            [
                sys.executable,
                str(ROSMC),
                "replay",
                str(fresh.path),
                "--rate=4",
                f"--prefix={PREFIX}",
            ],
            env=dict(client_node.env),
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        wait_until(
            lambda: all(len(heard[t]) >= len(recorded[t]) for t in TELEMETRY_TOPICS),
            30.0,
            "every recorded message arrived",
        )
    finally:
        for subscriber in subscribers:
            subscriber.unregister()
    for topic in TELEMETRY_TOPICS:
        assert heard[topic] == recorded[topic], f"{topic} differs from the recording"


def test_tobag_of_a_fresh_recording_holds_every_message(fresh: Fresh, tmp_path: Path) -> None:
    bag = tmp_path / "fresh.bag"
    done = subprocess.run(
        [sys.executable, str(ROSMC), "tobag", str(fresh.path), str(bag)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert_bag_holds_the_journal(fresh.path, bag)
    assert_rosbags_reads_the_bag(bag, fresh.path)


def _bytes(msg: Any) -> bytes:
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()
