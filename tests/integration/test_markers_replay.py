"""A replay in rviz, live: a recorded mission replayed under ``/replay``, shown read-only.

A real mission server journals a short planning session (markers added and moved through
:class:`MissionClient`); ``rosmc replay FILE --prefix /replay`` republishes it and the
marker node runs with ``ns:=/replay`` as ``markers.launch ns:=/replay`` starts it. The test
is rviz: it reads ``/replay/rosmc/markers/update_full`` and sends feedback on
``/replay/rosmc/markers/feedback``, which must change nothing. The session runs with a
custom library (the drone is called ``scout``): the replay must show it with that library,
which the journal recorded, not the shipped one.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rospy
from geometry_msgs.msg import Point, Pose, Quaternion
from visualization_msgs.msg import (
    InteractiveMarker,
    InteractiveMarkerControl,
    InteractiveMarkerFeedback,
    InteractiveMarkerInit,
)

from rosmc_rviz_markers import topics
from rosmc_server.core import MarkerType, TaskMarker
from rosmc_server.core import Pose as MissionPose
from rosmc_server.ros.client import MissionClient
from tests.integration.markers_fixtures import (
    MarkerNodeProcess,
    label_of,
    scout_library,
    wait_for,
)

pytest_plugins = ["tests.integration.server_fixtures"]

REPO = Path(__file__).resolve().parents[2]
NS = "/replay"
GOAL = (7.0, 6.0)
READ_ONLY_MODES = (InteractiveMarkerControl.NONE, InteractiveMarkerControl.BUTTON)


@pytest.fixture
def journal(start_server: Any, tmp_path: Path) -> Path:
    """The journal of a short planning session on a real server with a custom library."""
    server = start_server(library=str(scout_library(tmp_path)))
    client = MissionClient(10.0)
    try:
        client.get_mission()
        client.add_skill("scout", "take_off")
        client.add_task_marker(TaskMarker("goal", MarkerType.POSE, MissionPose(3.0, 4.0)))
        area = tuple(MissionPose(x, y) for x, y in ((10, 0), (16, 0), (16, 6), (10, 6)))
        client.add_task_marker(TaskMarker("site", MarkerType.AREA, MissionPose(), area))
        client.add_skill("science_rover", "navigate_to", bindings={"target": "goal"})
        client.move_task_marker("goal", MissionPose(*GOAL))
    finally:
        client.close()
    server.stop()
    (path,) = Path(server.params["journal_dir"]).glob("*.mcap")
    return path


class ReplayView:
    """What rviz sees of the replay's marker node, and its feedback publisher."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._init: InteractiveMarkerInit | None = None
        base = topics.topic(topics.MARKERS_NS, NS)
        self._sub = rospy.Subscriber(base + "/update_full", InteractiveMarkerInit, self._on_init)
        self.feedback = rospy.Publisher(
            base + "/feedback", InteractiveMarkerFeedback, queue_size=10
        )
        wait_for(self.feedback.get_num_connections, "the marker node on the feedback topic")

    def _on_init(self, msg: InteractiveMarkerInit) -> None:
        with self._lock:
            self._init = msg

    def markers(self) -> dict[str, InteractiveMarker]:
        """The interactive markers the node holds now."""
        with self._lock:
            init = self._init
        return {} if init is None else {m.name: m for m in init.markers}

    def send(self, name: str, event: int, x: float = 0.0, y: float = 0.0, entry: int = 0) -> None:
        """One feedback message, as rviz sends it."""
        msg = InteractiveMarkerFeedback()
        msg.header.frame_id = "map"
        msg.client_id = "/rviz_replay/InteractiveMarkers"
        msg.marker_name = name
        msg.event_type = event
        msg.menu_entry_id = entry
        msg.pose = Pose(Point(x, y, 0.0), Quaternion(0.0, 0.0, 0.0, 1.0))
        self.feedback.publish(msg)

    def close(self) -> None:
        """Unsubscribe and unadvertise."""
        self._sub.unregister()
        self.feedback.unregister()


@pytest.fixture
def replay_markers(client_node: Any, tmp_path: Path) -> Iterator[MarkerNodeProcess]:
    """The marker node following ``/replay`` (as ``markers.launch ns:=/replay`` runs it)."""
    node = MarkerNodeProcess(
        dict(client_node.env), tmp_path / "markers.log", f"_ns:={NS}", f"__ns:={NS}/rosmc"
    )
    try:
        wait_for(lambda: "marker node ready" in node.log(), "the replay marker node", 30.0)
        yield node
    finally:
        node.stop()
        print("--- markers_node ---\n" + "\n".join(node.log().splitlines()[-30:]))


def test_a_replay_shows_read_only_markers(
    journal: Path, replay_markers: MarkerNodeProcess, client_node: Any, tmp_path: Path
) -> None:
    view = ReplayView()
    log = (tmp_path / "replay.log").open("wb")
    replay = subprocess.Popen(
        [sys.executable, str(REPO / "scripts" / "rosmc"), "replay", str(journal), "--prefix", NS],
        env=dict(client_node.env),
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    try:

        def shown() -> dict[str, InteractiveMarker] | None:
            markers = view.markers()
            goal = markers.get("task/goal")
            if goal is None or "task/site" not in markers or "robot/scout" not in markers:
                return None
            at = (goal.pose.position.x, goal.pose.position.y)
            return markers if math.dist(at, GOAL) < 1e-6 else None

        markers = wait_for(shown, "the replayed markers on /replay/rosmc/markers", 30.0)
        # read-only: no menus, nothing to drag or turn, no vertex handles
        for name, marker in markers.items():
            assert not marker.menu_entries, f"{name} has a menu in a replay"
            modes = {c.interaction_mode for c in marker.controls}
            assert modes <= set(READ_ONLY_MODES), f"{name} is interactive: {modes}"
        assert not any("#v" in name for name in markers), "area vertices are draggable"
        assert "[blueprint]" in label_of(markers["task/goal"])

        # feedback changes nothing: a drag and a menu click are refused with a warning
        fb = InteractiveMarkerFeedback
        view.send("task/goal", fb.MOUSE_DOWN, *GOAL)
        view.send("task/goal", fb.POSE_UPDATE, 20.0, 20.0)
        view.send("task/goal", fb.MOUSE_UP, 20.0, 20.0)
        view.send("robot/scout", fb.MENU_SELECT, entry=1)
        wait_for(
            lambda: replay_markers.log().count("read-only") >= 2,
            "the node to refuse the drag and the menu",
        )
        goal = view.markers()["task/goal"]
        assert math.dist((goal.pose.position.x, goal.pose.position.y), GOAL) < 1e-6
        assert "robot/drone" not in markers  # the shipped library's drone: not recorded
        assert replay.wait(30) == 0, (tmp_path / "replay.log").read_text()
        assert "Traceback" not in replay_markers.log()
        assert "NotFound" not in replay_markers.log()
    finally:
        view.close()
        if replay.poll() is None:
            os.killpg(replay.pid, signal.SIGINT)
            replay.wait(10)
        log.close()
