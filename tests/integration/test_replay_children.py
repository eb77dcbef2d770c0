"""The command window's replay (``rosmc replay`` and its marker node) ends with the window.

A real master and the real children: a process stands in for the command window and
starts them as the window does (:class:`ReplayProcess`), then is killed with -9, as a crash
would end it. The replay must not outlive it: rviz would follow a replay nobody can steer.
"""

from __future__ import annotations

import os
import signal
import sys
import textwrap
from typing import Any

import pytest

from rosmc_rviz_markers.ros.rviz_window import replay_running
from tests.conftest import wait_until
from tests.integration.server_fixtures import REPO
from tests.ros.recording_checks import SAMPLE

pytestmark = pytest.mark.integration

START = 120.0  # a replay and a marker node starting on a busy machine
WINDOW = textwrap.dedent(
    """
    import sys, time
    from rosmc_rqt_command.replay_process import ReplayProcess
    process = ReplayProcess(sys.argv[1], sys.argv[2])
    process.start()
    print("children", *process.pids, flush=True)
    time.sleep(3600)
    """
)


def children_of(window: Any) -> list[int]:
    """The children's process ids the window printed (empty until it has)."""
    for line in window.log().splitlines():
        if line.startswith("children "):
            return [int(word) for word in line.split()[1:]]
    return []


def ended(pid: int) -> bool:
    """Whether process ``pid`` has exited (gone, or a zombie nobody reaped yet)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().split(") ")[1].startswith("Z")
    except FileNotFoundError:
        return True


def test_a_killed_window_takes_its_replay_and_marker_node_with_it(
    ros_master: Any, launch_process: Any
) -> None:
    prefix = "/replay_killed_window"
    window = launch_process(
        [sys.executable, "-c", WINDOW, str(SAMPLE), prefix],
        env=ros_master.env,
        name="window",
        cwd=REPO,
    )
    children = wait_until(lambda: children_of(window), START, "the window started its replay")
    assert len(children) == 2, children  # the replay, its marker node
    wait_until(lambda: replay_running(prefix), START, "the replay publishing its state")

    os.kill(window.pid, signal.SIGKILL)

    for pid in children:
        wait_until(lambda pid=pid: ended(pid), 60.0, f"the window's child {pid} to end")
    wait_until(lambda: not replay_running(prefix), 60.0, "the master to forget the replay")
