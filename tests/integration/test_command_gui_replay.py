"""Replaying a recording in the command GUI, with the mouse only, beside a live server.

A real master and mission server, the real widget and bridges (offscreen Qt), and the
replay the GUI starts itself (``rosmc replay`` and the marker node as child processes)
of the committed sample recording. What the window shows is checked against the
recording read here: the mission and the robots at the start, at a clicked event and at
the end; then the live mission again, with the children gone.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from typing import Any

import pytest
import rosgraph
import rospy

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import QPoint, Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.core.legality import RobotAction
from rosmc_rqt_command.qt.science_strip import NO_REPLAY_SCORE
from rosmc_rqt_command.replay_ticks import TickKind
from rosmc_server.core.robots.link import LinkStatus
from rosmc_server.core.views.science import Science
from rosmc_server.recording import read_journal
from rosmc_server.recording.history import MissionHistory
from rosmc_server.ros.client import agent_statuses_from_msg
from tests.integration.server_fixtures import StartServer
from tests.integration.test_command_gui_server import (
    Window,
    answer_file_dialog,
    no_traceback,
    shown,
    wait_until,
)
from tests.ros.recording_checks import SAMPLE

pytest_plugins = ["tests.integration.server_fixtures"]

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.fixture(scope="module")
def history() -> MissionHistory:
    return MissionHistory.from_journal(SAMPLE)


@pytest.fixture
def window(client_node: Any) -> Iterator[Window]:
    app = QApplication.instance() or QApplication([])
    opened = Window()
    yield opened
    opened.widget.replay.close()
    opened.close()
    app.processEvents()


# A replay is a process of its own: on a busy machine it starts slowly, never wrongly.
START = 120.0


def statuses(window: Window) -> dict[str, tuple[float, float]]:
    """Where the window's robots are (x, y), by name."""
    return {
        agent: (status.pose.x, status.pose.y)
        for agent, status in window.w.view.statuses.items()
        if status.pose is not None
    }


def first_poses() -> dict[str, tuple[float, float]]:
    """Each robot's first recorded pose (x, y), from the recorded agent states."""
    found: dict[str, tuple[float, float]] = {}
    for record in read_journal(SAMPLE).records:
        if record.topic == "/rosmc/agent_states":
            for agent, status in agent_statuses_from_msg(record.message).items():
                if status.pose is not None:
                    found.setdefault(agent, (status.pose.x, status.pose.y))
    return found


def links(window: Window) -> dict[str, LinkStatus]:
    """The link each of the window's robots shows, by name."""
    return {agent: status.link for agent, status in window.w.view.statuses.items()}


def recorded_links(history: MissionHistory, seconds: float) -> dict[str, LinkStatus]:
    """The robots' links in the last agent states recorded at or before ``seconds``."""
    until = history.start + round(seconds * 1e9)
    last = None
    for record in read_journal(SAMPLE).records:
        if record.topic == "/rosmc/agent_states" and record.log_time <= until:
            last = record
    assert last is not None
    return {a: s.link for a, s in agent_statuses_from_msg(last.message).items()}


def marker_topics() -> set[str]:
    """The topics published on the master right now."""
    publishers, _subscribers, _services = rosgraph.Master("/test").getSystemState()
    return {topic for topic, _nodes in publishers}


def skill_statuses(window: Window) -> dict[str, str]:
    return {s.id: s.status.name for v in window.w.view.agents.values() for s in v.skills}


def recorded_statuses(history: MissionHistory, seconds: float) -> dict[str, str]:
    state = history.at_time(seconds)
    return {s.id: s.status.name for task in state.content().tasks.values() for s in task}


def select_first_skill(widget: Any) -> Any:
    """Click the first row of the first robot with skills; return its column."""
    agent = next(a for a, v in widget.view.agents.items() if v.skills)
    column = widget.tasks.columns[agent]
    synced = column.synced_table
    table = synced if synced.section.rowCount() else column.blueprint_table
    rect = table.visualRect(table.section.index(0, 2))
    QTest.mouseClick(table.viewport(), Qt.LeftButton, Qt.NoModifier, rect.center())
    wait_until(lambda: widget.parameters.skill is not None, 10, "a skill selected")
    return column


def read_only_controls_disabled(window: Window) -> None:
    """Every control that would change the mission is greyed out, not silently inert."""
    widget = window.w
    enabled = [a.text() for a in widget.actions_.skill.values() if a.isEnabled()]
    enabled += [a.text() for a in widget.actions_.all_robots.values() if a.isEnabled()]
    enabled += [n for n, a in widget.actions_.file.items() if a.isEnabled() and n != "save_as"]
    for agent, column in widget.tasks.columns.items():
        buttons = [*column.buttons.values(), column.add_button, column.policy_button]
        enabled += [f"{agent}: {b.text()}" for b in buttons if b.isEnabled()]
        if column.blueprint_table.dragEnabled():
            enabled.append(f"{agent}: dragging the task")
    panel = widget.parameters
    for editor in (panel.label_edit, panel.timeout_spin, panel.retries_spin):
        if editor.isEnabled():
            enabled.append(f"parameter {editor.objectName()}")
    assert enabled == [], enabled


