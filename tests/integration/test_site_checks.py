"""Skill targets checked against the site: the real sim node publishes it, a real server refuses.

The mission server runs the shipped Mars library (rover targets ``reachable_ground``, the
drone's targets and every area ``on_site``). It starts first, with no site known: a target
inside a boulder is accepted, and its log says once that targets are not checked. Then the
sim node publishes the Mars site latched on ``/rosmc/site`` and the server refuses, through
the ordinary error path of its services, a target inside an obstacle or off the site on
add, edit, marker move and load, with one sentence and nothing changed, while valid
targets pass.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import rospy
import yaml

from rosmc_server.core import MarkerType, Pose, RuleViolation, TaskMarker
from rosmc_server.ros.client import MissionClient
from tests.conftest import wait_until
from tests.integration.executor_fixtures import (
    RosmcSystem,
    init_test_node,
    start_process,
    stop_process,
)

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
LIBRARY = REPO / "rosmc_server" / "config" / "mars_team.yaml"
MARS = REPO / "rosmc_sim" / "scenarios" / "mars_sample_return.yaml"
SCIENCE, ARM, DRONE = "science_rover", "manipulator_rover", "drone"
UNCHECKED = "skill targets are not checked against the site: no site map is known yet"
SITE_KNOWN = "site 'mars_sample_return' from /rosmc/sim at "


def target(x: float, y: float) -> dict[str, object]:
    return {"target": {"x": x, "y": y}}


@pytest.fixture
def system(ros_master, tmp_path: Path) -> Iterator[RosmcSystem]:
    """The mission server on the Mars library (no simulator yet)."""
    init_test_node()
    running = RosmcSystem(ros_master.env, tmp_path, library=LIBRARY)
    running.start_server()
    yield running
    running.close()
    print(running.log_tails())
    with contextlib.suppress(KeyError):
        rospy.delete_param("/rosmc/sim")  # the sim node's private parameters outlive it


def server_log(system: RosmcSystem) -> str:
    return system.log("server").read_text(errors="replace")


def refused(call: object, *args: object, **kwargs: object) -> str:
    """Run a client call that must be refused by the mission rules; its one sentence."""
    assert callable(call)
    with pytest.raises(RuleViolation) as caught:
        call(*args, **kwargs)
    message = str(caught.value)
    assert "\n" not in message
    return message


def test_the_server_refuses_targets_the_simulated_site_rules_out(
    system: RosmcSystem, ros_master, tmp_path: Path
) -> None:
    client = MissionClient(timeout=30.0)
    # No site yet: nothing is checked, and the log says so once.
    early = [client.add_skill(SCIENCE, "navigate_to", target(x, 6.0)).skill_id for x in (9.0, 9.2)]
    wait_until(lambda: UNCHECKED in server_log(system), 30.0, "the server says it cannot check")
    assert server_log(system).count(UNCHECKED) == 1

    sim = start_process(
        [
            sys.executable,
            str(REPO / "scripts" / "sim_node"),
            f"_scenario:={MARS}",
            "_real_time_factor:=1.0",
        ],
        ros_master.env,
        tmp_path / "logs" / "sim.log",
    )
    try:
        wait_until(lambda: SITE_KNOWN in server_log(system), 30.0, "the server has the site")
        revision = client.get_mission().revision

        # add: inside a boulder, off the site; the drone flies over the boulder
        assert refused(client.add_skill, SCIENCE, "navigate_to", target(9.0, 6.0)) == (
            "target (9.0, 6.0) of science_rover's 'navigate_to' lies inside obstacle "
            "'boulder_1'; pick a point outside it"
        )
        assert refused(client.add_skill, ARM, "place_box", target(50.0, 3.0)) == (
            "target (50.0, 3.0) of manipulator_rover's 'place_box' lies off the site "
            "'mars_sample_return' (x -40 to 40 m, y -40 to 40 m); pick a point on it"
        )
        area = [{"x": 10, "y": 4}, {"x": 45, "y": 4}, {"x": 22, "y": 14}]
        message = refused(client.add_skill, DRONE, "fly_over", {"area": area})
        assert message.startswith("corner 2 (45.0, 4.0) of area of drone's 'fly_over' lies off")
        assert client.get_mission().revision == revision  # nothing changed
        client.add_skill(DRONE, "navigate_to", target(9.0, 6.0))
        drive = client.add_skill(SCIENCE, "navigate_to", target(12.0, 0.0)).skill_id
        assert client.get_mission().skill(drive).params["target"] == Pose(12.0, 0.0)

        # edit: onto the lander; the skill added before the site arrived keeps its target
        message = refused(client.edit_skill, drive, target(1.0, 0.5))
        assert message == (
            f"target (1.0, 0.5) of science_rover's 'navigate_to' ({drive}) lies inside "
            "obstacle 'lander'; pick a point outside it"
        )
        client.edit_skill(early[0], label="added before the site was known")
        assert client.get_mission().skill(drive).params["target"] == Pose(12.0, 0.0)

        # marker move: a bound target follows the marker, so the marker cannot go into the ridge
        client.add_task_marker(TaskMarker("spot", MarkerType.POSE, Pose(14.0, -2.0)))
        bound = client.add_skill(ARM, "navigate_to", bindings={"target": "spot"}).skill_id
        message = refused(client.move_task_marker, "spot", Pose(22.0, -9.0))
        assert message == (
            f"target (22.0, -9.0) of manipulator_rover's 'navigate_to' ({bound}), bound to "
            "marker 'spot', lies inside obstacle 'ridge'; pick a point outside it"
        )
        state = client.get_mission()
        assert state.marker("spot").pose == Pose(14.0, -2.0)
        assert state.skill(bound).params["target"] == Pose(14.0, -2.0)
        client.move_task_marker("spot", Pose(14.0, 2.0))

        # load: a saved mission whose blueprint drives into the outcrop
        client.delete_skills(early)
        document = client.save_mission().document
        data = yaml.safe_load(document)
        planned = next(s for s in data["tasks"][SCIENCE] if s["id"] == drive)
        planned["params"]["target"].update(x=13.0, y=16.0)
        bad = yaml.safe_dump(data, sort_keys=False)
        revision = client.get_mission().revision
        message = refused(client.load_mission, bad, base_revision=revision)
        assert "lies inside obstacle 'outcrop'; pick a point outside it" in message
        assert client.get_mission().revision == revision
        client.load_mission(document, base_revision=revision)
    finally:
        stop_process(sim)
        client.close()
