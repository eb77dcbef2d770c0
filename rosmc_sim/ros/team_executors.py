"""One mission executor per robot of a scenario, kept running: ``/rosmc/team_executors``.

roslaunch cannot repeat a node for every robot a scenario lists, so the simulated team's
executors are started here instead: for each robot of ``~scenario``, the node
``/<robot>/mission_executor`` with the simulated skills of its kind, behind the link
emulator (``robot_side``), exactly as ``sim_executor.launch`` starts one. An executor that
dies is started again after :data:`RESTART_DELAY` seconds (it resumes from its state file
when ``~state_dir`` is set), as a robot's own supervisor would; all of them stop with this
node.

Parameters (private): ``~scenario`` (str, the scenario YAML), ``~library`` (str, the
executors' skill library, "" = the simulated team's), ``~state_dir`` (str, where executors
keep their queues across restarts, "" = nowhere), ``~cwd`` (str, relative paths above are
taken from it).
"""

from __future__ import annotations

import argparse
import ctypes
import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import roslib.packages
import rospy

from rosmc_server.common.ros.graph_join import join_graph
from rosmc_server.common.ros.logging_bridge import bridge_logging_to_rosout
from rosmc_sim.core.scenario import RobotSpec, load_scenario

_log = logging.getLogger(__name__)

_PR_SET_PDEATHSIG = 1  # prctl option (linux/prctl.h)
RESTART_DELAY = 2.0  # seconds before an executor that died is started again
SKILLS = {
    "drone": "rosmc_sim.ros.robot_skills:drone_skills",
    "science_rover": "rosmc_sim.ros.robot_skills:science_rover_skills",
    "manipulator_rover": "rosmc_sim.ros.robot_skills:manipulator_rover_skills",
}


@dataclass(frozen=True)
class TeamConfig:
    """What the node reads from its parameters."""

    scenario: Path
    library: str
    state_dir: str
    cwd: str

    @classmethod
    def from_params(cls) -> TeamConfig:
        """Read the private parameters once."""
        cwd = str(rospy.get_param("~cwd", "") or os.getcwd())
        scenario = Path(cwd, str(rospy.get_param("~scenario")))
        library = str(rospy.get_param("~library", ""))
        return cls(scenario, library, str(rospy.get_param("~state_dir", "")), cwd)


def executor_command(robot: RobotSpec, config: TeamConfig) -> list[str]:
    """The command line of one robot's executor node (private parameters as ``_name:=``)."""
    state_file = f"{config.state_dir}/{robot.name}_executor.json" if config.state_dir else ""
    return [
        sys.executable,
        executor_script(),
        "__name:=mission_executor",
        f"__ns:=/{robot.name}",
        f"_agent:={robot.name}",
        f"_skills:={SKILLS[robot.kind]}",
        "_robot_side:=true",
        f"_library:={config.library}",
        f"_cwd:={config.cwd}",
        f"_state_file:={state_file}",
    ]


def executor_script() -> str:
    """The ``mission_executor`` entry script, found as ``rosrun rosmc mission_executor`` finds
    it (devel space, install space or checkout)."""
    found = roslib.packages.find_node("rosmc", "mission_executor")
    if not found:
        raise RuntimeError("rosmc's mission_executor is not installed (rosrun cannot find it)")
    return str(found[0])


class Team:
    """The executors' processes, started again when one dies."""

    def __init__(self, robots: Sequence[RobotSpec], config: TeamConfig) -> None:
        self._commands = {robot.name: executor_command(robot, config) for robot in robots}
        self._running: dict[str, subprocess.Popen[bytes]] = {}
        self._died_at: dict[str, float] = {}

    def start(self) -> None:
        """Start every executor."""
        for name in self._commands:
            self._start(name)

    def watch(self) -> None:
        """Start again each executor that died a while ago."""
        now = time.monotonic()
        for name, process in list(self._running.items()):
            code = process.poll()
            if code is None:
                continue
            if name not in self._died_at:
                _log.error("the executor of %s exited (%s); starting it again", name, code)
                self._died_at[name] = now
            elif now - self._died_at[name] >= RESTART_DELAY:
                self._start(name)

    def stop(self) -> None:
        """Stop every executor (SIGINT, as roslaunch does, then SIGKILL after 15 s)."""
        for process in self._running.values():
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
        deadline = time.monotonic() + 15.0
        for process in self._running.values():
            try:
                process.wait(max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()

    def _start(self, name: str) -> None:
        self._died_at.pop(name, None)
        env = {k: v for k, v in os.environ.items() if k != "ROS_NAMESPACE"}  # __ns names it
        self._running[name] = subprocess.Popen(
            self._commands[name], env=env, start_new_session=True, preexec_fn=_die_with_parent
        )


def _die_with_parent() -> None:
    """In the child: end with SIGTERM when this node ends, even killed (no orphans)."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``team_executors``."""
    args = rospy.myargv(list(argv) if argv is not None else sys.argv)
    argparse.ArgumentParser(
        prog="team_executors",
        description="One mission executor per robot of a scenario (_scenario:=FILE).",
    ).parse_args(args[1:])
    join_graph("team_executors")
    bridge_logging_to_rosout()
    config = TeamConfig.from_params()
    robots = load_scenario(config.scenario).robots
    unknown = sorted({robot.kind for robot in robots} - set(SKILLS))
    if unknown:
        _log.critical("team executors: no simulated skills for robot kinds %s", unknown)
        return 2
    team = Team(robots, config)
    team.start()
    _log.info("team executors: %d robots of %s", len(robots), config.scenario.name)
    try:
        while not rospy.is_shutdown():
            team.watch()
            time.sleep(0.5)
    finally:
        team.stop()
    return 0
