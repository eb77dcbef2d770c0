"""The marker node against a real mission server, driven as rviz drives it.

Feedback is published on ``/rosmc/markers/feedback`` exactly as rviz sends it (menu
selections, pose updates while dragging, mouse up), the stock tools' messages on their
topics; every test asserts what the *server's* mission became (through the client
library), and for refused input that the mission did not change and the marker snapped
back to where the mission has it.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
import rosmc.msg as wire
import rospy
from geometry_msgs.msg import PointStamped, PoseStamped, PoseWithCovarianceStamped
from visualization_msgs.msg import InteractiveMarkerFeedback as F

from rosmc_server.core import MarkerType, Pose, SkillStatus, TaskMarker, Transfer
from rosmc_server.ros.client import MissionClient
from tests.integration.markers_fixtures import Rviz, current, label_of, wait_for

pytest_plugins = ["tests.integration.server_fixtures", "tests.integration.markers_fixtures"]

SQUARE = (Pose(0.0, 0.0), Pose(6.0, 0.0), Pose(6.0, 6.0), Pose(0.0, 6.0))

UNDO_TITLES = ["Undo my last change", "Redo"]  # every menu ends with them


def skills_of(client: MissionClient, agent: str) -> list[Any]:
    return list(current(client).task(agent))


def add_marker(client: MissionClient, rviz: Rviz, marker: TaskMarker) -> str:
    name = client.add_task_marker(marker).name
    rviz.marker(f"task/{name}")
    return name


def at(x: float, y: float) -> Any:
    """A check that an interactive marker is at (x, y)."""
    return lambda m: abs(m.pose.position.x - x) < 1e-6 and abs(m.pose.position.y - y) < 1e-6


# -- menus ------------------------------------------------------------------------------------
def test_robot_menu_adds_the_skill_with_a_new_bound_marker(mission: Any, rviz: Rviz) -> None:
    assert rviz.menu_id("robot/drone", "Add skill", "take_off")
    rviz.select_menu("robot/science_rover", "Add skill", "navigate_to")
    (skill,) = wait_for(lambda: skills_of(mission, "science_rover"), "the new skill")
    assert skill.skill == "navigate_to" and skill.status is SkillStatus.IDLE
    marker = current(mission).marker(skill.bindings["target"])
    assert marker.type is MarkerType.POSE
    # no telemetry here: the robot is taken at the origin, the marker 4 m ahead of it
    assert (marker.pose.x, marker.pose.y) == pytest.approx((4.0, 0.0))
    assert skill.params["target"] == marker.pose
    rviz.marker(f"task/{marker.name}", lambda m: "blueprint" in label_of(m))
    # a skill without marker parameters takes the library defaults
    rviz.select_menu("robot/drone", "Add skill", "take_off")
    (take_off,) = wait_for(lambda: skills_of(mission, "drone"), "take_off")
    assert take_off.params == {"altitude": 5.0} and not take_off.bindings


def test_robot_menu_area_skill_gets_an_area_in_front(mission: Any, rviz: Rviz) -> None:
    rviz.select_menu("robot/drone", "Add skill", "fly_over")
    (skill,) = wait_for(lambda: skills_of(mission, "drone"), "fly_over")
    area = current(mission).marker(skill.bindings["area"])
    assert area.type is MarkerType.AREA and len(area.vertices) == 4
    assert skill.params["area"] == [{"x": v.x, "y": v.y} for v in area.vertices]
    for index in range(4):
        rviz.marker(f"task/{area.name}#v{index}")


def test_task_marker_menu_adds_a_skill_bound_to_it(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("drop", MarkerType.POSE, Pose(5.0, 6.0, yaw=0.5)))
    assert rviz.titles(f"task/{name}") == [
        f"{name} \u2014 pose",  # the first entry names the object
        "Add skill here",
        "Rename",
        "Delete",
        *UNDO_TITLES,
    ]
    rviz.select_menu(f"task/{name}", "Add skill here", "manipulator_rover", "place_box")
    (skill,) = wait_for(lambda: skills_of(mission, "manipulator_rover"), "place_box")
    assert skill.skill == "place_box" and skill.bindings == {"target": name}
    assert skill.params["target"] == Pose(5.0, 6.0, yaw=0.5)
    # in use now: no Delete any more
    rviz.marker(f"task/{name}", lambda m: "Delete" not in [e.title for e in m.menu_entries])


def test_static_agent_menu_adds_a_skill_taking_the_object(mission: Any, rviz: Rviz) -> None:
    rviz.select_menu("object/lofar_box", "Add skill", "manipulator_rover", "pick_box")
    (skill,) = wait_for(lambda: skills_of(mission, "manipulator_rover"), "pick_box")
    assert skill.skill == "pick_box" and skill.params["box"] == "lofar_box"
    rviz.select_menu("object/lander", "Add skill", "drone", "return_to_lander")
    wait_for(lambda: skills_of(mission, "drone"), "return_to_lander")


def test_rename_and_delete(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("", MarkerType.POSITION, Pose(12.0, -3.0)))
    new_name = "Position at (12, -3)"
    rviz.select_menu(f"task/{name}", "Rename", new_name)
    wait_for(lambda: current(mission).has_marker(new_name), "the rename")
    assert not current(mission).has_marker(name)
    rviz.select_menu(f"task/{new_name}", "Delete")
    wait_for(lambda: not current(mission).has_marker(new_name), "the delete")
    wait_for(lambda: f"task/{new_name}" not in rviz.markers(), "the marker to go from rviz")


def test_undo_and_redo_from_any_menu_take_back_this_rvizs_own_edits(
    mission: Any, rviz: Rviz
) -> None:
    name = add_marker(mission, rviz, TaskMarker("", MarkerType.POSITION, Pose(14.0, -5.0)))
    renamed = "Position at (14, -5)"
    rviz.select_menu(f"task/{name}", "Rename", renamed)
    wait_for(lambda: current(mission).has_marker(renamed), "the rename")
    rviz.select_menu("robot/drone", "Undo my last change")  # any marker's menu will do
    wait_for(lambda: current(mission).has_marker(name), "the rename undone")
    assert not current(mission).has_marker(renamed)
    rviz.select_menu(f"task/{name}", "Redo")
    wait_for(lambda: current(mission).has_marker(renamed), "the rename redone")


# -- drags --------------------------------------------------------------------------------------
def test_drag_moves_the_marker_and_its_bound_skills(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("goal", MarkerType.POSE, Pose(1.0, 1.0)))
    first = mission.add_skill("science_rover", "navigate_to", bindings={"target": name})
    second = mission.add_skill("drone", "navigate_to", bindings={"target": name})
    revision = current(mission).revision
    rviz.drag(f"task/{name}", 8.0, 9.0, yaw=1.0)
    wait_for(lambda: current(mission).marker(name).pose.x == 8.0, "the move")
    state = current(mission)
    assert state.revision == revision + 1, "one MoveTaskMarker for the whole drag"
    expected = Pose(8.0, 9.0, yaw=pytest.approx(1.0))  # type: ignore[arg-type]
    assert state.marker(name).pose == expected
    for skill_id in (first.skill_id, second.skill_id):
        assert state.skill(skill_id).params["target"] == expected
    # an edit of the bound parameter elsewhere (a move through the server) moves the marker
    mission.move_task_marker(name, Pose(-4.0, 2.0), base_revision=state.revision)
    rviz.marker(f"task/{name}", at(-4.0, 2.0))


def test_drag_without_mouse_up_commits_after_a_pause(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("spot", MarkerType.POSITION, Pose(0.0, 0.0)))
    rviz.drag(f"task/{name}", 3.0, 4.0, yaw=2.0, mouse_up=False)
    wait_for(lambda: current(mission).marker(name).pose.x == 3.0, "the move")
    assert current(mission).marker(name).pose == Pose(3.0, 4.0), "a point keeps heading 0"


def test_area_vertex_and_centre_drags(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("field", MarkerType.AREA, Pose(), SQUARE))
    explore = mission.add_skill("science_rover", "explore", bindings={"area": name})
    rviz.drag(f"task/{name}#v2", 8.0, 7.0)
    wait_for(lambda: current(mission).marker(name).vertices[2] == Pose(8.0, 7.0), "vertex")
    state = current(mission)
    assert state.marker(name).vertices[0] == SQUARE[0]
    assert state.skill(explore.skill_id).params["area"][2] == {"x": 8.0, "y": 7.0}
    # the centre handle moves the whole polygon
    centre = state.marker(name).pose
    rviz.drag(f"task/{name}", centre.x + 10.0, centre.y)
    wait_for(lambda: current(mission).marker(name).vertices[0] == Pose(10.0, 0.0), "centre")
    assert current(mission).marker(name).vertices[2] == Pose(18.0, 7.0)
    rviz.marker(f"task/{name}#v2", at(18.0, 7.0))


# -- refusals ------------------------------------------------------------------------------------
def test_self_crossing_area_is_refused_and_snaps_back(
    mission: Any, rviz: Rviz, markers_node: Any
) -> None:
    name = add_marker(mission, rviz, TaskMarker("zone", MarkerType.AREA, Pose(), SQUARE))
    before = current(mission)
    rviz.drag(f"task/{name}#v1", 3.0, 9.0)  # through the opposite edge: a bow tie
    wait_for(lambda: "would cross itself" in markers_node.log(), "the warning")
    rviz.marker(f"task/{name}#v1", at(6.0, 0.0))
    assert current(mission).revision == before.revision


@pytest.fixture
def stop_server_after(module_server: Any) -> Any:
    """Stop the module's server after the test (``fresh`` starts it anew for the next one):
    an upload no robot answers cannot be undone by a new mission."""
    yield module_server
    module_server.stop()


@pytest.mark.usefixtures("stop_server_after")
def test_locked_marker_is_refused_and_snaps_back(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("site", MarkerType.POSE, Pose(2.0, 2.0)))
    mission.add_skill("drone", "navigate_to", bindings={"target": name})
    mission.synchronize(
        "drone", base_revision=current(mission).revision
    )  # no robot answers here: the upload stays under way
    state = current(mission)
    assert state.task("drone")[0].transfer is Transfer.UPLOADING
    rviz.marker(f"task/{name}", lambda m: "locked" in label_of(m))
    assert "Rename" not in rviz.titles(f"task/{name}")
    rviz.drag(f"task/{name}", 9.0, 9.0)
    rviz.marker(f"task/{name}", at(2.0, 2.0))
    assert current(mission).revision == state.revision
    assert current(mission).marker(name).pose == Pose(2.0, 2.0)


def test_bad_feedback_is_ignored_with_a_warning(
    mission: Any, rviz: Rviz, markers_node: Any
) -> None:
    name = add_marker(mission, rviz, TaskMarker("poi", MarkerType.POSE, Pose(1.0, 1.0)))
    revision = current(mission).revision
    rviz.feedback("task/nothing here", F.MENU_SELECT, menu_entry_id=1)
    rviz.feedback("robot/drone", F.MENU_SELECT, menu_entry_id=999)
    rviz.drag(f"task/{name}", math.nan, 3.0)
    rviz.feedback(f"task/{name}", F.POSE_UPDATE, x=math.inf, y=0.0)
    rviz.feedback(f"task/{name}", F.MOUSE_UP, x=math.inf, y=0.0)
    rviz.drag("robot/drone", 5.0, 5.0)
    for warning in (
        "unknown marker 'task/nothing here'",
        "stale menu entry 999",
        "not a finite position",
        "cannot be dragged",
    ):
        wait_for(lambda w=warning: w in markers_node.log(), repr(warning))  # type: ignore[misc]
    rviz.marker(f"task/{name}", at(1.0, 1.0))
    assert current(mission).revision == revision
    assert markers_node.process.poll() is None


# -- stock tools and selection -------------------------------------------------------------------
def test_stock_tools_create_task_markers(mission: Any, rviz: Rviz, markers_node: Any) -> None:
    point = PointStamped()
    point.header.frame_id = "map"
    point.point.x, point.point.y = 3.0, -7.0
    rviz.point_pub.publish(point)
    wait_for(lambda: current(mission).has_marker("Position 1"), "Publish Point's marker")
    assert current(mission).marker("Position 1").pose == Pose(3.0, -7.0)
    goal = PoseStamped()
    goal.header.frame_id = "map"
    goal.pose.position.x, goal.pose.position.y = 10.0, 2.0
    goal.pose.orientation.z, goal.pose.orientation.w = math.sin(0.4), math.cos(0.4)
    rviz.goal_pub.publish(goal)
    wait_for(lambda: current(mission).has_marker("Pose 1"), "2D Nav Goal's marker")
    assert current(mission).marker("Pose 1").pose.yaw == pytest.approx(0.8)
    estimate = PoseWithCovarianceStamped()
    estimate.header.frame_id = "map"
    estimate.pose.pose.position.x = -10.0
    estimate.pose.pose.orientation.w = 1.0
    rviz.area_pub.publish(estimate)
    wait_for(lambda: current(mission).has_marker("Area 1"), "2D Pose Estimate's area")
    area = current(mission).marker("Area 1")
    assert area.pose.x == pytest.approx(-10.0) and len(area.vertices) == 4
    revision = current(mission).revision
    point.header.frame_id = "drone/base_link"
    rviz.point_pub.publish(point)
    wait_for(lambda: "in frame 'drone/base_link'" in markers_node.log(), "the frame warning")
    assert current(mission).revision == revision


def test_selection_both_ways(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("rock", MarkerType.POSITION, Pose(4.0, 4.0)))
    added = mission.add_skill("science_rover", "identify_stones", bindings={"position": name})
    rviz.marker(f"task/{name}", lambda m: "blueprint" in label_of(m))
    rviz.feedback(f"task/{name}", F.MOUSE_DOWN, x=4.0, y=4.0)
    rviz.feedback(f"task/{name}", F.MOUSE_UP, x=4.0, y=4.0)
    selection = wait_for(
        lambda: [s for s in rviz.selections if name in s.marker_names], "the selection"
    )[-1]
    assert list(selection.skill_ids) == [added.skill_id]

    def highlighted(marker: Any) -> bool:
        return any(
            abs(m.color.r - 1.0) < 1e-3 and abs(m.color.g - 0.95) < 1e-3
            for c in marker.controls
            for m in c.markers
        )

    # the command GUI selects something else: the highlight moves
    other = add_marker(mission, rviz, TaskMarker("other", MarkerType.POSE, Pose(-4.0, 4.0)))
    rviz.selection_pub.publish(
        wire.Selection(source="/command_gui", stamp=rospy.Time.now(), marker_names=[other])
    )
    rviz.marker(f"task/{other}", highlighted)
    rviz.marker(f"task/{name}", lambda m: not highlighted(m))


def test_the_menus_first_entry_names_the_object_and_selects_it(mission: Any, rviz: Rviz) -> None:
    name = add_marker(mission, rviz, TaskMarker("RSS North", MarkerType.POSITION, Pose(3.0, 9.0)))
    assert rviz.titles("robot/drone")[0] == "drone \u2014 robot"
    assert rviz.titles("object/lander")[0] == "lander \u2014 object"
    assert rviz.titles(f"task/{name}")[0] == "RSS North \u2014 position"
    revision = current(mission).revision
    rviz.select_menu(f"task/{name}", "RSS North \u2014 position")
    wait_for(lambda: [s for s in rviz.selections if name in s.marker_names], "the selection")
    assert current(mission).revision == revision, "naming the object changes nothing"
