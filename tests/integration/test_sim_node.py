"""The sim node ``/rosmc/sim`` as a real process against a real master.

One node (the Mars scenario with a long-lived drone battery, real-time factor 20)
serves the whole module; each test drives a different robot or asks a different
question, so the order does not matter.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import xmlrpc.client
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rospy
import tf2_ros
import yaml
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Bool
from visualization_msgs.msg import MarkerArray

from rosmc_server.conversions import param_to_msg
from rosmc_server.core import Pose
from rosmc_sim.ros.topics import (
    SCIENCE_TOPIC,
    WORLD_TOPIC,
    blackout_topic,
    odom_topic,
    skill_run_status_topic,
    skill_run_topic,
)
from tests.conftest import wait_until

REPO = Path(__file__).resolve().parents[2]
MARS = REPO / "rosmc_sim" / "scenarios" / "mars_sample_return.yaml"
ROBOTS = ("drone", "science_rover", "manipulator_rover")
RTF = 20.0
TIMEOUT = 60.0
S = wire.SkillRunStatus
AREA_A = [{"x": 10, "y": 4}, {"x": 22, "y": 4}, {"x": 22, "y": 14}, {"x": 10, "y": 14}]


class Latest:
    """The latest message of a topic (and every message, for topics that matter)."""

    def __init__(self, topic: str, msg_type: Any) -> None:
        self.messages: list[Any] = []
        self._lock = threading.Lock()
        self._subscriber = rospy.Subscriber(topic, msg_type, self._on_msg, queue_size=100)

    def _on_msg(self, msg: Any) -> None:
        with self._lock:
            self.messages = [*self.messages[-500:], msg]

    @property
    def last(self) -> Any:
        with self._lock:
            return self.messages[-1] if self.messages else None

    def all(self) -> list[Any]:
        with self._lock:
            return list(self.messages)

    def close(self) -> None:
        self._subscriber.unregister()


class Robot:
    """One robot's skill-run topics, odometry and link state, as the executor would see them."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._runs = rospy.Publisher(skill_run_topic(name), wire.SkillRun, queue_size=10)
        self.status = Latest(skill_run_status_topic(name), wire.SkillRunStatus)
        self.odom = Latest(odom_topic(name), Odometry)
        self.telemetry = Latest(f"/{name}/telemetry", wire.Telemetry)
        self.blackout = Latest(blackout_topic(name), Bool)
        wait_until(
            lambda: self._runs.get_num_connections() > 0, TIMEOUT, f"{name}'s skill-run subscriber"
        )

    def send(self, run_id: str, action: int, skill: str = "", **params: Any) -> None:
        self._runs.publish(
            wire.SkillRun(
                robot=self.name,
                run_id=run_id,
                action=action,
                skill=skill,
                parameters=[param_to_msg(name, value) for name, value in params.items()],
            )
        )

    def start(self, run_id: str, skill: str, **params: Any) -> None:
        self.send(run_id, wire.SkillRun.START, skill, **params)

    def statuses(self, run_id: str) -> list[Any]:
        return [m for m in self.status.all() if m.run_id == run_id]

    def wait_state(self, run_id: str, *states: int, timeout: float = TIMEOUT) -> Any:
        def reached() -> Any:
            return next((m for m in self.statuses(run_id) if m.state in states), None)

        return wait_until(reached, timeout, f"{self.name} {run_id} in state {states}")

    def still(self) -> bool:
        """The latest odometry says the robot stands still (no odometry from before a stop)."""
        last = self.odom.last
        if last is None:
            return False
        twist = last.twist.twist
        return max(abs(twist.linear.x), abs(twist.linear.y), abs(twist.linear.z)) < 1e-9

    def position(self) -> tuple[float, float, float]:
        p = wait_until(lambda: self.odom.last, TIMEOUT, f"{self.name} odometry").pose.pose.position
        return (p.x, p.y, p.z)

    def close(self) -> None:
        self._runs.unregister()
        for latest in (self.status, self.odom, self.telemetry, self.blackout):
            latest.close()


