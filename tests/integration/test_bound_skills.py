"""Skills bound to existing ROS interfaces by the library, run by a real executor.

``tests/data/lab_team.yaml`` extends the test team with a lab robot whose skills are an
actionlib action, a service and a topic (no code). This process plays the lab: a real
``actionlib.SimpleActionServer`` (actionlib's own ``Test`` action, counting up to its
goal), a ``std_srvs/SetBool`` service and a subscriber; the mission server and the
robot's executor are real processes, and the operator calls the server's services.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import actionlib
import actionlib.msg as counting
import pytest
import rosmc.srv as srv
import rospy
import yaml
from geometry_msgs.msg import PoseStamped
from std_srvs.srv import SetBool, SetBoolRequest, SetBoolResponse

from rosmc_server.core import Pose, SkillStatus
from tests.conftest import RosMaster, wait_until
from tests.integration.executor_fixtures import (
    REPO_ROOT,
    Operator,
    RosmcSystem,
    init_test_node,
    stop_action_server,
)

pytestmark = pytest.mark.integration

S = SkillStatus
LAB_LIBRARY = REPO_ROOT / "tests" / "data" / "lab_team.yaml"
COUNT_PERIOD = 0.1  # wall seconds per count of the lab's counting server


@dataclass
class Lab:
    """The lab's own ROS interfaces, recording what the robot asked of them."""

    goals: list[int] = field(default_factory=list)
    preempted: list[int] = field(default_factory=list)
    switched: list[bool] = field(default_factory=list)
    looks: list[PoseStamped] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def start(self) -> None:
        """Advertise the action server, the service and the subscriber."""
        self.counter = actionlib.SimpleActionServer(
            "/lab/count", counting.TestAction, execute_cb=self._count, auto_start=False
        )
        self.counter.start()
        self.service = rospy.Service("/lab/switch", SetBool, self._switch)
        self.subscriber = rospy.Subscriber("/lab/look_at", PoseStamped, self._look)

    def _count(self, goal: object) -> None:
        target = goal.goal  # type: ignore[attr-defined]
        with self.lock:
            self.goals.append(target)
        if target < 0:
            self.counter.set_aborted(counting.TestResult(result=target), "cannot count down")
            return
        for count in range(1, target + 1):
            if self.counter.is_preempt_requested():
                with self.lock:
                    self.preempted.append(target)
                self.counter.set_preempted(counting.TestResult(result=count - 1))
                return
            self.counter.publish_feedback(counting.TestFeedback(feedback=count))
            time.sleep(COUNT_PERIOD)
        self.counter.set_succeeded(counting.TestResult(result=target))

    def _switch(self, request: SetBoolRequest) -> SetBoolResponse:
        with self.lock:
            self.switched.append(request.data)
        if request.data:
            return SetBoolResponse(success=True, message="the lamp is on")
        return SetBoolResponse(success=False, message="the lamp refuses to go off")

    def _look(self, msg: PoseStamped) -> None:
        with self.lock:
            self.looks.append(msg)

    def stop(self) -> None:
        """Withdraw the interfaces (the action server's thread would outlive the tests)."""
        stop_action_server(self.counter)
        self.service.shutdown()
        self.subscriber.unregister()

    def clear(self) -> None:
        """Forget what earlier tests asked."""
        with self.lock:
            self.goals.clear()
            self.preempted.clear()
            self.switched.clear()
            self.looks.clear()


@pytest.fixture(scope="module")
def lab(ros_master: RosMaster) -> Iterator[Lab]:
    """The lab's interfaces, advertised once for the module (the master outlives it)."""
    init_test_node()
    lab = Lab()
    lab.start()
    yield lab
    lab.stop()


@pytest.fixture
def robot(ros_master: RosMaster, lab: Lab, tmp_path: Path) -> Iterator[Operator]:
    """The mission server and the lab robot's executor, with the lab library; the operator."""
    lab.clear()
    system = RosmcSystem(ros_master.env, tmp_path, library=LAB_LIBRARY)
    system.start_server()
    system.start_executor("lab1")
    operator = Operator()
    try:
        operator.wait_links(["lab1"])
        yield operator
    finally:
        operator.close()
        system.close()
        print(system.log_tails())


def test_an_action_bound_skill_sends_goals_and_reports_feedback_and_result(
    robot: Operator, lab: Lab
) -> None:
    counted = robot.add("lab1", "count_to", {"target": 4})
    refused = robot.add("lab1", "count_to", {"target": -1})
    robot.sync("lab1")
    robot.start("lab1")
    robot.wait_status([counted], S.SUCCESS)
    state = robot.wait_status([refused], S.FAILURE)
    assert lab.goals == [4, -1]
    assert state.skill(counted).status_text == "reached 4"
    robot.events.wait_went(counted, S.SUCCESS)  # every event before it has arrived too
    assert any(text.startswith("counted ") for text in robot.status_texts(counted))
    assert state.skill(refused).status_text == "the action server aborted the goal: reached -1"


