"""What the GUIs offer is exactly what the real mission server accepts.

:mod:`rosmc_server.core.rules.legality` decides which skill and robot actions the command GUI
and rviz enable. This module checks it against the real server's operator services, not
against the core (``tests/unit/test_legality.py`` does that): for a set of mission states,
every action on every skill (and each robot's send / take back) is legal by the core
exactly when the service accepts the request the GUI sends for it. Every operation is
checked: add, edit, delete, move up and down (the command GUI's reorder request), send
and take back (of a skill and of a whole task), retry, skip, barrier add and delete, each
task marker's move, rename and delete (:mod:`rosmc_server.core.rules.edit_rules`), a new
marker, a new mission and a load (refused while a robot holds a skill). The states
include an upload waiting for a robot that was never heard (out of contact), where the
server cancels the upload on a take-back: *Take back* must then be offered.

The controls are the exception, by design: they go to the robot whatever the mission
says (a START to a robot the policy holds resumes it), so the server accepts every one
the GUIs offer and never refuses one on the mission's rules; the test says so.

One server for the module; the drone is played by a test robot that answers every
command, the science rover is never heard. A refused request leaves the mission as it
was; after an accepted one, the state is taken back to an empty mission and built again
(what the robots hold is given back first: a new mission needs idle robots).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import pytest
import rosmc.msg as wire
import rosmc.srv as srv
import rospy

from rosmc_rqt_command.core.dispatch import moved
from rosmc_server import interface
from rosmc_server.conversions import marker_to_msg, mission_from_msg, pose_to_msg
from rosmc_server.core import MarkerType, MissionState, Pose, SkillStatus, TaskMarker
from rosmc_server.core.model.control import ExecutorState
from rosmc_server.core.rules.edit_rules import MarkerAction, edit_refusal, legal_marker_actions
from rosmc_server.core.rules.legality import (
    RobotAction,
    SkillAction,
    StatePicture,
    TaskView,
    legal_robot_actions,
    legal_skill_actions,
)
from rosmc_server.core.rules.replacing import robots_idle_refusal

pytest.register_assert_rewrite("tests.integration.server_fixtures")
from tests.integration.server_fixtures import (  # noqa: E402
    Client,
    FakeRobot,
    ServerProcess,
    _launcher,
    _stop_all,
)

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

S = SkillStatus
A = SkillAction
ANSWERING = "drone"  # in contact, answers every command
SILENT = "science_rover"  # never heard: what is sent to it waits for contact
SETTLE = 60.0  # how long the server may take to show a robot's answer (a generous bound)


@dataclass
class Robot:
    """The drone's end of the link: acknowledges every command while ``answering``."""

    fake: FakeRobot
    answering: bool = True
    held: list[Any] = field(default_factory=list)  # commands left unanswered
    reports: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_command(self, command: Any) -> None:
        with self.lock:
            if self.answering:
                self.fake.ack(command)
            else:
                self.held.append(command)

    def answer(self) -> None:
        """Answer again, the commands held first."""
        with self.lock:
            self.answering = True
            for command in self.held:
                self.fake.ack(command)
            self.held.clear()

    def report(self, skill_id: str, status: S) -> None:
        self.reports += 1
        self.fake.report(self.reports, skill_id, int(status))


@dataclass
class Bench:
    """The module's server, a client, and the drone."""

    client: Client
    robot: Robot

    def state(self) -> MissionState:
        content, revision = mission_from_msg(self.client.mission())
        return MissionState(content, revision)

    def call(self, operation: str, **fields: Any) -> Any:
        return self.client.call(operation, base_revision=self.client.revision(), **fields)

    def do(self, operation: str, **fields: Any) -> Any:
        response = self.call(operation, **fields)
        assert response.error_code == 0, (operation, fields, response.error)
        return response

    def settle(self, done: Callable[[MissionState], bool], what: str) -> None:
        """Wait until the mission shows ``done`` (a robot's answer has arrived)."""
        deadline = time.monotonic() + SETTLE
        while not done(self.state()):
            assert time.monotonic() < deadline, f"the server never showed {what}"
            time.sleep(0.02)

    def reset(self) -> None:
        """An empty mission: what the robots hold comes back first."""
        self.robot.answer()
        deadline = time.monotonic() + SETTLE
        while True:
            state = self.state()
            for skill in state.task(ANSWERING):
                if skill.status.is_active:
                    self.robot.report(skill.id, S.SUCCESS)
            for agent in (ANSWERING, SILENT):
                self.call("unsynchronize", agent=agent, from_id="")  # refused if nothing
            if self.call("new_mission", keep_markers=False).error_code == 0:
                return
            assert time.monotonic() < deadline, "the robots never gave their skills back"
            time.sleep(0.02)


