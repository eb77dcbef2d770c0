"""The simulated robots' skills, as the mission executor sees them.

Each skill forwards its execution to the robot's controllers (played by the
simulator) with the skill-run protocol: START with the typed parameters,
PAUSE, RESUME and CANCEL on ``/<robot>/sim/skill_run`` (rosmc/SkillRun), progress
and outcome back on ``/<robot>/sim/skill_run_status`` (rosmc/SkillRunStatus). A
real robot would register skills of the same names that call its own stack.

Use one function per robot kind as the executor's ``~skills`` parameter:
``rosmc_sim.ros.robot_skills:drone_skills`` (or ``science_rover_skills``,
``manipulator_rover_skills``). The module's :func:`pose_source` (the robot's
odometry) is the executor's default ``~pose_source``, and its :func:`library` (the Mars
team's) the default ``~library``: it declares the skills' parameters.
"""

from __future__ import annotations

import functools
import itertools
import threading
import time
from collections.abc import Mapping
from pathlib import Path

import rosmc.msg as wire
import rospy

from rosmc_server.conversions import param_to_msg
from rosmc_server.core import Value
from rosmc_server.executor.core import Outcome, SkillBehavior, SkillContext, SkillType

from ..core.skills_registry import SIM_SKILLS
from .robot_pose import pose_source
from .topics import skill_run_status_topic, skill_run_topic

__all__ = [
    "drone_skills",
    "library",
    "manipulator_rover_skills",
    "pose_source",
    "science_rover_skills",
]

LIBRARY = Path(__file__).resolve().parents[2] / "rosmc_server" / "config" / "mars_team.yaml"
RESEND_AFTER = 1.0  # wall seconds without any status before a START is sent again


class RobotController:
    """One robot's skill-run channel to its controllers (shared by all its skills)."""

    def __init__(self, robot: str) -> None:
        self.robot = robot
        self._lock = threading.Lock()
        self._status: dict[str, wire.SkillRunStatus] = {}
        self._runs = itertools.count(1)
        self._publisher = rospy.Publisher(skill_run_topic(robot), wire.SkillRun, queue_size=100)
        self._subscriber = rospy.Subscriber(
            skill_run_status_topic(robot), wire.SkillRunStatus, self._on_status, queue_size=100
        )

    def _on_status(self, msg: wire.SkillRunStatus) -> None:
        with self._lock:
            self._status[msg.run_id] = msg

    def new_run_id(self, skill_id: str, attempt: int) -> str:
        """A run id for one run of a skill, never used before by this controller.

        A stopped skill runs again under the same skill id and attempt when the robot is
        started again; the controllers' answer about the cancelled run must not be taken
        for the new one's (it made the restarted skill fail at once as "cancelled").
        """
        return f"{skill_id}#{attempt}.{next(self._runs)}"

    def forget(self, run_id: str) -> None:
        """Drop what was heard about a run that is over (keeps the table small)."""
        with self._lock:
            self._status.pop(run_id, None)

    def status(self, run_id: str) -> wire.SkillRunStatus | None:
        """The latest status heard for a run."""
        with self._lock:
            return self._status.get(run_id)

    def send(
        self, run_id: str, action: int, skill: str = "", params: Mapping[str, Value] | None = None
    ) -> None:
        """Publish a skill-run request."""
        parameters = [param_to_msg(name, value) for name, value in (params or {}).items()]
        self._publisher.publish(
            wire.SkillRun(
                robot=self.robot, run_id=run_id, action=action, skill=skill, parameters=parameters
            )
        )


class ForwardedSkill(SkillBehavior):
    """Runs a skill on the robot's controllers and reports what they report."""

    def __init__(self, controller: RobotController, skill: str) -> None:
        self._controller = controller
        self._skill = skill
        self._ctx: SkillContext | None = None
        self._run_id = ""
        self._sent = 0.0
        self._last_text = ""

    def start(self, ctx: SkillContext) -> None:
        """Ask the controllers to start."""
        self._ctx = ctx
        self._run_id = self._controller.new_run_id(ctx.skill_id, ctx.attempt)
        self._send_start()

    def _send_start(self) -> None:
        assert self._ctx is not None
        self._controller.send(self._run_id, wire.SkillRun.START, self._skill, self._ctx.params)
        self._sent = time.monotonic()

    def update(self, now: float) -> Outcome | None:
        """Follow the controllers' status; resend START if nothing was heard yet."""
        assert self._ctx is not None
        status = self._controller.status(self._run_id)
        if status is None:
            if time.monotonic() - self._sent > RESEND_AFTER:
                self._send_start()
            return None
        if status.state == wire.SkillRunStatus.SUCCEEDED:
            self._controller.forget(self._run_id)
            return Outcome.ok(status.text)
        if status.state == wire.SkillRunStatus.FAILED:
            self._controller.forget(self._run_id)
            return Outcome.failed(status.text or "failed")
        if status.text and status.text != self._last_text:
            self._last_text = status.text
            self._ctx.progress(status.text)
        return None

    def pause(self) -> None:
        """Ask the controllers to hold still."""
        self._controller.send(self._run_id, wire.SkillRun.PAUSE)

    def resume(self) -> None:
        """Ask the controllers to go on."""
        self._controller.send(self._run_id, wire.SkillRun.RESUME)

    def cancel(self) -> None:
        """Ask the controllers to stop."""
        self._controller.send(self._run_id, wire.SkillRun.CANCEL)


def _skills(agent: str, kind: str) -> list[SkillType]:
    controller = RobotController(agent)
    return [
        SkillType(name, functools.partial(ForwardedSkill, controller, name))
        for name, sim_skill in SIM_SKILLS.items()
        if kind in sim_skill.kinds
    ]


def library(agent: str) -> Path:
    """The simulated team's library: it declares the parameters of these skills."""
    return LIBRARY


def drone_skills(agent: str) -> list[SkillType]:
    """The drone scout's skills."""
    return _skills(agent, "drone")


def science_rover_skills(agent: str) -> list[SkillType]:
    """The science rover's skills."""
    return _skills(agent, "science_rover")


def manipulator_rover_skills(agent: str) -> list[SkillType]:
    """The manipulator rover's skills."""
    return _skills(agent, "manipulator_rover")
