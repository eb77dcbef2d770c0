"""The 20-robot station from one command, and GUIs and executors that come back by themselves.

One real ``roslaunch rosmc operator.launch sim:=true team:=twenty`` on its own master, the
command GUI in it (offscreen Qt; rviz needs a screen and is left out): every robot of the
scenario gets its executor and the server its 20 robots. An executor and the command GUI are
then killed with SIGKILL: each comes back as a new process under the same node name.
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from tests.conftest import LaunchProcess, wait_until
from tests.integration.test_station_restart import Station, station  # noqa: F401

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
START_TIMEOUT = 180.0  # twenty executors start on two cores
ROBOTS = [
    *(f"drone_{n}" for n in range(1, 7)),
    *(f"science_rover_{n}" for n in range(1, 8)),
    *(f"manipulator_rover_{n}" for n in range(1, 8)),
]


def test_the_twenty_robot_station_starts_from_one_command_and_heals(
    station: Station,  # noqa: F811
    launch_process: LaunchProcess,
    tmp_path: Path,
) -> None:
    env = dict(station.env, QT_QPA_PLATFORM="offscreen")
    launch = launch_process(
        [
            "roslaunch",
            "-p",
            station.uri.rsplit(":", 1)[1].strip("/"),
            "rosmc",
            "operator.launch",
            "sim:=true",
            "team:=twenty",
            "rviz:=false",
            "real_time_factor:=2",
            f"journal_dir:={tmp_path}",
        ],
        env=env,
        name="team_station",
        cwd=tmp_path,
    )
    executors = [f"/{robot}/mission_executor" for robot in ROBOTS]

    def up() -> bool:
        assert launch.poll() is None, launch.log()[-4000:]
        return all(station.pid(n) for n in (*executors, "/command_gui", "/rosmc/mission_server"))

    wait_until(up, START_TIMEOUT, "the twenty-robot station is up", period=1.0)
    agents = [agent["name"] for agent in station.status()["agents"]]
    assert set(ROBOTS) <= set(agents)

    for node in ("/drone_3/mission_executor", "/command_gui"):
        first = station.pid(node)
        assert first is not None
        os.kill(first, signal.SIGKILL)

        def again(node: str = node, first: int = first) -> bool:
            assert launch.poll() is None, launch.log()[-4000:]
            pid = station.pid(node)
            return pid is not None and pid != first

        wait_until(again, START_TIMEOUT, f"{node} comes back", period=1.0)
