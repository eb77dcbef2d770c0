"""Fixtures for the marker-node tests: a real mission server, a real marker node, and rviz's side.

``markers_node`` (module) starts ``scripts/markers_node`` against the module's mission server
(``tests/integration/server_fixtures.py``). ``rviz`` (function) is what rviz is to the node:
it reads ``/rosmc/markers/update_full`` and publishes ``InteractiveMarkerFeedback`` on
``/rosmc/markers/feedback`` exactly as rviz does, and sends the stock tools' messages.
``mission`` (function) is a :class:`MissionClient` on an empty mission.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

import pytest
import rosmc.msg as wire
import rospy
from geometry_msgs.msg import (
    Point,
    PointStamped,
    Pose,
    PoseStamped,
    PoseWithCovarianceStamped,
    Quaternion,
)
from visualization_msgs.msg import (
    InteractiveMarker,
    InteractiveMarkerFeedback,
    InteractiveMarkerInit,
)

from rosmc_rviz_markers import topics
from rosmc_server import interface
from rosmc_server.core import MissionState
from rosmc_server.ros.client import MissionClient

REPO = Path(__file__).resolve().parents[2]
NODE = REPO / "scripts" / "markers_node"
TIMEOUT = 60.0
CLIENT_ID = "/rviz_test/InteractiveMarkers"
T = TypeVar("T")


def scout_library(directory: Path) -> Path:
    """A custom library: the shipped one with the drone called ``scout``."""
    shipped = (REPO / "rosmc_server" / "config" / "mars_team.yaml").read_text()
    path = directory / "scouts.yaml"
    path.write_text(shipped.replace("\n  drone: {", "\n  scout: {"))
    return path


def label_of(marker: InteractiveMarker) -> str:
    """The text an interactive marker shows: its description or the text it draws."""
    drawn = (m.text for c in marker.controls for m in c.markers if m.type == m.TEXT_VIEW_FACING)
    return str(marker.description or next(drawn, ""))


def wait_for(condition: Callable[[], T], what: str, timeout: float = TIMEOUT) -> T:
    """Poll ``condition`` until it returns something true; fail after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


class MarkerNodeProcess:
    """``scripts/markers_node`` in its own process, with its log."""

    def __init__(self, env: dict[str, str], log_path: Path, *args: str) -> None:
        self.log_path = log_path
        with log_path.open("wb") as log:
            self.process = subprocess.Popen(
                [sys.executable, str(NODE), "_commit_delay:=0.3", *args],
                env=env,
                cwd=REPO,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def log(self) -> str:
        """Everything the node printed."""
        return self.log_path.read_text(errors="replace")

    def stop(self) -> None:
        """SIGINT, then SIGKILL if it does not stop."""
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGINT)
            try:
                self.process.wait(8)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()


