"""Every operator service of the real mission server, and what it publishes.

Each service gets a happy path and every class of rejection; after a rejection the
mission (GetMission, minus its stamp) is exactly what it was, the response carries an
error code and one sentence, and no handler raises out of rospy (a ServiceException
fails the test). The published topics are checked as a subscriber sees them.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import yaml

from rosmc_server import interface
from rosmc_server.conversions import event_from_msg
from rosmc_server.core.robots.link import status_digest

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from tests.integration.server_fixtures import (  # noqa: E402
    Client,
    Recorder,
    accepted,
    assert_one_sentence,
    assert_rejected,
    mission_key,
    serialized,
    skill_ids,
    task_of,
)

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

E = wire.ErrorCode
PV = wire.ParameterValue
NAN, INF = math.nan, math.inf
AGENTS = ("drone", "science_rover", "manipulator_rover")


# -- request building blocks ---------------------------------------------------------------
def pf(name: str, value: float) -> PV:
    return PV(name=name, type=PV.FLOAT, float_value=value)


def pi(name: str, value: int) -> PV:
    return PV(name=name, type=PV.INT, int_value=value)


def ps(name: str, value: str) -> PV:
    return PV(name=name, type=PV.STRING, string_value=value)


def pb(name: str, value: bool) -> PV:
    return PV(name=name, type=PV.BOOL, bool_value=value)


def pl(name: str, text: str) -> PV:
    return PV(name=name, type=PV.LIST, json_value=text)


def pp(name: str, **pose: float) -> PV:
    return PV(name=name, type=PV.POSE, pose_value=wire.Pose6D(**pose))


def pm(name: str, marker: str, ptype: int = PV.POSE) -> PV:
    return PV(name=name, type=ptype, marker=marker)


def pose(**fields: float) -> wire.Pose6D:
    return wire.Pose6D(**fields)


def square(size: float = 4.0) -> list[wire.Pose6D]:
    return [pose(x=0, y=0), pose(x=size, y=0), pose(x=size, y=size), pose(x=0, y=size)]


def add(client: Client, agent: str, skill: str, **fields: Any) -> str:
    """Append a skill (on the current revision); its id."""
    fields.setdefault("index", -1)
    response = client.call(
        "add_skill", base_revision=client.revision(), agent=agent, skill=skill, **fields
    )
    return str(accepted(response).skill_id)


def do(client: Client, operation: str, **fields: Any) -> Any:
    """Call a mutating operation on the current revision; it must succeed."""
    return accepted(client.call(operation, base_revision=client.revision(), **fields))


def find(mission: wire.Mission, skill_id: str) -> wire.Skill:
    for task in mission.tasks:
        for skill in task.skills:
            if skill.id == skill_id:
                return skill
    raise AssertionError(f"no skill {skill_id}")


def param(skill: wire.Skill, name: str) -> PV:
    return next(p for p in skill.parameters if p.name == name)


# -- a populated mission ------------------------------------------------------------------
@dataclass
class Scene:
    """A small mission with markers, bound parameters and a barrier."""

    client: Client
    rev: int
    d1: str  # drone take_off
    d2: str  # drone navigate_to, target bound to "Site"
    d3: str  # drone fly_over, area bound to "Zone"
    s1: str  # science_rover navigate_to
    s2: str  # science_rover identify_stones, position bound to "Spot"
    m1: str  # manipulator_rover identify_stones
    m2: str  # manipulator_rover pick_box
    barrier: str  # s2 + m1


@pytest.fixture
def scene(fresh: Client) -> Scene:
    c = fresh
    do(c, "add_task_marker", marker=wire.TaskMarker(name="Site", type=1, pose=pose(x=3, y=4)))
    do(c, "add_task_marker", marker=wire.TaskMarker(name="Zone", type=2, vertices=square()))
    do(c, "add_task_marker", marker=wire.TaskMarker(name="Spot", type=0, pose=pose(x=1, y=1)))
    d1 = add(c, "drone", "take_off", parameters=[pf("altitude", 12.0)])
    d2 = add(c, "drone", "navigate_to", parameters=[pm("target", "Site")])
    d3 = add(c, "drone", "fly_over", parameters=[pm("area", "Zone", PV.LIST)])
    s1 = add(c, "science_rover", "navigate_to")
    s2 = add(c, "science_rover", "identify_stones", parameters=[pm("position", "Spot")])
    m1 = add(c, "manipulator_rover", "identify_stones")
    m2 = add(c, "manipulator_rover", "pick_box", parameters=[ps("box", "sample_box")])
    barrier = do(c, "add_barrier", skill_ids=[s2, m1]).barrier_id
    return Scene(c, c.revision(), d1, d2, d3, s1, s2, m1, m2, barrier)


Case = tuple[str, Callable[[Scene], dict[str, Any]], int]


def rejections(cases: list[Case]) -> Any:
    return pytest.mark.parametrize(
        ("build", "code"), [(build, code) for _, build, code in cases], ids=[c[0] for c in cases]
    )


def check_rejection(scene: Scene, operation: str, fields: dict[str, Any], code: int) -> Any:
    if operation != "control":
        fields.setdefault("base_revision", scene.rev)
    response = assert_rejected(scene.client, operation, code, **fields)
    if code == E.CONFLICT:
        assert f"revision {scene.rev}" in response.error, response.error
    return response


# -- library and mission ---------------------------------------------------------------------
def test_get_library_describes_every_agent_and_skill(client: Client) -> None:
    library = client.call("get_library").library
    assert library.name == "mars_sample_return"
    kinds = {a.name: a.kind for a in library.agents}
    assert {name for name, kind in kinds.items() if kind == wire.AgentSpec.DYNAMIC} == set(AGENTS)
    assert kinds["lander"] == wire.AgentSpec.STATIC
    drone = next(s for s in library.skill_sets if s.model == "drone_scout")
    take_off = next(s for s in drone.skills if s.name == "take_off")
    altitude = take_off.parameters[0]
    assert (altitude.type, altitude.has_min, altitude.min, altitude.max) == (PV.FLOAT, 1, 1, 30)


def test_get_mission_has_a_task_per_dynamic_agent(fresh: Client) -> None:
    mission = fresh.mission()
    assert [t.agent for t in mission.tasks] == list(AGENTS)
    assert mission.library == "mars_sample_return"
    assert not mission.barriers and not mission.markers


# -- add_skill ---------------------------------------------------------------------------------
def test_add_skill_appends_inserts_and_fills_defaults(fresh: Client) -> None:
    c = fresh
    rev = c.revision()
    first = add(c, "drone", "take_off")
    second = add(c, "drone", "take_off", parameters=[pf("altitude", 20.0)], label="  high  ")
    inserted = accepted(
        c.call(
            "add_skill",
            base_revision=rev + 2,
            agent="drone",
            skill="navigate_to",
            index=1,
            parameters=[pp("target", x=1.5, y=-2.0, yaw=0.5), pf("speed", 4)],
            timeout=30.0,
            max_retries=2,
        )
    )
    assert inserted.revision == rev + 3
    mission = c.mission()
    assert mission.revision == rev + 3
    assert skill_ids(mission, "drone") == [first, inserted.skill_id, second]
    assert param(find(mission, first), "altitude").float_value == 5.0  # library default
    high = find(mission, second)
    assert (high.label, param(high, "altitude").float_value) == ("high", 20.0)
    nav = find(mission, inserted.skill_id)
    assert (nav.timeout, nav.max_retries, nav.label) == (30.0, 2, "navigate_to")
    assert param(nav, "target").pose_value == pose(x=1.5, y=-2.0, yaw=0.5)
    assert param(nav, "speed").type == PV.FLOAT and param(nav, "speed").float_value == 4.0
    assert nav.status.value == wire.SkillStatus.IDLE and nav.transfer == wire.Skill.TRANSFER_NONE


def test_add_skill_binds_markers(scene: Scene) -> None:
    mission = scene.client.mission()
    target = param(find(mission, scene.d2), "target")
    assert (target.marker, target.pose_value.x, target.pose_value.y) == ("Site", 3.0, 4.0)
    area = param(find(mission, scene.d3), "area")
    assert area.marker == "Zone"
    assert json.loads(area.json_value) == [{"x": v.x, "y": v.y} for v in square()]


def _add(**fields: Any) -> Callable[[Scene], dict[str, Any]]:
    base = {"agent": "drone", "skill": "take_off", "index": -1}
    return lambda s: {**base, **fields}


ADD_REJECTIONS: list[Case] = [
    ("empty-agent", _add(agent=""), E.INVALID),
    ("blank-agent", _add(agent="  "), E.INVALID),
    ("unknown-agent", _add(agent="rover_9"), E.NOT_FOUND),
    ("unicode-agent", _add(agent="drône✈"), E.NOT_FOUND),
    ("static-agent", _add(agent="lander"), E.RULE),
    ("empty-skill", _add(skill=""), E.INVALID),
    ("unknown-skill", _add(skill="dance"), E.NOT_FOUND),
    ("skill-of-other-model", _add(skill="pick_box"), E.NOT_FOUND),
    ("nan-float", _add(parameters=[pf("altitude", NAN)]), E.INVALID),
    ("inf-float", _add(parameters=[pf("altitude", INF)]), E.INVALID),
    ("minus-inf-float", _add(parameters=[pf("altitude", -INF)]), E.INVALID),
    ("float-above-max", _add(parameters=[pf("altitude", 30.5)]), E.INVALID),
    ("int-below-min", _add(parameters=[pi("altitude", 0)]), E.INVALID),
    ("huge-int", _add(parameters=[pi("altitude", 2**63 - 1)]), E.INVALID),
    ("string-for-float", _add(parameters=[ps("altitude", "5")]), E.INVALID),
    ("bool-for-float", _add(parameters=[pb("altitude", True)]), E.INVALID),
    ("list-for-float", _add(parameters=[pl("altitude", "[5]")]), E.INVALID),
    ("pose-for-float", _add(parameters=[pp("altitude", x=5)]), E.INVALID),
    ("unknown-type-number", _add(parameters=[PV(name="altitude", type=42)]), E.INVALID),
    ("unknown-parameter", _add(parameters=[pf("height", 5.0)]), E.NOT_FOUND),
    ("empty-parameter-name", _add(parameters=[pf("", 5.0)]), E.INVALID),
    ("parameter-twice", _add(parameters=[pf("altitude", 5), pf("altitude", 6)]), E.INVALID),
    ("value-and-marker", _add(parameters=[pf("altitude", 5), pm("altitude", "Site")]), E.INVALID),
    ("nan-pose", _add(skill="navigate_to", parameters=[pp("target", x=NAN)]), E.INVALID),
    ("inf-pose", _add(skill="navigate_to", parameters=[pp("target", yaw=INF)]), E.INVALID),
    ("bad-json", _add(skill="fly_over", parameters=[pl("area", "[{")]), E.INVALID),
    ("json-not-list", _add(skill="fly_over", parameters=[pl("area", '{"x": 1}')]), E.INVALID),
    ("json-nan", _add(skill="fly_over", parameters=[pl("area", '[{"x": NaN}]')]), E.INVALID),
    ("json-infinity", _add(skill="fly_over", parameters=[pl("area", "[Infinity]")]), E.INVALID),
    ("empty-json", _add(skill="fly_over", parameters=[pl("area", "")]), E.INVALID),
    (
        "dict-type-for-list",
        _add(skill="fly_over", parameters=[PV(name="area", type=PV.DICT, json_value="{}")]),
        E.INVALID,
    ),
    (
        "not-a-choice",
        _add(agent="manipulator_rover", skill="pick_box", parameters=[ps("box", "x")]),
        E.INVALID,
    ),
    (
        "unknown-marker",
        _add(skill="navigate_to", parameters=[pm("target", "Nowhere")]),
        E.NOT_FOUND,
    ),
    ("area-marker-for-pose", _add(skill="navigate_to", parameters=[pm("target", "Zone")]), E.RULE),
    ("marker-for-plain-param", _add(parameters=[pm("altitude", "Site", PV.FLOAT)]), E.RULE),
    ("index-past-end", lambda s: {"agent": "drone", "skill": "land", "index": 4}, E.INVALID),
    ("index-huge", _add(index=2**31 - 1), E.INVALID),
    ("nan-timeout", _add(timeout=NAN), E.INVALID),
    ("inf-timeout", _add(timeout=INF), E.INVALID),
    ("negative-timeout", _add(timeout=-1.0), E.INVALID),
    ("too-many-retries", _add(max_retries=101), E.INVALID),
    ("huge-retries", _add(max_retries=2**32 - 1), E.INVALID),
    ("long-label", _add(label="x" * 121), E.INVALID),
    ("multi-line-label", _add(label="two\nlines"), E.INVALID),
    ("stale-revision", lambda s: {**_add()(s), "base_revision": s.rev - 1}, E.CONFLICT),
    ("future-revision", lambda s: {**_add()(s), "base_revision": s.rev + 7}, E.CONFLICT),
    ("first-revision", lambda s: {**_add()(s), "base_revision": 1}, E.CONFLICT),
]


@rejections(ADD_REJECTIONS)
def test_add_skill_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    response = check_rejection(scene, "add_skill", build(scene), code)
    assert response.skill_id == ""


# -- edit_skill ----------------------------------------------------------------------------
def test_edit_skill_changes_values_label_options_and_bindings(scene: Scene) -> None:
    c = scene.client
    response = do(
        c,
        "edit_skill",
        skill_id=scene.d1,
        label="climb",
        parameters=[pf("altitude", 25.0)],
        set_options=True,
        timeout=12.5,
        max_retries=3,
    )
    assert response.revision == scene.rev + 1
    skill = find(c.mission(), scene.d1)
    assert (skill.label, skill.timeout, skill.max_retries) == ("climb", 12.5, 3)
    assert param(skill, "altitude").float_value == 25.0
    # A value replaces the marker binding; binding again takes the marker's pose.
    do(c, "edit_skill", skill_id=scene.d2, parameters=[pp("target", x=-1.0, y=-1.0)])
    target = param(find(c.mission(), scene.d2), "target")
    assert (target.marker, target.pose_value.x) == ("", -1.0)
    do(c, "edit_skill", skill_id=scene.d2, parameters=[pm("target", "Spot")])
    target = param(find(c.mission(), scene.d2), "target")
    assert (target.marker, target.pose_value.x, target.pose_value.y) == ("Spot", 1.0, 1.0)
    # Options untouched unless set_options.
    do(c, "edit_skill", skill_id=scene.d1, label="again")
    assert find(c.mission(), scene.d1).timeout == 12.5


def _edit(**fields: Any) -> Callable[[Scene], dict[str, Any]]:
    return lambda s: {"skill_id": s.d1, "parameters": [pf("altitude", 7.0)], **fields}


EDIT_REJECTIONS: list[Case] = [
    ("empty-id", _edit(skill_id=""), E.INVALID),
    ("unknown-id", _edit(skill_id="drone-000000"), E.NOT_FOUND),
    ("changes-nothing", lambda s: {"skill_id": s.d1}, E.INVALID),
    ("blank-label", lambda s: {"skill_id": s.d1, "label": "   "}, E.INVALID),
    ("nan-value", _edit(parameters=[pf("altitude", NAN)]), E.INVALID),
    ("inf-value", _edit(parameters=[pf("altitude", INF)]), E.INVALID),
    ("wrong-type", _edit(parameters=[ps("altitude", "high")]), E.INVALID),
    ("out-of-range", _edit(parameters=[pf("altitude", 1e9)]), E.INVALID),
    ("unknown-parameter", _edit(parameters=[pf("speed", 1.0)]), E.NOT_FOUND),
    (
        "unknown-marker",
        lambda s: {"skill_id": s.d2, "parameters": [pm("target", "X")]},
        E.NOT_FOUND,
    ),
    ("nan-timeout", _edit(set_options=True, timeout=NAN), E.INVALID),
    ("retries-too-many", _edit(set_options=True, max_retries=1000), E.INVALID),
    ("stale-revision", lambda s: {**_edit()(s), "base_revision": s.rev - 2}, E.CONFLICT),
]


@rejections(EDIT_REJECTIONS)
def test_edit_skill_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "edit_skill", build(scene), code)


# -- delete_skills -----------------------------------------------------------------------------
def test_delete_skills_removes_them_and_dissolves_their_barrier(scene: Scene) -> None:
    c = scene.client
    do(c, "delete_skills", skill_ids=[scene.d1, scene.m1])
    mission = c.mission()
    assert scene.d1 not in skill_ids(mission) and scene.m1 not in skill_ids(mission)
    assert scene.d2 in skill_ids(mission)
    assert not mission.barriers  # a barrier below two members dissolves


DELETE_REJECTIONS: list[Case] = [
    ("no-ids", lambda s: {"skill_ids": []}, E.INVALID),
    ("empty-id", lambda s: {"skill_ids": [""]}, E.NOT_FOUND),
    ("unknown-id", lambda s: {"skill_ids": ["nope"]}, E.NOT_FOUND),
    ("one-unknown", lambda s: {"skill_ids": [s.d1, "nope"]}, E.NOT_FOUND),
    ("duplicate", lambda s: {"skill_ids": [s.d1, s.d1]}, E.INVALID),
    ("stale-revision", lambda s: {"skill_ids": [s.d1], "base_revision": s.rev - 1}, E.CONFLICT),
]


@rejections(DELETE_REJECTIONS)
def test_delete_skills_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "delete_skills", build(scene), code)


# -- reorder_skills ----------------------------------------------------------------------------
def test_reorder_skills_applies_the_permutation(scene: Scene) -> None:
    c = scene.client
    do(c, "reorder_skills", agent="drone", order=[scene.d3, scene.d1, scene.d2])
    assert skill_ids(c.mission(), "drone") == [scene.d3, scene.d1, scene.d2]


def test_a_whole_order_may_travel_as_one_string_of_lines(scene: Scene) -> None:
    c = scene.client
    do(c, "reorder_skills", agent="drone", order=[f"{scene.d2}\n{scene.d3}\n{scene.d1}"])
    assert skill_ids(c.mission(), "drone") == [scene.d2, scene.d3, scene.d1]


def test_reorders_travel_as_moves(scene: Scene, events: Any) -> None:
    """A whole new order and a list of moves both publish only the moves."""
    c, recorder = scene.client, events()
    first = do(c, "reorder_skills", agent="drone", order=[scene.d2, scene.d3, scene.d1]).revision
    second = do(c, "reorder_skills", agent="drone", moves=[move(scene.d2, 2), move(scene.d1, 0)])
    assert skill_ids(c.mission(), "drone") == [scene.d1, scene.d3, scene.d2]
    got = recorder.wait_for(lambda m: bool(m) and m[-1].revision >= second.revision)
    by_revision = {e.revision: e for e in got}
    for revision, moves in (
        (first, [(scene.d1, 2)]),
        (second.revision, [(scene.d2, 2), (scene.d1, 0)]),
    ):
        event = by_revision[revision]
        assert event.kind == wire.MissionEvent.SKILLS_REORDERED and event.order_agent == "drone"
        assert not event.blueprint_order and not event.moves  # packed in move_ids/_indexes
        assert [(m.skill_id, m.index) for m in event_from_msg(event).change.moves] == moves


REORDER_REJECTIONS: list[Case] = [
    ("empty-agent", lambda s: {"agent": "", "order": [s.d1, s.d2, s.d3]}, E.INVALID),
    ("unknown-agent", lambda s: {"agent": "rover", "order": [s.d1, s.d2, s.d3]}, E.NOT_FOUND),
    ("static-agent", lambda s: {"agent": "lander", "order": []}, E.NOT_FOUND),
    ("short", lambda s: {"agent": "drone", "order": [s.d1, s.d2]}, E.INVALID),
    ("empty", lambda s: {"agent": "drone", "order": []}, E.INVALID),
    ("long", lambda s: {"agent": "drone", "order": [s.d1, s.d2, s.d3, s.d3]}, E.INVALID),
    ("repeated", lambda s: {"agent": "drone", "order": [s.d1, s.d1, s.d2]}, E.INVALID),
    ("unknown-id", lambda s: {"agent": "drone", "order": [s.d1, s.d2, "x"]}, E.INVALID),
    ("lines-short", lambda s: {"agent": "drone", "order": [f"{s.d1}\n{s.d2}"]}, E.INVALID),
    (
        "lines-repeated",
        lambda s: {"agent": "drone", "order": [f"{s.d1}\n{s.d1}\n{s.d2}"]},
        E.INVALID,
    ),
    ("lines-blank", lambda s: {"agent": "drone", "order": [f"{s.d1}\n\n{s.d2}"]}, E.INVALID),
    ("other-agents-ids", lambda s: {"agent": "drone", "order": [s.d1, s.d2, s.s1]}, E.INVALID),
    (
        "stale-revision",
        lambda s: {"agent": "drone", "order": [s.d3, s.d2, s.d1], "base_revision": s.rev - 1},
        E.CONFLICT,
    ),
    (
        "order-and-moves",
        lambda s: {"agent": "drone", "order": [s.d1], "moves": [move(s.d1, 0)]},
        E.INVALID,
    ),
    ("move-other-agents", lambda s: {"agent": "drone", "moves": [move(s.s1, 0)]}, E.INVALID),
    ("move-unknown", lambda s: {"agent": "drone", "moves": [move("x", 0)]}, E.NOT_FOUND),
    ("move-past-the-end", lambda s: {"agent": "drone", "moves": [move(s.d1, 3)]}, E.INVALID),
]


def move(skill_id: str, index: int) -> wire.SkillMove:
    return wire.SkillMove(skill_id=skill_id, index=index)


@rejections(REORDER_REJECTIONS)
def test_reorder_skills_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "reorder_skills", build(scene), code)


def test_reorder_that_would_deadlock_a_barrier_is_refused(scene: Scene) -> None:
    c = scene.client
    # science_rover: s1, s2; manipulator_rover: m2, m1 after the first reorder; barriers
    # {s2, m1} and {s1, m2}. Putting m1 back before m2 makes each barrier wait for the other.
    do(c, "reorder_skills", agent="manipulator_rover", order=[scene.m2, scene.m1])
    do(c, "add_barrier", skill_ids=[scene.s1, scene.m2])
    scene.rev = c.revision()
    order = {"agent": "manipulator_rover", "order": [scene.m1, scene.m2]}
    response = check_rejection(scene, "reorder_skills", order, E.RULE)
    assert "deadlock" in response.error
    moves = {"agent": "manipulator_rover", "moves": [move(scene.m1, 0)]}
    response = check_rejection(scene, "reorder_skills", moves, E.RULE)
    assert "deadlock" in response.error


# -- barriers ----------------------------------------------------------------------------------
def test_add_and_delete_barrier(scene: Scene) -> None:
    c = scene.client
    response = do(c, "add_barrier", skill_ids=[scene.m2, scene.d1])
    barrier = next(b for b in c.mission().barriers if b.id == response.barrier_id)
    assert list(barrier.skill_ids) == [scene.m2, scene.d1]
    assert list(barrier.agents) == ["manipulator_rover", "drone"]
    do(c, "delete_barrier", barrier_id=response.barrier_id)
    assert [b.id for b in c.mission().barriers] == [scene.barrier]


BARRIER_REJECTIONS: list[Case] = [
    ("no-members", lambda s: {"skill_ids": []}, E.INVALID),
    ("one-member", lambda s: {"skill_ids": [s.d1]}, E.INVALID),
    ("same-skill-twice", lambda s: {"skill_ids": [s.d1, s.d1]}, E.INVALID),
    ("empty-id", lambda s: {"skill_ids": [s.d1, ""]}, E.NOT_FOUND),
    ("unknown-id", lambda s: {"skill_ids": [s.d1, "ghost"]}, E.NOT_FOUND),
    ("same-agent", lambda s: {"skill_ids": [s.d1, s.d2]}, E.RULE),
    ("already-in-barrier", lambda s: {"skill_ids": [s.d1, s.s2]}, E.RULE),
    (
        "stale-revision",
        lambda s: {"skill_ids": [s.d1, s.s1], "base_revision": s.rev + 1},
        E.CONFLICT,
    ),
]


@rejections(BARRIER_REJECTIONS)
def test_add_barrier_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "add_barrier", build(scene), code)


def test_add_barrier_that_would_deadlock_is_refused(scene: Scene) -> None:
    # science_rover runs s1 before s2; manipulator_rover runs m1 before m2; {s2, m1} is a
    # barrier, so {s1, m2} would make each wait for the other.
    response = check_rejection(scene, "add_barrier", {"skill_ids": [scene.s1, scene.m2]}, E.RULE)
    assert "deadlock" in response.error


@pytest.mark.parametrize(
    ("barrier_id", "revision_offset", "code"),
    [("", 0, E.INVALID), ("barrier-000000", 0, E.NOT_FOUND), (None, -1, E.CONFLICT)],
    ids=["empty-id", "unknown-id", "stale-revision"],
)
def test_delete_barrier_rejects(
    scene: Scene, barrier_id: str | None, revision_offset: int, code: int
) -> None:
    fields = {"barrier_id": scene.barrier if barrier_id is None else barrier_id}
    check_rejection(
        scene, "delete_barrier", {**fields, "base_revision": scene.rev + revision_offset}, code
    )


# -- task markers ------------------------------------------------------------------------------
def test_task_markers_add_move_rename_delete(scene: Scene) -> None:
    c = scene.client
    named = do(c, "add_task_marker", marker=wire.TaskMarker(type=1, pose=pose(x=1)))
    assert named.name == "Pose 1"  # an empty name gets a generated one
    area = do(
        c, "add_task_marker", marker=wire.TaskMarker(name="Field", type=2, vertices=square(6))
    )
    field = next(m for m in c.mission().markers if m.name == area.name)
    assert (field.pose.x, field.pose.y) == (3.0, 3.0)  # the centroid
    # Moving a marker moves every parameter bound to it.
    do(c, "move_task_marker", name="Site", pose=pose(x=-7, y=8, yaw=1.0))
    target = param(find(c.mission(), scene.d2), "target")
    assert (target.pose_value.x, target.pose_value.y, target.pose_value.yaw) == (-7, 8, 1.0)
    do(c, "move_task_marker", name="Zone", vertices=square(2))
    area_param = param(find(c.mission(), scene.d3), "area")
    assert json.loads(area_param.json_value)[2] == {"x": 2.0, "y": 2.0}
    # Renaming keeps the bindings.
    do(c, "rename_task_marker", name="Site", new_name="Landing site")
    assert param(find(c.mission(), scene.d2), "target").marker == "Landing site"
    do(c, "delete_task_marker", name="Pose 1")
    assert "Pose 1" not in [m.name for m in c.mission().markers]


def _marker(**fields: Any) -> Callable[[Scene], dict[str, Any]]:
    return lambda s: {"marker": wire.TaskMarker(**{"name": "New", "type": 1, **fields})}


ADD_MARKER_REJECTIONS: list[Case] = [
    ("unknown-type", _marker(type=3), E.INVALID),
    ("type-255", _marker(type=255), E.INVALID),
    ("area-two-vertices", _marker(type=2, vertices=square()[:2]), E.INVALID),
    ("area-no-vertices", _marker(type=2), E.INVALID),
    ("pose-with-vertices", _marker(vertices=square()), E.INVALID),
    ("nan-pose", _marker(pose=pose(x=NAN)), E.INVALID),
    ("inf-pose", _marker(pose=pose(roll=-INF)), E.INVALID),
    ("nan-vertex", _marker(type=2, vertices=[*square()[:3], pose(y=NAN)]), E.INVALID),
    ("duplicate-name", _marker(name="Site"), E.RULE),
    ("long-name", _marker(name="m" * 81), E.INVALID),
    ("multi-line-name", _marker(name="a\nb"), E.INVALID),
    ("stale-revision", lambda s: {**_marker()(s), "base_revision": s.rev - 1}, E.CONFLICT),
]


@rejections(ADD_MARKER_REJECTIONS)
def test_add_task_marker_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    response = check_rejection(scene, "add_task_marker", build(scene), code)
    assert response.name == ""


MOVE_MARKER_REJECTIONS: list[Case] = [
    ("empty-name", lambda s: {"name": "", "pose": pose(x=1)}, E.INVALID),
    ("unknown-name", lambda s: {"name": "Nowhere", "pose": pose(x=1)}, E.NOT_FOUND),
    ("nan-pose", lambda s: {"name": "Site", "pose": pose(x=NAN)}, E.INVALID),
    ("inf-pose", lambda s: {"name": "Site", "pose": pose(z=INF)}, E.INVALID),
    ("vertices-for-pose", lambda s: {"name": "Site", "vertices": square()}, E.INVALID),
    ("area-two-vertices", lambda s: {"name": "Zone", "vertices": square()[:2]}, E.INVALID),
    (
        "stale-revision",
        lambda s: {"name": "Site", "pose": pose(x=1), "base_revision": 1},
        E.CONFLICT,
    ),
]


@rejections(MOVE_MARKER_REJECTIONS)
def test_move_task_marker_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "move_task_marker", build(scene), code)


RENAME_MARKER_REJECTIONS: list[Case] = [
    ("empty-name", lambda s: {"name": "", "new_name": "X"}, E.INVALID),
    ("unknown-name", lambda s: {"name": "Nowhere", "new_name": "X"}, E.NOT_FOUND),
    ("empty-new-name", lambda s: {"name": "Site", "new_name": ""}, E.INVALID),
    ("same-name", lambda s: {"name": "Site", "new_name": "Site"}, E.INVALID),
    ("taken-name", lambda s: {"name": "Site", "new_name": "Spot"}, E.RULE),
    ("long-new-name", lambda s: {"name": "Site", "new_name": "n" * 500}, E.INVALID),
    (
        "stale-revision",
        lambda s: {"name": "Site", "new_name": "X", "base_revision": s.rev - 1},
        E.CONFLICT,
    ),
]


@rejections(RENAME_MARKER_REJECTIONS)
def test_rename_task_marker_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "rename_task_marker", build(scene), code)


DELETE_MARKER_REJECTIONS: list[Case] = [
    ("empty-name", lambda s: {"name": ""}, E.INVALID),
    ("unknown-name", lambda s: {"name": "Nowhere"}, E.NOT_FOUND),
    ("in-use", lambda s: {"name": "Site"}, E.RULE),
    ("stale-revision", lambda s: {"name": "Site", "base_revision": s.rev - 1}, E.CONFLICT),
]


@rejections(DELETE_MARKER_REJECTIONS)
def test_delete_task_marker_rejects(
    scene: Scene, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, "delete_task_marker", build(scene), code)


# -- whole missions ----------------------------------------------------------------------------
def test_new_mission_keeps_markers_on_request(scene: Scene) -> None:
    c = scene.client
    check_rejection(scene, "new_mission", {"keep_markers": True, "base_revision": 3}, E.CONFLICT)
    do(c, "new_mission", keep_markers=True)
    mission = c.mission()
    assert not skill_ids(mission) and not mission.barriers
    assert [m.name for m in mission.markers] == ["Site", "Zone", "Spot"]
    do(c, "new_mission", keep_markers=False)
    assert not c.mission().markers


def test_save_and_load_round_trip(scene: Scene, tmp_path: Path) -> None:
    c = scene.client
    before = c.mission()
    path = tmp_path / "saved.yaml"
    written = accepted(c.call("save_mission", path=str(path)))
    assert (written.path_written, written.revision) == (str(path), scene.rev)
    assert written.document == ""  # saved on the server's host: the document stays there
    saved = accepted(c.call("save_mission", path=str(path), return_document=True))
    assert path.read_text() == saved.document
    assert accepted(c.call("save_mission")).document == saved.document  # no path: returned
    assert c.revision() == scene.rev  # saving is not a change
    do(c, "new_mission", keep_markers=False)
    loaded = do(c, "load_mission", document=saved.document)
    assert loaded.revision == scene.rev + 2
    after = c.mission()
    before.revision = after.revision
    assert mission_key(after) == mission_key(before)
    do(c, "delete_skills", skill_ids=[scene.d1])
    do(c, "load_mission", path=str(path))
    assert scene.d1 in skill_ids(c.mission())


PYTHON_TAG = "!!python/object/apply:os.system ['touch {marker}']\n"


def test_load_mission_rejects(scene: Scene, tmp_path: Path) -> None:
    document = accepted(scene.client.call("save_mission")).document
    before = scene.client.call("get_mission").mission
    marker = tmp_path / "pwned"
    wrong_library = document.replace("library: mars_sample_return", "library: lunar")
    unknown_agent = document.replace("  drone:", "  zeppelin:")
    cases = [
        ({"path": "", "document": ""}, E.INVALID),
        ({"path": str(tmp_path / "a.yaml"), "document": document}, E.INVALID),
        ({"document": "rosmc_mission: [unclosed"}, E.INVALID),
        ({"document": "just a string"}, E.INVALID),
        ({"document": "{}"}, E.INVALID),
        ({"document": PYTHON_TAG.format(marker=marker)}, E.INVALID),
        (
            {"document": document.replace("tasks:", f"tasks: {PYTHON_TAG.format(marker=marker)}")},
            E.INVALID,
        ),
        ({"document": "rosmc_mission: !!python/name:os.system\n"}, E.INVALID),
        ({"document": wrong_library}, E.INVALID),
        ({"document": unknown_agent}, E.INVALID),
        ({"document": document.replace("rosmc_mission: 1", "rosmc_mission: 99")}, E.INVALID),
        ({"path": str(tmp_path / "missing.yaml")}, E.INVALID),
        ({"path": str(tmp_path)}, E.INVALID),
        ({"document": document, "base_revision": scene.rev - 1}, E.CONFLICT),
    ]
    for fields, code in cases:
        check_rejection(scene, "load_mission", dict(fields), code)
    assert not marker.exists(), "a Python object tag in a mission document was executed"
    # A load lets the snapshot's bytes go while it reads; after a refused one the mission's
    # snapshot is made afresh, the same as before.
    after = scene.client.call("get_mission").mission
    assert (after.revision, after.tasks, after.barriers, after.markers) == (
        before.revision,
        before.tasks,
        before.barriers,
        before.markers,
    )


def test_save_mission_to_an_unwritable_place_is_refused(scene: Scene, tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    # A missing folder is made (issue: save to team/plan.yaml); a file in the way is not.
    for path in (str(blocker / "dir.yaml"), str(tmp_path)):
        response = scene.client.call("save_mission", path=path)
        assert response.error_code == E.INVALID, (response.error_code, response.error)
        assert_one_sentence(response.error)
        assert response.path_written == ""


def test_paths_with_a_nul_byte_are_invalid_not_internal(scene: Scene, tmp_path: Path) -> None:
    path = f"{tmp_path}/a\0b.yaml"
    response = scene.client.call("save_mission", path=path)
    assert response.error_code == E.INVALID, (response.error_code, response.error)
    check_rejection(scene, "load_mission", {"path": path}, E.INVALID)


def test_deeply_nested_json_is_invalid_and_saving_keeps_working(scene: Scene) -> None:
    for depth in (40, 500, 100_000):
        nested = "[" * depth + "]" * depth
        fields = {
            "agent": "drone",
            "skill": "fly_over",
            "index": -1,
            "parameters": [pl("area", nested)],
        }
        check_rejection(scene, "add_skill", fields, E.INVALID)
    accepted(scene.client.call("save_mission"))


# -- execution services without a robot -------------------------------------------------------
CONTROL = {"start": 0, "pause": 1, "resume": 2, "stop": 3}


def test_control_queues_commands_without_changing_the_mission(scene: Scene) -> None:
    c = scene.client
    before = mission_key(c.mission())
    for command in CONTROL.values():
        response = accepted(c.call("control", agent="", command=command))
        assert list(response.agents) == list(AGENTS)
        assert response.revision == scene.rev
    assert list(accepted(c.call("control", agent="drone", command=0)).agents) == ["drone"]
    assert mission_key(c.mission()) == before


@pytest.mark.parametrize(
    ("agent", "command", "code"),
    [
        ("drone", 4, E.INVALID),
        ("drone", 255, E.INVALID),
        ("ufo", 0, E.NOT_FOUND),
        ("lander", 0, E.RULE),
    ],
    ids=["command-4", "command-255", "unknown-agent", "static-agent"],
)
def test_control_rejects(scene: Scene, agent: str, command: int, code: int) -> None:
    check_rejection(scene, "control", {"agent": agent, "command": command}, code)


EXECUTION_REJECTIONS: list[tuple[str, str, Callable[[Scene], dict[str, Any]], int]] = [
    ("sync-empty-agent", "synchronize", lambda s: {"agent": ""}, E.INVALID),
    ("sync-unknown-agent", "synchronize", lambda s: {"agent": "ufo"}, E.NOT_FOUND),
    ("sync-static-agent", "synchronize", lambda s: {"agent": "wifi_box"}, E.RULE),
    ("sync-unknown-upto", "synchronize", lambda s: {"agent": "drone", "upto_id": "x"}, E.NOT_FOUND),
    ("sync-upto-other-agent", "synchronize", lambda s: {"agent": "drone", "upto_id": s.s1}, E.RULE),
    (
        "sync-stale",
        "synchronize",
        lambda s: {"agent": "drone", "base_revision": s.rev - 1},
        E.CONFLICT,
    ),
    ("unsync-empty-agent", "unsynchronize", lambda s: {"agent": ""}, E.INVALID),
    ("unsync-unknown-agent", "unsynchronize", lambda s: {"agent": "ufo"}, E.NOT_FOUND),
    ("unsync-static-agent", "unsynchronize", lambda s: {"agent": "lander"}, E.RULE),
    ("unsync-nothing-synced", "unsynchronize", lambda s: {"agent": "drone"}, E.RULE),
    (
        "unsync-unknown-from",
        "unsynchronize",
        lambda s: {"agent": "drone", "from_id": "x"},
        E.NOT_FOUND,
    ),
    ("unsync-stale", "unsynchronize", lambda s: {"agent": "drone", "base_revision": 1}, E.CONFLICT),
    ("retry-empty-id", "retry_skill", lambda s: {"skill_id": ""}, E.INVALID),
    ("retry-unknown-id", "retry_skill", lambda s: {"skill_id": "x"}, E.NOT_FOUND),
    ("retry-not-failed", "retry_skill", lambda s: {"skill_id": s.d1}, E.RULE),
    ("skip-empty-id", "skip_skill", lambda s: {"skill_id": ""}, E.INVALID),
    ("skip-unknown-id", "skip_skill", lambda s: {"skill_id": "x"}, E.NOT_FOUND),
    ("skip-not-failed", "skip_skill", lambda s: {"skill_id": s.d1}, E.RULE),
]


@pytest.mark.parametrize(
    ("operation", "build", "code"),
    [case[1:] for case in EXECUTION_REJECTIONS],
    ids=[case[0] for case in EXECUTION_REJECTIONS],
)
def test_execution_services_reject(
    scene: Scene, operation: str, build: Callable[[Scene], dict[str, Any]], code: int
) -> None:
    check_rejection(scene, operation, build(scene), code)


# -- published topics -------------------------------------------------------------------------
def test_one_event_per_accepted_change_in_revision_order(scene: Scene, events: Any) -> None:
    c = scene.client
    recorder = events()
    expected = []
    do(c, "edit_skill", skill_id=scene.d1, parameters=[pf("altitude", 9)])
    expected.append(wire.MissionEvent.SKILL_EDITED)
    assert_rejected(c, "edit_skill", base_revision=c.revision(), skill_id="x", label="y")
    assert_rejected(c, "add_skill", base_revision=1, agent="drone", skill="land")
    new = add(c, "drone", "land")
    expected.append(wire.MissionEvent.SKILL_ADDED)
    do(c, "reorder_skills", agent="drone", order=[new, scene.d3, scene.d2, scene.d1])
    expected.append(wire.MissionEvent.SKILLS_REORDERED)
    assert_rejected(c, "reorder_skills", base_revision=c.revision(), agent="drone", order=[new])
    do(c, "add_barrier", skill_ids=[new, scene.s1])
    expected.append(wire.MissionEvent.BARRIER_ADDED)
    do(c, "move_task_marker", name="Spot", pose=pose(x=5))
    expected.append(wire.MissionEvent.MARKER_MOVED)
    accepted(c.call("control", agent="", command=0))  # no mission change, no event
    assert_rejected(c, "delete_task_marker", base_revision=c.revision(), name="Spot")
    do(c, "delete_skills", skill_ids=[new])
    expected.append(wire.MissionEvent.SKILL_DELETED)
    do(c, "new_mission", keep_markers=True)
    expected.append(wire.MissionEvent.MISSION_REPLACED)
    final = c.revision()
    got = recorder.wait_for(lambda m: bool(m) and m[-1].revision >= final)
    time.sleep(0.2)  # nothing else may follow
    got = recorder.snapshot()
    assert [e.revision for e in got] == list(range(scene.rev + 1, final + 1))
    assert [e.kind for e in got] == expected
    assert all(e.summary for e in got)


def test_event_size_does_not_grow_with_the_mission(fresh: Client, events: Any) -> None:
    c = fresh
    recorder = events()
    sizes: dict[int, tuple[int, int]] = {}
    rev = c.revision()
    for count in range(1, 1001):
        added = accepted(
            c.call(
                "add_skill",
                base_revision=rev,
                agent="drone",
                skill="take_off",
                index=-1,
                parameters=[pf("altitude", 6.0)],
            )
        )
        rev = added.revision
        if count in (10, 1000):
            rev = do(c, "edit_skill", skill_id=added.skill_id, parameters=[pf("altitude", 7.0)])
            rev = rev.revision
            got = recorder.wait_for(lambda m, r=rev: bool(m) and m[-1].revision >= r)
            add_event, edit_event = got[-2], got[-1]
            assert add_event.put_skills[0].skill.id == added.skill_id
            assert add_event.put_skills[0].index == count - 1
            sizes[count] = (len(serialized(add_event)), len(serialized(edit_event)))
    # Ids have the same length and the index is a fixed-size field: the sizes are equal.
    assert sizes[10] == sizes[1000], sizes
    assert sizes[1000][0] < 1000  # a few hundred bytes, not a mission
    assert len(serialized(c.mission())) > 100 * sizes[1000][0]


_FIRST_MESSAGE = """
import sys, rospy
rospy.init_node("late_joiner", anonymous=True)
msg = rospy.wait_for_message(sys.argv[1], rospy.AnyMsg, timeout=60.0)
open(sys.argv[2], "wb").write(msg._buff)
"""


def first_message(topic: str, folder: Path) -> bytes:
    """The first message a new subscriber in a process of its own gets on ``topic``."""
    target = folder / "first_message.bin"
    subprocess.run(
        [sys.executable, "-c", _FIRST_MESSAGE, topic, str(target)], check=True, timeout=90.0
    )
    return target.read_bytes()


def test_the_mission_topic_gives_each_subscriber_the_current_mission_once(
    fresh: Client, client_node: Any, tmp_path: Path
) -> None:
    """A change is not resent to every subscriber (they follow the events): a late joiner
    gets the current mission, and only a replaced mission goes to everyone."""
    c = fresh
    early = Recorder(interface.MISSION_TOPIC, wire.Mission)
    try:
        assert early.wait_for(bool, timeout=30.0)[0].revision <= c.revision()
        # A replaced mission goes to every subscriber (and ends what was being built).
        rev = accepted(c.call("new_mission", base_revision=c.revision(), keep_markers=False))
        start = rev.revision
        early.wait_for(lambda m: m[-1].revision == start, timeout=30.0)
        for _ in range(50):
            rev = accepted(
                c.call(
                    "add_skill",
                    base_revision=rev.revision,
                    agent="science_rover",
                    skill="explore",
                    index=-1,
                )
            )
        # Another process: this one's subscribers share one connection, and a late one
        # here would connect afresh for both.
        joined = wire.Mission().deserialize(first_message(interface.MISSION_TOPIC, tmp_path))
        assert joined.revision == rev.revision
        assert mission_key(joined) == mission_key(c.mission())
        replaced = accepted(c.call("new_mission", base_revision=rev.revision, keep_markers=False))
        got = early.wait_for(lambda m: m[-1].revision == replaced.revision, timeout=30.0)
        # Before, the burst's coalesced snapshot came between the two.
        assert [m.revision for m in got if m.revision >= start] == [start, replaced.revision]
        assert not any(t.skills for t in got[-1].tasks)
    finally:
        early.close()


def test_agent_states_keep_arriving_with_unknown_links(
    client: Client, module_server: Any, client_node: Any
) -> None:
    states = Recorder(interface.AGENT_STATES_TOPIC, wire.AgentStates)
    try:
        # They keep coming, unasked (their rate is a figure: bench/bench_server.py).
        got = states.wait_for(lambda m: len(m) >= 10, timeout=60.0)
    finally:
        states.close()
    for message in got:
        assert [a.agent for a in message.agents] == list(AGENTS)
        assert all(a.link.state == wire.LinkState.UNKNOWN for a in message.agents)
        assert all(a.link.last_heard == -1 for a in message.agents)
    assert got[-1].revision == client.revision()


# -- synchronization with the robot link -------------------------------------------------------
def _populate_drone(client: Client, count: int = 3) -> list[str]:
    return [add(client, "drone", "take_off") for _ in range(count)]


def test_synchronize_answers_at_once_and_uploads_when_the_robot_is_heard(
    start_server: Any, fake_robot: Any, events: Any
) -> None:
    start_server()
    with Client() as c:
        ids = _populate_drone(c)
        robot = fake_robot("drone")
        recorder = events()
        response = do(c, "synchronize", agent="drone", upto_id=ids[1])
        # It answered at once: the robot has not confirmed, the skills are still uploading.
        assert list(response.skill_ids) == ids[:2]
        mission = c.mission()
        uploading = [s.transfer for s in task_of(mission, "drone")]
        assert uploading == [wire.Skill.TRANSFER_UPLOADING] * 2 + [wire.Skill.TRANSFER_NONE]
        assert all(s.status.value == wire.SkillStatus.IDLE for s in task_of(mission, "drone"))
        # Skills being uploaded are no longer editable.
        assert_rejected(
            c,
            "edit_skill",
            wire.ErrorCode.RULE,
            base_revision=mission.revision,
            skill_id=ids[0],
            label="x",
        )
        assert_rejected(
            c,
            "delete_skills",
            wire.ErrorCode.RULE,
            base_revision=mission.revision,
            skill_ids=[ids[1]],
        )
        # The robot's numbering is unknown until it is heard; then the upload goes out.
        robot.announce()
        default = robot.wait_command(wire.RobotCommand.SET_OPTIONS)  # the library's policy
        assert (default.agent, default.seq) == ("drone", 1)
        robot.ack(default)
        upload = robot.wait_command(wire.RobotCommand.UPLOAD)
        assert (upload.agent, upload.seq) == ("drone", 2)
        assert [s.id for s in upload.skills] == ids[:2]
        robot.ack(upload)
        recorder.wait_for(
            lambda m: any(e.kind == wire.MissionEvent.SYNC_CONFIRMED for e in m), timeout=30.0
        )
        statuses = [s.status.value for s in task_of(c.mission(), "drone")]
        assert statuses == [wire.SkillStatus.IDLE_SYNCHRONIZED] * 2 + [wire.SkillStatus.IDLE]
        # Unsynchronize answers at once too; the skills come back when the robot confirms.
        rev = c.revision()
        response = do(c, "unsynchronize", agent="drone", from_id=ids[1])
        assert list(response.skill_ids) == [ids[1]]
        removing = task_of(c.mission(), "drone")[1]
        assert removing.transfer == wire.Skill.TRANSFER_REMOVING
        unsync = robot.wait_command(wire.RobotCommand.UNSYNC)
        assert list(unsync.skill_ids) == [ids[1]]
        robot.ack(unsync, [ids[1]])
        recorder.wait_for(
            lambda m: any(e.kind == wire.MissionEvent.UNSYNC_CONFIRMED for e in m), timeout=30.0
        )
        final = task_of(c.mission(), "drone")
        assert [s.id for s in final] == ids
        assert [s.status.value for s in final] == [wire.SkillStatus.IDLE_SYNCHRONIZED, 0, 0]
        assert c.revision() == rev + 2


def test_a_down_link_takes_execution_requests_and_holds_them_for_contact(
    start_server: Any, fake_robot: Any, client_node: Any
) -> None:
    start_server(link_timeout=0.5, agent_state_rate=10.0)
    with Client() as c:
        _populate_drone(c, 2)
        add(c, "science_rover", "explore")
        robot = fake_robot("drone")
        robot.announce()
        robot.ack(robot.wait_command(wire.RobotCommand.SET_OPTIONS))  # the library's policy
        heard = len(robot.commands.snapshot())
        states = Recorder(interface.AGENT_STATES_TOPIC, wire.AgentStates)
        try:

            def drone_down(messages: list[wire.AgentStates]) -> bool:
                return bool(messages) and messages[-1].agents[0].link.state == wire.LinkState.DOWN

            got = states.wait_for(drone_down, timeout=30.0)
            assert [a.link.state for a in got[-1].agents[1:]] == [wire.LinkState.UNKNOWN] * 2
            for response in (
                do(c, "synchronize", agent="drone"),
                accepted(c.call("control", agent="drone", command=0)),
            ):
                assert response.note.startswith("queued for drone: out of contact"), response

            def two_waiting(messages: list[wire.AgentStates]) -> bool:
                return bool(messages) and messages[-1].agents[0].link.commands_waiting == 2

            states.wait_for(two_waiting, timeout=30.0)
        finally:
            states.close()
        assert len(robot.commands.snapshot()) == heard, "nothing leaves while the link is down"
        # Other robots are not held up by the one that cannot be reached.
        assert list(do(c, "synchronize", agent="science_rover").skill_ids)


def _failed_skill_document(client: Client) -> tuple[str, str]:
    skill_id = add(client, "drone", "take_off")
    add(client, "drone", "land")
    data = yaml.safe_load(accepted(client.call("save_mission")).document)
    data["tasks"]["drone"][0].update(status="FAILURE", started=10.0, finished=20.0)
    return skill_id, yaml.safe_dump(data, sort_keys=False)


def test_retry_a_failed_skill(start_server: Any) -> None:
    start_server()
    with Client() as c:
        failed, document = _failed_skill_document(c)
        do(c, "new_mission", keep_markers=False)
        do(c, "load_mission", document=document)
        skill = find(c.mission(), failed)
        assert skill.status.value == wire.SkillStatus.FAILURE
        rev = c.revision()
        for operation in ("retry_skill", "skip_skill"):
            assert_rejected(c, operation, E.CONFLICT, base_revision=rev - 1, skill_id=failed)
        response = do(c, "retry_skill", skill_id=failed)
        task = task_of(c.mission(), "drone")
        assert [s.id for s in task[:2]] == [failed, response.new_skill_id]
        assert task[0].resolution == wire.Skill.RESOLUTION_RETRIED
        assert (task[1].status.value, task[1].attempt) == (wire.SkillStatus.IDLE_SYNCHRONIZED, 2)
        rev = c.revision()
        for operation in ("retry_skill", "skip_skill"):  # already resolved
            assert_rejected(c, operation, E.RULE, base_revision=rev, skill_id=failed)


def test_skip_a_failed_skill(fresh: Client) -> None:
    c = fresh
    failed, document = _failed_skill_document(c)
    do(c, "new_mission", keep_markers=False)
    do(c, "load_mission", document=document)
    do(c, "skip_skill", skill_id=failed)
    assert find(c.mission(), failed).resolution == wire.Skill.RESOLUTION_SKIPPED
    assert_rejected(c, "skip_skill", E.RULE, base_revision=c.revision(), skill_id=failed)


def test_errors_quoting_the_request_stay_one_line(scene: Scene) -> None:
    for text in ("a\nb", "tab\there", "nul\0byte", "ls\u2028sep", "cr\r"):
        check_rejection(scene, "delete_skills", {"skill_ids": [text]}, E.NOT_FOUND)
        check_rejection(scene, "delete_task_marker", {"name": text}, E.NOT_FOUND)
        check_rejection(scene, "add_skill", {"agent": text, "skill": "land"}, E.NOT_FOUND)


def test_mission_files_stay_inside_the_mission_directory(scene: Scene) -> None:
    """Anybody on the graph can call the services: no file outside ~mission_dir is touched."""
    for path in ("/etc/rosmc_escape.yaml", "../../escape.yaml"):
        response = scene.client.call("save_mission", path=path)
        assert response.error_code == E.INVALID, (response.error_code, response.error)
        assert "only under" in response.error
        check_rejection(scene, "load_mission", {"path": path}, E.INVALID)
    assert not Path("/etc/rosmc_escape.yaml").exists()


def test_a_document_nested_too_deeply_is_invalid(scene: Scene) -> None:
    nested = "x: " + "[" * 5000 + "]" * 5000 + "\n"
    check_rejection(scene, "load_mission", {"document": nested}, E.INVALID)


def test_the_ground_asks_for_a_robots_queue_only_when_it_needs_it(
    start_server: Any, fake_robot: Any, client_node: Any
) -> None:
    """Snapshots leave the queue out; the ground asks (ReportAck.want_full) when a new
    ground must reconcile, or when the robot's status digest differs from its own."""
    start_server()
    robot = fake_robot("drone")
    acks = Recorder(interface.ground_link("drone").report_ack, wire.ReportAck)
    try:
        robot.announce(digest=status_digest([]))  # a robot this ground never heard
        acks.wait_for(lambda ms: any(m.want_full for m in ms), 30.0)
        robot.ack(robot.wait_command(wire.RobotCommand.SET_OPTIONS))  # the library's policy
        robot.announce()  # its whole (empty) queue
        asked = len(acks.wait_for(lambda ms: not ms[-1].want_full, 30.0))
        for _ in range(3):  # a digest that agrees: nothing more is asked
            robot.announce(digest=status_digest([]))
            time.sleep(0.2)
        assert not any(m.want_full for m in acks.snapshot()[asked:])
        robot.announce(digest="0123456789ab")  # statuses that disagree
        acks.wait_for(lambda ms: ms[-1].want_full, 30.0)
    finally:
        acks.close()
