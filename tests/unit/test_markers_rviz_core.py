"""The marker node's pure core: geometry, areas, styling, icons, menus, specs and requests.

Everything runs against the shipped Mars library (rosmc_server/config/mars_team.yaml) and
core mission states, with no ROS.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from rosmc_rviz_markers.core.icons import (
    BAD,
    DIM,
    GOOD,
    ICON_ROW,
    WARN,
    block_centre,
    icon_levels,
    status_color,
    status_parts,
    status_rows,
)
from rosmc_rviz_markers.core.menus import (
    AddSkill,
    DeleteMarker,
    RenameMarker,
    ResumeRobot,
    flatten,
    robot_menu,
    static_agent_menu,
    task_marker_menu,
    with_drives,
)
from rosmc_rviz_markers.core.requests import moved_area, moved_pose, robot_skill_plan
from rosmc_rviz_markers.core.scene import Scene, Selection
from rosmc_rviz_markers.core.specs import Interaction, parse_name, vertex_name
from rosmc_rviz_markers.core.styling import USE_COLORS, MarkerUse, is_locked, marker_use
from rosmc_server.core import (
    AgentStatus,
    InvalidRequest,
    MarkerType,
    MissionContent,
    MissionState,
    Pose,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
    load_library,
)
from rosmc_server.core.live.updates import AgentStatusChanged, MarkerPut, MirrorUpdate, SkillChanged
from rosmc_server.core.model.changes import Change, PlacedSkill
from rosmc_server.core.views import geometry
from rosmc_server.core.world import areas

LIBRARY = load_library(
    Path(__file__).resolve().parents[2] / "rosmc_server" / "config" / "mars_team.yaml"
)
SQUARE = tuple(Pose(x, y) for x, y in ((0, 0), (4, 0), (4, 4), (0, 4)))


def skill(status: SkillStatus = SkillStatus.IDLE, **kw: Any) -> SkillInstance:
    base = SkillInstance("s1", "science_rover", "navigate_to", "go", {}, {"target": "Pose 1"})
    return replace(base, status=status, **kw)


def state_with(*markers: TaskMarker, skills: tuple[SkillInstance, ...] = ()) -> MissionState:
    state = MissionState(MissionContent.empty(LIBRARY))
    state.apply(
        Change(
            put_markers=markers,
            put_skills=tuple(PlacedSkill(i, s) for i, s in enumerate(skills)),
        )
    )
    return state


# -- geometry ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("model", "kind"),
    [
        ("drone_scout", geometry.BodyKind.DRONE),
        ("rover_science", geometry.BodyKind.SCIENCE_ROVER),
        ("rover_manipulator", geometry.BodyKind.MANIPULATOR_ROVER),
        ("lander", geometry.BodyKind.LANDER),
        ("payload_box", geometry.BodyKind.PAYLOAD_BOX),
        ("mystery", geometry.BodyKind.GENERIC),
    ],
)
def test_body_kind_from_model(model: str, kind: geometry.BodyKind) -> None:
    assert geometry.body_kind(model) is kind


def test_bodies_are_recognisable() -> None:
    drone = geometry.agent_body(geometry.BodyKind.DRONE)
    rotors = [p for p in drone if p.shape is geometry.Shape.CYLINDER and p.scale[2] < 0.05]
    assert len(rotors) == 4
    rover = geometry.agent_body(geometry.BodyKind.SCIENCE_ROVER)
    wheels = [p for p in rover if p.color == geometry.DARK and p.shape is geometry.Shape.CYLINDER]
    assert len(wheels) == 6
    arm = geometry.agent_body(geometry.BodyKind.MANIPULATOR_ROVER)
    assert max(p.position[0] for p in arm) > 0.8, "the arm reaches ahead of the chassis"
    for part in drone + rover + arm:
        assert all(math.isfinite(v) for v in (*part.position, *part.scale, *part.orientation))


# -- areas --------------------------------------------------------------------------------------
def test_area_checks() -> None:
    areas.check_area([(0, 0), (4, 0), (4, 4), (0, 4)])
    with pytest.raises(InvalidRequest, match="cross"):
        areas.check_area([(0, 0), (4, 4), (4, 0), (0, 4)])  # a bow tie
    with pytest.raises(InvalidRequest, match="shorter"):
        areas.check_area([(0, 0), (0.5, 0), (0.5, 4)])
    with pytest.raises(InvalidRequest, match=r"smaller|shorter"):
        areas.check_area([(0, 0), (5, 0), (10, 0.01)])
    with pytest.raises(InvalidRequest, match="3 vertices"):
        areas.check_area([(0, 0), (4, 0)])


def test_square_and_triangulation_cover_the_area() -> None:
    sq = areas.square(1.0, 2.0, yaw=0.3, side=8.0)
    assert areas.signed_area(sq) == pytest.approx(64.0)
    assert areas.centroid(sq) == pytest.approx((1.0, 2.0))
    concave = [(0, 0), (6, 0), (6, 6), (3, 2), (0, 6)]
    triangles = areas.triangulate(concave)
    total = sum(abs(areas.signed_area(t)) for t in triangles)
    assert total == pytest.approx(abs(areas.signed_area(concave)))


def test_vertex_drag_and_centre_drag() -> None:
    field = TaskMarker("Area 1", MarkerType.AREA, Pose(2, 2), SQUARE)
    moved = moved_area(field, 2, 6.0, 5.0)
    assert moved[2] == Pose(6.0, 5.0) and moved[0] == SQUARE[0]
    shifted = moved_area(field, None, 12.0, 2.0)  # the centre moved by +10 in x
    assert [(v.x, v.y) for v in shifted] == [(v.x + 10, v.y) for v in SQUARE]
    with pytest.raises(InvalidRequest, match="cross"):
        moved_area(field, 1, 2.0, 6.0)
    with pytest.raises(InvalidRequest, match="finite"):
        moved_area(field, 0, math.nan, 1.0)
    with pytest.raises(InvalidRequest, match="no vertex"):
        moved_area(field, 7, 1.0, 1.0)


def test_pose_drag() -> None:
    pose = TaskMarker("P", MarkerType.POSE, Pose(1, 1))
    assert moved_pose(pose, 3.0, 4.0, 0.7) == Pose(3.0, 4.0, 0.0, 0.0, 0.0, 0.7)
    point = TaskMarker("Q", MarkerType.POSITION, Pose(1, 1))
    assert moved_pose(point, 3.0, 4.0, 0.7).yaw == 0.0
    with pytest.raises(InvalidRequest):
        moved_pose(pose, math.inf, 0.0, 0.0)


# -- styling ------------------------------------------------------------------------------------
def test_marker_use_and_lock() -> None:
    assert marker_use([]) is MarkerUse.UNUSED
    assert marker_use([skill()]) is MarkerUse.BLUEPRINT
    assert marker_use([skill(transfer=Transfer.UPLOADING)]) is MarkerUse.UPLOADING
    mixed = [skill(), skill(SkillStatus.RUNNING), skill(SkillStatus.SUCCESS)]
    assert marker_use(mixed) is MarkerUse.RUNNING
    assert marker_use([skill(SkillStatus.SYNCWAITING)]) is MarkerUse.WAITING
    assert not is_locked([skill()])
    assert is_locked([skill(SkillStatus.IDLE_SYNCHRONIZED)])
    assert is_locked([skill(SkillStatus.PAUSED)])
    # finished skills no longer lock their marker
    assert not is_locked([skill(SkillStatus.SUCCESS), skill(SkillStatus.FAILURE)])
    assert len({USE_COLORS[u] for u in MarkerUse}) == len(MarkerUse), "one colour per use"


# -- icons --------------------------------------------------------------------------------------
def test_icon_thresholds() -> None:
    parts = {r.key: r for r in status_parts(None)}
    assert parts["battery"].color == DIM and parts["battery"].text == "BAT ?"
    assert "never heard" in parts["link"].text
    status = AgentStatus(
        "drone",
        link="up",
        last_heard=0.2,
        battery=0.2,
        wifi_signal=-72.0,
        current_skill="d-1",
        current_status=SkillStatus.SYNCWAITING,
        waiting_on="science_rover",
    )
    parts = {r.key: r for r in status_parts(status, "fly over A")}
    assert parts["battery"].color == BAD and "20%" in parts["battery"].text
    assert parts["wifi"].color == BAD and "-72 dBm" in parts["wifi"].text
    assert parts["link"].color == GOOD
    assert parts["skill"].text == "fly over A .. waiting on science_rover"
    assert parts["skill"].color == status_color(SkillStatus.SYNCWAITING)
    status = replace(status, battery=0.4, wifi_signal=-63.0, link="down", last_heard=12.0)
    parts = {r.key: r for r in status_parts(status)}
    assert parts["battery"].color == WARN and parts["wifi"].color == WARN
    assert parts["link"].text == "LINK DOWN 12 s" and parts["link"].color == BAD
    waiting = replace(status, commands_waiting=2, waiting_for=95.0)
    link = {r.key: r for r in status_parts(waiting)}["link"]
    assert link.text == "LINK DOWN 12 s, 2 WAITING 1 min"
    never = AgentStatus("drone", commands_waiting=1, waiting_for=5.0)
    row = {r.key: r for r in status_parts(never)}["link"]
    assert (row.text, row.color) == ("link never heard, 1 WAITING 5 s", WARN)
    status = replace(status, battery=0.9, wifi_signal=-50.0, current_status=SkillStatus.FAILURE)
    parts = {r.key: r for r in status_parts(status)}
    assert parts["battery"].color == GOOD and parts["wifi"].color == GOOD
    assert "!! FAILED" in parts["skill"].text
    assert parts["skill"].color == status_color(SkillStatus.FAILURE)


def test_icon_block_is_two_short_lines_in_the_worst_colour() -> None:
    status = AgentStatus(
        "science_rover",
        link="up",
        last_heard=0.1,
        battery=0.97,
        wifi_signal=-54.0,
        current_skill="s-1",
        current_status=SkillStatus.RUNNING,
    )
    head, health = status_rows(status, "navigate_to", "science_rover")
    assert head.text == "science_rover: navigate_to >> running"
    assert head.color == status_color(SkillStatus.RUNNING)
    assert health.text == "BAT 97% | WiFi -54 dBm | link up" and health.color == GOOD
    assert max(len(head.text), len(health.text)) <= 40
    _, health = status_rows(replace(status, wifi_signal=-64.0))
    assert health.color == WARN
    _, health = status_rows(replace(status, wifi_signal=-64.0, battery=0.1))
    assert health.color == BAD and "BAT LOW 10%" in health.text
    head, health = status_rows(None, agent="drone")
    assert head.text == "drone: no status yet" and health.color == DIM


def test_icon_levels_stack_only_robots_standing_together() -> None:
    apart = {"a": (0.0, 0.0, 0.0), "b": (12.0, 0.0, 0.0), "c": (0.0, 12.0, 0.0)}
    assert icon_levels(apart) == {"a": 0, "b": 0, "c": 0}
    together = {"a": (0.0, 0.0, 0.0), "b": (6.0, 0.0, 0.0), "c": (1.0, 1.0, 0.0)}
    assert icon_levels(together) == {"a": 0, "b": 1, "c": 2}
    # a drone flying over a rover does not lift the rover's block
    assert icon_levels({"rover": (0.0, 0.0, 0.0), "drone": (0.5, 0.0, 6.0)}) == {
        "rover": 0,
        "drone": 0,
    }
    assert icon_levels({"a": None, "b": None, "c": (0.0, 0.0, 0.0)}) == {"a": 0, "b": 1, "c": 0}
    # the robot further north (higher on screen in the default view) is the one lifted
    assert icon_levels({"north": (0.0, 0.8, 0.0), "south": (1.0, 0.0, 0.0)}) == {
        "north": 1,
        "south": 0,
    }
    # 3 m further north, a block already shows above the other one: no lift
    assert icon_levels({"north": (0.0, 3.0, 0.0), "south": (1.0, 0.0, 0.0)}) == {
        "north": 0,
        "south": 0,
    }
    assert block_centre(1) > block_centre(0) + 2 * ICON_ROW


# -- menus --------------------------------------------------------------------------------------
def test_robot_menu_lists_exactly_its_skills_then_resume() -> None:
    add, resume = robot_menu(LIBRARY, "drone")
    assert add.title == "Add skill"
    assert resume.title == "Resume" and resume.action == ResumeRobot("drone")
    assert [c.title for c in add.children] == sorted(LIBRARY.skills_of("drone"))
    assert all(isinstance(c.action, AddSkill) and c.action.from_robot for c in add.children)


def test_static_agent_menus() -> None:
    (add,) = static_agent_menu(LIBRARY, "wifi_box")
    entries = {(r.title, c.title): c.action for r in add.children for c in r.children}
    assert entries == {
        ("manipulator_rover", "pick_box"): AddSkill(
            "manipulator_rover", "pick_box", values=(("box", "wifi_box"),)
        )
    }
    (add,) = static_agent_menu(LIBRARY, "lander")
    titles = {(r.title, c.title) for r in add.children for c in r.children}
    assert ("manipulator_rover", "deposit_at_lander") in titles
    assert ("drone", "return_to_lander") in titles and ("drone", "recharge") in titles
    assert not any(skill == "navigate_to" for _, skill in titles)


def test_task_marker_menu_and_flattening() -> None:
    pose = TaskMarker("Pose 1", MarkerType.POSE, Pose(3, 4))
    state = state_with(pose)
    menu = task_marker_menu(LIBRARY, state, pose, [], locked=False)
    assert [m.title for m in menu] == ["Add skill here", "Rename", "Delete"]
    robots = {r.title: [c.title for c in r.children] for r in menu[0].children}
    # a pose marker fills pose and position parameters
    assert robots["drone"] == ["navigate_to"]
    assert robots["manipulator_rover"][-2:] == ["place_box", "place_box, driving there first"]
    assert "identify_stones" in robots["science_rover"]
    assert "place_box" in robots["manipulator_rover"]
    flat = flatten(menu)
    assert [e.id for e in flat.entries] == list(range(1, len(flat.entries) + 1))
    parents = {e.id: e.parent for e in flat.entries}
    delete = next(e for e in flat.entries if e.title == "Delete")
    assert parents[delete.id] == 0 and isinstance(flat.actions[delete.id], DeleteMarker)
    renames = [a for a in flat.actions.values() if isinstance(a, RenameMarker)]
    assert renames and all(a.new_name != "Pose 1" for a in renames)
    area = TaskMarker("Area 1", MarkerType.AREA, Pose(2, 2), SQUARE)
    menu = task_marker_menu(LIBRARY, state_with(area), area, [skill()], locked=True)
    assert [m.title for m in menu] == ["Add skill here"], "locked and in use: no rename, no delete"
    robots = {r.title: [c.title for c in r.children] for r in menu[0].children}
    assert robots == {"drone": ["fly_over"], "science_rover": ["explore"]}  # an area: no drive


def test_driving_there_first_is_offered_unless_the_robot_goes_there_already() -> None:
    rock = TaskMarker("rock", MarkerType.POSITION, Pose(7, 8))
    drive = AddSkill("manipulator_rover", "pick_stone", bind="position")
    offered = dict(with_drives(LIBRARY, state_with(rock), rock, [(drive, "pick_stone")]))
    assert offered == {
        drive: "pick_stone",
        replace(drive, drive=("navigate_to", "target")): "pick_stone, driving there first",
    }
    going = SkillInstance(
        "s1", "manipulator_rover", "navigate_to", "", {"target": Pose(7, 8)}, {"target": "rock"}
    )
    state = state_with(rock, skills=(going,))
    assert dict(with_drives(LIBRARY, state, rock, [(drive, "pick_stone")])) == {drive: "pick_stone"}


def test_robot_skill_plan_puts_new_markers_in_front() -> None:
    here = Pose(10.0, 0.0, 0.0, 0.0, 0.0, math.pi / 2)
    plan = robot_skill_plan(LIBRARY, "drone", "navigate_to", here)
    ((param, marker),) = plan.new_markers
    assert param == "target" and marker.type is MarkerType.POSE
    assert (marker.pose.x, marker.pose.y) == pytest.approx((10.0, 4.0))
    assert marker.pose.yaw == pytest.approx(math.pi / 2)
    plan = robot_skill_plan(LIBRARY, "drone", "fly_over", here)
    ((param, area),) = plan.new_markers
    assert param == "area" and area.type is MarkerType.AREA and len(area.vertices) == 4
    assert plan.params == {}
    assert robot_skill_plan(LIBRARY, "drone", "take_off", None).new_markers == ()


# -- specs and the scene -------------------------------------------------------------------------
def test_names_round_trip() -> None:
    assert parse_name("robot/drone").kind == "robot"  # type: ignore[union-attr]
    parsed = parse_name(vertex_name("Area 1", 3))
    assert parsed is not None and (parsed.kind, parsed.name, parsed.vertex) == ("task", "Area 1", 3)
    assert parse_name("something/else") is None


def test_scene_specs_follow_status() -> None:
    area = TaskMarker("Area 1", MarkerType.AREA, Pose(2, 2), SQUARE)
    blueprint = SkillInstance("e1", "science_rover", "explore", "ex", {}, {"area": "Area 1"})
    scene = Scene(LIBRARY)
    specs = scene.marker_specs(state_with(area, skills=(blueprint,)), "Area 1")
    assert len(specs) == 5, "centre and four vertices"
    centre = specs[0]
    assert centre.controls[0].interaction is Interaction.MOVE_PLANE
    assert "blueprint" in centre.label
    synced = replace(blueprint, status=SkillStatus.RUNNING)
    specs = scene.marker_specs(state_with(area, skills=(synced,)), "Area 1")
    assert len(specs) == 1, "locked: no vertex handles"
    assert specs[0].controls[0].interaction is Interaction.MENU
    assert "running, locked" in specs[0].label
    done = replace(blueprint, status=SkillStatus.SUCCESS)
    assert len(scene.marker_specs(state_with(area, skills=(done,)), "Area 1")) == 5
    replay = Scene(LIBRARY, read_only=True)
    (only,) = replay.marker_specs(state_with(area, skills=(blueprint,)), "Area 1")
    assert not only.menu.entries and only.controls[0].interaction is Interaction.NONE


def test_scene_touches_only_what_changed() -> None:
    scene = Scene(LIBRARY)
    old = skill()
    moved = MirrorUpdate(
        3,
        (
            MarkerPut(
                TaskMarker("A", MarkerType.POSE, Pose()), TaskMarker("B", MarkerType.POSE, Pose())
            ),
        ),
    )
    assert scene.touched(moved).markers == {"A", "B"}
    params_only = MirrorUpdate(4, (SkillChanged(old, replace(old, params={"speed": 1.0}), 0),))
    assert not scene.touched(params_only).markers
    status = MirrorUpdate(5, (SkillChanged(old, replace(old, status=SkillStatus.RUNNING), 0),))
    assert scene.touched(status).markers == {"Pose 1"}
    state = state_with(TaskMarker("Pose 1", MarkerType.POSE, Pose()), skills=(old,))
    touched = scene.select(Selection(frozenset({"s1"}), frozenset()), state)
    assert touched.markers == {"Pose 1"} and touched.agents == {"science_rover"}
    (spec,) = scene.marker_specs(state, "Pose 1")
    assert any(
        p.color.r == 1.0 and p.shape is geometry.Shape.LINE_STRIP
        for c in spec.controls
        for p in c.primitives
    ), "highlight ring"
    robot = scene.agent_spec("science_rover", state, None)
    assert robot.frame == "science_rover/base_link" and robot.menu.entries


def test_an_agent_without_tf_is_drawn_in_the_map_frame_as_not_heard() -> None:
    # rviz draws no marker of an update until it can transform every one: an agent whose
    # frame is missing must not be in its TF frame, or no robot is drawn at all.
    scene = Scene(LIBRARY)
    touched = scene.set_tf_missing({"drone", "lander"})
    assert touched.agents == {"drone", "lander"}
    drone = scene.agent_spec("drone", None, None)
    assert drone.frame == "map" and drone.description == "drone: not heard"
    lander = scene.agent_spec("lander", None, None)
    assert lander.frame == "map" and lander.position != drone.position  # side by side
    rover = scene.agent_spec("science_rover", None, None)
    assert rover.frame == "science_rover/base_link" and "not heard" not in rover.description
    heard = AgentStatus("drone", pose=Pose(5.0, 6.0, 3.0, 0.0, 0.0, 1.0))
    assert scene.agent_spec("drone", None, heard).position == (5.0, 6.0, 3.0)
    moved = MirrorUpdate(1, (AgentStatusChanged(None, heard),))
    assert scene.touched(moved).agents == {"drone"}  # its reported pose moves it
    assert scene.set_tf_missing({"lander"}).agents == {"drone"}  # its frame came back
    assert scene.agent_spec("drone", None, heard).frame == "drone/base_link"
    assert not scene.touched(moved).agents  # TF moves it now


def test_replay_scene_places_agents_from_status() -> None:
    scene = Scene(LIBRARY, read_only=True, follow_tf=False)
    status = AgentStatus("drone", pose=Pose(5.0, 6.0, 3.0, 0.0, 0.0, 1.0))
    spec = scene.agent_spec("drone", None, status)
    assert spec.frame == "map" and spec.position == (5.0, 6.0, 3.0) and spec.yaw == 1.0
    assert not spec.menu.entries