class Rviz:
    """rviz as the marker node sees it: the latched init topic in, feedback and tools out."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._init: InteractiveMarkerInit | None = None
        self.selections: list[Any] = []
        self._subscribers = [
            rospy.Subscriber(
                topics.MARKERS_NS + "/update_full", InteractiveMarkerInit, self._on_init
            ),
            rospy.Subscriber(interface.SELECTION_TOPIC, wire.Selection, self.selections.append),
        ]
        self.feedback_pub = rospy.Publisher(
            topics.MARKERS_NS + "/feedback", InteractiveMarkerFeedback, queue_size=100
        )
        self.point_pub = rospy.Publisher(topics.NEW_POSITION_TOPIC, PointStamped, queue_size=10)
        self.goal_pub = rospy.Publisher(topics.NEW_POSE_TOPIC, PoseStamped, queue_size=10)
        self.area_pub = rospy.Publisher(
            topics.NEW_AREA_TOPIC, PoseWithCovarianceStamped, queue_size=10
        )
        self.selection_pub = rospy.Publisher(
            interface.SELECTION_TOPIC, wire.Selection, queue_size=1, latch=True
        )
        for publisher in (self.feedback_pub, self.point_pub, self.goal_pub, self.area_pub):
            wait_for(publisher.get_num_connections, f"the marker node on {publisher.name}")

    def _on_init(self, msg: InteractiveMarkerInit) -> None:
        with self._lock:
            self._init = msg

    def close(self) -> None:
        """Unsubscribe and unadvertise."""
        for subscriber in self._subscribers:
            subscriber.unregister()
        for publisher in (
            self.feedback_pub,
            self.point_pub,
            self.goal_pub,
            self.area_pub,
            self.selection_pub,
        ):
            publisher.unregister()

    def markers(self) -> dict[str, InteractiveMarker]:
        """The interactive markers the node holds now (from its latest init message)."""
        with self._lock:
            init = self._init
        return {} if init is None else {m.name: m for m in init.markers}

    def marker(
        self, name: str, check: Callable[[InteractiveMarker], bool] = lambda _: True
    ) -> InteractiveMarker:
        """Wait until marker ``name`` exists and satisfies ``check``; return it."""

        def found() -> InteractiveMarker | None:
            marker = self.markers().get(name)
            return marker if marker is not None and check(marker) else None

        return wait_for(found, f"interactive marker {name!r}")

    def menu_id(self, name: str, *path: str) -> int:
        """The id of the menu entry at ``path`` (titles) of marker ``name``."""
        entries = self.marker(name).menu_entries
        parent = 0
        for title in path:
            matches = [e for e in entries if e.parent_id == parent and e.title == title]
            assert matches, f"no menu entry {title!r} under {parent} of {name}: {entries}"
            parent = matches[0].id
        return parent

    def titles(self, name: str) -> list[str]:
        """The top-level menu titles of marker ``name``."""
        return [e.title for e in self.marker(name).menu_entries if e.parent_id == 0]

    def feedback(
        self,
        name: str,
        event: int,
        *,
        control: str = "",
        menu_entry_id: int = 0,
        x: float = 0.0,
        y: float = 0.0,
        yaw: float = 0.0,
    ) -> None:
        """Publish one feedback message as rviz does."""
        msg = InteractiveMarkerFeedback()
        msg.header.frame_id = "map"
        msg.header.stamp = rospy.Time.now()
        msg.client_id = CLIENT_ID
        msg.marker_name = name
        msg.control_name = control
        msg.event_type = event
        msg.menu_entry_id = menu_entry_id
        msg.pose = Pose(
            Point(x, y, 0.0), Quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
        )
        self.feedback_pub.publish(msg)

    def select_menu(self, name: str, *path: str) -> None:
        """Click menu entry ``path`` of marker ``name``."""
        entry = self.menu_id(name, *path)
        self.feedback(name, InteractiveMarkerFeedback.MENU_SELECT, menu_entry_id=entry)

    def drag(self, name: str, x: float, y: float, yaw: float = 0.0, mouse_up: bool = True) -> None:
        """Drag marker ``name`` to (x, y, yaw): mouse down, pose updates, mouse up."""
        fb = InteractiveMarkerFeedback
        self.feedback(name, fb.MOUSE_DOWN, x=x - 1, y=y - 1)
        for fraction in (0.5, 1.0):
            self.feedback(name, fb.POSE_UPDATE, x=x - 1 + fraction, y=y - 1 + fraction, yaw=yaw)
        if mouse_up:
            self.feedback(name, fb.MOUSE_UP, x=x, y=y, yaw=yaw)


@pytest.fixture(scope="module")
def markers_node(
    module_server: Any, client_node: Any, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[MarkerNodeProcess]:
    """The marker node following the module's server."""
    log = tmp_path_factory.mktemp("markers") / "markers_node.log"
    node = MarkerNodeProcess(dict(client_node.env), log)
    try:
        wait_for(
            lambda: "markers for library" in node.log() or node.process.poll() is not None,
            "the marker node to start",
            30.0,
        )
        assert node.process.poll() is None, node.log()[-3000:]
        yield node
    finally:
        node.stop()
        print("--- markers_node ---\n" + "\n".join(node.log().splitlines()[-40:]))


@pytest.fixture
def mission(fresh: Any, markers_node: MarkerNodeProcess) -> Iterator[MissionClient]:
    """A client on an empty mission that the marker node shows."""
    client = MissionClient(10.0)
    client.get_mission()
    yield client
    client.close()


@pytest.fixture
def rviz(markers_node: MarkerNodeProcess, mission: MissionClient) -> Iterator[Rviz]:
    """rviz's side of the marker node."""
    fake = Rviz()
    fake.marker("robot/drone")
    # the node has caught up with the empty mission (it may have followed a server restart)
    wait_for(lambda: not any(n.startswith("task/") for n in fake.markers()), "an empty view")
    yield fake
    fake.close()


def current(client: MissionClient) -> MissionState:
    """The server's mission now."""
    return client.fetch_mission()
