"""Every shell command the docs show is run by a test.

The commands are taken from the shell blocks of README.md, CONTRIBUTING.md and docs/*.md
(:mod:`tests.integration.doc_commands`). The cheap ones run here as they are written (make
targets as a dry run, launch files with ``roslaunch --nodes``); the review and replay
commands of docs/replay.md, the command GUI and ``roscore`` run here too, against a real
master; every other command is registered with the test that runs it, and that test must
exist and contain the command as it runs it.
"""

from __future__ import annotations

import json
import os
import subprocess
import xmlrpc.client
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import RosMaster, free_port, master_answers, wait_until
from tests.integration.doc_commands import (
    DOC_COMMANDS,
    REPO,
    Evidence,
    cheap_run,
    commands_in,
    doc_commands,
    evidence_problems,
    undeclared_launch_args,
    unexercised,
)

pytestmark = pytest.mark.integration

COMMANDS = doc_commands(REPO)
SHOWN = {command.command for command in COMMANDS}
CHEAP = sorted({command.command for command in COMMANDS if cheap_run(command.command)})

# docs/replay.md, run as they are written, in a folder where bags/ is the repository's
REC = "REC=bags/samples/demo.mcap"
REVIEW_COMMANDS = (
    "rosmc info $REC",
    "rosmc at $REC 8.5",
    "rosmc at $REC r80 --json",
    "rosmc timeline $REC -o timeline.svg",
    "rosmc diff $REC r60 0:09",
    "rosmc tobag $REC mission.bag",
    "rosbag play --clock -r 20 mission.bag",
)
REPLAY_COMMANDS = ("rosmc replay $REC --rate 5", "rosmc replay $REC --start 6 --prefix /replay")
SEEK = 'rosservice call /rosmc/replay/control "{command: 2, time: 8.5}"'
PAUSE = 'rosservice call /rosmc/replay/control "{command: 0}"'
FOLLOW_REPLAY = ("rosmc replay $REC --prefix /replay &", "rosrun rosmc rosmc_command --ns /replay")


# -- the registry ----------------------------------------------------------------------


def test_the_docs_show_commands() -> None:
    paths = {command.path for command in COMMANDS}
    assert {"README.md", "CONTRIBUTING.md", "docs/replay.md", "docs/operator-guide.md"} <= paths
    assert len(SHOWN) >= 60


def test_every_command_in_the_docs_is_run_by_a_test() -> None:
    problems = unexercised(COMMANDS, DOC_COMMANDS)
    assert not problems, "\n".join(problems)


def test_each_registered_test_exists_and_runs_its_command() -> None:
    problems = evidence_problems(DOC_COMMANDS, REPO)
    assert not problems, "\n".join(problems)


def test_every_registered_command_is_still_in_the_docs() -> None:
    stale = sorted(set(DOC_COMMANDS) - SHOWN)
    assert not stale, f"DOC_COMMANDS lists commands no doc shows any more: {stale}"


def test_a_command_neither_run_nor_registered_fails() -> None:
    doc = "Text.\n\n```bash\nmake demo            # cheap: a dry run\nrosmc frobnicate --now\n```\n"
    problems = unexercised(commands_in(doc, "docs/new.md"), DOC_COMMANDS)
    assert problems == [
        "docs/new.md:5: `rosmc frobnicate --now` is shown in the docs but no test runs it: make "
        "it one the docs test runs itself, or add it verbatim to DOC_COMMANDS in "
        "tests/integration/doc_commands.py with the test that runs it"
    ]
    undo = "tests/integration/test_cli.py::test_undo_walks_back_and_redoes"
    wrong = {
        "rosmc frobnicate --now": Evidence(undo, ('"frobnicate"',)),
        "rosmc undo": Evidence("tests/integration/test_cli.py::test_no_such_test", ("undo",)),
    }
    assert evidence_problems(wrong, REPO) == [
        f"`rosmc frobnicate --now`: {undo} does not contain '\"frobnicate\"'",
        "`rosmc undo`: its test tests/integration/test_cli.py::test_no_such_test does not exist",
    ]