@pytest.fixture(scope="module")
def bench(client_node: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Bench]:
    start, started = _launcher(dict(client_node.env), tmp_path_factory.mktemp("legality"))
    server: ServerProcess = start("legality", link_timeout=3600.0)
    fake = FakeRobot(ANSWERING)
    robot = Robot(fake)
    topics = interface.ground_link(ANSWERING)
    listener = rospy.Subscriber(topics.command, wire.RobotCommand, robot.on_command)
    fake.announce()
    with Client() as client:
        yield Bench(client, robot)
    listener.unregister()
    fake.close()
    assert server.alive, "the mission server died"
    _stop_all(started)


# -- the mission states (each built from an empty mission; skills named by role) -------------
Roles = dict[str, str]


ZONE = TaskMarker("zone", MarkerType.AREA, Pose(3, 3), (Pose(2, 2), Pose(4, 2), Pose(4, 4)))
FREE = TaskMarker("free", MarkerType.POSITION, Pose(1, 1))
MARKERS = (ZONE.name, FREE.name)
DOCUMENT = "rosmc_mission: 1\nlibrary: mars_sample_return\nrevision: 1\ntasks: {}\n"


def blueprint(bench: Bench) -> Roles:
    """Three drone skills, two rover skills; a barrier between the last of each; the
    rover's first explores the area marker "zone", and "free" is bound to nothing."""
    roles = {}
    for agent, skill, prefix, count in (
        (ANSWERING, "take_off", "d", 3),
        (SILENT, "explore", "r", 2),
    ):
        for n in range(count):
            roles[f"{prefix}{n}"] = bench.do(
                "add_skill", agent=agent, skill=skill, index=-1
            ).skill_id
    bench.do("add_barrier", skill_ids=[roles["d2"], roles["r1"]])
    for marker in (ZONE, FREE):
        bench.do("add_task_marker", marker=marker_to_msg(marker))
    zone = wire.ParameterValue(name="area", marker=ZONE.name)
    bench.do("edit_skill", skill_id=roles["r0"], parameters=[zone])
    return roles


def rover_upload_waits(bench: Bench) -> Roles:
    """The rover's whole task is being uploaded to it: it was never heard."""
    roles = blueprint(bench)
    bench.do("synchronize", agent=SILENT, upto_id="")
    return roles


def drone_synced(bench: Bench) -> Roles:
    """The drone stored its first two skills; the rover's upload waits."""
    roles = rover_upload_waits(bench)
    bench.do("synchronize", agent=ANSWERING, upto_id=roles["d1"])
    bench.settle(
        lambda s: s.task(ANSWERING)[1].status is S.IDLE_SYNCHRONIZED, "the drone's confirmation"
    )
    return roles


def drone_uploading(bench: Bench) -> Roles:
    """The drone stored one skill; the upload of the next awaits its answer."""
    roles = rover_upload_waits(bench)
    bench.do("synchronize", agent=ANSWERING, upto_id=roles["d0"])
    bench.settle(lambda s: s.task(ANSWERING)[0].status is S.IDLE_SYNCHRONIZED, "the upload")
    bench.robot.answering = False
    bench.do("synchronize", agent=ANSWERING, upto_id=roles["d1"])
    return roles


def drone_running(bench: Bench) -> Roles:
    """The drone runs its first skill."""
    roles = drone_synced(bench)
    bench.robot.report(roles["d0"], S.RUNNING)
    bench.settle(lambda s: s.task(ANSWERING)[0].status is S.RUNNING, "the RUNNING report")
    return roles


def drone_failed(bench: Bench) -> Roles:
    """The drone's first skill failed."""
    roles = drone_running(bench)
    bench.robot.report(roles["d0"], S.FAILURE)
    bench.settle(lambda s: s.task(ANSWERING)[0].status is S.FAILURE, "the FAILURE report")
    return roles