def test_open_a_recording_seek_to_an_event_play_to_the_end_and_return_to_live(
    start_server: StartServer, window: Window, history: MissionHistory
) -> None:
    start_server()
    shown(window)
    window.add("drone", "take_off")
    wait_until(lambda: window.ids("drone"), 10, "the live take_off shown")
    live_ids = window.ids("drone")
    widget, mode = window.w, window.w.replay

    live_score = Science(0.7, 1)
    widget.science.show_science(live_score)  # as the live simulator published it
    # File > Open recording…, the file chosen in the dialog.
    file_menu = widget.menu_bar.actions()[0].menu()
    assert mode.open_action in file_menu.actions()
    answer_file_dialog(str(SAMPLE))
    mode.open_action.trigger()
    bar = mode.bar
    wait_until(lambda: bar.isVisible() and bar.play_button.isEnabled(), START, "the replay bar")
    assert mode.process is not None
    start = history.revision_at(0.0).revision
    wait_until(lambda: widget.view.revision == start, 20, f"the recording's r{start}")
    assert widget.backend.read_only and bar.play_button.text() == "Play"
    # Paused at the start, the live score is not shown as the recording's.
    assert widget.science.text() == NO_REPLAY_SCORE and widget.science.science is None
    assert bar.live_button.width() >= bar.live_button.sizeHint().width()  # not cut off

    # Paused at the start, the robots stand where the recording first heard them.
    expected = first_poses()
    assert len(expected) == 3 and len(set(expected.values())) == 3, expected
    wait_until(lambda: statuses(window) == expected, 20, "the robots where they stood")
    # rviz follows the same replay: the marker node the GUI started serves under /replay.
    wait_until(
        lambda: "/replay/rosmc/markers/update_full" in marker_topics(),
        30,
        "the replay's marker node for rviz",
    )

    # Clicking the tick of an event moves the replay there: the mission as it was then.
    tick = next(t for t in bar.slider.ticks if t.kind is TickKind.SUCCESS)
    x = bar.slider.x_of(tick.time)
    QTest.mouseClick(bar.slider, Qt.LeftButton, Qt.NoModifier, QPoint(x, 6))
    revision = history.revision_at(tick.time).revision
    wait_until(lambda: widget.view.revision == revision, 20, f"r{revision} at {tick.text}")
    assert skill_statuses(window) == recorded_statuses(history, tick.time)
    assert "SUCCESS" in skill_statuses(window).values()
    # The robots as recorded then (heard, their links up), though the replay is paused: it
    # published their states for the new time before it said it had moved.
    then = recorded_links(history, tick.time)
    assert set(then.values()) == {LinkStatus.UP}, then
    wait_until(lambda: links(window) == then, 20, "the robots' links as recorded then")
    wait_until(lambda: bar.shown and bar.shown.status.position == tick.time, 10, "the bar there")

    # Read-only: a skill selected, nothing that would change the mission can act.
    select_first_skill(widget)
    read_only_controls_disabled(window)
    assert mode.open_action.isEnabled() and bar.live_button.isEnabled()

    # Faster, play, and to the end: the window says so and offers the way back.
    for rate in (2.0, 4.0):
        QTest.mouseClick(bar.faster_button, Qt.LeftButton)
        wait_until(lambda r=rate: bar.shown and bar.shown.status.rate == r, 10, f"{rate:g}x")
    assert bar.rate_label.text() == "4x"
    QTest.mouseClick(bar.play_button, Qt.LeftButton)
    wait_until(lambda: bar.end_label.isVisible(), 30, "the end of the replay")
    last = history.revisions[-1].revision
    wait_until(lambda: widget.view.revision == last, 20, f"the last revision r{last}")
    window.said("The replay has ended")
    assert bar.live_button.isVisible() and bar.play_button.text() == "Play"

    # Return to live: the live mission, editable again, and the replay's processes gone.
    children = list(mode.process.pids)
    QTest.mouseClick(bar.live_button, Qt.LeftButton)
    wait_until(lambda: window.ids("drone") == live_ids, 20, "the live mission again")
    assert not bar.isVisible() and not widget.backend.read_only and mode.process is None
    column = widget.tasks.columns["drone"]
    wait_until(lambda: column.add_button.isEnabled(), 10, "adding skills enabled again")
    assert column.blueprint_table.dragEnabled()
    for pid in children:
        assert not os.path.exists(f"/proc/{pid}") or _zombie(pid), f"replay child {pid} runs"
    window.said("Back to the live mission")
    assert widget.science.science == live_score
    no_traceback(window)


def _zombie(pid: int) -> bool:
    with open(f"/proc/{pid}/stat") as stat:
        return stat.read().split(") ")[1].startswith("Z")


def test_following_a_replay_greys_out_what_cannot_act(
    client_node: Any, launch_process: Any, history: MissionHistory
) -> None:
    # The first whole second with skills (when the demo's first skill comes depends on
    # how busy the machine that recorded the sample was).
    start = next(s for s in range(int(history.duration) + 1) if history.at_time(s).skill_count)
    launch_process(
        [
            sys.executable,
            os.path.join(REPO, "scripts", "rosmc"),
            "replay",
            str(SAMPLE),
            "--prefix",
            "/following",
            "--start",
            str(start),
            "--paused",
            "--hold",
        ],
        name="replay",
    )
    rospy.wait_for_service("/following/rosmc/replay/control", timeout=START)
    app = QApplication.instance() or QApplication([])
    from rosmc_rqt_command.standalone import build

    widget, bridge = build("/following")
    widget.resize(1400, 800)
    widget.show()
    try:
        wait_until(lambda: widget.view.loaded and widget.tasks.columns, START, "the replay shown")
        column = select_first_skill(widget)
        assert not widget.parameters.label_edit.isEnabled()
        assert not column.blueprint_table.dragEnabled()
        assert not any(b.isEnabled() for b in column.buttons.values())
        assert not column.buttons[RobotAction.START].isEnabled()
    finally:
        widget.replay.close()
        bridge.close()
        widget.close()
        app.processEvents()
