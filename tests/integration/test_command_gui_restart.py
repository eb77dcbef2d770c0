"""The command GUI across mission server restarts (a crash that roslaunch heals).

A real master, real ``mission_server`` processes resuming one journal, a real executor, and
the real widget and ROS bridge (offscreen Qt). After each restart the message area says the
server restarted and from which revision; robot link states are the new server's, not what
the old one said; and the window's threads stay bounded over 20 restarts.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from python_qt_binding.QtWidgets import QApplication

from tests.conftest import LaunchProcess
from tests.integration.server_fixtures import REPO, ServerProcess, StartServer
from tests.integration.test_command_gui_server import Window, meanwhile, shown, wait_until

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

EXECUTOR = REPO / "scripts" / "mission_executor"
RESTARTS = 20
WARM_UP = 3  # restarts before the thread count is taken as the baseline
THREAD_SLACK = 3  # threads that may come and go (a retry timer, a connection being closed)


@pytest.fixture
def window(client_node: Any) -> Iterator[Window]:
    """One command window (offscreen), closed after the test."""
    app = QApplication.instance() or QApplication([])
    opened = Window()
    yield opened
    opened.close()
    app.processEvents()


def connected(window: Window) -> None:
    """The window has seen the server (so it can tell a restarted one from it)."""
    shown(window)
    window.said("Connected to the mission server")


def restarted_from(window: Window, revision: int, count: int) -> str:
    """The ``count``-th "restarted" message, which must name ``revision``."""

    def oldest_first() -> list[tuple[str, str]]:
        entries = reversed(window.w.messages.entries())
        return [(text, detail) for text, detail in entries if "restarted" in text]

    said = wait_until(lambda: oldest_first()[count - 1 :], 30, f"restart message {count}")
    text, detail = said[0]
    assert detail == f"restarted from mission revision {revision}", (text, detail)
    return text


def test_after_a_restart_the_window_says_so_and_shows_the_new_servers_robots(
    start_server: StartServer,
    window: Window,
    launch_process: LaunchProcess,
    client_node: Any,
    tmp_path: Path,
) -> None:
    journal = tmp_path / "station.mcap"
    server: ServerProcess = start_server(journal=journal, agent_state_rate=10.0)
    executor = launch_process(
        [sys.executable, str(EXECUTOR), "_agent:=drone", "_state_file:="],
        env=client_node.env,
        name="drone_executor",
        cwd=REPO,
    )
    connected(window)
    window.add("drone", "take_off")
    wait_until(lambda: window.ids("drone"), 10, "take_off shown")
    header = window.w.tasks.columns["drone"].status_label
    wait_until(lambda: "link up" in header.text(), 30, "the drone's link up")
    revision = window.bridge.mirror_revision
    assert revision is not None

    executor.kill()  # the robot is gone, and so is the server
    executor.wait()
    server.kill9()
    meanwhile(lambda: start_server(journal=journal, resume=True, agent_state_rate=10.0))
    restarted_from(window, revision, 1)
    wait_until(lambda: "never heard" in header.text(), 30, "the drone shown never heard")
    assert window.w.view.statuses["drone"].link == "unknown"
    assert window.ids("drone")  # the resumed mission is shown


def test_threads_stay_bounded_over_20_restarts(
    start_server: StartServer, window: Window, tmp_path: Path
) -> None:
    journal = tmp_path / "station.mcap"
    server: ServerProcess = start_server(journal=journal)
    connected(window)
    counts = []
    for restart in range(1, RESTARTS + 1):
        window.add("drone", "take_off")
        wait_until(lambda r=restart: len(window.ids("drone")) == r, 20, "the skill shown")
        revision = window.bridge.mirror_revision
        assert revision is not None
        server.kill9()
        if restart % 2:  # as roslaunch's respawn delay does: the window sees it gone first
            wait_until(lambda: window.w.banner.isVisibleTo(window.w), 20, "the banner")
        server = meanwhile(lambda: start_server(journal=journal, resume=True))
        restarted_from(window, revision, restart)
        wait_until(lambda: not window.w.banner.isVisibleTo(window.w), 20, "the banner gone")
        counts.append(threading.active_count())
    baseline = max(counts[:WARM_UP])
    print(f"threads after each restart: {counts}")
    assert max(counts[WARM_UP:]) <= baseline + THREAD_SLACK, counts