def drone_removing(bench: Bench) -> Roles:
    """A take-back of the drone's second skill awaits its answer."""
    roles = drone_synced(bench)
    bench.robot.answering = False
    bench.do("unsynchronize", agent=ANSWERING, from_id=roles["d1"])
    return roles


STATES = [blueprint, rover_upload_waits, drone_synced, drone_uploading, drone_running]
STATES += [drone_failed, drone_removing]


# -- the requests each action sends, as the GUIs send them ----------------------------------
Request = tuple[str, dict[str, Any]] | None  # None: the GUI has no request to send


def skill_requests(state: MissionState, skill_id: str) -> Iterator[tuple[A, Request]]:
    """Each action on one skill with the request the command GUI sends for it."""
    agent = state.locate(skill_id)[0]
    editable = [skill.id for skill in TaskView.of(state, agent).editable]
    for move in (A.MOVE_UP, A.MOVE_DOWN):  # within the editable blueprint, as the GUI does
        order = moved(editable, [state.skill(skill_id)], move) if skill_id in editable else []
        changed = order != editable and skill_id in editable
        yield move, ("reorder_skills", {"agent": agent, "order": order}) if changed else None
    yield A.DELETE, ("delete_skills", {"skill_ids": [skill_id]})
    yield A.SYNC, ("synchronize", {"agent": agent, "upto_id": skill_id})
    yield A.UNSYNC, ("unsynchronize", {"agent": agent, "from_id": skill_id})
    yield A.RETRY, ("retry_skill", {"skill_id": skill_id})
    yield A.SKIP, ("skip_skill", {"skill_id": skill_id})
    barrier = state.barrier_of(skill_id)
    if barrier is not None:
        yield A.DELETE_BARRIER, ("delete_barrier", {"barrier_id": barrier.id})


def robot_requests(agent: str) -> Iterator[tuple[RobotAction, Request]]:
    """A robot's send and take-back of its whole task."""
    yield RobotAction.SYNC_ALL, ("synchronize", {"agent": agent, "upto_id": ""})
    yield RobotAction.UNSYNC_ALL, ("unsynchronize", {"agent": agent, "from_id": ""})


def marker_requests(name: str) -> Iterator[tuple[MarkerAction, Request]]:
    """Each action on one task marker with the request rviz sends for it."""
    yield MarkerAction.MOVE, ("move_task_marker", _marker_move(name))
    yield MarkerAction.RENAME, ("rename_task_marker", {"name": name, "new_name": f"{name}2"})
    yield MarkerAction.DELETE, ("delete_task_marker", {"name": name})


def _marker_move(name: str) -> dict[str, Any]:
    """A move of marker ``name`` by one metre (an area keeps its shape)."""
    marker = ZONE if name == ZONE.name else FREE
    shifted = [pose_to_msg(Pose(v.x + 1.0, v.y)) for v in marker.vertices]
    pose = pose_to_msg(Pose(marker.pose.x + 1.0, marker.pose.y))
    return {"name": name, "pose": pose, "vertices": shifted}


def whole_requests(state: MissionState) -> Iterator[tuple[str, bool, Request]]:
    """A new marker and a new skill (always legal), a new mission and a load."""
    new_marker = marker_to_msg(TaskMarker("", MarkerType.POSITION, Pose(7, 7)))  # named by it
    yield "ADD marker", True, ("add_task_marker", {"marker": new_marker})
    for agent in (ANSWERING, SILENT):
        skill = "land" if agent == ANSWERING else "return_to_lander"
        yield f"ADD {agent}", True, ("add_skill", {"agent": agent, "skill": skill, "index": -1})
    tasks = state.content().tasks.values()
    idle = robots_idle_refusal(tasks, "start a new mission") is None
    yield "NEW mission", idle, ("new_mission", {"keep_markers": True})
    idle = robots_idle_refusal(tasks, "load a mission") is None
    yield "LOAD mission", idle, ("load_mission", {"document": DOCUMENT})


