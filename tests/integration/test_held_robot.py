"""A robot holding after its lost-link policy: said where the operator looks, freed by Resume.

Real rosmaster, mission server, link emulator and two executors; the real command widget
over its ROS bridge (offscreen Qt), the real marker node with rviz's side of its topics,
and the real ``rosmc status``. r1 holds when its link goes silent (policy ``hold``) while
its barrier partner r2 waits at their barrier; contact comes back and r1 still holds. The
command GUI, rviz's label and menu and ``rosmc status`` each say so with what frees it;
a mouse click on the warnings area's *Resume r1* frees it and r2 starts.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rospy

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication
from rosgraph_msgs.msg import Log
from visualization_msgs.msg import MarkerArray

from rosmc_rqt_command.qt.task_model import STATUS
from rosmc_rqt_command.standalone import build
from rosmc_rviz_markers import topics
from rosmc_server.core import LostLinkKind, LostLinkPolicy, SkillStatus
from rosmc_server.ros.client import MissionClient
from tests import conftest
from tests.integration.executor_fixtures import (
    LinkEnd,
    Operator,
    RosmcSystem,
    init_test_node,
    policy_words,
)
from tests.integration.markers_fixtures import MarkerNodeProcess, Rviz

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
S = SkillStatus
HELD = "r1 holds where it lost the link \u2014 its barrier partners r2 wait."
SHOTS = "ROSMC_SCREENSHOTS"  # a directory: the window with the held robot is saved there


def wait_until(condition: Any, timeout: float, what: str) -> Any:
    """Run the Qt event loop until ``condition()`` is truthy; fail after ``timeout``."""
    return conftest.wait_until(condition, timeout, what, pause=conftest.qt_pause)


class Holds:
    """The robots' "held after" lines on ``/rosout`` (what rqt_console shows)."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self._sub = rospy.Subscriber("/rosout", Log, self._on_log, queue_size=1000)

    def _on_log(self, msg: Log) -> None:
        if " held after " in msg.msg:
            self.lines.append(msg.msg)

    def close(self) -> None:
        self._sub.unregister()


class Icons:
    """The status blocks the marker node publishes, the latest text per namespace."""

    def __init__(self) -> None:
        self.texts: dict[str, list[str]] = {}
        self._sub = rospy.Subscriber(topics.ICONS_TOPIC, MarkerArray, self._on_icons)

    def _on_icons(self, msg: MarkerArray) -> None:
        for marker in msg.markers:
            self.texts.setdefault(marker.ns, [])
            self.texts[marker.ns] = [*self.texts[marker.ns][-20:], marker.text]

    def said(self, robot: str, words: str) -> bool:
        """Whether the newest texts of ``robot``'s block hold ``words``."""
        return any(words in text for text in self.texts.get(f"icons/{robot}", []))

    def close(self) -> None:
        self._sub.unregister()


@pytest.fixture
def system(ros_master: Any, tmp_path: Path) -> Iterator[tuple[RosmcSystem, Operator]]:
    """Server, r1 behind the link emulator, r2; both heard."""
    init_test_node()
    team = RosmcSystem(ros_master.env, tmp_path / "system")
    operator: Operator | None = None
    try:
        team.start_server()
        team.start_emulator(["r1"])
        team.start_executor("r1", True)
        team.start_executor("r2")
        operator = Operator()
        operator.wait_links(["r1", "r2"])
        yield team, operator
    finally:
        if operator is not None:
            operator.close()
        team.close()


def hold_r1_before_its_barrier(op: Operator) -> tuple[str, str, str]:
    """r1 works, then meets r2 at a barrier; r1's link goes silent and it holds."""
    with MissionClient(timeout=60.0) as client:
        client.set_lost_link_policy("r1", LostLinkPolicy(LostLinkKind.HOLD, after=1.0))
    conftest.wait_until(
        lambda: "hold after 1 s" in policy_words(op.agent_state("r1").lost_link),
        30.0,
        "r1's policy in force",
    )
    work = op.add("r1", "wait", {"duration": 12.0})
    meet_r1 = op.add("r1", "wait", {"duration": 0.1})
    meet_r2 = op.add("r2", "wait", {"duration": 0.1})
    op.add_barrier([meet_r1, meet_r2])
    op.sync("r1")
    op.sync("r2")
    op.wait_status([work, meet_r1, meet_r2], S.IDLE_SYNCHRONIZED)
    robot_side = LinkEnd("r1", "ground", robot_names=True)  # hears r1 behind the emulator
    conftest.wait_until(robot_side.connected, 30.0, "r1's side of the link")
    op.start("r1")
    op.start("r2")
    op.events.wait_went(work, S.RUNNING)
    op.wait_status([meet_r2], S.SYNCWAITING)
    op.blackout("r1", True)
    robot_side.wait_heard("report", lambda r: r.skill_id == work and r.status.value == S.PAUSED)
    robot_side.close()
    op.blackout("r1", False)
    conftest.wait_until(
        lambda: op.agent_state("r1").hold == "lost_link", 30.0, "the ground hears r1 hold"
    )
    return work, meet_r1, meet_r2