def test_pause_and_stop_preempt_the_goal_and_resume_sends_it_again(
    robot: Operator, lab: Lab
) -> None:
    long = robot.add("lab1", "count_to", {"target": 100000})
    robot.sync("lab1")
    robot.start("lab1")
    robot.wait_mission(
        lambda m: m.skill(long).status_text.startswith("counted "), 60.0, "the count to go on"
    )
    robot.control("lab1", srv.ControlRequest.PAUSE)
    robot.wait_status([long], S.PAUSED)
    wait_until(lambda: lab.preempted == [100000], 30.0, "the goal to be preempted by the pause")
    robot.control("lab1", srv.ControlRequest.RESUME)
    wait_until(lambda: lab.goals == [100000, 100000], 30.0, "the goal to be sent again")
    robot.wait_status([long], S.RUNNING)
    robot.control("lab1", srv.ControlRequest.STOP)
    robot.wait_status([long], S.IDLE_SYNCHRONIZED)
    wait_until(lambda: len(lab.preempted) == 2, 30.0, "the goal to be preempted by the stop")


def test_a_service_bound_skill_calls_and_its_response_is_the_outcome(
    robot: Operator, lab: Lab
) -> None:
    on = robot.add("lab1", "switch", {"lit": True})
    off = robot.add("lab1", "switch", {"lit": False})
    robot.sync("lab1")
    robot.start("lab1")
    robot.wait_status([on], S.SUCCESS)
    state = robot.wait_status([off], S.FAILURE)
    assert lab.switched == [True, False]
    assert state.skill(on).status_text == "the lamp is on"
    assert state.skill(off).status_text == "the lamp refuses to go off"


def test_a_topic_bound_skill_publishes_the_pose_parameter(robot: Operator, lab: Lab) -> None:
    look = robot.add("lab1", "point_at", {"target": Pose(1.5, -2.0, 0.5, yaw=math.pi / 2)})
    robot.sync("lab1")
    robot.start("lab1")
    robot.wait_status([look], S.SUCCESS)
    wait_until(lambda: lab.looks, 30.0, "the pose on /lab/look_at")
    sent = lab.looks[0]
    assert sent.header.frame_id == "map"
    position, orientation = sent.pose.position, sent.pose.orientation
    assert (position.x, position.y, position.z) == (1.5, -2.0, 0.5)
    assert orientation.z == pytest.approx(math.sqrt(0.5))
    assert orientation.w == pytest.approx(math.sqrt(0.5))


MISFITS = {
    "the type does not exist": (
        {"action": "/lab/count", "type": "actionlib/Nope", "fields": {"goal": "target"}},
        "skill 'broken' bound to action /lab/count (actionlib/Nope): there is no message type "
        "actionlib/NopeAction on this robot",
    ),
    "a goal field does not match its parameter": (
        {"action": "/lab/count", "type": "actionlib/Test", "fields": {"goal": "label"}},
        "skill 'broken' bound to action /lab/count (actionlib/Test): field 'goal' of "
        "actionlib/TestGoal is of type int32, which parameter 'label' (string) cannot fill",
    ),
    "a goal field does not exist": (
        {"service": "/lab/switch", "type": "std_srvs/SetBool", "fields": {"value": "target"}},
        "skill 'broken' bound to service /lab/switch (std_srvs/SetBool): "
        "std_srvs/SetBoolRequest has no field 'value' (it has: data)",
    ),
}


@pytest.mark.parametrize("case", sorted(MISFITS))
def test_the_executor_refuses_to_start_when_a_binding_does_not_fit(
    ros_master: RosMaster, tmp_path: Path, case: str
) -> None:
    binding, sentence = MISFITS[case]
    library = tmp_path / "misfit.yaml"
    parameters = {
        "label": {"type": "string", "default": "x"},
        "target": {"type": "int", "default": 1},
    }
    broken = {"parameters": parameters, "binding": binding}
    library.write_text(
        yaml.safe_dump(
            {
                "rosmc_library": 1,
                "name": "misfit",
                "extends": str(LAB_LIBRARY),
                "models": {"lab_robot": {"skills": {"broken": broken}}},
            }
        )
    )
    system = RosmcSystem(ros_master.env, tmp_path, library=library)
    system.start_executor("lab1")
    try:
        process = system.processes["lab1"]
        wait_until(lambda: process.poll() is not None, 60.0, "the executor to refuse to start")
        assert process.returncode == 1
        assert f"mission executor lab1: {sentence}\n" in system.log("lab1").read_text()
    finally:
        system.close()
