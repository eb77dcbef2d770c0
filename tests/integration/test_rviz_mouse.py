"""The operator's rviz driven with a real mouse: every click on the site hits what it aims at.

A real master, mission server, sim node and marker node; real rviz with
``rviz/operator.rviz`` under Xvfb; Debian's ``xdotool`` moves, clicks, drags and types as a
person would. Where to click is computed from the config's camera (the projection of
``test_rviz_operator.py``) and the 3D view's place on the screen (where the config's
background colour fills rows and columns). Each test checks the outcome in the mission:

* *Publish Point* on open ground (between the grid's lines) creates a position marker there;
* dragging a pose marker by its heading arrow moves it without turning it, and dragging
  its ring's knob turns it without moving it;
* right-clicking the drone where it rests on the lander opens the drone's own menu, whose
  first entry names it, and whose *Resume* (what frees a robot holding after its lost-link
  policy) goes to the drone;
* right-clicking a flag's ground disc near its rim (outside the 1.2 m disc flags had)
  opens that marker's menu, and its first entry (the marker's name) selects it.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rospy
from visualization_msgs.msg import InteractiveMarkerFeedback

from rosmc_rviz_markers import topics
from rosmc_server import interface
from rosmc_server.core import MarkerType, Pose, TaskMarker
from rosmc_server.core.views import geometry
from rosmc_server.ros.client import MissionClient
from tests.conftest import RosMaster
from tests.integration.markers_fixtures import wait_for
from tests.integration.test_rviz import gui_programs, load_tool, sim  # noqa: F401
from tests.integration.test_rviz_operator import CONFIG, markers, project, server  # noqa: F401

pytest_plugins = ["tests.integration.server_fixtures"]

Point3 = tuple[float, float, float]
OPEN_GROUND = (3.0, -13.0)  # between the grid's lines (every 10 m), nothing above it
POSE_AT = (-2.0, -14.0)
FLAG_AT = (-3.0, -11.0)  # a position marker, clicked on the rim of its ground disc
DRONE_AT = (0.0, 0.0)  # resting on the lander, inside the lander's clickable shell
STEPS = 12  # mouse positions per drag
SETTLE = 2.0  # seconds a dragged marker must hold still to count as put down


@dataclass
class Screen:
    """rviz on a virtual screen, and xdotool on that screen."""

    display: str
    left: int
    top: int
    width: int
    height: int
    tool: Any

    def at(self, point: Point3) -> tuple[int, int]:
        """The screen pixel where map ``point`` shows."""
        col, row = project(point, self.width, self.height)
        assert 0 <= col < self.width and 0 <= row < self.height, f"{point} is out of view"
        return self.left + round(col), self.top + round(row)

    def xdotool(self, *args: str) -> None:
        """Run one xdotool command on this screen."""
        env = {**os.environ, "DISPLAY": self.display}
        subprocess.run(["xdotool", *args], env=env, check=True, timeout=20)

    def click(self, point: Point3, button: int = 1) -> None:
        """Move to map ``point`` and click ``button`` there."""
        x, y = self.at(point)
        self.xdotool("mousemove", "--sync", str(x), str(y))
        time.sleep(0.3)  # rviz picks what lies under the pointer when it moves
        self.xdotool("click", str(button))

    def drag(self, path: list[Point3]) -> None:
        """Press the left button at ``path[0]``, move through ``path``, release at its end."""
        pixels = [self.at(p) for p in path]
        self.xdotool("mousemove", "--sync", *map(str, pixels[0]))
        time.sleep(0.3)
        self.xdotool("mousedown", "1")
        for x, y in pixels[1:]:
            time.sleep(0.1)
            self.xdotool("mousemove", "--sync", str(x), str(y))
        time.sleep(0.3)
        self.xdotool("mouseup", "1")

    def save(self, path: Path) -> Path:
        """A screenshot of the whole screen as a PNG (to look at when a test fails)."""
        self.tool.grab(self.display).write_png(path)
        return path


def view_box(shot: Any, background: tuple[int, int, int]) -> tuple[int, int, int, int]:
    """Left, top, width and height of the 3D view in a screenshot (as Screenshot.view)."""
    box = shot.view_box(background)
    assert box is not None, "no 3D view on the screen"
    return tuple(box)


@pytest.fixture
def screen(
    markers: Any,  # noqa: F811 (the fixture imported above)
    ros_master: RosMaster,
    tmp_path: Path,
) -> Iterator[Screen]:
    """rviz with the operator config, drawn, on its own virtual screen."""
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is not installed (make setup installs it)")
    tool = load_tool()
    background = tool.config_background(CONFIG)
    check = tool.DrawnCheck(background=background, min_colors=100)
    with tool.virtual_screen(*tool.DEFAULT_SIZE) as display:
        env = tool.rviz_environment(display, ros_master.env)
        # rviz under software OpenGL now and then dies at start-up: started up to 3 times.
        with tool.drawn_rviz(
            CONFIG, env, tmp_path / "rviz.log", check, timeout=60.0, attempts=3
        ) as started:
            if started.problems:
                started.shot.write_png(tmp_path / "start.png")
            assert not started.problems, f"rviz did not draw: {started.problems} ({tmp_path})"
            time.sleep(3.0)  # the markers' full update and TF arrive
            shot = tool.grab(display)
            yield Screen(display, *view_box(shot, background), tool=tool)


def mission_markers(client: MissionClient) -> dict[str, TaskMarker]:
    return {m.name: m for m in client.get_mission().markers}


@pytest.mark.usefixtures("gui_programs", "sim")
def test_publish_point_on_open_ground_creates_a_marker_there(
    screen: Screen, tmp_path: Path
) -> None:
    client = MissionClient(10.0)
    assert not mission_markers(client)
    screen.click((*OPEN_GROUND, 0.0))  # focus the 3D view (the Interact tool: nothing there)
    screen.xdotool("key", "c")  # rviz's shortcut for Publish Point
    screen.click((*OPEN_GROUND, 0.0))

    def created() -> list[TaskMarker]:
        return list(mission_markers(client).values())

    made = wait_for(created, f"a marker from the click ({screen.save(tmp_path / 'pp.png')})")
    assert len(made) == 1 and made[0].type is MarkerType.POSITION
    miss = math.hypot(made[0].pose.x - OPEN_GROUND[0], made[0].pose.y - OPEN_GROUND[1])
    assert miss < 1.0, f"the marker is {miss:.2f} m from the click: {made[0].pose}"


def _moved(client: MissionClient, name: str, before: Pose) -> Callable[[], TaskMarker | None]:
    """The marker once it moved from ``before`` and then held still for a second.

    A loaded machine may deliver the drag in bursts, and the markers node commits the
    pose each time the mouse rests: the first change can be part of the way.
    """
    seen: list[tuple[float, tuple[float, float, float]]] = []

    def check() -> TaskMarker | None:
        marker = mission_markers(client)[name]
        pose = (marker.pose.x, marker.pose.y, marker.pose.yaw)
        if pose == (before.x, before.y, before.yaw):
            return None
        now = time.monotonic()
        if not seen or seen[-1][1] != pose:
            seen.append((now, pose))
            return None
        return marker if now - seen[-1][0] >= SETTLE else None

    return check


@pytest.mark.usefixtures("gui_programs", "sim")
def test_pose_marker_moves_by_its_arrow_and_turns_by_its_ring(
    screen: Screen, tmp_path: Path
) -> None:
    client = MissionClient(10.0)
    client.get_mission()
    name = client.add_task_marker(TaskMarker("goal", MarkerType.POSE, Pose(*POSE_AT))).name
    time.sleep(2.0)  # rviz shows the new marker
    x, y = POSE_AT

    # grab the heading arrow half-way along and pull north by 4 m: a move, no turn
    start = mission_markers(client)[name].pose
    screen.drag([(x + 1.4, y + 4.0 * k / STEPS, 0.1) for k in range(STEPS + 1)])
    what = f"the drag to arrive ({screen.save(tmp_path / 'move.png')})"
    moved = wait_for(_moved(client, name, start), what).pose
    assert abs(moved.yaw - start.yaw) < 0.05, f"the marker turned to {moved.yaw:.2f} rad"
    assert math.hypot(moved.x - x, moved.y - (y + 4.0)) < 0.7, (moved.x, moved.y)

    # grab the ring's knob (where the heading points) and sweep a quarter turn left
    radius, cx, cy = geometry.TURN_RADIUS, moved.x, moved.y
    arc = [
        (cx + radius * math.cos(a), cy + radius * math.sin(a), 0.15)
        for a in (math.pi / 2 * k / STEPS for k in range(STEPS + 1))
    ]
    screen.drag(arc)
    what = f"the turn to arrive ({screen.save(tmp_path / 'turn.png')})"
    turned = wait_for(_moved(client, name, moved), what).pose
    assert math.hypot(turned.x - cx, turned.y - cy) < 0.05, "the marker moved while turning"
    assert abs(turned.yaw - math.pi / 2) < 0.35, f"turned to {turned.yaw:.2f} rad, not 1.57"


@pytest.mark.usefixtures("gui_programs", "sim")
def test_the_drone_on_the_lander_opens_its_own_menu(screen: Screen, tmp_path: Path) -> None:
    client = MissionClient(10.0)
    client.get_mission()
    selected: list[InteractiveMarkerFeedback] = []

    def on_feedback(feedback: InteractiveMarkerFeedback) -> None:
        if feedback.event_type == InteractiveMarkerFeedback.MENU_SELECT:
            selected.append(feedback)

    feedback_topic = topics.topic(topics.MARKERS_NS, "") + "/feedback"
    subscriber = rospy.Subscriber(feedback_topic, InteractiveMarkerFeedback, on_feedback)
    try:
        screen.click((*DRONE_AT, geometry.PIN_CENTRE), button=3)  # right click: the menu
        time.sleep(1.0)
        screen.save(tmp_path / "menu.png")
        # the first entry names the drone; Add skill > its first skill is the second
        screen.xdotool("key", "Down", "Down", "Right", "Return")
        what = f"a menu entry chosen ({tmp_path / 'menu.png'})"
        chosen = wait_for(lambda: list(selected), what)
    finally:
        subscriber.unregister()
    assert chosen[0].marker_name == "robot/drone", f"the menu of {chosen[0].marker_name}"
    added = wait_for(lambda: client.get_mission().task("drone"), "the drone's new skill")
    assert len(added) == 1


@pytest.mark.usefixtures("gui_programs", "sim")
def test_a_flag_is_hit_near_its_rim_and_its_menu_names_it(screen: Screen, tmp_path: Path) -> None:
    client = MissionClient(10.0)
    client.get_mission()
    marker = TaskMarker("RSS spot", MarkerType.POSITION, Pose(*FLAG_AT))
    name = client.add_task_marker(marker).name
    time.sleep(2.0)  # rviz shows the new marker
    chosen: list[InteractiveMarkerFeedback] = []
    selected: list[Any] = []

    def on_feedback(feedback: InteractiveMarkerFeedback) -> None:
        if feedback.event_type == InteractiveMarkerFeedback.MENU_SELECT:
            chosen.append(feedback)

    feedback_topic = topics.topic(topics.MARKERS_NS, "") + "/feedback"
    subscribers = [
        rospy.Subscriber(feedback_topic, InteractiveMarkerFeedback, on_feedback),
        rospy.Subscriber(interface.SELECTION_TOPIC, wire.Selection, selected.append),
    ]
    try:
        # 0.85 m east of the pole: on the 2 m disc, beyond the 1.2 m disc of before
        rim = (FLAG_AT[0] + 0.85, FLAG_AT[1], 0.04)
        screen.click(rim, button=3)
        time.sleep(1.0)
        screen.save(tmp_path / "flag_menu.png")
        screen.xdotool("key", "Down", "Return")  # the first entry: the marker's name
        what = f"a menu entry chosen ({tmp_path / 'flag_menu.png'})"
        feedback = wait_for(lambda: list(chosen), what)[0]
        assert feedback.marker_name == f"task/{name}", f"the menu of {feedback.marker_name}"
        assert feedback.menu_entry_id == 1, "the first entry"
        wait_for(lambda: [s for s in selected if name in s.marker_names], "the marker selected")
    finally:
        for subscriber in subscribers:
            subscriber.unregister()
    assert mission_markers(client)[name].pose == marker.pose, "naming it changed nothing"


@pytest.mark.usefixtures("gui_programs", "sim")
def test_a_flags_menu_adds_a_skill_there_driving_there_first(
    screen: Screen, tmp_path: Path
) -> None:
    client = MissionClient(10.0)
    client.get_mission()
    name = client.add_task_marker(TaskMarker("stone", MarkerType.POSITION, Pose(*FLAG_AT))).name
    time.sleep(2.0)  # rviz shows the new marker and its menu
    screen.click((FLAG_AT[0] + 0.85, FLAG_AT[1], 0.04), button=3)  # its menu opens
    time.sleep(1.0)
    # Add skill here ▸ manipulator_rover ▸ "pick_stone, driving there first" (after
    # identify_stones, its driving variant and navigate_to)
    screen.xdotool("key", "Down", "Down", "Right", "Down", "Down", "Right")
    screen.xdotool("key", "Down", "Down", "Down", "Down")
    screen.save(tmp_path / "add_here.png")
    screen.xdotool("key", "Return")

    def added() -> list[Any]:
        return list(client.get_mission().task("manipulator_rover"))

    what = f"the skills added ({tmp_path / 'add_here.png'})"
    drive, pick = wait_for(lambda: len(added()) == 2 and added(), what)
    assert (drive.skill, drive.bindings) == ("navigate_to", {"target": name})
    assert (pick.skill, pick.bindings) == ("pick_stone", {"position": name})
    assert (pick.params["position"].x, pick.params["position"].y) == FLAG_AT
    client.close()


@pytest.mark.usefixtures("gui_programs", "sim")
def test_resume_from_the_robots_menu_goes_to_the_robot(screen: Screen, tmp_path: Path) -> None:
    """The entry a holding robot's label points to: *Resume* in its menu, clicked in rviz."""
    chosen: list[InteractiveMarkerFeedback] = []
    waiting: list[int] = []

    def on_feedback(feedback: InteractiveMarkerFeedback) -> None:
        if feedback.event_type == InteractiveMarkerFeedback.MENU_SELECT:
            chosen.append(feedback)

    def on_states(msg: wire.AgentStates) -> None:
        waiting.extend(a.link.commands_waiting for a in msg.agents if a.agent == "drone")

    feedback_topic = topics.topic(topics.MARKERS_NS, "") + "/feedback"
    subscribers = [
        rospy.Subscriber(feedback_topic, InteractiveMarkerFeedback, on_feedback),
        rospy.Subscriber(interface.AGENT_STATES_TOPIC, wire.AgentStates, on_states),
    ]
    try:
        wait_for(lambda: list(waiting), "the drone's state")
        before = waiting[-1]  # commands waiting for it already (its library policy)
        screen.click((*DRONE_AT, geometry.PIN_CENTRE), button=3)
        time.sleep(1.0)
        screen.save(tmp_path / "resume_menu.png")
        screen.xdotool("key", "Down", "Down", "Down", "Return")  # its name, Add skill, Resume
        feedback = wait_for(lambda: list(chosen), f"an entry chosen ({tmp_path})")[0]
        assert feedback.marker_name == "robot/drone"
        assert feedback.menu_entry_id > 1, "not the entry that names it"
        # No executor runs here: the server keeps the Resume waiting for the drone's contact.
        wait_for(lambda: waiting[-1] == before + 1, "the Resume sent to the drone")
    finally:
        for subscriber in subscribers:
            subscriber.unregister()
