"""``rosmc replay`` against a real master: it republishes a recording, and stays off live names.

The recording is made with the mission core and JournalWriter (a short planning
session); the replay runs as a subprocess, this test process subscribes as rviz
or the command GUI would.
"""

from __future__ import annotations

import itertools
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import rosgraph
import rosmc.msg as wire
import rospy
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from rosmc_server.conversions import event_to_msg, mission_to_msg, site_to_msg
from rosmc_server.core import Mission, Pose, TaskMarker, load_library
from rosmc_server.core.skills.params import MarkerType
from rosmc_server.core.world.site import SiteModel
from rosmc_server.interface import (
    MAP_FRAME,
    SCIENCE_TOPIC,
    SITE_IN_FORCE_TOPIC,
    TF_TOPIC,
    WORLD_TOPIC,
    base_link,
)
from rosmc_server.recording import JournalWriter
from rosmc_server.ros.graph_names import taken_names
from tests.conftest import free_port

REPO = Path(__file__).resolve().parents[2]
ROSMC = REPO / "scripts" / "rosmc"
LIBRARY = REPO / "rosmc_server" / "config" / "mars_team.yaml"
SPACING = 0.05  # seconds between recorded events
EVENTS = 24


@pytest.fixture(scope="module")
def journal(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A closed journal: a snapshot, then EVENTS planning changes SPACING s apart."""
    counter = itertools.count(1)
    clock = itertools.count(100, 5)
    mission = Mission(
        load_library(LIBRARY),
        new_id=lambda prefix: f"{prefix}-{next(counter)}",
        clock=lambda: float(next(clock)),
    )
    path = tmp_path_factory.mktemp("replay") / "mission.mcap"
    t0 = time.time_ns()
    snapshot = mission_to_msg(mission.state.content(), 0, 0.0)
    with JournalWriter.create(path, snapshot, t0) as writer:
        for index in range(1, EVENTS + 1):
            if index == 1:
                event = mission.add_marker(TaskMarker("RSS A", MarkerType.POSITION, Pose(3, 4)))
            else:
                event = mission.add_skill("drone", "take_off", {"altitude": float(index)})
            msg = event_to_msg(event, lambda skill_id: mission.state.locate(skill_id)[0])
            stamp = t0 + round(index * SPACING * 1e9)
            writer.append_event(msg, stamp)
            for topic, telemetry in telemetry_at(index):
                writer.append_telemetry(topic, telemetry, stamp + 1000)
    return path


SITE_SENDERS = {1: "/rosmc/sim", 13: "/site_mapper"}


def telemetry_at(index: int) -> list[tuple[str, Any]]:
    """What the server journals beside the changes: the drone climbing, the site, the score."""
    transform = TransformStamped()
    transform.header.frame_id = MAP_FRAME
    transform.child_frame_id = base_link("drone")
    transform.transform.translation.z = float(index)
    transform.transform.rotation.w = 1.0
    records: list[tuple[str, Any]] = [(TF_TOPIC, TFMessage(transforms=[transform]))]
    if index % 6 == 1:
        marker = Marker(ns="site", id=index, type=Marker.CYLINDER, action=Marker.ADD)
        records.append((WORLD_TOPIC, MarkerArray(markers=[marker])))
        records.append((SCIENCE_TOPIC, wire.ScienceState(score=index / 10)))
    if index in SITE_SENDERS:  # the map in force, and who sent it
        sender = SITE_SENDERS[index]
        site = site_to_msg(SiteModel(f"site {index}", (-40.0, 40.0, -40.0, 40.0)), index)
        records.append((SITE_IN_FORCE_TOPIC, wire.SiteInForce(sender=sender, site=site)))
    return records


@pytest.fixture
def node(ros_master: Any) -> Any:
    """This process as a rospy node on the session's master."""
    if not rospy.core.is_initialized():
        rospy.init_node("replay_tests", anonymous=True, disable_signals=True)
    return ros_master


class Listener:
    """Subscribes to a replay's mission and events, as a GUI would."""

    def __init__(self, prefix: str = "") -> None:
        self.snapshots: list[int] = []
        self.events: list[int] = []
        self._changed = threading.Condition()
        self._subscribers = [
            rospy.Subscriber(f"{prefix}/rosmc/mission", wire.Mission, self._on_mission),
            rospy.Subscriber(
                f"{prefix}/rosmc/mission_events", wire.MissionEvent, self._on_event, queue_size=100
            ),
        ]

    def _on_mission(self, msg: Any) -> None:
        with self._changed:
            self.snapshots.append(int(msg.revision))
            self._changed.notify_all()

    def _on_event(self, msg: Any) -> None:
        with self._changed:
            self.events.append(int(msg.revision))
            self._changed.notify_all()

    def wait(self, done: Callable[[], bool], timeout: float = 30.0) -> bool:
        with self._changed:
            return self._changed.wait_for(done, timeout)

    def close(self) -> None:
        for subscriber in self._subscribers:
            subscriber.unregister()


@pytest.fixture
def listen(node: Any) -> Iterator[Callable[[str], Listener]]:
    listeners: list[Listener] = []

    def make(prefix: str = "") -> Listener:
        listeners.append(Listener(prefix))
        return listeners[-1]

    yield make
    for listener in listeners:
        listener.close()


def replay(env: Any, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(ROSMC), "replay", *args],
        env=dict(env),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def publishers(master: Any, topic: str) -> list[str]:
    _, _, (pubs, _, _) = master.proxy().getSystemState("/replay_tests")
    return next((nodes for name, nodes in pubs if name == topic), [])


def test_replay_republishes_every_event_and_the_final_snapshot(
    node: Any, journal: Path, listen: Callable[[str], Listener]
) -> None:
    listener = listen("")
    done = replay(node.env, str(journal), "--rate", "10")
    assert done.returncode == 0, done.stderr
    assert listener.wait(lambda: EVENTS in listener.snapshots)
    assert listener.events == list(range(1, EVENTS + 1))
    assert listener.snapshots[0] == 0 and listener.snapshots[-1] == EVENTS
    assert "replay done at revision 24" in done.stdout
    assert publishers(node, "/rosmc/mission") == []  # the replay left the graph


def test_replay_from_a_start_time_begins_with_the_mission_then(
    node: Any, journal: Path, listen: Callable[[str], Listener]
) -> None:
    listener = listen("")
    start = 10.5 * SPACING  # revision 10 is the current one then
    done = replay(node.env, str(journal), "--rate", "10", "--start", str(start))
    assert done.returncode == 0, done.stderr
    assert listener.wait(lambda: EVENTS in listener.snapshots)
    assert listener.snapshots[0] == 10
    assert listener.events == list(range(11, EVENTS + 1))


def test_replay_refuses_live_names_but_plays_under_a_prefix(
    node: Any, journal: Path, listen: Callable[[str], Listener]
) -> None:
    live = rospy.Publisher("/rosmc/mission", wire.Mission, queue_size=1, latch=True)
    try:
        deadline = time.monotonic() + 30
        while not publishers(node, "/rosmc/mission") and time.monotonic() < deadline:
            time.sleep(0.05)
        refused = replay(node.env, str(journal), "--rate", "50")
        assert refused.returncode == 1
        assert f"/rosmc/mission by {rospy.get_name()}" in refused.stderr
        assert "--prefix" in refused.stderr
        listener = listen("/replay")
        done = replay(node.env, str(journal), "--rate", "50", "--prefix", "/replay")
        assert done.returncode == 0, done.stderr
        assert listener.wait(lambda: EVENTS in listener.snapshots)
        assert listener.events == list(range(1, EVENTS + 1))
    finally:
        live.unregister()


def test_a_dead_nodes_registrations_do_not_block_a_replay(
    node: Any, journal: Path, listen: Callable[[str], Listener]
) -> None:
    # What a mission server killed with -9 leaves behind: the master still lists it.
    ghost = rosgraph.Master("/ghost_mission_server")
    nobody = f"http://127.0.0.1:{free_port()}/"
    ghost.registerPublisher("/rosmc/mission_events", "rosmc/MissionEvent", nobody)
    try:
        assert "/ghost_mission_server" in publishers(node, "/rosmc/mission_events")
        assert taken_names(["/rosmc/mission_events"]) == {}
        listener = listen("")
        done = replay(node.env, str(journal), "--rate", "50")
        assert done.returncode == 0, done.stderr
        assert listener.wait(lambda: EVENTS in listener.snapshots)
    finally:
        ghost.unregisterPublisher("/rosmc/mission_events", nobody)


def test_rosmc_watch_follows_a_replay(node: Any, journal: Path, launch_process: Any) -> None:
    # watch starts from get_mission, which the replay serves, then follows the events.
    watch = launch_process(
        [sys.executable, str(ROSMC), "--timeout", "20", "watch", "--count", "3"],
        env=node.env,
        name="watch",
    )
    done = replay(node.env, str(journal), "--rate", "0.5")
    assert done.returncode == 0, done.stderr
    assert watch.wait(timeout=60) == 0, watch.log()
    events = [line.split()[:2] for line in watch.log().splitlines() if line[1:2].isdigit()]
    assert len(events) == 3 and events[-1][1] == "SKILL_ADDED", watch.log()


def test_replay_shows_the_robots_the_site_and_the_score_under_its_prefix(
    node: Any, journal: Path
) -> None:
    heights: list[float] = []
    world: list[int] = []
    science: list[float] = []
    sites: list[str] = []
    subscribers = [
        rospy.Subscriber(
            f"/replay{SITE_IN_FORCE_TOPIC}", wire.SiteInForce, lambda m: sites.append(m.sender)
        ),
        rospy.Subscriber(
            f"/replay{TF_TOPIC}",
            TFMessage,
            lambda m: heights.extend(t.transform.translation.z for t in m.transforms),
            queue_size=100,
        ),
        rospy.Subscriber(
            f"/replay{WORLD_TOPIC}", MarkerArray, lambda m: world.append(m.markers[0].id)
        ),
        rospy.Subscriber(
            f"/replay{SCIENCE_TOPIC}", wire.ScienceState, lambda m: science.append(m.score)
        ),
    ]
    try:
        done = replay(node.env, str(journal), "--rate", "10", "--prefix", "/replay")
        assert done.returncode == 0, done.stderr
        assert heights == [float(i) for i in range(1, EVENTS + 1)], "every TF record, in order"
        assert world == [1, 7, 13, 19]
        assert science == pytest.approx([0.1, 0.7, 1.3, 1.9])
        assert sites == list(SITE_SENDERS.values())
    finally:
        for subscriber in subscribers:
            subscriber.unregister()
