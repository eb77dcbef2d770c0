"""What rviz receives per mission event: the markers the event changes, nothing else.

The marker node against a real mission server, with robots reporting telemetry at 10 Hz
and a cluster of task markers whose labels stack in columns (so a label that moves could
push its neighbours). ``/rosmc/markers/update`` is read as rviz reads it; the tests assert
which interactive markers each event sends and how (full insert or pose), never how fast
(timings are in ``bench/bench_markers.py``).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
import rosmc.msg as wire
import rospy
from visualization_msgs.msg import InteractiveMarkerUpdate, MarkerArray

from rosmc_rviz_markers import topics
from rosmc_server.core import MarkerType, Pose, TaskMarker
from rosmc_server.ros.client import MissionClient
from tests.integration.markers_fixtures import Rviz, wait_for

pytest_plugins = ["tests.integration.server_fixtures", "tests.integration.markers_fixtures"]

ROBOTS = ("drone", "science_rover", "manipulator_rover")
CLUSTER = [(f"c{i:02d}", float(i % 4), float(i // 4)) for i in range(16)]
AFTER = 0.5  # s of updates still taken after the one carrying the event's marker


class Updates:
    """Every non-empty ``InteractiveMarkerUpdate`` and icon array, with its arrival."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.got: list[tuple[float, set[str], set[str]]] = []  # (time, inserted, posed)
        self.icons: list[tuple[float, set[str]]] = []  # (time, ns of each icon marker sent)
        self._subscribers = [
            rospy.Subscriber(
                topics.MARKERS_NS + "/update", InteractiveMarkerUpdate, self._on_update
            ),
            rospy.Subscriber(topics.ICONS_TOPIC, MarkerArray, self._on_icons),
        ]
        for subscriber in self._subscribers:  # a one-off update must not go unseen
            wait_for(subscriber.get_num_connections, f"the marker node on {subscriber.name}")

    def _on_update(self, msg: Any) -> None:
        if msg.markers or msg.poses or msg.erases:
            with self.lock:
                self.got.append(
                    (time.monotonic(), {m.name for m in msg.markers}, {p.name for p in msg.poses})
                )

    def _on_icons(self, msg: Any) -> None:
        with self.lock:
            self.icons.append((time.monotonic(), {m.ns for m in msg.markers}))

    def since(self, began: float) -> tuple[set[str], set[str]]:
        """Interactive markers inserted and posed since ``began``."""
        with self.lock:
            got = [(m, p) for at, m, p in self.got if at >= began]
        return set().union(*(m for m, _ in got)), set().union(*(p for _, p in got))

    def close(self) -> None:
        """Unsubscribe."""
        for subscriber in self._subscribers:
            subscriber.unregister()


@pytest.fixture
def telemetry(rviz: Rviz) -> Iterator[None]:
    """The three robots report at 10 Hz, every message different (no TF: the node places
    them where they report)."""
    publishers = [rospy.Publisher(f"/{r}/telemetry", wire.Telemetry, queue_size=10) for r in ROBOTS]
    stop = threading.Event()

    def run() -> None:
        tick = 0
        while not stop.wait(0.1):
            tick += 1
            for i, (robot, pub) in enumerate(zip(ROBOTS, publishers, strict=True)):
                angle = 0.05 * tick + i
                msg = wire.Telemetry(
                    agent=robot,
                    stamp=rospy.Time.now(),
                    frame_id="map",
                    battery=0.5 + 0.4 * math.sin(angle),
                    wifi_signal=-60 + 10 * math.cos(angle),
                    in_coverage=True,
                )
                # they drive past the cluster, their status blocks over its labels
                x, y = 2 + 6 * math.cos(angle), -4.0 + 3 * math.sin(3 * angle)
                msg.pose.x, msg.pose.y, msg.pose.yaw = x, y, angle
                pub.publish(msg)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    yield
    stop.set()
    thread.join()
    for publisher in publishers:
        publisher.unregister()


def cluster(mission: MissionClient, rviz: Rviz) -> None:
    """16 task markers 1 m apart, every second one used by a blueprint skill."""
    for i, (name, x, y) in enumerate(CLUSTER):
        mission.add_task_marker(TaskMarker(name, MarkerType.POSITION, Pose(x, y)))
        if i % 2 == 0:
            mission.add_skill("science_rover", "navigate_to", bindings={"target": name})
    for name, _, _ in CLUSTER:
        rviz.marker(f"task/{name}")
    # no TF here: once the node has noticed, every agent is placed in the map frame
    for name in rviz.markers():
        if not name.startswith("task/"):
            rviz.marker(name, lambda m: m.header.frame_id == "map")


def sent_for(updates: Updates, expected: str, call: Any) -> tuple[set[str], set[str]]:
    """Run ``call``; what rviz got from then until a while after ``expected`` arrived."""
    began = time.monotonic()
    call()
    wait_for(lambda: expected in updates.since(began)[0], f"an update of {expected}")
    time.sleep(AFTER)
    return updates.since(began)


def test_robots_reporting_send_no_task_marker_and_robots_as_poses(
    mission: MissionClient, rviz: Rviz, telemetry: None
) -> None:
    cluster(mission, rviz)
    updates = Updates()
    try:
        began = time.monotonic()
        # robots without TF are placed where they report: they move by pose updates
        wait_for(lambda: {f"robot/{r}" for r in ROBOTS} <= updates.since(began)[1], "poses")
        time.sleep(1.5)  # three agent-state messages at least
        inserted, posed = updates.since(began)
        assert not inserted, "a robot's report made no marker be sent whole"
        assert {name for name in posed if name.startswith("task/")} == set()
        # the status icons: each message carries the robots whose block changed
        with updates.lock:
            icon_ns = [ns for at, ns in updates.icons if at >= began]
        assert icon_ns and all(ns <= {f"icons/{r}" for r in ROBOTS} for ns in icon_ns)
    finally:
        updates.close()


def test_an_isolated_event_sends_the_markers_it_changes(
    mission: MissionClient, rviz: Rviz, telemetry: None
) -> None:
    cluster(mission, rviz)
    updates = Updates()
    try:
        # a skill added to an unused marker amid the cluster: its colour and label change
        added = []
        inserted, _ = sent_for(
            updates,
            "task/c05",
            lambda: added.append(
                mission.add_skill("drone", "navigate_to", bindings={"target": "c05"}).skill_id
            ),
        )
        assert inserted == {"task/c05"}
        # rebound to another marker: the two markers it names
        inserted, _ = sent_for(
            updates,
            "task/c09",
            lambda: mission.edit_skill(added[0], bindings={"target": "c09"}),
        )
        assert inserted == {"task/c05", "task/c09"}
        inserted, _ = sent_for(updates, "task/c09", lambda: mission.delete_skills(added))
        assert inserted == {"task/c09"}
        # a marker moved into the middle of the cluster: that marker alone
        inserted, _ = sent_for(
            updates, "task/c15", lambda: mission.move_task_marker("c15", Pose(1.5, 1.5))
        )
        assert inserted == {"task/c15"}
    finally:
        updates.close()