def stop(process: subprocess.Popen[bytes]) -> None:
    """SIGINT the node's process group, then SIGKILL what is left."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGINT)
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(10)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(10)


def node_argv(*args: str) -> list[str]:
    return [sys.executable, str(REPO / "scripts" / "sim_node"), *args]


@pytest.fixture(scope="module")
def sim(ros_master: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Robot]]:
    """The running sim node; yields a :class:`Robot` handle per robot."""
    tmp = tmp_path_factory.mktemp("sim_node")
    scenario = yaml.safe_load(MARS.read_text())
    scenario["robots"]["drone"]["endurance"] = 3600.0  # the test outlives a 300 s battery
    (tmp / "scenario.yaml").write_text(yaml.safe_dump(scenario))
    log_path = tmp / "sim_node.log"
    with log_path.open("wb") as log:
        process = subprocess.Popen(
            node_argv(f"_scenario:={tmp / 'scenario.yaml'}", f"_real_time_factor:={RTF}"),
            env=dict(ros_master.env),
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    if not rospy.core.is_initialized():
        rospy.init_node("sim_node_tests", anonymous=True, disable_signals=True)
    robots: dict[str, Robot] = {}
    try:
        robots = {name: Robot(name) for name in ROBOTS}
        yield robots
    finally:
        for robot in robots.values():
            robot.close()
        stop(process)
        print(log_path.read_text(errors="replace")[-4000:])
    assert process.returncode == 0, "the node did not shut down cleanly"


def test_clock_advances(sim: dict[str, Robot]) -> None:
    """Sim time moves on (its pace, sim seconds per wall second, is bench/bench_sim.py's)."""
    clock = Latest("/clock", Clock)
    try:
        first = wait_until(lambda: clock.last, TIMEOUT, "/clock").clock.to_sec()
        wait_until(
            lambda: clock.last.clock.to_sec() >= first + RTF, TIMEOUT, f"{RTF:g} sim seconds more"
        )
    finally:
        clock.close()


def test_tf_has_every_agent(sim: dict[str, Robot]) -> None:
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    try:
        for agent in (*ROBOTS, "lander", "wifi_box", "sample_box", "lofar_box", "power_box"):
            transform = buffer.lookup_transform(
                "map", f"{agent}/base_link", rospy.Time(0), rospy.Duration(TIMEOUT)
            )
            assert transform.header.stamp.to_sec() > 0.0
        lander = buffer.lookup_transform("map", "lander/base_link", rospy.Time(0))
        assert lander.transform.translation.x == 0.0 == lander.transform.translation.y
    finally:
        listener.unregister()


def test_telemetry_per_robot(sim: dict[str, Robot]) -> None:
    for name, robot in sim.items():
        msg = wait_until(lambda robot=robot: robot.telemetry.last, TIMEOUT, f"{name} telemetry")
        assert msg.agent == name and msg.frame_id == "map"
        assert 0.0 < msg.battery <= 1.0
        assert msg.wifi_signal < 0.0


def test_take_off_then_navigate(sim: dict[str, Robot]) -> None:
    drone = sim["drone"]
    drone.start("up", "take_off", altitude=6.0)
    assert drone.wait_state("up", S.SUCCEEDED, S.FAILED).text == "flying at 6.0 m"
    drone.start("go", "navigate_to", target=Pose(8.0, -4.0, 0.0, 0.0, 0.0, 0.5), speed=3.0)
    done = drone.wait_state("go", S.SUCCEEDED, S.FAILED)
    assert (done.state, done.text) == (S.SUCCEEDED, "arrived at (8.0, -4.0)")
    assert any(m.state == S.RUNNING and "to go" in m.text for m in drone.statuses("go"))
    wait_until(
        lambda: math.dist(drone.position(), (8.0, -4.0, 6.0)) < 0.05, TIMEOUT, "odom at target"
    )


def test_unknown_and_foreign_skills_fail_with_a_reason(sim: dict[str, Robot]) -> None:
    rover = sim["science_rover"]
    rover.start("u1", "moonwalk")
    assert "unknown skill 'moonwalk'" in rover.wait_state("u1", S.FAILED).text
    rover.start("u2", "pick_box", box="wifi_box")
    assert rover.wait_state("u2", S.FAILED).text == "a science rover cannot pick_box"
    rover.start("u3", "navigate_to")  # no target
    assert rover.wait_state("u3", S.FAILED).text == "missing parameter 'target'"


def test_pause_resume_cancel_preempt(sim: dict[str, Robot]) -> None:
    arm = sim["manipulator_rover"]
    arm.start("p1", "navigate_to", target=Pose(-20.0, -3.5))
    wait_until(lambda: arm.position()[0] < -5.0, TIMEOUT, "the rover driving")
    arm.send("p1", wire.SkillRun.PAUSE)
    assert arm.wait_state("p1", S.PAUSED).text.startswith("paused")
    wait_until(arm.still, TIMEOUT, "the paused rover to stand still")
    held = arm.position()
    time.sleep(0.5)  # and it stays where it is
    assert math.dist(arm.position(), held) < 1e-6
    arm.send("p1", wire.SkillRun.RESUME)
    wait_until(lambda: math.dist(arm.position(), held) > 0.5, TIMEOUT, "the rover going on")
    assert arm.statuses("p1")[-1].state == S.RUNNING
    arm.start("p2", "navigate_to", target=Pose(-6.0, -6.0))  # preempts p1
    assert arm.wait_state("p1", S.FAILED).text == "preempted by p2"
    arm.send("p2", wire.SkillRun.CANCEL)
    assert arm.wait_state("p2", S.FAILED).text == "cancelled"
    wait_until(arm.still, TIMEOUT, "the cancelled rover to stand still")
    where = arm.position()
    answers = len(arm.statuses("p2"))
    arm.start("p2", "navigate_to", target=Pose(-6.0, -6.0))  # a retransmission: answered
    wait_until(lambda: len(arm.statuses("p2")) > answers, TIMEOUT, "the answer to the resend")
    assert arm.statuses("p2")[-1].text == "cancelled"
    assert math.dist(arm.position(), where) < 1e-6


def test_leaving_coverage_blacks_out_the_link(sim: dict[str, Robot]) -> None:
    rover = sim["science_rover"]
    assert wait_until(lambda: rover.blackout.last, TIMEOUT, "blackout state").data is False
    rover.start("out", "navigate_to", target=Pose(3.5, -30.0), speed=1.0)
    assert rover.wait_state("out", S.SUCCEEDED, S.FAILED, timeout=30.0).state == S.SUCCEEDED
    wait_until(lambda: rover.blackout.last.data is True, TIMEOUT, "blackout true")
    wait_until(
        lambda: rover.telemetry.last.in_coverage is False, TIMEOUT, "telemetry out of coverage"
    )


def test_fly_over_discovers_a_region(sim: dict[str, Robot]) -> None:
    drone = sim["drone"]
    science = Latest(SCIENCE_TOPIC, wire.ScienceState)
    world = Latest(WORLD_TOPIC, MarkerArray)
    try:
        drone.start("climb", "take_off", altitude=8.0)
        drone.wait_state("climb", S.SUCCEEDED)
        drone.start("survey", "fly_over", area=AREA_A, altitude=8.0, spacing=4.0)
        assert drone.wait_state("survey", S.SUCCEEDED, S.FAILED).text == "found RSS A"
        regions = wait_until(lambda: science.last and science.last.regions, TIMEOUT, "a region")
        assert [r.name for r in regions] == ["RSS A"]
        assert regions[0].stones_left == 3 and regions[0].identified_by == ""
        events = [line for msg in science.all() for line in msg.events]
        assert any("drone discovered RSS A" in line for line in events)

        def world_shows_region() -> bool:
            return bool(world.last) and any(m.ns == "regions" for m in world.last.markers)

        wait_until(world_shows_region, TIMEOUT, "the region in the world markers")
        namespaces = {m.ns for m in world.last.markers}
        assert {"ground", "obstacles", "lander", "boxes", "wifi", "stones"} <= namespaces
        # The site says what the science stands at: each region's label and the score.
        texts = {m.ns: m.text for m in world.last.markers if m.type == m.TEXT_VIEW_FACING}
        assert texts["region_labels"] == "RSS A (max 1)\nnot identified, 3 left", texts
        assert texts["score"] == "science score 0.00\n0 stones delivered", texts
    finally:
        science.close()
        world.close()


def test_a_missing_scenario_exits_with_one_clear_line(ros_master: Any, tmp_path: Path) -> None:
    result = subprocess.run(
        node_argv(f"_scenario:={tmp_path / 'nowhere.yaml'}", "__name:=sim_bad"),
        env=dict(ros_master.env),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 1
    lines = [line for line in result.stderr.splitlines() if "nowhere.yaml" in line]
    assert len(lines) == 1 and "cannot read the scenario" in lines[0], result.stderr


def test_under_sim_time_the_clock_source_does_not_hear_itself(tmp_path: Path) -> None:
    """With /use_sim_time true (as launched), rospy would subscribe the node to its own /clock.

    Run as fast as possible, the node also publishes /clock at most ``~clock_rate`` times
    per wall second, not at every step.
    """
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    uri = f"http://127.0.0.1:{port}/"
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_IP="127.0.0.1", ROS_HOME=str(tmp_path))
    env.pop("ROS_HOSTNAME", None)
    master = subprocess.Popen(
        ["rosmaster", "--core", "-p", str(port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    log_path = tmp_path / "sim_node.log"
    proxy = xmlrpc.client.ServerProxy(uri)
    try:
        wait_until(lambda: _answers(proxy), TIMEOUT, "the private master")
        proxy.setParam("/test", "/use_sim_time", True)
        with log_path.open("wb") as log:
            node = subprocess.Popen(
                node_argv("_real_time_factor:=0", "_clock_rate:=20"),
                env=env,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

        def clock_nodes() -> tuple[list[str], list[str]] | None:
            publishers, subscribers, _ = proxy.getSystemState("/test")[2]
            pubs = next((nodes for topic, nodes in publishers if topic == "/clock"), [])
            subs = next((nodes for topic, nodes in subscribers if topic == "/clock"), [])
            return (pubs, subs) if "/rosmc/sim" in pubs else None

        wait_until(clock_nodes, TIMEOUT, "the node publishing /clock")
        time.sleep(1.0)  # and it never subscribes to /clock
        assert "/rosmc/sim" not in clock_nodes()[1]
        stop(node)
        assert node.returncode == 0
        summary = re.search(
            r"sim: ([0-9.]+) s of sim time in (\d+) steps \((\d+) on /clock\), "
            r"real-time factor ([0-9.]+)",
            log_path.read_text(),
        )
        assert summary, log_path.read_text()[-2000:]
        sim_time, steps, clocks, factor = (float(g) for g in summary.groups())
        assert sim_time > 10.0
        wall = sim_time / max(factor - 0.05, 0.01)  # the factor is printed rounded
        assert 0 < clocks <= 20 * wall + 2 and clocks < steps
    finally:
        stop(master)


def _answers(proxy: xmlrpc.client.ServerProxy) -> bool:
    try:
        return bool(proxy.getSystemState("/test")[0] == 1)
    except OSError:
        return False