def rosmc_status(env: dict[str, str]) -> str:
    """What ``rosmc status`` prints."""
    done = subprocess.run(
        [sys.executable, str(REPO / "scripts" / "rosmc"), "status"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return done.stdout


def test_a_held_robot_is_said_everywhere_and_resume_frees_its_partners(
    system: tuple[RosmcSystem, Operator], ros_master: Any, tmp_path: Path
) -> None:
    team, op = system
    app = QApplication.instance() or QApplication([])
    markers = MarkerNodeProcess(dict(ros_master.env), tmp_path / "markers.log")
    icons = Icons()
    holds = Holds()
    widget, bridge = build(timeout=5.0)
    try:
        widget.resize(1600, 1000)  # as the other pictures of docs/
        widget.show()
        work, meet_r1, meet_r2 = hold_r1_before_its_barrier(op)

        # The command GUI: r1's header and the warnings say it, with Resume next to them.
        wait_until(lambda: "r1" in widget.tasks.columns, 30.0, "the mission shown")
        notice = widget.tasks.columns["r1"].hold_notice
        wait_until(lambda: notice.isVisible() and notice.text.text() == HELD, 30.0, "r1 held")
        widget.repaints.warn_now()
        assert HELD in widget.messages.warnings
        rows = widget.tasks.columns["r1"].synced_model
        assert rows.data(rows.index(0, STATUS)) == "holding (Resume frees it)"  # its work
        waits = widget.tasks.columns["r2"].wait_label
        wait_until(
            lambda: waits.text().startswith("r2 waits for r1 at barrier B1 since "),
            30.0,
            "r2 says whom it waits for",
        )
        button = widget.messages.hold_buttons["r1"]
        assert button.isVisible() and button.text() == "Resume r1"
        shots = os.environ.get(SHOTS)
        widget.grab().save(str(Path(shots or tmp_path) / "command_gui_held.png"))

        # rosmc status: the hold, whom it blocks and the command that frees it.
        text = rosmc_status(dict(ros_master.env))
        assert f"HOLDING: {HELD} Free it: rosmc resume r1" in text, text
        assert "r2 waits for r1 at barrier " in text and " since " in text, text

        # rviz: the label says it and the robot's menu has Resume.
        rviz = Rviz()
        try:
            assert "Resume" in rviz.titles("robot/r1")
            conftest.wait_until(
                lambda: icons.said("r1", "r1: holding \u2014 Resume from its menu"),
                60.0,
                "r1's label in rviz",
            )
        finally:
            rviz.close()

        # One click frees r1; it finishes its work, meets r2, and both go on.
        QTest.mouseClick(button, Qt.LeftButton)
        state = op.wait_status([work, meet_r1, meet_r2], S.SUCCESS, timeout=60.0)
        assert state.skill(meet_r2).started >= state.skill(work).finished
        # Held once, for the blackout: in contact, the ground's beats keep its policy (hold
        # after 1 s of silence) quiet for the rest of the 12 s work; a beat every 2 s, as
        # before the beats followed the policy, held it again and again.
        op.events.wait_went(work, S.SUCCESS)  # the mission may show it before the event
        went = op.events.statuses(work)
        assert went[went.index(S.RUNNING) :] == [S.RUNNING, S.PAUSED, S.RUNNING, S.SUCCESS], went
        wait_until(lambda: not notice.isVisible(), 30.0, "the notice goes")
        widget.repaints.warn_now()
        assert not widget.messages.hold_bar.isVisible()
        assert op.agent_state("r1").hold == ""
        assert len(holds.lines) == 1, holds.lines  # never again in contact
    finally:
        icons.close()
        holds.close()
        bridge.close()
        widget.close()
        widget.deleteLater()
        app.processEvents()
        markers.stop()
        del team
