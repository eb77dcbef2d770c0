"""Benchmark of the sim node ``/rosmc/sim``; prints one JSON object.

For the 3-robot Mars scenario and a 20-robot team (``rosmc_sim/scenarios/twenty_robots.yaml``)
it starts a private ``rosmaster`` and the real sim node headless, keeps every robot
busy (drones take off, then fly back and forth; rovers drive back and forth, planned
around the obstacles), and measures over a window of wall time:

* ``rtf``: sim seconds per wall second, from ``/clock`` (which this process
  subscribes to, as every ``/use_sim_time`` node does);
* ``cpu_s_per_robot_per_sim_s``: the node's CPU seconds (user + system, from
  ``/proc/<pid>/stat``) per robot per sim second;
* ``tasks_finished``: skill runs that ended in the window (they keep being replaced).

Runs at ``~real_time_factor`` 0 (as fast as possible) and, to check pacing, at the
targets (20 with 3 robots, 2 with 20), with ``/use_sim_time`` true as in the launch
files. The ``baseline`` rows run as fast as possible with ``~clock_rate`` 0 (``/clock``
at every step, the node's behaviour before the rate limit) in the same run.
Run from the repository root::

    source env.sh
    python bench/bench_sim.py [--window 10]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import rosmc.msg as wire
import rospy
from _server_harness import stop_process
from rosgraph_msgs.msg import Clock

from rosmc_server.conversions import param_to_msg
from rosmc_server.core import Pose
from rosmc_sim.core.scenario import Scenario, load_scenario
from rosmc_sim.ros.topics import skill_run_status_topic, skill_run_topic

REPO = Path(__file__).resolve().parents[1]
SCENARIOS = {
    3: REPO / "rosmc_sim" / "scenarios" / "mars_sample_return.yaml",
    20: REPO / "rosmc_sim" / "scenarios" / "twenty_robots.yaml",
}
TARGETS = {3: 20.0, 20: 2.0}
WARM_UP = 3.0
CORNERS = ((25.0, 25.0), (-25.0, -25.0), (-25.0, 25.0), (25.0, -25.0))


@contextmanager
def private_master(home: Path) -> Iterator[dict[str, str]]:
    """A ``rosmaster`` on a free loopback port; yields the environment for its nodes."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}/", ROS_IP="127.0.0.1")
    env.update(ROS_HOME=str(home), ROS_LOG_DIR=str(home / "log"))
    env.pop("ROS_HOSTNAME", None)
    os.environ.update({k: env[k] for k in ("ROS_MASTER_URI", "ROS_IP", "ROS_HOME")})
    master = subprocess.Popen(
        ["rosmaster", "--core", "-p", str(port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        time.sleep(1.5)
        yield env
    finally:
        stop_process(master, signal.SIGTERM)


def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of a process so far (Linux)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Driver:
    """Keeps every robot of a scenario busy with skill runs and watches ``/clock``."""

    def __init__(self, scenario: Scenario) -> None:
        self.sim_time = 0.0
        self.finished = 0
        self.failed = 0
        self._lock = threading.Lock()
        self._count = 0
        self._handles: list[Any] = [rospy.Subscriber("/clock", Clock, self._on_clock)]
        self._pubs = {}
        self._robots = {r.name: r for r in scenario.robots}
        self._legs = dict.fromkeys(self._robots, 0)
        for name in self._robots:
            self._pubs[name] = rospy.Publisher(skill_run_topic(name), wire.SkillRun, queue_size=10)
            self._handles.append(
                rospy.Subscriber(
                    skill_run_status_topic(name),
                    wire.SkillRunStatus,
                    self._on_status,
                    callback_args=name,
                )
            )

    def _on_clock(self, msg: Any) -> None:
        self.sim_time = msg.clock.to_sec()

    def start(self) -> None:
        """Send every robot its first skill run."""
        for name in self._robots:
            self._next(name)

    def _on_status(self, msg: Any, robot: str) -> None:
        if msg.state in (msg.SUCCEEDED, msg.FAILED) and msg.run_id == self._current(robot):
            with self._lock:
                self.finished += 1
                self.failed += msg.state == msg.FAILED
            self._next(robot)

    def _current(self, robot: str) -> str:
        return f"{robot}-{self._legs[robot]}"

    def _next(self, robot: str) -> None:
        spec = self._robots[robot]
        self._legs[robot] += 1
        leg = self._legs[robot]
        if spec.kind == "drone" and leg == 1:
            skill, params = "take_off", {"altitude": 5.0}
        else:
            # Back and forth between the start and a far corner of the site.
            index = list(self._robots).index(robot)
            x, y = CORNERS[index % len(CORNERS)] if leg % 2 == 0 else (spec.x, spec.y)
            skill, params = "navigate_to", {"target": Pose(x, y)}
        self._pubs[robot].publish(
            wire.SkillRun(
                robot=robot,
                run_id=self._current(robot),
                action=wire.SkillRun.START,
                skill=skill,
                parameters=[param_to_msg(k, v) for k, v in params.items()],
            )
        )

    def close(self) -> None:
        """Drop the subscriptions and publishers."""
        for handle in [*self._handles, *self._pubs.values()]:
            handle.unregister()


def long_lived(source: Path, target: Path) -> Path:
    """A copy of a scenario whose batteries last the whole benchmark (the drone's would not)."""
    data = yaml.safe_load(source.read_text())
    for robot in data["robots"].values():
        robot["endurance"] = 100000.0
    target.write_text(yaml.safe_dump(data))
    return target


def measure(
    env: dict[str, str],
    robots: int,
    rtf: float,
    window: float,
    tmp: Path,
    clock_rate: float | None = None,
) -> dict[str, Any]:
    """Run the node on one scenario and measure one window (``clock_rate``: the node's own)."""
    path = long_lived(SCENARIOS[robots], tmp / f"bench_{robots}_robots.yaml")
    scenario = load_scenario(path)
    node = subprocess.Popen(
        [
            sys.executable,
            str(REPO / "scripts" / "sim_node"),
            f"_scenario:={path}",
            f"_real_time_factor:={rtf}",
            *([] if clock_rate is None else [f"_clock_rate:={clock_rate}"]),
        ],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    driver = Driver(scenario)
    try:
        deadline = time.monotonic() + 20.0
        while driver.sim_time == 0.0 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)  # let the subscriptions connect before the first skill runs go out
        driver.start()
        time.sleep(WARM_UP)
        wall0, sim0, cpu0 = time.monotonic(), driver.sim_time, cpu_seconds(node.pid)
        done0, failed0 = driver.finished, driver.failed
        time.sleep(window)
        wall, sim = time.monotonic() - wall0, driver.sim_time - sim0
        cpu = cpu_seconds(node.pid) - cpu0
    finally:
        driver.close()
        stop_process(node, signal.SIGTERM, grace=20.0)
    return {
        "robots": robots,
        "real_time_factor_param": rtf,
        "clock_rate_param": "default" if clock_rate is None else clock_rate,
        "rtf": round(sim / wall, 2),
        "cpu_s_per_robot_per_sim_s": round(cpu / robots / sim, 6) if sim > 0 else None,
        "cpu_share": round(cpu / wall, 3),
        "tasks_finished": driver.finished - done0,
        "tasks_failed": driver.failed - failed0,
        "window_s": round(wall, 2),
    }


def main() -> int:
    """Run the benchmark and print JSON."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--window", type=float, default=10.0, help="wall seconds measured per run")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp, private_master(Path(tmp)) as env:
        rospy.init_node("bench_sim", anonymous=True, disable_signals=True)
        rospy.set_param("/use_sim_time", True)  # as the launch files set it
        results: dict[str, Any] = {"as_fast_as_possible": [], "paced": [], "baseline": []}
        for robots in (3, 20):
            for key, rtf in (("as_fast_as_possible", 0.0), ("paced", TARGETS[robots])):
                results[key].append(measure(env, robots, rtf, args.window, Path(tmp)))
            # Baseline, same run: /clock at every step, as the node did before ~clock_rate.
            results["baseline"].append(
                measure(env, robots, 0.0, args.window, Path(tmp), clock_rate=0.0)
            )
        results["load_average"] = os.getloadavg()
        rospy.signal_shutdown("done")
    results["targets"] = {f"{n}_robots": TARGETS[n] for n in TARGETS}
    results["cpu_count"] = os.cpu_count()
    print(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
