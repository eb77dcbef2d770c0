"""The operator station heals itself: ``kill -9`` of the mission server in ``operator.launch``.

One real ``roslaunch rosmc operator.launch sim:=true`` (no rviz, no command GUI: they need
a display) on its own master, driven with the ``rosmc`` command as an operator would. The
server is killed with SIGKILL mid-mission; roslaunch starts it again, it resumes the journal
the first server was writing (the change acknowledged just before the kill is there), the
simulator, radio links, executors and marker node are the same processes, and the mission
goes on to its end.

Also: the manual resume command of docs/replay.md with a relative journal path, typed from a
working directory, reads and writes the journal there (not in ``ROS_HOME``).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import xmlrpc.client
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import LOOPBACK, LaunchProcess, free_port, stop_process, wait_until

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
ROSMC = REPO / "scripts" / "rosmc"
CALLER = "/station_test"
START_TIMEOUT = 90.0
MISSION_TIMEOUT = 240.0
# Every process of the launch that must outlive the server's crash.
KEPT_NODES = (
    "/rosmc/sim",
    "/rosmc/link_emulator",
    "/rosmc/markers",
    "/rosmc/team_executors",
    "/drone/mission_executor",
    "/science_rover/mission_executor",
    "/manipulator_rover/mission_executor",
)
SERVER = "/rosmc/mission_server"


class Station:
    """A private master's environment and the ``rosmc`` command on it."""

    def __init__(self, port: int, home: Path) -> None:
        self.uri = f"http://{LOOPBACK}:{port}/"
        env = dict(os.environ)
        env.pop("ROS_HOSTNAME", None)
        env.update(
            ROS_MASTER_URI=self.uri,
            ROS_IP=LOOPBACK,
            ROS_HOME=str(home),
            ROS_LOG_DIR=str(home / "log"),
            PYTHONUNBUFFERED="1",
        )
        self.env: Mapping[str, str] = env

    def rosmc(self, *args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
        """Run ``rosmc ARGS`` against this master."""
        result = subprocess.run(
            [sys.executable, str(ROSMC), "--timeout", "20", *args],
            env=dict(self.env),
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        if check:
            assert result.returncode == 0, f"rosmc {' '.join(args)}: {result.stderr}"
        return result

    def status(self) -> dict[str, Any]:
        """The mission as ``rosmc --json status`` prints it."""
        data: dict[str, Any] = json.loads(self.rosmc("--json", "status").stdout)
        return data

    def server_note(self) -> str | None:
        """The marker node's "mission server restarted ..." text in rviz, if it shows one."""
        result = subprocess.run(
            ["rostopic", "echo", "-n", "1", "/rosmc/markers/icons"],
            env=dict(self.env),
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        found = re.search(r'text: "(mission server restarted [^"]*)"', result.stdout)
        return found.group(1) if found else None

    def pid(self, node: str) -> int | None:
        """The process id of ``node`` (None if the master does not know it or it is gone)."""
        master = xmlrpc.client.ServerProxy(self.uri)
        try:
            code, _, uri = master.lookupNode(CALLER, node)
            if code != 1:
                return None
            code, _, pid = xmlrpc.client.ServerProxy(uri).getPid(CALLER)
        except (OSError, xmlrpc.client.Error):
            return None
        return int(pid) if code == 1 else None


def skills(status: Mapping[str, Any], agent: str) -> list[dict[str, Any]]:
    """The skills of ``agent`` in a ``rosmc --json status``."""
    entry = next(a for a in status["agents"] if a["name"] == agent)
    found: list[dict[str, Any]] = entry["skills"]
    return found


def statuses(station: Station, agent: str) -> list[str]:
    return [s["status"] for s in skills(station.status(), agent)]


@pytest.fixture
def station(tmp_path: Path) -> Station:
    home = tmp_path / "ros_home"
    (home / "log").mkdir(parents=True)
    return Station(free_port(), home)


def test_a_killed_server_comes_back_on_its_journal_and_the_team_goes_on(
    station: Station, launch_process: LaunchProcess, tmp_path: Path
) -> None:
    journal_dir = tmp_path / "journals"
    journal_dir.mkdir()
    launch = launch_process(
        [
            "roslaunch",
            "-p",
            station.uri.rsplit(":", 1)[1].strip("/"),
            "rosmc",
            "operator.launch",
            "sim:=true",
            "rviz:=false",
            "command_gui:=false",
            "real_time_factor:=4",
            f"journal_dir:={journal_dir}",
        ],
        env=station.env,
        name="operator_launch",
        cwd=tmp_path,
    )

    def up() -> bool:
        assert launch.poll() is None, launch.log()[-4000:]
        return all(station.pid(n) for n in (SERVER, *KEPT_NODES))

    wait_until(up, START_TIMEOUT, "the operator launch is up", period=0.5)
    station.rosmc("add", "drone", "take_off", "altitude=4")
    station.rosmc("add", "drone", "navigate_to", "target=12,0", "speed=1.5")
    station.rosmc("add", "drone", "land")
    station.rosmc("sync", "drone")
    station.rosmc("start", "drone")
    # Started, or already done: a poll on a busy machine may miss the seconds it runs.
    wait_until(
        lambda: statuses(station, "drone")[1] in ("RUNNING", "SUCCESS"),
        MISSION_TIMEOUT,
        "the drone flies to its target",
        period=0.5,
    )
    # The last change acknowledged before the crash.
    added = json.loads(station.rosmc("--json", "add", "science_rover", "explore").stdout)
    acknowledged = int(added["revision"])
    kept = {node: station.pid(node) for node in KEPT_NODES}
    first = station.pid(SERVER)
    assert first is not None
    journals = sorted(journal_dir.glob("*.mcap"))
    assert len(journals) == 1, journals

    os.kill(first, signal.SIGKILL)

    def restarted() -> int | None:
        assert launch.poll() is None, "the launch ended with the server:\n" + launch.log()[-4000:]
        pid = station.pid(SERVER)
        return pid if pid not in (None, first) else None

    wait_until(restarted, START_TIMEOUT, "the server is back", period=0.5)
    after = station.status()
    assert after["revision"] >= acknowledged
    assert [s["skill"] for s in skills(after, "science_rover")] == ["explore"]
    assert sorted(journal_dir.glob("*.mcap")) == journals  # the same journal, resumed
    assert "resumed from" in launch.log()

    # rviz: the marker node's status text says so (on the icons topic rviz shows).
    note = wait_until(station.server_note, 60, "the restart shown in rviz", period=1.0)
    assert int(note.rsplit(" ", 1)[1]) >= acknowledged, note

    wait_until(
        lambda: statuses(station, "drone") == ["SUCCESS"] * 3,
        MISSION_TIMEOUT,
        "the drone's mission ends",
        period=1.0,
    )
    assert {node: station.pid(node) for node in KEPT_NODES} == kept
    died = [line for line in launch.log().splitlines() if "has died" in line]
    assert died and all("mission_server" in line for line in died), died  # only the server


# As docs/replay.md shows it ("Crash recovery"); the first run writes the journal it names.
DOC_RESUME = "roslaunch rosmc mission_server.launch journal:=bags/mission_X.mcap resume:=true"


def typed_in(directory: Path, command: str) -> list[str]:
    """``command`` as a user types it in a shell after ``cd directory`` (which sets PWD)."""
    return ["bash", "-c", f"cd '{directory}' && exec {command}"]


def test_the_documented_resume_command_reads_the_journal_where_it_was_typed(
    station: Station, launch_process: LaunchProcess, tmp_path: Path
) -> None:
    work = tmp_path / "work"
    work.mkdir()
    first_run = DOC_RESUME.replace(" resume:=true", "")
    server = launch_process(typed_in(work, first_run), env=station.env, name="first_run")

    def serving() -> bool:
        assert server.poll() is None, server.log()[-4000:]
        return station.pid(SERVER) is not None

    wait_until(serving, START_TIMEOUT, "the server is up", period=0.5)
    station.rosmc("add", "drone", "take_off")
    stop_process(server)
    assert (work / "bags" / "mission_X.mcap").is_file()
    assert not list(Path(station.env["ROS_HOME"]).rglob("*.mcap"))

    server = launch_process(typed_in(work, DOC_RESUME), env=station.env, name="resume")
    wait_until(serving, START_TIMEOUT, "the server is up again", period=0.5)
    assert [s["skill"] for s in skills(station.status(), "drone")] == ["take_off"]
    assert f"resumed from {work / 'bags' / 'mission_X.mcap'}" in server.log()