def test_commands_are_read_as_a_shell_reads_them() -> None:
    doc = "\n".join(
        [
            "```text",
            "rosmc not-a-command",
            "```",
            "  ```bash",
            "  # a comment line",
            '  rosservice call /x "{a: 1}  # inside quotes"   # a comment',
            "  rosmc add drone \\",
            "      take_off",
            "  ```",
            "```console",
            "$ rosmc status",
            "mission at revision 20",
            "```",
        ]
    )
    assert [(c.command, c.line) for c in commands_in(doc, "x.md")] == [
        ('rosservice call /x "{a: 1}  # inside quotes"', 6),
        ("rosmc add drone take_off", 7),
        ("rosmc status", 11),
    ]


def test_the_readme_test_command_is_what_ci_runs() -> None:
    readme = {c.command for c in COMMANDS if c.path == "README.md"}
    assert {"make demo", "make test"} <= readme
    ci = [line for line in (REPO / ".ci" / "run").read_text().splitlines() if line.strip()]
    assert ci[-1] == "make test", "CI must run exactly the README's test command"


# -- the cheap commands, run here ------------------------------------------------------


@pytest.mark.parametrize("command", CHEAP)
def test_the_cheap_commands_run(command: str, tmp_path: Path) -> None:
    argv = cheap_run(command)
    assert argv
    if argv[0] == "roslaunch":
        assert not undeclared_launch_args(command, REPO / "launch"), command
    env = {**os.environ, "ROS_HOME": str(tmp_path)}  # roslaunch writes its log there
    done = subprocess.run(
        argv, cwd=REPO, env=env, capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, f"{argv}:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    if argv[0] == "roslaunch":
        assert done.stdout.strip(), "the launch file starts no node"


def test_a_launch_argument_the_file_does_not_declare_is_found() -> None:
    command = "roslaunch rosmc sim.launch real_time_factor:=5 real_time:=5"
    assert undeclared_launch_args(command, REPO / "launch") == ["real_time"]


# -- the commands that need a master, run here as written ------------------------------


def shell(script: str, env: dict[str, str], cwd: Path, timeout: float = 120.0) -> Any:
    """Run ``script`` with bash after the doc's ``REC=`` line; the completed process."""
    return subprocess.run(
        ["bash", "-c", f"set -e\n{REC}\n{script}"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )


@pytest.fixture
def sandbox(tmp_path: Path) -> Path:
    """A working folder whose ``bags`` is the repository's (outputs stay in ``tmp_path``)."""
    (tmp_path / "bags").symlink_to(REPO / "bags", target_is_directory=True)
    return tmp_path


def ran(done: Any) -> str:
    assert done.returncode == 0, f"{done.args}:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    return str(done.stdout)


def test_the_review_commands_run_on_the_sample(ros_master: RosMaster, sandbox: Path) -> None:
    assert {REC, *REVIEW_COMMANDS} <= SHOWN
    env = dict(ros_master.env)
    out = {command: ran(shell(command, env, sandbox)) for command in REVIEW_COMMANDS}
    assert out["rosmc info $REC"].startswith("demo.mcap: ")
    assert out["rosmc at $REC 8.5"].startswith("=== demo.mcap at 8.5 s (revision ")
    assert json.loads(out["rosmc at $REC r80 --json"])["revision"] == 80
    assert "<svg" in (sandbox / "timeline.svg").read_text()
    assert out["rosmc diff $REC r60 0:09"].startswith("r60 (r60, ")
    assert out["rosmc tobag $REC mission.bag"].startswith("wrote mission.bag: ")


def _service_exists(master: RosMaster, name: str) -> bool:
    proxy = xmlrpc.client.ServerProxy(master.uri)
    code, _message, _uri = proxy.lookupService("/pytest", name)
    return bool(code == 1)


def test_the_replay_commands_run_against_a_master(
    ros_master: RosMaster, launch_process: Any, sandbox: Path
) -> None:
    assert {*REPLAY_COMMANDS, SEEK, PAUSE} <= SHOWN
    env = dict(ros_master.env)
    for command in REPLAY_COMMANDS:  # they play to the end and leave
        assert ran(shell(command, env, sandbox)).startswith("replaying bags/samples/demo.mcap")

    # the rosservice calls steer a replay held at its start
    held = f"{REC}\nexec rosmc replay $REC --paused --hold"
    launch_process(["bash", "-c", held], env=env, name="held", cwd=sandbox)
    wait_until(lambda: _service_exists(ros_master, "/rosmc/replay/control"), 60, "the replay")
    seek = ran(shell(SEEK, env, sandbox))
    assert "success: True" in seek and "position: 8.5" in seek, seek
    pause = ran(shell(PAUSE, env, sandbox))
    assert "paused: True" in pause, pause


def _subscribers(master: RosMaster, topic: str) -> list[str]:
    proxy = xmlrpc.client.ServerProxy(master.uri)
    _code, _message, (_publishers, subscribers, _services) = proxy.getSystemState("/pytest")
    return next((nodes for name, nodes in subscribers if name == topic), [])


def test_the_command_gui_commands_start_the_window(
    ros_master: RosMaster, launch_process: Any, sandbox: Path
) -> None:
    assert {*FOLLOW_REPLAY, "rosmc_command"} <= SHOWN
    env = {**ros_master.env, "QT_QPA_PLATFORM": "offscreen"}
    replay, follower = FOLLOW_REPLAY
    launch_process(["bash", "-c", f"{REC}\n{replay}\nwait"], env=env, name="replay", cwd=sandbox)
    gui = launch_process(["bash", "-c", follower], env=env, name="follower", cwd=sandbox)
    live = launch_process(["rosmc_command"], env=env, name="live", cwd=sandbox)

    def window_on(topic: str) -> list[str]:
        return [n for n in _subscribers(ros_master, topic) if n.startswith("/rosmc_command_")]

    wait_until(
        lambda: window_on("/replay/rosmc/mission_events"), 90, "the window following /replay"
    )
    wait_until(
        lambda: window_on("/rosmc/mission_events"), 90, "the window following the live names"
    )
    assert gui.poll() is None and live.poll() is None, "a window closed on its own"


def test_roscore_starts_a_master(launch_process: Any, tmp_path: Path) -> None:
    port = free_port()  # roscore takes its port from -p, not from ROS_MASTER_URI
    uri = f"http://127.0.0.1:{port}/"
    env = {**os.environ, "ROS_MASTER_URI": uri, "ROS_IP": "127.0.0.1", "ROS_HOME": str(tmp_path)}
    env.pop("ROS_HOSTNAME", None)
    launch_process(["roscore", "-p", str(port)], env=env, name="roscore")
    wait_until(lambda: master_answers(uri), 60, "roscore's master")

    def rosout_runs() -> bool:
        _code, _message, state = xmlrpc.client.ServerProxy(uri).getSystemState("/pytest")
        return any("/rosout" in nodes for _topic, nodes in state[0])  # it publishes /rosout_agg

    wait_until(rosout_runs, 60, "roscore's /rosout")


def test_the_resume_command_the_station_test_types_is_the_documented_one() -> None:
    # tests/integration/test_station_restart.py types DOC_RESUME as docs/replay.md shows it
    command = "roslaunch rosmc mission_server.launch journal:=bags/mission_X.mcap resume:=true"
    assert f"`{command}`" in (REPO / "docs" / "replay.md").read_text()
    station_test = (REPO / "tests" / "integration" / "test_station_restart.py").read_text()
    assert f'DOC_RESUME = "{command}"' in station_test
