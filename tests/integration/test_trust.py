"""Trust on the ROS graph: site maps checked for sanity, and an operator allow-list.

A real master, a real ``mission_server`` and real nodes in their own processes: site maps
come from ``tests/integration/site_sender.py`` nodes with names of their own, and service
calls from the ``rosmc`` command line and from small client nodes named for the test.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rospy

from rosmc_server.core import NotPermitted, RuleViolation
from rosmc_server.interface import SITE_IN_FORCE_TOPIC
from rosmc_server.recording import read_journal
from rosmc_server.ros.client import MissionClient
from tests.conftest import wait_until
from tests.integration.executor_fixtures import start_process, stop_process
from tests.integration.server_fixtures import ServerProcess, StartServer

pytest_plugins = ["tests.integration.server_fixtures"]

REPO = Path(__file__).resolve().parents[2]
ROSMC = REPO / "scripts" / "rosmc"
ROVER = "science_rover"


class Senders:
    """Starts site-sender nodes; stops them all at the end."""

    def __init__(self, env: dict[str, str], logs: Path) -> None:
        self.env, self.logs = env, logs
        self.running: list[subprocess.Popen[bytes]] = []

    def start(self, name: str, obstacles: int, radius: float) -> subprocess.Popen[bytes]:
        argv = [sys.executable, "-m", "tests.integration.site_sender", name, str(obstacles)]
        process = start_process([*argv, repr(radius)], self.env, self.logs / f"{name}.log")
        self.running.append(process)
        return process

    def close(self) -> None:
        for process in self.running:
            stop_process(process)


@pytest.fixture
def senders(client_node: Any, tmp_path: Path) -> Iterator[Senders]:
    running = Senders(dict(client_node.env), tmp_path / "senders")
    yield running
    running.close()


def target(x: float, y: float) -> dict[str, object]:
    return {"target": {"x": x, "y": y}}


def refused(error: type[Exception], call: Any, *args: Any) -> str:
    with pytest.raises(error) as caught:
        call(*args)
    return str(caught.value)


def rosmc(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(ROSMC), *args], env=env, capture_output=True, text=True, timeout=60
    )


def journal_of(server: ServerProcess) -> Path:
    return max(Path(str(server.params["journal_dir"])).glob("*.mcap"))


def test_insane_site_maps_are_refused_naming_the_sender_and_the_map_in_force_stays(
    start_server: StartServer, senders: Senders, client_node: Any
) -> None:
    server = start_server()
    client = MissionClient(timeout=10.0)
    env = dict(client_node.env)
    # Before any map: status says none is in force.
    assert "site: no map in force" in rosmc(env, "status").stdout

    good = senders.start("site_provider", 3, 0.4)  # rocks at x = -30, -29, -28 on y = 0
    in_force = "site 'from_site_provider' from /site_provider at "
    wait_until(lambda: in_force in server.log(), 30.0, "the sane map in force")
    assert "inside obstacle 'rock_1'" in refused(
        RuleViolation, client.add_skill, ROVER, "navigate_to", target(-29.0, 0.0)
    )
    stop_process(good)  # the server keeps the map it took

    insane = [
        (2, 1e308, "obstacle 'rock_0' of site 'from_rogue_1' holds 1e+308, beyond the 100000 m"),
        (2001, 0.5, "site 'from_rogue_2' has 2001 obstacles, more than the 2000"),
    ]
    for number, (obstacles, radius, why) in enumerate(insane, 1):
        rogue = senders.start(f"rogue_{number}", obstacles, radius)
        warning = f"site map from /rogue_{number} on /rosmc/site refused: {why}"
        wait_until(lambda w=warning: w in server.log(), 30.0, f"the WARN about rogue {number}")
        stop_process(rogue)
    assert "[WARN]" in next(line for line in server.log().splitlines() if "/rogue_1" in line)

    # The sane map still decides: open ground is fine, the rock still is not.
    client.add_skill(ROVER, "navigate_to", target(10.0, 10.0))
    refused(RuleViolation, client.add_skill, ROVER, "navigate_to", target(-29.0, 0.0))

    lines = rosmc(env, "status").stdout.splitlines()
    assert any(line.startswith(in_force) for line in lines), lines
    site = json.loads(rosmc(env, "status", "--json").stdout)["site"]
    assert (site["name"], site["sender"], site["obstacles"]) == (
        "from_site_provider", "/site_provider", 3
    )  # fmt: skip

    server.stop()
    records = read_journal(journal_of(server), topics=[SITE_IN_FORCE_TOPIC]).records
    assert [(r.message.sender, r.message.site.name) for r in records] == [
        ("/site_provider", "from_site_provider")
    ]


ALLOWED_CLIENT = """
import sys, rospy
from rosmc_server.ros.client import MissionClient
rospy.init_node(sys.argv[1], disable_signals=True)
print(MissionClient(timeout=10.0).add_skill("drone", "take_off").skill_id)
"""


def call_as(env: dict[str, str], name: str) -> str:
    """``add_skill`` from a node called ``name``; the new skill's id."""
    done = subprocess.run(
        [sys.executable, "-c", ALLOWED_CLIENT, name],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_only_nodes_on_the_operator_allow_list_change_the_mission(
    start_server: StartServer, client_node: Any
) -> None:
    # docs/integrator-guide.md, "Deployment security": _operators:="[/station/, /trusted_operator]"
    start_server(operators="[/station/, /trusted_operator]")
    env = dict(client_node.env)
    client = MissionClient(timeout=10.0)
    revision = client.get_mission().revision  # reading stays open to every node

    me = rospy.get_name()
    assert refused(NotPermitted, client.add_skill, "drone", "take_off") == (
        f"node '{me}' may not call add_skill: it is not on the mission server's operator "
        "allow-list (~operators: /station/, /trusted_operator)"
    )
    cli = rosmc(env, "add", "drone", "take_off")
    assert cli.returncode == 1 and "rosmc: node '/rosmc_cli_" in cli.stderr, cli
    assert "may not call add_skill" in cli.stderr
    assert client.get_mission().revision == revision  # nothing changed

    by_name = call_as(env, "trusted_operator")
    # docs/integrator-guide.md: ROS_NAMESPACE=/station rosmc add drone take_off
    station = rosmc({**env, "ROS_NAMESPACE": "/station"}, "add", "drone", "take_off")
    assert station.returncode == 0, station.stderr
    mission = client.get_mission()
    first, _second = (s.id for s in mission.task("drone"))
    assert first == by_name and mission.revision == revision + 2