def checks(state: MissionState, roles: Roles) -> Iterator[tuple[str, bool, Request]]:
    """(what, legal by the core, request) for every action of the state."""
    picture = StatePicture(state)
    for role, skill_id in roles.items():
        skill = state.skill(skill_id)
        legal = legal_skill_actions(picture, [skill])
        for action, request in skill_requests(state, skill_id):
            yield f"{action.name} {role}", action in legal, request
        editable = edit_refusal(skill, "edited") is None
        yield f"EDIT {role}", editable, ("edit_skill", {"skill_id": skill_id, "label": "new"})
    for name in MARKERS:
        legal_marker = legal_marker_actions(state, name)
        for marker_action, request in marker_requests(name):
            yield f"{marker_action.name} marker {name}", marker_action in legal_marker, request
    yield from whole_requests(state)
    pair = [roles["d0"], roles["r0"]]
    both = legal_skill_actions(picture, state_skills(state, pair))
    yield "BARRIER d0+r0", A.BARRIER in both, ("add_barrier", {"skill_ids": pair})
    team = {"agents": [ANSWERING, SILENT], "upto_ids": pair}  # one send of both robots
    yield "SYNC d0+r0", A.SYNC in both, ("synchronize_team", team)
    for agent in (ANSWERING, SILENT):
        actions = legal_robot_actions(TaskView.of(state, agent), ExecutorState.UNKNOWN)
        for action, request in robot_requests(agent):
            yield f"{action.name} {agent}", action in actions, request


def state_skills(state: MissionState, ids: list[str]) -> list[Any]:
    return [state.skill(i) for i in ids]


@pytest.mark.parametrize("build", STATES, ids=[build.__name__ for build in STATES])
def test_the_gui_offers_exactly_what_the_server_accepts(
    bench: Bench, build: Callable[[Bench], Roles]
) -> None:
    bench.reset()
    roles = build(bench)
    state = bench.state()
    table = {what: (legal, request) for what, legal, request in checks(state, roles)}
    accepted = []
    for what in list(table):
        legal, request = table[what]
        if request is None:  # a move past the end: nothing to send, so nothing to offer
            assert not legal, what
            continue
        operation, fields = request
        response = bench.call(operation, **fields)
        assert (response.error_code == 0) == legal, (what, legal, response.error)
        if response.error_code == 0:  # the mission changed: build the state again
            accepted.append(what)
            bench.reset()
            roles = build(bench)
            state = bench.state()
            table = {what: (legal, request) for what, legal, request in checks(state, roles)}
        else:
            assert bench.client.revision() == state.revision, f"{what} changed the mission"
    assert accepted  # every state offers something


def test_take_back_is_offered_for_an_upload_to_a_robot_out_of_contact(bench: Bench) -> None:
    """The case that disagreed: the server cancels the waiting upload, so the GUIs offer it."""
    bench.reset()
    roles = rover_upload_waits(bench)
    state = bench.state()
    rover = state.skill(roles["r0"])
    assert A.UNSYNC in legal_skill_actions(StatePicture(state), [rover])
    response = bench.do("unsynchronize", agent=SILENT, from_id=roles["r0"])
    assert list(response.skill_ids) == [roles["r0"], roles["r1"]]
    assert all(skill.is_editable for skill in bench.state().task(SILENT))


CONTROLS = {
    RobotAction.START: srv.ControlRequest.START,
    RobotAction.PAUSE: srv.ControlRequest.PAUSE,
    RobotAction.RESUME: srv.ControlRequest.RESUME,
    RobotAction.STOP: srv.ControlRequest.STOP,
}


@pytest.mark.parametrize("build", STATES, ids=[build.__name__ for build in STATES])
def test_every_control_the_gui_offers_goes_to_the_robot_and_none_changes_the_mission(
    bench: Bench, build: Callable[[Bench], Roles]
) -> None:
    """Controls are the robot's to carry out (a START to a held robot resumes it): the
    server takes every one for a robot with a link, offered or not, and the mission only
    changes when the robot reports what it did."""
    bench.reset()
    build(bench)
    state = bench.state()
    offered: set[RobotAction] = set()
    for agent in (ANSWERING, SILENT):
        offered |= legal_robot_actions(TaskView.of(state, agent), ExecutorState.UNKNOWN)
        for action, command in CONTROLS.items():
            response = bench.client.call("control", agent=agent, command=command)
            assert response.error_code == 0, (action, agent, response.error)
            assert bench.client.revision() == state.revision, f"{action} changed the mission"
    held = any(TaskView.of(state, agent).synced for agent in (ANSWERING, SILENT))
    assert bool(offered & set(CONTROLS)) == held  # a robot holding skills can be started
