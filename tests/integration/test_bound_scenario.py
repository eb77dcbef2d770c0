"""A skill bound by configuration runs in the simulated team, between simulated skills.

``tests/data/scenario_lab.yaml`` extends the Mars team's library (``extends``) with the
science rover's ``take_spectrum``, bound to an actionlib action server: the spectrometer,
played here by a real ``SimpleActionServer``. The team (server, sim, link emulator,
executors) runs on sim time as in ``test_scenarios.py``; the server and the executors read
the extended library.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import actionlib
import actionlib.msg as counting
import pytest
import rospy

from rosmc_server.core import Pose, SkillStatus
from tests.integration.executor_fixtures import stop_action_server
from tests.integration.scenario_fixtures import Operator, Team, TeamSettings

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
LIBRARY = REPO / "tests" / "data" / "scenario_lab.yaml"
SCIENCE = "science_rover"
S = SkillStatus


class Spectrometer:
    """The science rover's instrument: one feedback per exposure, then the count taken."""

    def __init__(self) -> None:
        self.goals: list[int] = []
        self._lock = threading.Lock()
        self.server = actionlib.SimpleActionServer(
            f"/{SCIENCE}/spectrometer", counting.TestAction, self._expose, auto_start=False
        )
        self.server.start()

    def close(self) -> None:
        """Withdraw the action server (its thread would outlive the tests)."""
        stop_action_server(self.server)

    def _expose(self, goal: Any) -> None:
        with self._lock:
            self.goals.append(goal.goal)
        for exposure in range(1, goal.goal + 1):
            self.server.publish_feedback(counting.TestFeedback(feedback=exposure))
        self.server.set_succeeded(counting.TestResult(result=goal.goal))


@pytest.fixture
def lab_team(ros_master: Any, tmp_path: Path) -> Iterator[tuple[Team, Operator, Spectrometer]]:
    """The simulated team with the extended library, its links up, and the spectrometer."""
    if not rospy.core.is_initialized():  # before /use_sim_time is set: this process keeps wall time
        rospy.init_node("bound_scenario_tests", anonymous=True, disable_signals=True)
    spectrometer = Spectrometer()
    team = Team(dict(ros_master.env), tmp_path, TeamSettings(library=LIBRARY))
    operator: Operator | None = None
    try:
        team.start()
        operator = Operator()
        operator.wait_links_up(timeout=60.0)
        yield team, operator, spectrometer
        assert not team.dead(), f"{team.dead()} died:\n{team.log_tails()}"
    finally:
        if operator is not None:
            operator.close()
        team.close()
        spectrometer.close()


def test_a_bound_skill_runs_in_the_simulated_team_after_a_simulated_one(
    lab_team: tuple[Team, Operator, Spectrometer],
) -> None:
    _, op, spectrometer = lab_team
    c = op.client
    drive = c.add_skill(SCIENCE, "navigate_to", {"target": Pose(3.0, 4.0), "speed": 1.0}).skill_id
    spectrum = c.add_skill(SCIENCE, "take_spectrum", {"exposures": 4}).skill_id
    op.sync_and_start([SCIENCE])
    state = op.wait_status([drive, spectrum], S.SUCCESS, timeout=120.0)

    assert spectrometer.goals == [4]
    assert state.skill(spectrum).status_text == "4 exposures taken"
    assert state.skill(spectrum).started >= state.skill(drive).finished
